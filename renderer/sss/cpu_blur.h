#pragma once
// CPU reference of the screen-space SSS passes (plain C++, float arithmetic in the same order as the shaders
// renderer/shaders/sss_*.frag), used by tests to check the GL passes and to test energy and isotropy without GL.
//
// One pass along an axis, for a pixel p with skin mask m_p > 0, linear depth z_p (world units):
//   pixels per mm     k_px = f_px / (mm_per_unit · z_p)          (docs/methods.md; the same on both axes)
//   tap i             position u = p + o_i · k_px along the axis, between texels j = floor(u) and j + 1
//                     (clamped to the image), interpolation fraction f = u − floor(u) (linear filtering, done by
//                     hand so that every texel is tested on its own)
//   texel j           s_j = 1 − mask_j (its non-skin share); with follow surface
//                     s_j = max(s_j, saturate(k · |z_p − z_j| · mm_per_unit)) where mask_j > 0;
//                     value_j = mix(colour_j, centre, s_j): a non-skin texel or one across a depth step
//                     contributes the centre colour, so no light comes from background/non-skin pixels and the
//                     weights still sum to 1 (energy is kept)
//   tap value         mix(value_j, value_{j+1}, f)
//   result            mix(centre, Σ w_i · tap value_i, m_p)
// Pixels with m_p = 0 are copied unchanged. (The shader reads the mask from the colour texture's alpha, which the
// pipeline sets to the skin mask and every pass carries along; here it is SurfaceBuffers::mask.)
//
// The artifact extensions (docs/extensions.md; renderer/sss/extension_weights.h), as in
// renderer/shaders/sss_extension_inputs.glsl:
//   E3 sss.curvature   k_px × curvatureWidthScale(strategy, normalisedCurvature(κ_p, mm_per_unit), floor)
//   E1/E2 (cbf, lab)   each texel j of tap i weighs w_i · (1 − f or f) · e_j with
//                      e_j = labWeight(Lab(albedo_p), Lab(albedo_j), β) · auxiliaryWeight(F_p, F_j, λ);
//                      with sss.extension_input = "lit" the pass's input colour replaces the albedo in Lab and
//                      F_j = litAuxiliaryValue(F_j, albedo_j, input_j) (extensionColour / extensionAuxiliary);
//                      Σ (weight · value_j) / Σ weight per channel, or the centre where Σ weight < 1e-4
//                      (resolveWeightedSum), then mix(centre, ·, m_p) as above.
// With both cbf and lab_weight off the tap loop is the one above, unchanged.
#include "renderer/sss/extension_weights.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/sss_params.h"

#include <array>
#include <optional>
#include <vector>

namespace skinlab::renderer::sss {

using Rgb = std::array<float, 3>;

struct SurfaceBuffers {
    int width = 0;
    int height = 0;
    std::vector<float> depth; // linear view depth, world units, +inf on background; row-major, row 0 at the bottom
    std::vector<float> mask;  // skin mask 0…1
    float focalLengthPixels = 0.0f; // f_px = (H/2) / tan(fovY/2)
    // Where the view axis meets the image, pixels (row 0 at the bottom): the centre unless given (a render.window).
    std::optional<std::array<float, 2>> principalPoint;
    float mmPerUnit = 1.0f;
    // Extension inputs, read only while the matching switch of BlurSettings is on (may stay empty otherwise):
    std::vector<Rgb> albedo;      // linear albedo (sss.lab_weight; the albedo AOV)
    std::vector<float> aux;       // Mikkelsen's auxiliary image F (sss.cbf; the aux.Y AOV)
    std::vector<float> curvature; // curvature κ, 1/world unit, ≥ 0 (sss.curvature; the curvature.Y AOV)
};

struct BlurSettings {
    bool followSurface = true;
    float followSurfaceK = 0.5f;                              // 1/mm
    bool cbf = false;                                         // E1
    float cbfLambda = 10.0f;                                  // λ, dimensionless
    float labWeight = 0.0f;                                   // E2: β in 1/ΔE*ab, 0 = off
    ExtensionInput input = ExtensionInput::Albedo;            // E1/E2: albedo AOV or the colour this pass blurs
    CurvatureStrategy curvature = CurvatureStrategy::Off;     // E3
    float curvatureFloor = 0.5f;                              // [0, 1]
    float curvatureReferenceMm = kCurvatureReferenceRadiusMm; // sss.curvature_reference_mm

    bool weighsTaps() const { return cbf || labWeight > 0.0f; }
};

// E1/E2 inputs of texel i for a pass whose input colour is `input` (albedo or lit, as `settings.input` says).
glm::vec3 extensionColour(const SurfaceBuffers& surface, const std::vector<Rgb>& input, std::size_t i,
                          const BlurSettings& settings);
float extensionAuxiliary(const SurfaceBuffers& surface, const std::vector<Rgb>& input, std::size_t i,
                         const BlurSettings& settings);

// Follow-surface and extension settings of resolved [sss] parameters.
BlurSettings blurSettingsFromParams(const SssParams& params);

enum class BlurAxis { Horizontal, Vertical };

// One 1-D pass of `stage` along `axis`.
std::vector<Rgb> blurPass(const SurfaceBuffers& surface, const std::vector<Rgb>& input, const KernelStage& stage,
                          BlurAxis axis, const BlurSettings& settings);

// A whole method: for each stage a horizontal then a vertical pass on the previous stage's result, accumulated
// with the stage's weights (kernel.h). An empty kernel (method none) returns the input.
std::vector<Rgb> applyKernel(const SurfaceBuffers& surface, const std::vector<Rgb>& diffuse, const Kernel& kernel,
                             const BlurSettings& settings);

} // namespace skinlab::renderer::sss
