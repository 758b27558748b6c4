#pragma once
// The object-space reference as a render method (sss.method = "reference"; docs/extensions.md, "The object-space
// reference"). It replaces the SSS stage; renderer.cpp calls it after the main pass (and the passes that add to
// the diffuse buffer) and before add_specular:
//
//  1. tessellate the skin parts to sss.reference_edge_mm (renderer/reference/tessellation.h, adaptive) and gather
//     one sample per vertex; both are cached by model, edge length, mm per unit and the parts' skin flags, together
//     with the tessellated mesh's GL buffers (stimulus sets render one model from many views); prepare() does this
//     before the first pass of a render;
//  2. bake: draw the vertices of the tessellated skin parts, once each, as GL_POINTS with reference_bake.vert
//     (vertex i → pixel (i mod W, i div W) of a float target) linked with the unchanged main_pass.frag
//     (MainPass::bindShading / setMaterial), and read back location 0 (diffuse = exposure · (lights · shadow + IBL · AO) · albedo, alpha =
//     mask) plus location 7 (transmittance, added to the diffuse);
//  3. convolve the baked diffuse over the surface (renderer/reference/surface_convolution.h) with the radial
//     profile of sss.profile / sss.material / sss.width_mm, skin samples only (skin material, vertex skin ≥ 0.5 and
//     baked mask ≥ 0.5); the sample albedo is 1 because the bake already holds E · α;
//  4. draw: copy the main pass's diffuse into the output, then draw the tessellated skin parts with the per-vertex
//     convolved radiance (interpolated across triangles), keeping a fragment only where its view depth matches the
//     main pass's linear depth (relative 1e-4; the tessellated surface lies in the main pass's triangle planes) and,
//     of several matches, the closest (the front and back faces at a silhouette); blended by the skin mask. Non-skin
//     parts, occluded skin and the background keep the main pass's diffuse.
//
// The result resolves detail down to the tessellation edge length: lighting, shadows and albedo-map detail are
// sampled at the vertices and interpolated linearly in between (maps are read at level 0 at the vertex uv, so map
// detail finer than the vertex spacing is not averaged but point-sampled).
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/gpu_scene.h"
#include "renderer/gl/main_pass.h"
#include "renderer/gl/shader_library.h"
#include "renderer/sss/sss_params.h"

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::renderer::gl {

struct ReferenceInputs {
    std::shared_ptr<const Model> model;     // the model the main pass drew (world units)
    std::vector<GpuMaterial> partMaterials; // per part, after the spec's material overrides (skin flags included)
    const GpuScene* scene = nullptr;        // maps, lights, irradiance of the main pass
    GLuint shadowMaps = 0;
    MainPassSettings mainSettings;         // camera, exposure, ... of the main pass
    const FrameTargets* targets = nullptr; // diffuse, mask and depthBuffer of the main pass
    float mmPerUnit = 1.0f;
    std::string source; // scene spec file, for error messages
};

class ReferenceMethod {
public:
    explicit ReferenceMethod(ShaderLibrary& shaders);
    ~ReferenceMethod();
    ReferenceMethod(const ReferenceMethod&) = delete;
    ReferenceMethod& operator=(const ReferenceMethod&) = delete;

    // Checks the parameters and tessellates (or finds the cached tessellation); needs model, partMaterials,
    // mmPerUnit and source of `inputs` only. Throws InputError "<source>: sss.profile: ..." for a profile without
    // a radial form and "<source>: sss.reference_edge_mm: ..." for an edge length that needs more than
    // kMaxReferenceVertices vertices. renderer.cpp calls it before the first pass, so bad input fails before any
    // GL work; run() calls it too (a cache hit then).
    void prepare(const ReferenceInputs& inputs, const sss::SssParams& params);

    // Writes every pixel of `output` (GL_RGBA32F, frame size); the same InputErrors as prepare(). Leaves GL state as the SSS stage contract asks (sss_stage.h).
    void run(const ReferenceInputs& inputs, const sss::SssParams& params, GLuint output);

    // CPU timings and sizes of the last run: {"tessellate_ms", "cached", "samples", "skin_samples",
    // "bake_readback_ms", "convolve_ms", "sources_per_sample", "cutoff_mm", "edge_mm", "longest_edge_mm"}.
    const nlohmann::json& lastRun() const { return lastRun_; }

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    nlohmann::json lastRun_ = nlohmann::json::object();
};

} // namespace skinlab::renderer::gl
