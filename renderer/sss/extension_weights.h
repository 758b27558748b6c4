#pragma once
// The three artifact extensions of the thesis (§3.3) as plain functions on one pixel, in float
// arithmetic: the reference that renderer/shaders/sss_extensions.glsl mirrors and tests check it against.
// docs/extensions.md explains each one, its parameters and what it fixes.
//
//  E1  sss.cbf        halo reduction: cross-bilateral weight on Mikkelsen's auxiliary image F (Mikkelsen 2010 Eq. 2
//                     in the thesis's distance-invariant form), with the fallback to the unblurred colour where the
//                     weights vanish;
//  E2  sss.lab_weight skin/non-skin bleeding: weight exp(−β ‖ΔLab‖) on the CIELAB (D65) distance of the albedos;
//  E3  sss.curvature  curvature modulation of the kernel width: off | increase | reduce | reduce-floor.
#include <glm/glm.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::renderer::sss {

// --- E2: CIELAB ----------------------------------------------------------------------------------------------

// Linear Rec.709/sRGB primaries → CIE XYZ (D65 white, Y of white = 1). IEC 61966-2-1 matrix.
glm::vec3 linearRec709ToXyz(const glm::vec3& rgb);
// CIE XYZ → CIELAB (CIE 15:2004) with the D65 reference white (0.95047, 1, 1.08883).
glm::vec3 xyzToLab(const glm::vec3& xyz);
// Linear albedo → CIELAB: L in [0, 100] for albedos in [0, 1].
glm::vec3 linearRec709ToLab(const glm::vec3& rgb);
// E2 weight of a tap: exp(−β ‖Lab_centre − Lab_tap‖) (ΔE*ab, CIE76). β in 1/ΔE; β = 0 switches it off (weight 1).
// Thesis: β = 0.09 for the separable methods, 0.5 for the sum of Gaussians.
float labWeight(const glm::vec3& labCentre, const glm::vec3& labTap, float beta);

// --- E1/E2 input (sss.extension_input) ----------------------------------------------------------------------
// What the CIELAB weight compares and what grey modulates F: the albedo (the thesis code's later revision, every
// method; the default) or the lit colour being blurred, i.e. the input of each pass (the thesis as submitted, every
// method; its text, Eq. 3.13, "the lab color of the image I"). They differ at shadow terminators, where the lit form
// also cuts the blur.
enum class ExtensionInput { Albedo, Lit };
std::string_view extensionInputName(ExtensionInput input);
ExtensionInput extensionInputFromName(std::string_view name, std::string_view source);
// F with the lit colour's grey: the stored F (modulated by the albedo grey, surface_aovs.frag) divided by the albedo
// grey and multiplied by the lit colour's grey (mean of R, G, B); 0 where the albedo grey is below 1e-6.
float litAuxiliaryValue(float storedAux, const glm::vec3& albedo, const glm::vec3& lit);

// --- E1: Mikkelsen's auxiliary image -------------------------------------------------------------------------

// Smallest cos φ_j used (φ_j: angle between the normal and the direction to the viewer). At silhouettes cos φ_j
// reaches 0 and F diverges; clamping at 0.05 (φ_j ≈ 87°) bounds F to 20 while leaving every pixel that faces the
// camera by more than 3° unchanged.
inline constexpr float kAuxiliaryMinCosine = 0.05f;

// Auxiliary value F(p) = cos³φ_i ‖x(p)‖² / cos φ_j (Mikkelsen 2010, Eq. 2) in the thesis's distance-invariant form:
// x(p) is taken on the projection plane at unit distance, ‖x‖ = 1/cos φ_i, so F = cos φ_i / cos φ_j.
//   viewPosition: the point in view space (camera at the origin looking along −Z), any units;
//   viewNormal:   the (geometric or mapped) unit normal in view space.
// Back-facing normals (cos φ_j ≤ 0) are clamped like grazing ones.
float auxiliaryValue(const glm::vec3& viewPosition, const glm::vec3& viewNormal);
// The thesis code modulated F by the albedo's grey value (mean of the linear albedo) so that taps of a different
// material also differ in F; albedoGrey = 1 leaves F as is.
float auxiliaryValue(const glm::vec3& viewPosition, const glm::vec3& viewNormal, float albedoGrey);
// E1 weight of a tap: exp(−λ |F_centre − F_tap|), λ dimensionless (thesis code: 10); λ = 0 gives 1.
float auxiliaryWeight(float auxiliaryCentre, float auxiliaryTap, float lambda);

// A weighted sum of taps with its weight sum, resolved with the E1/E2 fallback: Σ w_i c_i / Σ w_i, or the unblurred
// centre colour where Σ w_i < kMinimumWeightSum (without it, pixels whose every tap is rejected turn black: the
// "black dots" at edges the thesis reports). Weights are the kernel weight × extension weights, so Σ w_i ≤ 1.
inline constexpr float kMinimumWeightSum = 1e-4f;
glm::vec3 resolveWeightedSum(const glm::vec3& weightedSum, float weightSum, const glm::vec3& centre);

// --- E3: curvature -------------------------------------------------------------------------------------------

enum class CurvatureStrategy {
    Off,         // width × 1
    Increase,    // width × (1 + c): the thesis's (a): strongest at silhouettes, worse halos
    Reduce,      // width × c: the thesis's (b): flat areas lose SSS
    ReduceFloor, // width × (floor + (1 − floor) c): the thesis's (c), the good one
};
std::string_view curvatureStrategyName(CurvatureStrategy strategy);
const std::vector<std::string>& curvatureStrategyNames(); // "off", "increase", "reduce", "reduce-floor"
// Throws InputError("<source>: sss.curvature: ...") for an unknown name.
CurvatureStrategy curvatureStrategyFromName(std::string_view name, std::string_view source);

// A surface of radius kCurvatureReferenceRadiusMm or tighter counts as fully curved (c = 1). 20 mm: the radius
// of the nose tip, ears and lips is below it, the cheeks and forehead (60–100 mm) give c = 0.2–0.33.
inline constexpr float kCurvatureReferenceRadiusMm = 20.0f; // the default of sss.curvature_reference_mm

// Normalised curvature c = saturate(κ · mm-per-unit⁻¹ · reference radius): κ is the curvature AOV (1/world unit,
// ≈ 1/radius, ≥ 0).
float normalisedCurvature(float curvaturePerUnit, float mmPerUnit,
                          float referenceRadiusMm = kCurvatureReferenceRadiusMm);
// Multiplier of the kernel's width (its footprint in pixels) at a pixel of normalised curvature c ∈ [0, 1].
// floor ∈ [0, 1] is sss.curvature_floor (used by reduce-floor only).
float curvatureWidthScale(CurvatureStrategy strategy, float normalisedCurvature, float floor);
// transmittance.curvature: transmittance × (1 + c). Documented as producing bright artefacts at nostrils and other
// tight, thin features (thesis §3.3), where c is largest.
float transmittanceCurvatureScale(float normalisedCurvature);

} // namespace skinlab::renderer::sss
