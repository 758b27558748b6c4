// `skinlab render` end to end through the real executable (SKINLAB_CLI): outputs, --timings, --png, and every
// bad-input case: non-zero exit, one line naming what and where, no output file (not even a temporary one).
#include "render_test_support.h"

#include <cstdlib>
#include <fstream>
#include <regex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <sys/wait.h>

namespace skinlab::renderer {
namespace {

struct CliRun {
    int exitCode = -1;
    std::string out;
    std::string err;
};

std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

CliRun runCli(const std::vector<std::string>& arguments, const test::TempFolder& folder,
              const std::string& environment = "") {
    std::string command = environment + " " + quote(SKINLAB_CLI);
    for (const auto& a : arguments) command += " " + quote(a);
    const auto outPath = folder.path().parent_path() / (folder.path().filename().string() + ".stdout");
    const auto errPath = folder.path().parent_path() / (folder.path().filename().string() + ".stderr");
    command += " > " + quote(outPath.string()) + " 2> " + quote(errPath.string());
    const int status = std::system(command.c_str());
    CliRun run;
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.out = test::readText(outPath);
    run.err = test::readText(errPath);
    std::filesystem::remove(outPath);
    std::filesystem::remove(errPath);
    return run;
}

// The error line of a failed run: stderr holds exactly one line starting "skinlab: error: " (log lines of
// spdlog start with "[").
std::string errorLine(const CliRun& run) {
    std::string line;
    int lines = 0;
    std::istringstream in(run.err);
    for (std::string l; std::getline(in, l);)
        if (!l.empty() && l[0] != '[') {
            line = l;
            ++lines;
        }
    return lines == 1 ? line : "(" + std::to_string(lines) + " non-log lines) " + run.err;
}

bool folderIsEmpty(const std::filesystem::path& folder) { return std::filesystem::is_empty(folder); }

bool eglAvailable() { return test::sharedRenderer() != nullptr; }

class RenderCli : public ::testing::Test {
protected:
    test::TempFolder folder{"cli"};
    test::TempFolder out{"cli-out"};
    std::filesystem::path write(const std::string& name, const std::string& text) {
        std::ofstream(folder / name, std::ios::binary) << text;
        return folder / name;
    }
    std::filesystem::path sceneWith(const std::string& body) { return write("scene.toml", body); }
};

TEST_F(RenderCli, RendersExrPngAndTimings) {
    if (!eglAvailable()) GTEST_SKIP() << "no EGL: " << test::rendererFailure();
    const CliRun run =
        runCli({"render", "--scene", "builtin:ear", "--width", "64", "--height", "40", "-o", (out / "ear.exr").string(),
                "--png", (out / "ear.png").string(), "--timings", (out / "t.json").string()},
               folder);
    ASSERT_EQ(run.exitCode, 0) << run.err;
    const test::ExrImage image = test::readExr(out / "ear.exr");
    EXPECT_EQ(image.width, 64);
    EXPECT_EQ(image.height, 40);
    int width = 0, height = 0;
    test::readPng(out / "ear.png", width, height);
    EXPECT_EQ(width, 64);
    const nlohmann::json timings = nlohmann::json::parse(test::readText(out / "t.json"));
    EXPECT_TRUE(timings["passes"].contains("main"));
    EXPECT_GT(timings["wall_total"].get<double>(), 0.0);
    EXPECT_EQ(timings["width"], 64);
    // Milliseconds to the microsecond (no "1.9999999999999998e-05"), and no status line a user cannot act on.
    const std::string text = test::readText(out / "t.json");
    EXPECT_FALSE(std::regex_search(text, std::regex("[0-9]\\.[0-9]{4,}"))) << text;
    EXPECT_FALSE(std::regex_search(text, std::regex("[0-9][eE][-+]?[0-9]"))) << text;
    EXPECT_EQ(text.find("timer_check"), std::string::npos) << text;
}

TEST_F(RenderCli, UnknownBuiltinScene) {
    const CliRun run = runCli({"render", "--scene", "builtin:torso", "-o", (out / "x.exr").string()}, folder);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(errorLine(run),
              "skinlab: error: unknown built-in scene 'builtin:torso' (known: builtin:halo, "
              "builtin:bleed, builtin:ear, builtin:head, builtin:halo-grey-backdrop, builtin:bleed-true-mask)");
    EXPECT_TRUE(folderIsEmpty(out.path()));
}

TEST_F(RenderCli, BadSpecValueThroughSet) {
    const CliRun run = runCli(
        {"render", "--scene", "builtin:head", "--set", "camera.fov_deg=500", "-o", (out / "x.exr").string()}, folder);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(errorLine(run), "skinlab: error: builtin:head: camera.fov_deg: 500 is out of range [1, 179]");
    EXPECT_TRUE(folderIsEmpty(out.path()));
}

TEST_F(RenderCli, UnknownKeyInSpecFile) {
    const auto spec = sceneWith("[model]\nsource = \"builtin:halo\"\n[camera]\nfov = 20\n");
    const CliRun run = runCli({"render", "--scene", spec.string(), "-o", (out / "x.exr").string()}, folder);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(errorLine(run), "skinlab: error: " + spec.string() + ": camera.fov: unknown key");
    EXPECT_TRUE(folderIsEmpty(out.path()));
}

TEST_F(RenderCli, MissingModelFile) {
    const auto spec = sceneWith("[model]\nsource = \"missing.glb\"\n");
    const CliRun run = runCli({"render", "--scene", spec.string(), "-o", (out / "x.exr").string()}, folder);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(errorLine(run), "skinlab: error: " + spec.string() +
                                  ": model.source: file not found: " + (folder / "missing.glb").string());
    EXPECT_TRUE(folderIsEmpty(out.path()));
}

TEST_F(RenderCli, CorruptModelTextureAndEnvironment) {
    if (!eglAvailable()) GTEST_SKIP() << "no EGL: " << test::rendererFailure();
    write("corrupt.glb", "glTF this is not a binary glTF file");
    write("corrupt.jpg", "\xff\xd8\xff not a JPEG");
    write("corrupt.hdr", "#?RADIANCE\nnot an image\n");
    struct Case {
        std::string body;
        std::string expectedStart;
    };
    const std::vector<Case> cases = {
        {"[model]\nsource = \"corrupt.glb\"\n", (folder / "corrupt.glb").string() + ": cannot load model"},
        {"[model]\nsource = \"builtin:halo\"\n[textures]\nalbedo = \"corrupt.jpg\"\n",
         (folder / "corrupt.jpg").string() + ": cannot read texture"},
        {"[model]\nsource = \"builtin:halo\"\n[environment]\nfile = \"corrupt.hdr\"\n",
         (folder / "corrupt.hdr").string() + ": cannot read environment"},
    };
    for (const Case& c : cases) {
        const auto spec = sceneWith(c.body);
        const CliRun run = runCli(
            {"render", "--scene", spec.string(), "-o", (out / "x.exr").string(), "--png", (out / "x.png").string()},
            folder);
        EXPECT_EQ(run.exitCode, 2) << c.body << run.err;
        const std::string line = errorLine(run);
        EXPECT_EQ(line.rfind("skinlab: error: " + c.expectedStart, 0), 0u) << line;
        EXPECT_TRUE(folderIsEmpty(out.path())) << c.body;
    }
}

TEST_F(RenderCli, UnwritableOutput) {
    write("a-file", "x");
    const std::string target = (folder / "a-file" / "out.exr").string();
    const CliRun run = runCli({"render", "--scene", "builtin:halo", "-o", target}, folder);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(errorLine(run), "skinlab: error: " + target + ": cannot write -o output (folder " +
                                  (folder / "a-file").string() + " does not exist)");
}

TEST_F(RenderCli, UnwritableOutputDetectedWhileWritingLeavesNoFile) {
    if (!eglAvailable()) GTEST_SKIP() << "no EGL: " << test::rendererFailure();
    // The EXR's folder exists but the final name is a folder: rename fails after rendering; nothing remains.
    std::filesystem::create_directories(out / "taken.exr");
    const CliRun run = runCli(
        {"render", "--scene", "builtin:halo", "--width", "32", "--height", "32", "-o", (out / "taken.exr").string()},
        folder);
    EXPECT_NE(run.exitCode, 0);
    EXPECT_EQ(errorLine(run).rfind("skinlab: ", 0), 0u) << run.err;
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(out.path())) names.push_back(entry.path().filename());
    EXPECT_EQ(names, std::vector<std::string>{"taken.exr"}); // no temporary left behind
}

TEST_F(RenderCli, UnknownMethod) {
    const CliRun run =
        runCli({"render", "--scene", "builtin:halo", "--method", "magic", "-o", (out / "x.exr").string()}, folder);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(errorLine(run).rfind("skinlab: error: builtin:halo: sss.method: 'magic' is not one of:", 0), 0u)
        << errorLine(run);
    EXPECT_TRUE(folderIsEmpty(out.path()));
}

TEST_F(RenderCli, ShaderFolderOverrideAndShaderErrorsNameTheFile) {
    if (!eglAvailable()) GTEST_SKIP() << "no EGL: " << test::rendererFailure();
    // A copy of the shaders renders the same image as the embedded ones ...
    const auto shaders = folder / "shaders";
    std::filesystem::copy(std::filesystem::path(SKINLAB_SOURCE_DIR) / "renderer/shaders", shaders);
    const std::vector<std::string> arguments = {"render", "--scene", "builtin:bleed", "--width", "32", "--height",
                                                "32",     "-o"};
    auto withOutput = [&](const std::string& name) {
        auto a = arguments;
        a.push_back((out / name).string());
        return a;
    };
    ASSERT_EQ(runCli(withOutput("embedded.exr"), folder).exitCode, 0);
    ASSERT_EQ(runCli(withOutput("folder.exr"), folder, "SKINLAB_SHADER_DIR=" + quote(shaders.string())).exitCode, 0);
    EXPECT_EQ(test::readText(out / "embedded.exr"), test::readText(out / "folder.exr"));
    // ... and a broken one fails with the file name and the driver's info log (exit 1: not the user's input).
    std::ofstream(shaders / "add_specular.frag", std::ios::app) << "\nthis is not GLSL\n";
    const CliRun run = runCli(withOutput("broken.exr"), folder, "SKINLAB_SHADER_DIR=" + quote(shaders.string()));
    EXPECT_EQ(run.exitCode, 1);
    EXPECT_NE(
        run.err.find("skinlab: failure: shader add_specular.frag: compile failed (sources: 0 = add_specular.frag): 0:"),
        std::string::npos)
        << run.err;
    EXPECT_FALSE(std::filesystem::exists(out / "broken.exr"));
}

} // namespace
} // namespace skinlab::renderer
