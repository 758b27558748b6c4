#pragma once
// Mikkelsen's pseudo-separable cross-bilateral filter as a GL method (sss.method = "pscbf"; M. S. Mikkelsen,
// "Skin Rendering by Pseudo-Separable Cross Bilateral Filtering", 2010; docs/extensions.md).
// Two 1-D passes of renderer/shaders/pscbf_blur.frag: diffuse → scratch (horizontal) → output (vertical, plus the
// spike: output = spike · diffuse + (1 − spike) · blurred). The taps are the broad Gaussian part of the profile
// (renderer/sss/pscbf_kernel.h, built by makeKernel), scaled by width_mm / 3. What differs from the kernel methods
// (sss_kernel_method.h): the footprint is corrected for the surface's tilt per axis, taps are weighed by a depth
// range weight and the skin mask and renormalised (non-skin taps are discarded, not replaced by the centre colour).
// The artifact extensions (sss.cbf, sss.lab_weight, sss.curvature) apply as in every screen-space method.
#include "renderer/gl/gl_resources.h"
#include "renderer/gl/sss_stage.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/sss_params.h"

namespace skinlab::renderer::gl {

class ShaderLibrary;

class PscbfMethod {
public:
    explicit PscbfMethod(ShaderLibrary& shaders);

    // `kernel` = makeKernel(params) for method pscbf (one stage, accumulate = 1 − spike). `output`: GL_RGBA32F of
    // the inputs' size, not one of the inputs. inputs.geometricNormal may be 0 (every pixel then faces the camera:
    // no tilt correction, no tangent-plane depth prediction).
    void run(const SssStageInputs& inputs, const sss::SssParams& params, const sss::Kernel& kernel, GLuint output);

    // σ_c of the depth range weight per channel, mm: √v_c × width_mm / 3 (the profile's own Gaussian; see the shader).
    static glm::dvec3 depthSigmaMm(const sss::SssParams& params);

private:
    void ensureScratch(int width, int height);
    ShaderLibrary& shaders_;
    Texture scratch_;
    int width_ = 0;
    int height_ = 0;
};

} // namespace skinlab::renderer::gl
