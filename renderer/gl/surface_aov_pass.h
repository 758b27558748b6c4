#pragma once
// Surface-AOV pass: two screen-space images of the visible skin surface that the SSS extensions read
// (docs/extensions.md E1 and E3; docs/rendering.md "Surface AOVs"), computed every frame after the background pass
// from linear depth, geometric normal, albedo and skin mask:
//   aux.Y       (surface_aovs.frag)     Mikkelsen's auxiliary image F = cos φ_i / cos φ_j in the thesis's
//               distance-invariant form × albedo grey (auxiliaryValue of sss_extensions.glsl), 0 off skin;
//   curvature.Y (surface_aovs.frag, then curvature_smooth.frag) the mean normal curvature of the *geometric*
//               surface in 1/world unit, ≥ 0 (convex > 0, concave clamped to 0), by finite differences of the
//               geometric normals across neighbouring pixels, then smoothed on skin by a depth-aware Gaussian
//               (σ = 1.5 px, 7 taps, along x then along y); 0 off skin. A sphere of radius r gives ≈ 1/r, a
//               plane ≈ 0.
// View-space positions are reconstructed from the linear depth, the pixel centre and the camera's projection.
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/shader_library.h"
#include "renderer/scene/scene_spec.h"

namespace skinlab::renderer::gl {

// A neighbour whose linear depth differs from the centre's by more than this many pixel footprints (the world size
// of one pixel at the centre's depth, depth / f_px) lies across a depth step: it is not used for the curvature
// differences nor for their smoothing. 8 footprints accept surfaces up to atan(8) ≈ 83° from facing the camera.
inline constexpr float kSurfaceDepthStepPixels = 8.0f;
// The smoothing of the curvature (curvature_smooth.frag; SIGMA_PIXELS is defined there): a Gaussian of standard
// deviation 1.5 px truncated to ±kCurvatureSmoothingRadius px, separable (x, then y), over the measured skin taps
// on the same surface.
inline constexpr int kCurvatureSmoothingRadius = 3;

struct SurfaceAovSettings {
    CameraPose camera; // view, projection, focal length in pixels
    // sss.curvature_measure = "screen": the thesis' screen-space curvature instead of the 3-D normal curvature
    // (surface_aovs.frag; docs/extensions.md E3).
    bool screenCurvature = false;
};

class SurfaceAovPass {
public:
    explicit SurfaceAovPass(ShaderLibrary& shaders) : shaders_(shaders) {}
    // Writes targets.aux and targets.curvature (every pixel).
    void run(FrameTargets& targets, const SurfaceAovSettings& settings);

private:
    ShaderLibrary& shaders_;
    // GL_RG32F (curvature, linear depth): unsmoothed curvature, −1 on skin where it cannot be measured, −2 off skin;
    // then the same after the x pass of the smoothing.
    Texture rawCurvature_;
    Texture smoothedAlongX_;
    int width_ = 0;
    int height_ = 0;
};

} // namespace skinlab::renderer::gl
