// ShaderLibrary (renderer/gl/shader_library.h), label gl: compile errors name the right file and line after an
// #include, uniform names are checked against the program's sources, and every listed variant compiles and links.
#include "render_test_support.h"
#include "renderer/gl/egl_context.h"
#include "renderer/gl/shader_checks.h"
#include "renderer/gl/shader_library.h"

#include "common/error.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <latch>
#include <string>
#include <thread>

namespace skinlab::renderer {
namespace {

namespace fs = std::filesystem;

// A folder for SKINLAB_SHADER_DIR with fullscreen.vert from the sources, an include of `includeLines` lines and
// a copy.frag (a listed variant) that includes it and fails in main() at line 6.
class ShaderFolder {
public:
    ShaderFolder() {
        fs::copy_file(fs::path(SKINLAB_SOURCE_DIR) / "renderer/shaders/fullscreen.vert", folder_ / "fullscreen.vert",
                      fs::copy_options::overwrite_existing);
    }
    ~ShaderFolder() { ::unsetenv("SKINLAB_SHADER_DIR"); }
    void write(const std::string& name, const std::string& text) const { folder_.write(name, text); }
    const fs::path& path() const { return folder_.path(); }

private:
    const test_support::TempFolder folder_{"shader-lines"};
};

std::string compileError(const ShaderFolder& folder) {
    ::setenv("SKINLAB_SHADER_DIR", folder.path().c_str(), 1);
    gl::ShaderLibrary library; // reads SKINLAB_SHADER_DIR
    try {
        library.program("fullscreen.vert", "copy.frag");
    } catch (const RuntimeError& e) {
        return e.what();
    }
    return "no error";
}

} // namespace

TEST(ShaderLibrary, CompileErrorsKeepTheLinesOfTheFilesAfterAnInclude) {
    SKINLAB_REQUIRE_RENDERER(renderer); // its context is current on this thread
    (void)renderer;
    ShaderFolder folder;
    std::string include;
    for (int i = 0; i < 40; ++i) include += "// line " + std::to_string(i + 1) + " of the include\n";
    include += "float helper(float x) { return 2.0 * x; }\n"; // line 41
    folder.write("lines.glsl", include);
    folder.write("copy.frag", "#version 450 core\n"
                              "#extension GL_GOOGLE_include_directive : require\n"
                              "#include \"lines.glsl\"\n"
                              "out vec4 colour;\n"
                              "void main() {\n"
                              "    colour = vec4(helper(undeclaredName));\n" // line 6 of copy.frag
                              "}\n");
    const std::string error = compileError(folder);
    // Mesa writes SOURCE:LINE(COLUMN); the file itself is source 0, the include source 1.
    EXPECT_NE(error.find("0:6("), std::string::npos) << error;
    EXPECT_NE(error.find("undeclaredName"), std::string::npos) << error;
    EXPECT_NE(error.find("sources: 0 = copy.frag, 1 = lines.glsl"), std::string::npos) << error;

    // An error inside the include names the include's own line.
    folder.write("lines.glsl", include + "float broken() { return undeclaredInInclude; }\n"); // line 42
    folder.write("copy.frag", "#version 450 core\n"
                              "#extension GL_GOOGLE_include_directive : require\n"
                              "#include \"lines.glsl\"\n"
                              "out vec4 colour;\n"
                              "void main() { colour = vec4(1.0); }\n");
    const std::string inInclude = compileError(folder);
    EXPECT_NE(inInclude.find("1:42("), std::string::npos) << inInclude;
}

TEST(ShaderLibrary, UniformNamesAreCheckedAgainstTheSources) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    (void)renderer;
    gl::ShaderLibrary library;
    const GLuint copy = library.program("fullscreen.vert", "copy.frag");
    EXPECT_NO_THROW(gl::setUniform(copy, "source", 0));
    try {
        gl::setUniform(copy, "sourse", 0);
        FAIL() << "no error for an unknown uniform";
    } catch (const RuntimeError& e) {
        EXPECT_STREQ(e.what(), "uniform sourse: not declared in shaders fullscreen.vert + copy.frag");
    }
    // Array elements of a declared array resolve; declared but compiled out (another variant) is ignored.
    const GLuint mainPass = library.program("main_pass.vert", "main_pass.frag");
    EXPECT_GE(gl::uniformLocation(mainPass, "lightType[1]"), 0);
    EXPECT_THROW(gl::uniformLocation(mainPass, "lightTipe[1]"), RuntimeError);
    const GLuint blur = library.program("fullscreen.vert", "sss_blur.frag");
    EXPECT_NO_THROW(gl::setUniform(blur, "extensionCbf", 0));
    EXPECT_THROW(library.program("fullscreen.vert", "sss_blur.frag", {{"NO_SUCH_SWITCH", "1"}}), RuntimeError);
}

// Program names are per context: two contexts on two threads (a stimulus build's parallel jobs) link different
// programs under the same names, and each keeps its own uniform table.
TEST(ShaderLibrary, ContextsOnOtherThreadsKeepTheirOwnUniformTables) {
    SKINLAB_REQUIRE_RENDERER(renderer); // skips where no context can be made
    (void)renderer;
    std::latch linked(2);
    std::string errors[2];
    auto job = [&](int index) {
        bool counted = false;
        try {
            gl::EglContext context; // current on this thread
            gl::ShaderLibrary library;
            // Fresh contexts hand out the same names in the same order: thread 0 gets copy.frag, thread 1 the
            // main pass under that name.
            const GLuint program = index == 0 ? library.program("fullscreen.vert", "copy.frag")
                                              : library.program("main_pass.vert", "main_pass.frag");
            counted = true;
            linked.arrive_and_wait();
            for (int i = 0; i < 2000; ++i) {
                if (index == 0) gl::setUniform(program, "source", 0);
                else gl::setUniform(program, "irradianceSH[2]", glm::vec3(0.0f));
            }
        } catch (const std::exception& e) {
            errors[index] = e.what();
            if (!counted) linked.count_down();
        }
    };
    std::thread first(job, 0);
    std::thread second(job, 1);
    first.join();
    second.join();
    EXPECT_EQ(errors[0], "");
    EXPECT_EQ(errors[1], "");
}

// Every variant the passes may ask for compiles and links (shaderVariants(); ShaderLibrary refuses any other).
TEST(ShaderLibrary, EveryVariantCompilesAndLinks) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    (void)renderer;
    gl::ShaderLibrary library;
    ASSERT_GE(gl::shaderVariants().size(), 19u);
    for (const gl::ShaderVariant& variant : gl::shaderVariants()) {
        std::string name = variant.vertex + " + " + variant.fragment;
        for (const auto& [key, value] : variant.defines) name += " " + key + "=" + value;
        EXPECT_NO_THROW(library.program(variant.vertex, variant.fragment, variant.defines)) << name;
    }
}

} // namespace skinlab::renderer
