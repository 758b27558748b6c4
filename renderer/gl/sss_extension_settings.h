#pragma once
// How the artifact extensions (thesis §3.3; docs/extensions.md) reach a screen-space SSS pass: the switches of
// [sss] and the three AOV textures they read, set on a program that includes renderer/shaders/sss_extensions.glsl
// then renderer/shaders/sss_extension_inputs.glsl. Used by SssBlurPass (gaussian-sum, separable, artistic) and
// meant for any other screen-space pass (pscbf): build one with fromParams, add defines() to the program's
// defines, call bind() before drawing and unbind() after.
//
//  E1 sss.cbf / sss.cbf_lambda  tap weight exp(−λ |F_centre − F_tap|) on the aux.Y AOV (Mikkelsen's F)
//  E2 sss.lab_weight = β        tap weight exp(−β ΔE*ab) on the CIELAB distance of the albedos (albedo AOV)
//  E3 sss.curvature, _floor     the kernel's footprint × curvatureWidthScale(strategy, c, floor), c from
//                               the curvature.Y AOV (1/world unit) through normalisedCurvature
#include "renderer/gl/shader_library.h"
#include "renderer/sss/extension_weights.h"
#include "renderer/sss/sss_params.h"

#include <epoxy/gl.h>

namespace skinlab::renderer::gl {

struct SssExtensionSettings {
    bool cbf = false;
    float cbfLambda = 10.0f; // λ, dimensionless
    float labWeight = 0.0f;  // β, 1/ΔE*ab; 0 = off
    sss::CurvatureStrategy curvature = sss::CurvatureStrategy::Off;
    float curvatureFloor = 0.5f;                                   // [0, 1], reduce-floor only
    float curvatureReferenceMm = sss::kCurvatureReferenceRadiusMm; // sss.curvature_reference_mm
    sss::ExtensionInput input = sss::ExtensionInput::Albedo;       // sss.extension_input (E1/E2)

    GLuint albedoTexture = 0;    // GL_RGBA32F, rgb = linear albedo (SssStageInputs::albedo)
    GLuint auxTexture = 0;       // GL_R32F, F (SssStageInputs::aux)
    GLuint curvatureTexture = 0; // GL_R32F, κ in 1/world unit (SssStageInputs::curvature)
    GLuint litTexture = 0;       // the colour the pass blurs (its source), read with input = lit; set per pass

    // The switches of resolved [sss] parameters (textures left 0: set them from SssStageInputs).
    static SssExtensionSettings fromParams(const sss::SssParams& params);
    // The same with the three AOV textures (SssStageInputs::albedo, ::aux, ::curvature).
    static SssExtensionSettings fromParams(const sss::SssParams& params, GLuint albedoTexture, GLuint auxTexture,
                                           GLuint curvatureTexture);

    // True where E1 or E2 weigh the taps (the program then needs the SSS_EXTENSION_WEIGHTS variant).
    bool weighsTaps() const { return cbf || labWeight > 0.0f; }
    // {"SSS_EXTENSION_WEIGHTS", "1"} when weighsTaps(), else nothing: with every extension off a pass compiles
    // exactly its extension-free shader.
    ShaderDefines defines() const;

    // Sets the extension* uniforms of `program` and binds the four textures to units firstTextureUnit,
    // firstTextureUnit + 1, firstTextureUnit + 2 and firstTextureUnit + 3 (the lit colour). A texture that is 0 while its extension is on is a pipeline bug:
    // RuntimeError, thrown before any GL state is changed.
    void bind(GLuint program, GLuint firstTextureUnit) const;
    // Unbinds the four units bind() used.
    void unbind(GLuint firstTextureUnit) const;
};

} // namespace skinlab::renderer::gl
