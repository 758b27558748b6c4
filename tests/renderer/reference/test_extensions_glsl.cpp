// renderer/shaders/sss_extensions.glsl against its C++ mirror renderer/sss/extension_weights.h: a compute shader
// that includes the GLSL file evaluates every function on a set of cases on the GL device (llvmpipe in CI) and the
// results must match the C++ functions. Label gl; skips with the EGL failure message where no context exists.
#include "common/error.h"
#include "renderer/gl/egl_context.h"
#include "renderer/sss/extension_weights.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using namespace skinlab::renderer;
using namespace skinlab::renderer::sss;

namespace {
struct Case {
    glm::vec3 rgb, viewPosition, viewNormal, otherRgb;
    float beta, lambda, curvaturePerUnit, floor;
};

// Inputs per case: 5 vec4; outputs: 4 vec4 (see the shader's main()).
const char* kMain = R"(
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 outputs[]; };
uniform float mmPerUnit;
void main() {
    uint i = gl_GlobalInvocationID.x;
    vec3 rgb = inputs[5u * i].xyz;
    vec3 viewPosition = inputs[5u * i + 1u].xyz;
    vec3 viewNormal = inputs[5u * i + 2u].xyz;
    vec3 otherRgb = inputs[5u * i + 3u].xyz;
    vec4 p = inputs[5u * i + 4u];  // beta, lambda, curvature per unit, floor
    vec3 lab = linearRec709ToLab(rgb);
    outputs[4u * i] = vec4(lab, labWeight(lab, linearRec709ToLab(otherRgb), p.x));
    float aux = auxiliaryValue(viewPosition, viewNormal);
    float c = normalisedCurvature(p.z, mmPerUnit, kCurvatureReferenceRadiusMm);
    outputs[4u * i + 1u] = vec4(aux, auxiliaryWeight(aux, auxiliaryValue(viewPosition, viewNormal, otherRgb.g), p.y),
                               c, transmittanceCurvatureScale(c));
    outputs[4u * i + 2u] = vec4(curvatureWidthScale(kCurvatureOff, c, p.w), curvatureWidthScale(kCurvatureIncrease, c, p.w),
                               curvatureWidthScale(kCurvatureReduce, c, p.w), curvatureWidthScale(kCurvatureReduceFloor, c, p.w));
    outputs[4u * i + 3u] = vec4(resolveWeightedSum(rgb, p.x * 0.01, otherRgb), 0.0);
}
)";

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

GLuint compileCompute(const std::string& source, std::string& log) {
    const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    char buffer[4096] = {0};
    glGetShaderInfoLog(shader, sizeof buffer, nullptr, buffer);
    log = buffer;
    if (!ok) {
        glDeleteShader(shader);
        return 0;
    }
    const GLuint program = glCreateProgram();
    glAttachShader(program, shader);
    glLinkProgram(program);
    glDeleteShader(shader);
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    glGetProgramInfoLog(program, sizeof buffer, nullptr, buffer);
    log += buffer;
    if (!ok) {
        glDeleteProgram(program);
        return 0;
    }
    return program;
}
} // namespace

TEST(ExtensionsGlsl, MatchesTheCppFunctions) {
    std::unique_ptr<gl::EglContext> context;
    try {
        context = std::make_unique<gl::EglContext>();
    } catch (const std::exception& e) {
        GTEST_SKIP() << "no EGL/OpenGL 4.5 context: " << e.what();
    }
    const std::string include = readFile(std::string(SKINLAB_SOURCE_DIR) + "/renderer/shaders/sss_extensions.glsl");
    ASSERT_FALSE(include.empty());
    std::string log;
    const GLuint program = compileCompute("#version 450 core\n" + include + kMain, log);
    ASSERT_NE(program, 0u) << "sss_extensions.glsl does not compile on " << context->renderer() << ":\n" << log;

    const float mmPerUnit = 2.0f;
    const std::vector<Case> cases{
        {{1, 1, 1}, {0, 0, -5}, {0, 0, 1}, {0.6f, 0.4f, 0.3f}, 0.09f, 10.0f, 0.0f, 0.5f},
        {{1, 0, 0},
         {1, 2, -50},
         glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f)),
         {0.05f, 0.6f, 0.8f},
         0.5f,
         10.0f,
         0.01f,
         0.3f},
        {{0.18f, 0.18f, 0.18f}, {-3, 1, -7}, {1, 0, 0}, {0.02f, 0.02f, 0.02f}, 0.09f, 1.0f, 0.05f, 0.0f},
        {{0.005f, 0.004f, 0.003f}, {0, 0, -5}, {0, 0, -1}, {0.5f, 0.5f, 0.5f}, 0.0f, 0.0f, 1.0f, 1.0f},
        {{0.6f, 0.4f, 0.3f},
         {10, -10, -40},
         glm::normalize(glm::vec3(-0.5f, 0.5f, 0.7f)),
         {0.6f, 0.45f, 0.3f},
         0.09f,
         10.0f,
         -0.2f,
         0.5f},
        {{0.02f, 0.6f, 0.8f}, {0, 0, 0}, {0, 0, 1}, {1, 1, 1}, 2.0f, 10.0f, 0.03f, 0.25f},
    };
    std::vector<glm::vec4> inputs;
    for (const Case& c : cases) {
        inputs.push_back(glm::vec4(c.rgb, 0));
        inputs.push_back(glm::vec4(c.viewPosition, 0));
        inputs.push_back(glm::vec4(c.viewNormal, 0));
        inputs.push_back(glm::vec4(c.otherRgb, 0));
        inputs.push_back(glm::vec4(c.beta, c.lambda, c.curvaturePerUnit, c.floor));
    }
    GLuint buffers[2];
    glCreateBuffers(2, buffers);
    glNamedBufferStorage(buffers[0], GLsizeiptr(inputs.size() * sizeof(glm::vec4)), inputs.data(), 0);
    glNamedBufferStorage(buffers[1], GLsizeiptr(cases.size() * 4 * sizeof(glm::vec4)), nullptr, GL_MAP_READ_BIT);
    glUseProgram(program);
    glUniform1f(glGetUniformLocation(program, "mmPerUnit"), mmPerUnit);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffers[0]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffers[1]);
    glDispatchCompute(GLuint(cases.size()), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<glm::vec4> out(cases.size() * 4);
    glGetNamedBufferSubData(buffers[1], 0, GLsizeiptr(out.size() * sizeof(glm::vec4)), out.data());
    ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR));
    glUseProgram(0);
    glDeleteBuffers(2, buffers);
    glDeleteProgram(program);

    // Tolerances: GLSL pow(t, 1/3) against std::cbrt and exp/length in the driver's float precision differ in the
    // last bits; Lab components (0…100) within 2e-3, weights and scales (0…20) within 1e-4 relative.
    const auto near = [](float a, float b, float relative) {
        return std::abs(a - b) <= relative * std::max(1.0f, std::abs(b));
    };
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const Case& c = cases[i];
        const glm::vec3 lab = linearRec709ToLab(c.rgb);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(out[4 * i][k], lab[k], 2e-3f) << "case " << i << " Lab " << k;
        EXPECT_TRUE(near(out[4 * i].w, labWeight(lab, linearRec709ToLab(c.otherRgb), c.beta), 1e-4f)) << "case " << i;
        const float aux = auxiliaryValue(c.viewPosition, c.viewNormal);
        EXPECT_TRUE(near(out[4 * i + 1].x, aux, 1e-5f)) << "case " << i << ": " << out[4 * i + 1].x << " vs " << aux;
        EXPECT_TRUE(near(out[4 * i + 1].y,
                         auxiliaryWeight(aux, auxiliaryValue(c.viewPosition, c.viewNormal, c.otherRgb.g), c.lambda),
                         1e-4f))
            << "case " << i;
        const float curvature = normalisedCurvature(c.curvaturePerUnit, mmPerUnit);
        EXPECT_TRUE(near(out[4 * i + 1].z, curvature, 1e-6f)) << "case " << i;
        EXPECT_TRUE(near(out[4 * i + 1].w, transmittanceCurvatureScale(curvature), 1e-6f)) << "case " << i;
        const CurvatureStrategy strategies[] = {CurvatureStrategy::Off, CurvatureStrategy::Increase,
                                                CurvatureStrategy::Reduce, CurvatureStrategy::ReduceFloor};
        for (int k = 0; k < 4; ++k)
            EXPECT_TRUE(near(out[4 * i + 2][k], curvatureWidthScale(strategies[k], curvature, c.floor), 1e-6f))
                << "case " << i << " strategy " << k;
        const glm::vec3 resolved = resolveWeightedSum(c.rgb, c.beta * 0.01f, c.otherRgb);
        for (int k = 0; k < 3; ++k)
            EXPECT_TRUE(near(out[4 * i + 3][k], resolved[k], 1e-5f)) << "case " << i << " resolve " << k;
    }
}
