#pragma once
// GLSL sources of renderer/shaders/, embedded into the binary at build time (cmake/SkinlabEmbed.cmake) and
// validated at build time with glslangValidator (SKINLAB_VALIDATE_SHADERS). Setting the environment variable
// SKINLAB_SHADER_DIR to a folder loads the sources from there instead (edit a shader, re-run, no rebuild).
//
// Source conventions: the first line is `#version 450 core`; `#include "name.glsl"` lines (with
// `#extension GL_GOOGLE_include_directive : require`, so glslangValidator can follow them) are replaced by the
// named file; a prelude of `#define NAME VALUE` lines (variants) is inserted right after the version line.
#include "renderer/gl/gl_resources.h"

#include <glm/glm.hpp>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace skinlab::renderer::gl {

using ShaderDefines = std::vector<std::pair<std::string, std::string>>;

class ShaderLibrary {
public:
    // Reads SKINLAB_SHADER_DIR once.
    ShaderLibrary();

    // The source of `name` (e.g. "main_pass.frag") with includes resolved and `defines` inserted.
    // Throws RuntimeError naming the file when it does not exist.
    std::string source(const std::string& name, const ShaderDefines& defines = {}) const;

    // A linked program (cached by names + defines). Compile/link failures throw RuntimeError with the shader
    // file name and the driver's info log.
    GLuint program(const std::string& vertexName, const std::string& fragmentName, const ShaderDefines& defines = {});

    // Where sources come from: "embedded" or the folder of SKINLAB_SHADER_DIR.
    std::string origin() const;

    // Draws one triangle covering the viewport (vertex shader fullscreen.vert, no vertex attributes).
    void drawFullscreenTriangle();

private:
    std::string raw(const std::string& name) const;
    std::string shaderDirectory_;
    std::map<std::string, Program> programs_;
    VertexArray emptyVertexArray_;
};

// Uniform setters by name. A name the program's sources do not declare is an error (RuntimeError); one the linker
// removed as unused is ignored, as GL does for location -1 (shader_checks.h).
void setUniform(GLuint program, const char* name, float value);
void setUniform(GLuint program, const char* name, int value);
void setUniform(GLuint program, const char* name, const glm::vec2& value);
void setUniform(GLuint program, const char* name, const glm::vec3& value);
void setUniform(GLuint program, const char* name, const glm::vec4& value);
void setUniform(GLuint program, const char* name, const glm::mat4& value);
void setUniform(GLuint program, const char* name, const glm::mat3& value);
void setUniformArray(GLuint program, const char* name, const glm::vec3* values, int count);

} // namespace skinlab::renderer::gl
