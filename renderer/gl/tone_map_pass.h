#pragma once
// Tone map pass (fullscreen.vert + tone_map.frag): beauty → linear display-referred [0, 1] with one of the
// operators of tone_mappers.glsl; the sRGB encoding follows on the CPU through OpenColorIO.
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/shader_library.h"

#include <string>

namespace skinlab::renderer::gl {

class ToneMapPass {
public:
    explicit ToneMapPass(ShaderLibrary& shaders) : shaders_(shaders) {}
    // toneMapper: linear | exponential | reinhard | reinhard-rgb | filmic. reinhardScale = a / L̄ (reinhard only:
    // the key over the beauty's log-average luminance, renderer/shading/tone_mappers.h).
    void run(FrameTargets& targets, const std::string& toneMapper, float exponentialK, float filmicWhite,
             float reinhardScale = 1.0f);

private:
    ShaderLibrary& shaders_;
};

// Index of a tone mapper in tone_mappers.glsl (0 linear, 1 exponential, 2 reinhard-rgb, 3 filmic, 4 reinhard).
int toneMapperIndex(const std::string& toneMapper);

} // namespace skinlab::renderer::gl
