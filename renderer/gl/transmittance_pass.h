#pragma once
// Transmittance pass (fullscreen.vert + transmittance.frag): adds the light transmitted through thin parts, which
// the main pass wrote to its own target, to the diffuse buffer before the SSS stage, so the blur spreads it like
// any other irradiance (Jimenez et al., IEEE CG&A 2010; docs/rendering.md, "Transmittance"):
//   diffuse.rgb += transmittance.rgb × (1 + c if transmittance.curvature)
// with c = normalisedCurvature(curvature AOV) of sss_extensions.glsl (the thesis's option, which brightens
// nostrils and other tight features; docs/extensions.md). Reads transmittance and curvature, never diffuse: the
// addition is done by additive blending into the diffuse texture (rgb only; its alpha is the skin mask).
// Runs after the surface-AOV pass (it needs the curvature AOV) and before the SSS stage.
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/shader_library.h"

namespace skinlab::renderer::gl {

struct TransmittanceSettings {
    bool enabled = false;    // transmittance.enabled: off draws nothing (the transmittance target holds zeros)
    bool curvature = false;  // transmittance.curvature
    float mmPerUnit = 1.0f;  // millimetres per world unit (the curvature AOV is in 1/world unit)
    bool thesisForm = false; // transmittance.curvature_form = "thesis": applied in the main pass instead
    float curvatureReferenceMm = 20.0f; // sss.curvature_reference_mm
};

class TransmittancePass {
public:
    explicit TransmittancePass(ShaderLibrary& shaders) : shaders_(shaders) {}
    void run(FrameTargets& targets, const TransmittanceSettings& settings);

private:
    ShaderLibrary& shaders_;
};

} // namespace skinlab::renderer::gl
