#pragma once
// sss.method = "pathtraced" (Cycles) and "eevee" (EEVEE): the frame rendered by Blender, merged with the layers the
// rasterizer's passes made of the same frame (same camera and triangles), and its record in the EXR metadata
// (docs/pathtraced.md). The renderer runs Blender before any pass (a missing or failing Blender leaves nothing
// done), reads back its own layers, then calls mergeRasterizerLayers and addBlenderMetadata.
#include "renderer/output/exr_writer.h"
#include "renderer/pathtraced/cycles_render.h"
#include "renderer/scene/scene_spec.h"

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::renderer::pathtraced {

enum class BlenderEngine { Cycles, Eevee };

// Renders `inputs` (scene, model, materials, camera, re-toned albedo) with `engine`: its parameters ([pathtraced]
// or [eevee]) are taken from inputs.spec.
CyclesImage renderBlenderFrame(BlenderEngine engine, BlenderSceneInputs inputs, float exposure);

// The rasterizer's layers at the output size, top row first, as read back (specular RGBA, depth and mask one
// channel each).
struct RasterizerLayers {
    const std::vector<float>* specular = nullptr;
    const std::vector<float>* depth = nullptr;
    const std::vector<float>* mask = nullptr;
    bool antialiased = false;    // render.ssaa_factor > 1
    bool fractionalSkin = false; // a skin-mask map, or per-vertex skin below 1
};

// What the merge took from the rasterizer.
struct BlenderMerge {
    bool rasterizerSpecular = false;     // [pathtraced] / [eevee] specular_source = "rasterizer"
    bool rasterizerDepthAndMask = false; // anti-aliasing: depth and mask are the rasterizer's resolve
};

// Replaces or completes Blender's layers with the rasterizer's where the scene says so: the specular lobe
// (specular_source = "rasterizer"), depth and mask with anti-aliasing (Blender's depth and material-index passes do
// not follow its box filter's coverage), the skin fraction of the mask (a skin-mask map or per-vertex skin).
BlenderMerge mergeRasterizerLayers(CyclesImage& image, BlenderEngine engine, const SceneSpec& spec,
                                   const RasterizerLayers& layers);

// The EXR attributes of a Blender frame: skinlab:pathtraced or skinlab:eevee (parameters, Blender's version and
// times, the channels that came from Blender), skinlab:blender_version, skinlab:render_seconds and, for Cycles,
// skinlab:pathtraced_samples and skinlab:pathtraced_seed. `blenderChannels`: the EXR channels the AOV table takes
// from a Blender image ("R", "G", "B", "diffuse.*", ..., "depth.Z", "mask.Y").
void addBlenderMetadata(ExrMetadata& metadata, BlenderEngine engine, const SceneSpec& spec, const CyclesImage& image,
                        const BlenderMerge& merge, const nlohmann::json& blenderChannels);

} // namespace skinlab::renderer::pathtraced
