#include "renderer/gl/sss_extension_settings.h"

#include "common/error.h"

namespace skinlab::renderer::gl {

SssExtensionSettings SssExtensionSettings::fromParams(const sss::SssParams& params, GLuint albedoTexture,
                                                      GLuint auxTexture, GLuint curvatureTexture) {
    SssExtensionSettings settings = fromParams(params);
    settings.albedoTexture = albedoTexture;
    settings.auxTexture = auxTexture;
    settings.curvatureTexture = curvatureTexture;
    return settings;
}

SssExtensionSettings SssExtensionSettings::fromParams(const sss::SssParams& params) {
    SssExtensionSettings settings;
    settings.cbf = params.cbf;
    settings.cbfLambda = static_cast<float>(params.cbfLambda);
    settings.labWeight = static_cast<float>(params.labWeight);
    settings.curvature = sss::curvatureStrategyFromName(params.curvature, "sss");
    settings.input = sss::extensionInputFromName(params.extensionInput, "sss");
    settings.curvatureFloor = static_cast<float>(params.curvatureFloor);
    settings.curvatureReferenceMm = static_cast<float>(params.curvatureReferenceMm);
    return settings;
}

ShaderDefines SssExtensionSettings::defines() const {
    if (!weighsTaps()) return {};
    return {{"SSS_EXTENSION_WEIGHTS", "1"}};
}

void SssExtensionSettings::bind(GLuint program, GLuint firstTextureUnit) const {
    // A switch that is on without its texture would silently read texture 0 (all zeros in GL): a pipeline bug.
    if ((labWeight > 0.0f && albedoTexture == 0) || (cbf && auxTexture == 0) ||
        (curvature != sss::CurvatureStrategy::Off && curvatureTexture == 0) ||
        (weighsTaps() && input == sss::ExtensionInput::Lit && (litTexture == 0 || albedoTexture == 0)))
        throw RuntimeError("SSS extensions: an extension is on but its input texture is missing");
    setUniform(program, "extensionLabBeta", labWeight);
    setUniform(program, "extensionCbf", cbf ? 1 : 0);
    setUniform(program, "extensionCbfLambda", cbfLambda);
    // The GLSL constants kCurvatureOff … kCurvatureReduceFloor follow the enum's order (sss_extensions.glsl).
    setUniform(program, "extensionCurvatureStrategy", static_cast<int>(curvature));
    setUniform(program, "extensionCurvatureFloor", curvatureFloor);
    setUniform(program, "extensionCurvatureReferenceMm", curvatureReferenceMm);
    setUniform(program, "extensionAlbedo", static_cast<int>(firstTextureUnit));
    setUniform(program, "extensionAux", static_cast<int>(firstTextureUnit + 1));
    setUniform(program, "extensionCurvature", static_cast<int>(firstTextureUnit + 2));
    setUniform(program, "extensionLit", static_cast<int>(firstTextureUnit + 3));
    setUniform(program, "extensionInputLit", input == sss::ExtensionInput::Lit ? 1 : 0);
    glBindTextureUnit(firstTextureUnit, albedoTexture);
    glBindTextureUnit(firstTextureUnit + 1, auxTexture);
    glBindTextureUnit(firstTextureUnit + 2, curvatureTexture);
    glBindTextureUnit(firstTextureUnit + 3, litTexture);
}

void SssExtensionSettings::unbind(GLuint firstTextureUnit) const {
    for (GLuint unit = firstTextureUnit; unit < firstTextureUnit + 4; ++unit) glBindTextureUnit(unit, 0);
}

} // namespace skinlab::renderer::gl
