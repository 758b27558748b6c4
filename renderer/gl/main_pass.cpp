#include "renderer/gl/main_pass.h"

#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <string>

namespace skinlab::renderer::gl {

namespace {
// Texture unit of the raw shadow-map depths (main_pass.frag `shadowDepths`).
constexpr GLuint kShadowDepthUnit = 6;
// Texture unit of the irradiance map (main_pass.frag `irradianceMap`, environment.irradiance = "exact").
constexpr GLuint kIrradianceMapUnit = 7;
// The sampler object that reads the shadow maps with compare mode off (the texture itself compares, for PCF),
// created by bindShading and deleted by unbindShading in the same context.
GLuint shadowDepthSampler = 0;
} // namespace

void MainPass::bindShading(GLuint program, const GpuScene& scene, GLuint shadowMaps, const MainPassSettings& settings) {
    setUniform(program, "view", settings.camera.view);
    setUniform(program, "cameraPosition", settings.camera.position);
    setUniform(program, "exposure", settings.exposure);
    setUniform(program, "normalStrength", settings.normalStrength);
    setUniform(program, "pcfRadius", settings.pcfRadius);
    setUniform(program, "environmentFromWorld", settings.environmentFromWorld);
    setUniformArray(program, "irradianceSH", scene.irradianceCoefficients().data(), 9);
    setUniform(program, "hasIrradianceMap", scene.irradianceMap() ? 1 : 0);
    glBindTextureUnit(kIrradianceMapUnit, scene.irradianceMap() ? scene.irradianceMap() : scene.fallbackMap());

    const int lightCount = static_cast<int>(scene.lights.size());
    setUniform(program, "lightCount", lightCount);
    for (int i = 0; i < lightCount; ++i) {
        const GpuLight& light = scene.lights[static_cast<std::size_t>(i)];
        const std::string index = "[" + std::to_string(i) + "]";
        setUniform(program, ("lightType" + index).c_str(), light.type);
        setUniform(program, ("lightDirection" + index).c_str(), light.direction);
        setUniform(program, ("lightPosition" + index).c_str(), light.position);
        setUniform(program, ("lightRadiance" + index).c_str(), light.radiance);
        setUniform(program, ("lightReferenceDistance" + index).c_str(), light.referenceDistance);
        setUniform(program, ("lightCosInner" + index).c_str(), light.cosInner);
        setUniform(program, ("lightCosOuter" + index).c_str(), light.cosOuter);
        setUniform(program, ("lightShadowLayer" + index).c_str(), light.shadowLayer);
        setUniform(program, ("lightViewProjection" + index).c_str(), light.viewProjection);
        setUniform(program, ("lightNormalOffset" + index).c_str(), light.normalOffset);
        setUniform(program, ("lightInverseViewProjection" + index).c_str(), glm::inverse(light.viewProjection));
    }

    // Transmittance: s = thickness (world units) × 8.25 (1 − translucency) / sssWidth, the demo's sssWidth being
    // width_mm / (2 mm_per_unit): s = thickness × mm_per_unit × 16.5 (1 − translucency) / width_mm.
    setUniform(program, "transmittanceEnabled", settings.transmittanceEnabled ? 1 : 0);
    setUniform(program, "transmittanceShrink", kTransmittanceShrinkMm / settings.mmPerUnit);
    setUniform(program, "transmittanceThesisCurvature", settings.transmittanceThesisCurvature ? 1 : 0);
    setUniform(program, "transmittanceCurvatureScale",
               settings.camera.focalLengthPixels / 8.0f * settings.curvatureReferenceMm / settings.mmPerUnit);
    setUniform(program, "transmittanceToneWeights", settings.transmittanceWeights ? 1 : 0);
    for (int k = 0; k < 6; ++k)
        setUniform(program, ("transmittanceWeight" + std::to_string(k)).c_str(),
                   settings.transmittanceWeights ? (*settings.transmittanceWeights)[static_cast<std::size_t>(k)]
                                                 : glm::vec3(0.0f));
    setUniform(program, "transmittanceScale",
               static_cast<float>(sss::transmittanceScalePerUnit(
                   settings.translucency, std::max(settings.sssWidthMm, 1e-6f), settings.mmPerUnit)));

    const GLuint fallback = scene.fallbackMap();
    const GLuint maps[] = {scene.albedoMap(), scene.normalMap(), scene.specularMap(), scene.occlusionMap(),
                           scene.skinMaskMap()};
    const char* flags[] = {"hasAlbedoMap", "hasNormalMap", "hasSpecularMap", "hasOcclusionMap", "hasSkinMaskMap"};
    for (GLuint unit = 0; unit < 5; ++unit) {
        glBindTextureUnit(unit, maps[unit] ? maps[unit] : fallback);
        setUniform(program, flags[unit], maps[unit] ? 1 : 0);
    }
    glBindTextureUnit(5, shadowMaps);
    if (shadowDepthSampler != 0) glDeleteSamplers(1, &shadowDepthSampler);
    glCreateSamplers(1, &shadowDepthSampler);
    glSamplerParameteri(shadowDepthSampler, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    glSamplerParameteri(shadowDepthSampler, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glSamplerParameteri(shadowDepthSampler, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glSamplerParameteri(shadowDepthSampler, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glSamplerParameteri(shadowDepthSampler, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTextureUnit(kShadowDepthUnit, shadowMaps);
    glBindSampler(kShadowDepthUnit, shadowDepthSampler);
}

void MainPass::unbindShading() {
    for (GLuint unit = 0; unit < 8; ++unit) {
        glBindTextureUnit(unit, 0);
        glBindSampler(unit, 0);
    }
    if (shadowDepthSampler != 0) glDeleteSamplers(1, &shadowDepthSampler);
    shadowDepthSampler = 0;
}

void MainPass::setMaterial(GLuint program, const GpuMaterial& material) {
    setUniform(program, "materialAlbedo", material.albedo);
    setUniform(program, "materialSkin", material.skin);
    setUniform(program, "glossiness", material.glossiness);
    setUniform(program, "specularIntensity", material.specularIntensity);
}

void MainPass::run(FrameTargets& targets, const GpuScene& scene, GLuint shadowMaps, const MainPassSettings& settings) {
    targets.clear();
    const GLuint program = shaders_.program("main_pass.vert", "main_pass.frag");
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, targets.mainFramebuffer.get());
    glViewport(0, 0, targets.width, targets.height);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE); // thin and open surfaces (backdrop, fin) are seen from both sides

    bindShading(program, scene, shadowMaps, settings);
    setUniform(program, "projection", settings.camera.projection); // main_pass.vert (the bake's vertex stage has none)
    for (const GpuPart& part : scene.parts()) {
        setMaterial(program, part.material);
        scene.drawPart(part);
    }
    unbindShading();
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("main pass");
}

} // namespace skinlab::renderer::gl
