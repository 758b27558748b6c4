#pragma once
// How published screen-space SSS code scales its kernel by `sssWidth`, converted to sss.width_mm, the distance on
// the surface at which skinlab places the kernel edge (±3 profile-mm, kProfileWidthMm in sss_params.h): Jimenez's
// separable SSS demo convention, width_mm = 2 · sssWidth · mm_per_unit (widthMmFromDemoSssWidth), and the conventions
// of the thesis "Physically-based rendering of human skin" (master thesis, UPC, 2015), whose shaders were adapted
// from that demo. docs/methods.md, "sssWidth in millimetres", derives both.
//
// `sssWidth` is always the value a blur shader receives (its `sssWidth` uniform), in world units. The thesis'
// application scaled its width slider before passing it on (× 0.9 · 0.7 for the demo's kernel, × 0.9 · 0.2 for the
// tabulated kernels, × 0.2 for the sum of Gaussians); those factors are not part of these conversions.

namespace skinlab::renderer::sss {

// The thesis' blur shaders, each with its own step.
enum class ThesisBlurShader {
    // Its separable shaders (the demo's artistic kernel and the tabulated pre-integrated kernels, Jimenez et al.
    // 2015): the demo's step times 0.7, `sssWidth · (cot(fovY/2) / z) · dir · 0.7 / kernel_range` in UV per kernel
    // unit, kernel_range the kernel's outermost offset, so its kernel edge lies at 1.4 · sssWidth world units.
    Separable,
    // Its sum-of-Gaussians passes (Jimenez et al. 2009 / 2010): per Gaussian of variance Δv (mm², d'Eon's table)
    // `√Δv · 0.1 · sssWidth · (cot(fovY/2) / z) · dir / 3` in UV per tap offset, offsets in [−1, 1] spanning ±3
    // standard deviations, so a Gaussian's 3σ point (the separable kernels' edge, ±3 profile-mm, at Δv = 1 mm²)
    // lies at 0.2/3 · sssWidth world units per mm of √Δv. (Its taps, seven fixed ones or its sampled ones, have an
    // RMS width of about 1.04 times the nominal σ = 1/3 of the offset range.)
    GaussianSum,
};

// The thesis' extra factor on the demo's step in its separable shaders.
constexpr double kThesisSeparableStepFactor = 0.7;
// Where the kernel edge lies, in world units per unit of sssWidth: the demo 2, the thesis' separable shaders
// 2 · 0.7 = 1.4, its sum-of-Gaussians passes 2 · 0.1 / 3 = 1/15.
constexpr double kDemoEdgePerSssWidth = 2.0;
constexpr double kThesisSeparableEdgePerSssWidth = kDemoEdgePerSssWidth * kThesisSeparableStepFactor;
constexpr double kThesisGaussianSumEdgePerSssWidth = kDemoEdgePerSssWidth * 0.1 / 3.0;

// sss.width_mm for a thesis setting: 1.4 · sssWidth · mm_per_unit (Separable), sssWidth · mm_per_unit / 15
// (GaussianSum). The demo's conversion gives 2 / 1.4 ≈ 1.43 times the width of the first for the same sssWidth.
double widthMmFromThesisSssWidth(double sssWidth, double mmPerUnit, ThesisBlurShader shader);

// Jimenez's separable SSS demo steps `sssWidth · (cot(fovY/2) / z) · dir / 3` in UV per kernel unit (its kernel
// spans ±3), and one UV unit spans 2 · z · tan(fovY/2) world units at linear depth z (vertically), so its kernel edge
// lands at 2 · sssWidth world units. In skinlab the edge lies at width_mm, hence width_mm = 2 · sssWidth · mm_per_unit.
// (The demo steps the same UV length horizontally, so there its edge lies at 2 · aspect · sssWidth; skinlab uses the
// vertical, aspect-free scale on both axes.)
double widthMmFromDemoSssWidth(double sssWidth, double mmPerUnit);

} // namespace skinlab::renderer::sss
