#pragma once
// The resolved scene written for Blender (GL-free): the same triangles, camera, lights, environment and materials
// the rasterizer draws, as a JSON description plus one binary geometry file, read by cycles_scene.py (embedded in
// the binary and written beside them). docs/pathtraced.md, "What Cycles is given".
#include "renderer/sss/pathtraced_params.h"
#include "renderer/scene/mesh.h"
#include "renderer/scene/scene_spec.h"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::renderer::pathtraced {

// A part's material after the spec's [[materials]] overrides (as the rasterizer uses it).
struct PartMaterial {
    glm::vec3 albedo{1.0f};
    float skin = 1.0f;
    float glossiness = 0.6f;
    float specularIntensity = 1.0f;
};

struct BlenderSceneInputs {
    const SceneSpec* spec = nullptr;
    const Model* model = nullptr;
    std::vector<PartMaterial> partMaterials; // one per Model::parts entry
    CameraPose camera;
    PathtracedParams params;
    double sssWidthMm = 3.0; // sss.width_mm: radii scale by width_mm / 3
    // [skin] with a spec albedo map: the map re-toned through the skin model, written beside the scene in its place.
    const Image* retonedAlbedoMap = nullptr;
    // "cycles" (sss.method = "pathtraced") or "eevee" (sss.method = "eevee"): the same scene, another engine.
    std::string engine = "cycles";
    // engine "eevee": EEVEE's own settings (keys of scene.json's settings.eevee, cycles_scene.py configure_eevee).
    nlohmann::json eeveeSettings = nlohmann::json::object();
};

// Principled roughness (GGX α = roughness²) for the rasterizer's glossiness s (normalised Blinn-Phong exponent
// α_p = 8192 s^5): Beckmann m = √(2 / (α_p + 2)) (Walter et al. 2007, Eq. 33), and GGX's α taken equal to m.
double principledRoughness(double glossiness);
// Principled "Specular" for F0 (F0 = 0.08 · specular): the rasterizer's skin F0 0.028 gives 0.35.
double principledSpecular(double f0);

// Whether the triangles of `part` bound a closed surface (every edge, with vertices welded by position, shared by
// exactly two triangles). Recorded per part in the JSON ("closed"): Cycles' random walk treats an open skin surface
// as the boundary of the half-space behind it (a walk ends where it meets the surface again), so a flat patch
// such as builtin:bleed's scatters like a semi-infinite slab, except for light that walks past its rim.
bool isClosedSurface(const Model& model, const SubMesh& part);

// The maps a model generates in memory (Model::albedoMap, normalMap: builtin:head's skin detail) that the scene
// uses because the spec names no texture file in their place (as the rasterizer chooses). writeBlenderScene
// writes each as a linear float EXR `file` in the scene's folder; the JSON names it under textures.`key`, with
// textures.`key`_colorspace "Non-Color" (the values are linear: the albedo a multiplier, the normal 0.5 + 0.5 n).
struct ModelMapFile {
    std::string key;  // "albedo" or "normal"
    std::string file; // relative to the scene's folder
    const Image* image = nullptr;
};
std::vector<ModelMapFile> modelMapFiles(const BlenderSceneInputs& inputs);

// pathtraced.environment_shadow = false with lights in the scene: Cycles renders the lights (with their shadows)
// into the output and the unshadowed environment into `folder`/kEnvironmentOutput, and the two are summed.
inline constexpr std::string_view kEnvironmentOutput = "cycles-environment.exr";
bool rendersEnvironmentSeparately(const BlenderSceneInputs& inputs);

// The JSON description (the geometry itself goes to `meshFile`, named relative to the JSON's folder).
nlohmann::json blenderSceneJson(const BlenderSceneInputs& inputs, std::string_view meshFile, std::string_view output,
                                std::string_view record);

// Writes `folder`/scene.json, mesh.bin and cycles_scene.py; the image will be `folder`/cycles.exr and the
// record `folder`/cycles.json. Throws InputError when the folder cannot be written.
void writeBlenderScene(const std::filesystem::path& folder, const BlenderSceneInputs& inputs);

// The embedded cycles_scene.py.
std::string_view cyclesScript();

} // namespace skinlab::renderer::pathtraced
