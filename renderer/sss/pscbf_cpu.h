#pragma once
// CPU mirror of Mikkelsen's pseudo-separable cross-bilateral filter as the GL method runs it
// (renderer/shaders/pscbf_blur.frag, renderer/gl/pscbf_method.h): the same operations in float, in the same order,
// so that a test can compare the GPU with it pixel by pixel. docs/extensions.md describes the method.
//
// One pass along an axis, for a skin pixel p (mask m_p > 0, linear depth z_p in world units, view-space unit
// normal n facing the camera, w = (ray to the camera at unit depth) = ((W/2 − x − ½)/f_px, (H/2 − y − ½)/f_px, 1)):
//   c_x        = max(|n·w| / √((n_y w_y + n_z)² + n_x² (1 + w_y²)), 0.05)        (c_y: swap x and y)
//   px per mm  = f_px / (mm_per_unit · z_p) · c_axis · curvatureWidthScale(...)
//   texel j of tap i (linear interpolation share s_ij):
//              weight_ij = w_i (RGB) · s_ij · mask_j · exp(−Δ_j² / (2 σ_c²)) · extension weights,
//              Δ_j = (z_j − z_plane,j) · mm_per_unit, z_plane,j = z_p (n·w) / (n·w − n_axis (j − p_axis) / f_px)
//              (the centre's tangent plane; z_p where n·w ≤ 0.05 or the denominator ≤ 0.05 n·w)
//   result     Σ weight · colour / Σ weight per channel (centre where Σ weight < 1e-4); mix(centre, ·, m_p)
// Vertical pass: mix(unblurred, spike · unblurred + (1 − spike) · result, m_p). Non-skin pixels are copied.
#include "renderer/sss/cpu_blur.h"
#include "renderer/sss/kernel.h"

#include <array>
#include <vector>

namespace skinlab::renderer::sss {

struct PscbfCpuInputs {
    const SurfaceBuffers* surface = nullptr; // depth, mask, f_px, mm per unit, extension AOVs; rows bottom first
    std::vector<Rgb> viewNormal;             // unit geometric normal in view space per pixel; empty: facing (0,0,1)
    bool depthWeight = true;                 // sss.follow_surface
    Rgb depthSigmaMm{1.0f, 1.0f, 1.0f};      // σ_c, mm (PscbfMethod::depthSigmaMm)
    BlurSettings extensions;                 // cbf, lab_weight, curvature (its follow-surface fields are unused)
};

// One pass of the broad stage along `axis`. `unblurred` is used by the vertical pass only (the spike).
std::vector<Rgb> pscbfPass(const PscbfCpuInputs& inputs, const std::vector<Rgb>& input,
                           const std::vector<Rgb>& unblurred, const KernelStage& stage, BlurAxis axis);

// The whole method: horizontal pass, then vertical pass with the spike (1 − stage.accumulate).
std::vector<Rgb> applyPscbf(const PscbfCpuInputs& inputs, const std::vector<Rgb>& diffuse, const Kernel& kernel);

} // namespace skinlab::renderer::sss
