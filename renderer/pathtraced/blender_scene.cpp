#include "renderer/pathtraced/blender_scene.h"
#include "renderer/output/exr_writer.h"
#include "renderer/scene/texture.h"
#include "renderer/sss/skin_model.h"
#include "renderer/sss/sss_params.h"

#include "common/error.h"
#include "common/files.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <map>
#include <optional>
#include <tuple>

namespace skinlab::renderer::pathtraced_files {
std::optional<std::string_view> embeddedFile(std::string_view name);
}

namespace skinlab::renderer::pathtraced {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr float kSkinF0 = 0.028f; // renderer/shaders/specular_brdf.glsl

nlohmann::json vec3Json(const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

template <typename T>
void appendRaw(std::string& out, const std::vector<T>& values) {
    const auto* bytes = reinterpret_cast<const char*>(values.data());
    out.append(bytes, bytes + values.size() * sizeof(T));
}

// A colour split into a unit-maximum colour and a scale (Blender's light colours are clamped to [0, 1]).
std::pair<glm::vec3, float> splitColor(const glm::vec3& color) {
    const float peak = std::max({color.x, color.y, color.z});
    if (!(peak > 0.0f)) return {glm::vec3(1.0f), 0.0f};
    return {color / peak, peak};
}

} // namespace

bool isClosedSurface(const Model& model, const SubMesh& part) {
    // Weld by position (exact float bits): seams duplicate vertices with the same position.
    std::map<std::tuple<float, float, float>, std::uint32_t> welded;
    auto id = [&](std::uint32_t index) {
        const glm::vec3& p = model.vertices[index].position;
        return welded.emplace(std::make_tuple(p.x, p.y, p.z), static_cast<std::uint32_t>(welded.size())).first->second;
    };
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (std::uint32_t t = part.firstIndex; t + 2 < part.firstIndex + part.indexCount; t += 3) {
        const std::uint32_t a = id(model.indices[t]), b = id(model.indices[t + 1]), c = id(model.indices[t + 2]);
        for (auto [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
            if (u == v) continue; // degenerate (a pole of a UV sphere)
            ++edges[{std::min(u, v), std::max(u, v)}];
        }
    }
    for (const auto& [edge, count] : edges)
        if (count != 2) return false;
    return !edges.empty();
}

double principledRoughness(double glossiness) {
    const double alpha = 8192.0 * std::pow(glossiness, 5.0);
    return std::pow(2.0 / (alpha + 2.0), 0.25);
}

double principledSpecular(double f0) { return f0 / 0.08; }

std::string_view cyclesScript() {
    const auto script = pathtraced_files::embeddedFile("cycles_scene.py");
    if (!script) throw RuntimeError("cycles_scene.py is not embedded in this build");
    return *script;
}

std::vector<ModelMapFile> modelMapFiles(const BlenderSceneInputs& inputs) {
    std::vector<ModelMapFile> files;
    if (inputs.spec->textures.albedo.empty() && inputs.model->albedoMap)
        files.push_back({"albedo", "model-albedo.exr", inputs.model->albedoMap.get()});
    if (!inputs.spec->textures.albedo.empty() && inputs.retonedAlbedoMap)
        files.push_back({"albedo", "retoned-albedo.exr", inputs.retonedAlbedoMap});
    if (inputs.spec->textures.normal.empty() && inputs.model->normalMap)
        files.push_back({"normal", "model-normal.exr", inputs.model->normalMap.get()});
    return files;
}

bool rendersEnvironmentSeparately(const BlenderSceneInputs& inputs) {
    return !inputs.params.environmentShadow && !inputs.spec->lights.empty();
}

namespace {
// One material per part. Radii: the profile's mm at width 3 mm, scaled like every kernel, in scene units.
nlohmann::json materialsJson(const BlenderSceneInputs& inputs) {
    const SceneSpec& spec = *inputs.spec;
    const PathtracedParams& p = inputs.params;
    const double radiusScale = sss::profileScale(inputs.sssWidthMm) / spec.mmPerUnit;
    // A [skin] tone: the radii (fitted to d'Eon's profile) scale by the tone's profile width over d'Eon's, per
    // channel (sss::skinWidthRatio; (1, 1, 1) without [skin]).
    const std::array<double, 3> tone = sss::skinWidthRatio(spec.sss);
    nlohmann::json materials = nlohmann::json::array();
    for (std::size_t i = 0; i < inputs.partMaterials.size(); ++i) {
        const PartMaterial& m = inputs.partMaterials[i];
        materials.push_back(
            {{"name", "part" + std::to_string(i)},
             {"albedo", vec3Json(m.albedo)},
             {"skin", m.skin},
             {"sss", p.sss},
             {"diffuse", p.diffuse},
             {"radius",
              {p.radiusMm[0] * radiusScale * tone[0], p.radiusMm[1] * radiusScale * tone[1],
               p.radiusMm[2] * radiusScale * tone[2]}},
             {"roughness", principledRoughness(m.glossiness)},
             {"specular",
              p.specular && p.specularSource == "cycles" ? principledSpecular(kSkinF0) * m.specularIntensity : 0.0}});
    }
    // radius_model "albedo" (Cycles only): the shader maps each channel of the subsurface colour through the table
    // (piecewise linear, constant beyond its ends), already scaled like the constant radius and by radius_mm over
    // the table's value at the built-in skin's colour (radiusAtAlbedoMm).
    if (inputs.engine == "cycles" && p.radiusModel == "albedo") {
        const AlbedoRadiusTable& table = albedoRadiusTable();
        nlohmann::json radius = nlohmann::json::array();
        for (int c = 0; c < 3; ++c) {
            nlohmann::json channel = nlohmann::json::array();
            for (const double a : table.albedo)
                channel.push_back(radiusAtAlbedoMm(p, c, a) * radiusScale * tone[static_cast<std::size_t>(c)]);
            radius.push_back(channel);
        }
        const nlohmann::json radiusTable = {{"albedo", table.albedo}, {"radius", radius}};
        for (auto& material : materials) material["radius_table"] = radiusTable;
    }
    // diffuse "lambert": the walk's colour divided by its measured excess reflectance (walkReflectanceTable).
    if (inputs.engine == "cycles" && p.diffuse == "lambert") {
        const WalkReflectanceTable& walk = walkReflectanceTable();
        const nlohmann::json gainTable = {{"albedo", walk.albedo}, {"gain", walk.gain}};
        for (auto& material : materials) material["walk_gain_table"] = gainTable;
    }
    return materials;
}
} // namespace

nlohmann::json blenderSceneJson(const BlenderSceneInputs& inputs, std::string_view meshFile, std::string_view output,
                                std::string_view record) {
    const SceneSpec& spec = *inputs.spec;
    const PathtracedParams& p = inputs.params;
    nlohmann::json scene;
    scene["settings"] = {{"width", spec.width}, {"height", spec.height},       {"samples", p.samples},
                         {"seed", p.seed},      {"max_bounces", p.maxBounces}, {"filter_width_px", p.filterWidthPx},
                         {"threads", p.threads}};
    scene["settings"]["engine"] = inputs.engine;
    // render.antialiasing = "ssaa": Cycles' box filter of one pixel, the rasterizer's reconstruction (EEVEE has no
    // box; its filter width is set by the scene spec, kEeveeBoxMatchedFilterPx). "none": a narrow Gaussian.
    scene["settings"]["pixel_filter"] = spec.antialiasing == "ssaa" ? "box" : "gaussian";
    if (inputs.engine == "eevee") scene["settings"]["eevee"] = inputs.eeveeSettings;
    // One object per part (cycles_scene.py), each with its own vertices, in Model::parts order in the file.
    nlohmann::json parts = nlohmann::json::array();
    std::size_t offset = 0;
    for (std::size_t i = 0; i < inputs.model->parts.size(); ++i) {
        const SubMesh& part = inputs.model->parts[i];
        std::vector<bool> used(inputs.model->vertices.size(), false);
        std::size_t vertexCount = 0;
        for (std::uint32_t k = part.firstIndex; k < part.firstIndex + part.indexCount; ++k)
            if (!used[inputs.model->indices[k]]) used[inputs.model->indices[k]] = true, ++vertexCount;
        parts.push_back({{"offset", offset},
                         {"vertex_count", vertexCount},
                         {"index_count", part.indexCount},
                         {"material", i},
                         {"closed", isClosedSurface(*inputs.model, part)}});
        offset += vertexCount * (3 + 3 + 2 + 3 + 1) * 4 + static_cast<std::size_t>(part.indexCount) * 4;
    }
    scene["mesh"] = {{"file", std::string(meshFile)}, {"parts", parts}};
    scene["output"] = std::string(output);
    scene["record"] = std::string(record);

    scene["materials"] = materialsJson(inputs);
    scene["textures"] = {{"albedo", spec.textures.albedo.string()},
                         {"normal", spec.textures.normal.string()},
                         {"normal_strength", spec.textures.normalStrength},
                         {"specular", spec.textures.specular.string()},
                         {"skin_mask", spec.textures.skinMask.string()}};
    // Maps the model generates in memory (builtin:head's skin detail) where the spec names none, as the rasterizer
    // chooses them: written beside the scene as linear float EXRs, read without a colour transform.
    for (const ModelMapFile& map : modelMapFiles(inputs)) {
        scene["textures"][map.key] = map.file;
        scene["textures"][map.key + "_colorspace"] = "Non-Color";
    }

    // Lights. L_c (spec intensity × colour) is the radiance of a white Lambertian facing the light, so the
    // irradiance is π L_c: a sun of strength π L_c (W/m²); a spot whose irradiance at the target distance d is
    // π L_c: radiant intensity π L_c d², Blender power 4π × that (its point lights radiate power / 4π per sr).
    nlohmann::json lights = nlohmann::json::array();
    for (const LightSpec& light : spec.lights) {
        const auto [color, scale] = splitColor(light.color * static_cast<float>(light.intensity));
        if (light.type == "directional") {
            lights.push_back({{"type", "sun"},
                              {"direction", vec3Json(glm::normalize(light.direction))},
                              {"color", vec3Json(color)},
                              {"strength", kPi * scale},
                              {"angle_rad", p.sunAngleDeg * kPi / 180.0},
                              {"shadow", light.shadow}});
        } else {
            const double distance = glm::length(light.target - light.position);
            const double cosInner = std::cos(light.innerAngleDeg * kPi / 180.0);
            const double cosOuter = std::cos(light.outerAngleDeg * kPi / 180.0);
            lights.push_back({{"type", "spot"},
                              {"position", vec3Json(light.position)},
                              {"direction", vec3Json(glm::normalize(light.target - light.position))},
                              {"color", vec3Json(color)},
                              {"power", 4.0 * kPi * kPi * scale * distance * distance},
                              // Cycles: zero outside the half-angle spot_size/2, smoothstep over
                              // (1 - cos(spot_size/2)) · blend in cosine: the rasterizer's inner..outer ramp.
                              {"spot_size_rad", 2.0 * light.outerAngleDeg * kPi / 180.0},
                              {"spot_blend", std::clamp((cosInner - cosOuter) / (1.0 - cosOuter), 0.0, 1.0)},
                              {"shadow", light.shadow}});
        }
    }
    scene["lights"] = lights;

    // Environment: rows of the map from a world direction d to Blender's equirectangular lookup direction D
    // (cycles_scene.py): D = M · R_y(−rotation) · d with M = [[0,0,−1],[−1,0,0],[0,1,0]].
    const EnvironmentSpec& e = spec.environment;
    nlohmann::json world = {{"intensity", e.intensity}, {"shadow", p.environmentShadow}};
    if (!e.file.empty()) {
        const glm::mat3 environmentFromWorld(
            glm::rotate(glm::mat4(1.0f), static_cast<float>(-e.rotationDeg * kPi / 180.0), glm::vec3(0, 1, 0)));
        const glm::mat3 m = glm::transpose(glm::mat3(0, 0, -1, -1, 0, 0, 0, 1, 0)); // rows as written above
        const glm::mat3 lookup = m * environmentFromWorld;
        nlohmann::json rows = nlohmann::json::array();
        for (int r = 0; r < 3; ++r) rows.push_back({lookup[0][r], lookup[1][r], lookup[2][r]});
        world["file"] = e.file.string();
        world["lookup_rows"] = rows;
    } else {
        world["radiance"] = vec3Json(e.radiance);
    }
    if (e.background == "color") world["camera_background"] = vec3Json(e.backgroundColor);
    else if (e.file.empty()) world["camera_background"] = nullptr;
    scene["world"] = world;
    if (rendersEnvironmentSeparately(inputs)) scene["environment_output"] = std::string(kEnvironmentOutput);

    const glm::mat4 viewToWorld = glm::inverse(inputs.camera.view);
    nlohmann::json matrix = nlohmann::json::array();
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 4; ++row) matrix.push_back(viewToWorld[column][row]);
    scene["camera"] = {{"view_to_world", matrix},
                       {"fov_y_rad", inputs.camera.fovYRadians},
                       {"near", inputs.camera.nearPlane * 0.5f},
                       {"far", inputs.camera.farPlane * 2.0f}};
    if (spec.window) {
        // render.window: Blender renders the window's pixels (settings.width/height) with the same focal length in
        // pixels, so the vertical field of view is the window's, and the lens shift moves the image off the view
        // axis. With a vertical sensor fit Blender measures the shift in units of the image height.
        const auto h = static_cast<float>(spec.height), w = static_cast<float>(spec.width);
        const float f = inputs.camera.focalLengthPixels;
        scene["camera"]["fov_y_rad"] = 2.0f * std::atan(0.5f * h / f);
        scene["camera"]["shift_x"] = (0.5f * w - inputs.camera.principalPoint.x) / h;
        scene["camera"]["shift_y"] = (0.5f * h - inputs.camera.principalPoint.y) / h;
    }
    return scene;
}

void writeBlenderScene(const std::filesystem::path& folder, const BlenderSceneInputs& inputs) {
    const Model& model = *inputs.model;
    if (inputs.partMaterials.size() != model.parts.size())
        throw RuntimeError("writeBlenderScene: " + std::to_string(inputs.partMaterials.size()) + " materials for " +
                           std::to_string(model.parts.size()) + " parts");
    static_assert(sizeof(float) == 4 && sizeof(std::uint32_t) == 4);
    std::string bytes;
    // Per part: positions, normals, UVs, colours, skin (its own vertices, first use order), then its indices.
    for (const SubMesh& part : model.parts) {
        std::vector<std::int64_t> local(model.vertices.size(), -1);
        std::vector<std::uint32_t> order, indices;
        for (std::uint32_t k = part.firstIndex; k < part.firstIndex + part.indexCount; ++k) {
            const std::uint32_t global = model.indices[k];
            if (local[global] < 0) local[global] = static_cast<std::int64_t>(order.size()), order.push_back(global);
            indices.push_back(static_cast<std::uint32_t>(local[global]));
        }
        std::vector<float> positions, normals, uvs, colors, skin;
        for (const std::uint32_t index : order) {
            const Vertex& v = model.vertices[index];
            positions.insert(positions.end(), {v.position.x, v.position.y, v.position.z});
            normals.insert(normals.end(), {v.normal.x, v.normal.y, v.normal.z});
            uvs.insert(uvs.end(), {v.uv.x, 1.0f - v.uv.y}); // Model: v = 0 at the image top; Blender: at the bottom
            colors.insert(colors.end(), {v.color.x, v.color.y, v.color.z});
            skin.push_back(v.skin);
        }
        appendRaw(bytes, positions);
        appendRaw(bytes, normals);
        appendRaw(bytes, uvs);
        appendRaw(bytes, colors);
        appendRaw(bytes, skin);
        appendRaw(bytes, indices);
    }
    ensureDirectory(folder);
    writeFileAtomic(folder / "mesh.bin", bytes);
    for (const ModelMapFile& map : modelMapFiles(inputs)) {
        const Image& image = *map.image;
        std::vector<ExrChannel> channels{{"R", {}}, {"G", {}}, {"B", {}}};
        for (int c = 0; c < 3; ++c) {
            channels[c].values.resize(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height));
            for (std::size_t p = 0; p < channels[c].values.size(); ++p) channels[c].values[p] = image.pixels[p * 4 + c];
        }
        writeExr(folder / map.file, image.width, image.height, channels, {});
    }
    writeFileAtomic(folder / "scene.json", blenderSceneJson(inputs, "mesh.bin", "cycles.exr", "cycles.json").dump(1));
    writeFileAtomic(folder / "cycles_scene.py", cyclesScript());
}

} // namespace skinlab::renderer::pathtraced
