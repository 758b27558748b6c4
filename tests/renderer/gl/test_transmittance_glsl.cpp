// renderer/shaders/transmittance_profile.glsl against its C++ mirror deonTransmittance()
// (renderer/sss/gaussian_sum_profile.h): a compute shader that includes the GLSL file evaluates T(s) on the GL
// device (llvmpipe in CI) for thicknesses 0…8 mm, in the context of the test process's shared Renderer (one
// context per process: the Renderer's GL objects are released at exit in its context). Label gl; skips with the
// EGL failure message without a context.
#include "render_test_support.h"
#include "renderer/sss/gaussian_sum_profile.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace skinlab::renderer;

namespace {

const char* kMain = R"(
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer Inputs { float thicknessMm[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 transmittance[]; };
void main() {
    uint i = gl_GlobalInvocationID.x;
    transmittance[i] = vec4(deonTransmittance(thicknessMm[i]), 0.0);
}
)";

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

} // namespace

TEST(TransmittanceGlsl, MatchesDeonTransmittance) {
    SKINLAB_REQUIRE_RENDERER(renderer); // its context is current on this thread
    (void)renderer;
    const std::string include =
        readFile(std::string(SKINLAB_SOURCE_DIR) + "/renderer/shaders/transmittance_profile.glsl");
    ASSERT_FALSE(include.empty());
    const std::string source = "#version 450 core\n" + include + kMain;
    const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    char log[4096] = {0};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    ASSERT_EQ(ok, GL_TRUE) << "transmittance_profile.glsl does not compile:\n" << log;
    const GLuint program = glCreateProgram();
    glAttachShader(program, shader);
    glLinkProgram(program);
    glDeleteShader(shader);
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    ASSERT_EQ(ok, GL_TRUE);

    std::vector<float> thicknesses;
    for (int i = 0; i <= 64; ++i) thicknesses.push_back(0.125f * static_cast<float>(i)); // 0…8 mm
    GLuint buffers[2];
    glCreateBuffers(2, buffers);
    glNamedBufferStorage(buffers[0], GLsizeiptr(thicknesses.size() * sizeof(float)), thicknesses.data(), 0);
    glNamedBufferStorage(buffers[1], GLsizeiptr(thicknesses.size() * 4 * sizeof(float)), nullptr, GL_MAP_READ_BIT);
    glUseProgram(program);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffers[0]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffers[1]);
    glDispatchCompute(static_cast<GLuint>(thicknesses.size()), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> out(thicknesses.size() * 4);
    glGetNamedBufferSubData(buffers[1], 0, GLsizeiptr(out.size() * sizeof(float)), out.data());
    ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    double largest = 0.0;
    for (std::size_t i = 0; i < thicknesses.size(); ++i) {
        const auto expected = sss::deonTransmittance(thicknesses[i]);
        for (int c = 0; c < 3; ++c) {
            // float32 exp on the device against double: 1e-6 absolute on values ≤ 1.
            EXPECT_NEAR(out[i * 4 + static_cast<std::size_t>(c)], expected[static_cast<std::size_t>(c)], 1e-6)
                << "s = " << thicknesses[i] << " mm, channel " << c;
            largest = std::max(
                largest, std::abs(out[i * 4 + static_cast<std::size_t>(c)] - expected[static_cast<std::size_t>(c)]));
        }
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[static_cast<std::size_t>(c)], 1.0f, 1e-6f); // T(0) = 1 per channel
    std::printf("transmittance_profile.glsl vs deonTransmittance(), 65 thicknesses 0-8 mm: largest difference %.2g\n",
                largest);
    glDeleteBuffers(2, buffers);
    glDeleteProgram(program);
}
