#pragma once
// Resolve pass (fullscreen.vert + resolve.frag): supersampling anti-aliasing's reconstruction. Reads one layer of
// the frame targets at the internal resolution (output size × factor) and writes it at the output size, each output
// pixel from the factor × factor samples it covers, filtered by a box of one output pixel in linear values
// (docs/rendering.md, "Anti-aliasing").
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/shader_library.h"

namespace skinlab::renderer::gl {

// How the samples of one output pixel combine (resolve.frag).
enum class ResolveMode {
    Average = 0,          // mean of all samples: radiance, albedo, transmittance; the mask becomes coverage
    CoveredAverage = 1,   // mean over the samples that see a surface, 0 where none does (aux, curvature)
    CoveredDirection = 2, // as CoveredAverage, renormalised to unit length (normals)
    Nearest = 3,          // the smallest value: linear depth of the nearest surface, +inf where none
};

class ResolvePass {
public:
    explicit ResolvePass(ShaderLibrary& shaders) : shaders_(shaders) {}
    // `source` and `internal.linearDepth` are internal.width × internal.height = factor × (output.width ×
    // output.height); `destination` is a texture of `output`.
    void run(const FrameTargets& internal, GLuint source, FrameTargets& output, GLuint destination, int factor,
             ResolveMode mode);

private:
    ShaderLibrary& shaders_;
};

} // namespace skinlab::renderer::gl
