#include "renderer/scene/scene_spec.h"

#include "common/error.h"
#include "common/spec.h"
#include "renderer/scene/builtin_scenes.h"
#include "renderer/scene/skin_spec.h"
#include "renderer/sss/eevee_params.h"
#include "renderer/sss/pathtraced_params.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>

namespace skinlab::renderer {

namespace {

glm::vec3 toVec3(const std::array<double, 3>& v) {
    return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])};
}
nlohmann::json jsonVec3(const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

constexpr double kHuge = 1e30;
constexpr std::int64_t kMaxImage = 8192;          // render.width/height, render.window.width/height
constexpr std::int64_t kMaxWindowedFrame = 65536; // render.width/height with a render.window

// Resolves a path of the spec: "assets:REL" under the assets folder, else relative to the spec's folder.
// Checks that the file exists (a missing file is bad input, named with its key).
struct PathResolver {
    const SpecReader* root;
    std::filesystem::path specDirectory;
    std::filesystem::path assetsDirectory;

    std::filesystem::path resolve(const SpecReader& reader, std::string_view key, const std::string& value) const {
        if (value.empty()) return {};
        std::filesystem::path path;
        if (value.rfind("assets:", 0) == 0) {
            if (assetsDirectory.empty())
                reader.fail(key, "'" + value + "' needs the assets folder: pass --assets DIR or set SKINLAB_ASSETS");
            path = assetsDirectory / value.substr(7);
        } else {
            path = value;
            if (path.is_relative()) path = specDirectory / path;
        }
        std::error_code error;
        if (!std::filesystem::is_regular_file(path, error)) reader.fail(key, "file not found: " + path.string());
        return path;
    }
};

void checkDirection(const SpecReader& reader, std::string_view key, const glm::vec3& v) {
    if (glm::length(v) < 1e-6f) reader.fail(key, "must not be the zero vector");
}

// Each reader below reads one table of the spec into `spec` and records its resolved values in `resolved`.

// [model]: a built-in model or a model file, and the keys that apply to it only.
void readModel(const SpecReader& root, const PathResolver& paths, SceneSpec& spec, nlohmann::json& resolved) {
    const SpecReader model = root.table("model");
    const std::string source = model.requiredString("source");
    if (source.rfind("builtin:", 0) == 0) {
        static const std::vector<std::string> known = {"builtin:halo", "builtin:bleed", "builtin:ear", "builtin:head"};
        bool found = false;
        for (const auto& k : known) found = found || k == source;
        if (!found)
            model.fail("source", "unknown built-in model '" + source +
                                     "' (known: builtin:halo, builtin:bleed, builtin:ear, builtin:head)");
        spec.modelSource = source;
    } else {
        spec.modelSource = paths.resolve(model, "source", source).string();
    }
    resolved["model"]["source"] = source;
    if (model.has("depth_gap_mm")) {
        if (source != "builtin:halo") model.fail("depth_gap_mm", "only applies to builtin:halo");
    }
    if (model.has("thickness_mm")) {
        if (source != "builtin:ear") model.fail("thickness_mm", "only applies to builtin:ear");
    }
    if (model.has("skin_detail")) {
        if (source != "builtin:head") model.fail("skin_detail", "only applies to builtin:head");
    }
    spec.skinDetail = model.boolean("skin_detail", true);
    if (source == "builtin:head") resolved["model"]["skin_detail"] = spec.skinDetail;
    if (model.has("flip_v") && source.rfind("builtin:", 0) == 0) model.fail("flip_v", "only applies to model files");
    spec.flipV = model.boolean("flip_v", false);
    if (source.rfind("builtin:", 0) != 0) resolved["model"]["flip_v"] = spec.flipV;
    spec.depthGapMm = model.number("depth_gap_mm", 200.0, 1e-3, 10000.0);
    spec.thicknessMm = model.number("thickness_mm", 2.5, 0.05, 20.0);
    if (source == "builtin:halo") resolved["model"]["depth_gap_mm"] = spec.depthGapMm;
    if (source == "builtin:ear") resolved["model"]["thickness_mm"] = spec.thicknessMm;
}

// [textures]: the maps of a model file (paths checked).
void readTextures(const SpecReader& root, const PathResolver& paths, SceneSpec& spec, nlohmann::json& resolved) {
    const SpecReader textures = root.table("textures");
    const std::string albedo = textures.string("albedo", "");
    const std::string normal = textures.string("normal", "");
    const std::string specular = textures.string("specular", "");
    const std::string occlusion = textures.string("occlusion", "");
    const std::string skinMask = textures.string("skin_mask", "");
    spec.textures.albedo = paths.resolve(textures, "albedo", albedo);
    spec.textures.normal = paths.resolve(textures, "normal", normal);
    spec.textures.specular = paths.resolve(textures, "specular", specular);
    spec.textures.occlusion = paths.resolve(textures, "occlusion", occlusion);
    spec.textures.skinMask = paths.resolve(textures, "skin_mask", skinMask);
    spec.textures.normalStrength = textures.number("normal_strength", 1.0, 0.0, 4.0);
    resolved["textures"] = {{"albedo", albedo},      {"normal", normal},
                            {"specular", specular},  {"occlusion", occlusion},
                            {"skin_mask", skinMask}, {"normal_strength", spec.textures.normalStrength}};
}

// [[materials]]: overrides per material of the model ("*" for all).
void readMaterials(const SpecReader& root, SceneSpec& spec, nlohmann::json& resolved) {
    resolved["materials"] = nlohmann::json::array();
    for (const SpecReader& material : root.tables("materials")) {
        MaterialSpec m;
        m.name = material.requiredString("name");
        nlohmann::json entry = {{"name", m.name}};
        if (material.has("albedo")) {
            m.albedo = toVec3(material.vec3("albedo", {1, 1, 1}, 0.0, 1.0));
            entry["albedo"] = jsonVec3(*m.albedo);
        }
        if (material.has("skin")) entry["skin"] = *(m.skin = material.boolean("skin", true));
        if (material.has("glossiness"))
            entry["glossiness"] = *(m.glossiness = material.number("glossiness", 0.6, 0.0, 1.0));
        if (material.has("specular_intensity"))
            entry["specular_intensity"] =
                *(m.specularIntensity = material.number("specular_intensity", 1.0, 0.0, 100.0));
        spec.materials.push_back(m);
        resolved["materials"].push_back(entry);
    }
}

// [camera]: a named view (orbited by yaw and pitch) or an explicit one.
void readCamera(const SpecReader& root, SceneSpec& spec, nlohmann::json& resolved) {
    const SpecReader camera = root.table("camera");
    CameraSpec& c = spec.camera;
    c.view = camera.choice("view", "mid", {"close", "mid", "far", "explicit"});
    c.fovDeg = camera.number("fov_deg", 30.0, 1.0, 179.0);
    nlohmann::json& r = resolved["camera"];
    r = {{"view", c.view}, {"fov_deg", c.fovDeg}};
    if (c.view == "explicit") {
        if (!camera.has("position"))
            camera.fail("position", "missing (camera.view = explicit needs position and target)");
        if (!camera.has("target")) camera.fail("target", "missing (camera.view = explicit needs position and target)");
        c.position = toVec3(camera.vec3("position", {0, 0, 1}, -kHuge, kHuge));
        c.target = toVec3(camera.vec3("target", {0, 0, 0}, -kHuge, kHuge));
        c.up = toVec3(camera.vec3("up", {0, 1, 0}, -kHuge, kHuge));
        checkDirection(camera, "up", c.up);
        if (glm::length(c.position - c.target) < 1e-9f) camera.fail("target", "equals camera.position");
        if (glm::length(glm::cross(glm::normalize(c.target - c.position), glm::normalize(c.up))) < 1e-4f)
            camera.fail("up", "is parallel to the viewing direction");
        for (const char* key : {"yaw_deg", "pitch_deg"})
            if (camera.has(key)) camera.fail(key, "only applies to the named views close|mid|far");
        r["position"] = jsonVec3(c.position);
        r["target"] = jsonVec3(c.target);
        r["up"] = jsonVec3(c.up);
    } else {
        for (const char* key : {"position", "target", "up"})
            if (camera.has(key)) camera.fail(key, "only applies to camera.view = explicit");
        c.yawDeg = camera.number("yaw_deg", 0.0, -180.0, 180.0);
        c.pitchDeg = camera.number("pitch_deg", 0.0, -89.0, 89.0);
        r["yaw_deg"] = c.yawDeg;
        r["pitch_deg"] = c.pitchDeg;
    }
}

// [[lights]]: directional and spot lights, at most 4.
void readLights(const SpecReader& root, SceneSpec& spec, nlohmann::json& resolved) {
    resolved["lights"] = nlohmann::json::array();
    for (const SpecReader& light : root.tables("lights")) {
        LightSpec l;
        l.type = light.choice("type", "directional", {"directional", "spot"});
        l.color = toVec3(light.vec3("color", {1, 1, 1}, 0.0, 1e6));
        l.intensity = light.number("intensity", 1.0, 0.0, 1e6);
        l.shadow = light.boolean("shadow", true);
        nlohmann::json entry = {
            {"type", l.type}, {"color", jsonVec3(l.color)}, {"intensity", l.intensity}, {"shadow", l.shadow}};
        if (l.type == "directional") {
            for (const char* key : {"position", "target", "inner_angle_deg", "outer_angle_deg"})
                if (light.has(key)) light.fail(key, "only applies to type = spot");
            l.direction = toVec3(light.vec3("direction", {0, 0, -1}, -kHuge, kHuge));
            checkDirection(light, "direction", l.direction);
            l.direction = glm::normalize(l.direction);
            entry["direction"] = jsonVec3(l.direction);
        } else {
            if (light.has("direction"))
                light.fail("direction", "does not apply to type = spot (give position and target)");
            if (!light.has("position")) light.fail("position", "missing (a spot light needs position and target)");
            l.position = toVec3(light.vec3("position", {0, 0, 1}, -kHuge, kHuge));
            l.target = toVec3(light.vec3("target", {0, 0, 0}, -kHuge, kHuge));
            if (glm::length(l.position - l.target) < 1e-9f) light.fail("target", "equals the light's position");
            l.innerAngleDeg = light.number("inner_angle_deg", 20.0, 0.0, 89.0);
            l.outerAngleDeg = light.number("outer_angle_deg", 30.0, 0.1, 89.0);
            if (l.outerAngleDeg <= l.innerAngleDeg)
                light.fail("outer_angle_deg",
                           "must be larger than inner_angle_deg (" + std::to_string(l.innerAngleDeg) + ")");
            entry["position"] = jsonVec3(l.position);
            entry["target"] = jsonVec3(l.target);
            entry["inner_angle_deg"] = l.innerAngleDeg;
            entry["outer_angle_deg"] = l.outerAngleDeg;
        }
        spec.lights.push_back(l);
        resolved["lights"].push_back(entry);
    }
    if (spec.lights.size() > 4) root.fail("lights", "at most 4 lights, got " + std::to_string(spec.lights.size()));
}

// [shadow]: the shadow map.
void readShadow(const SpecReader& root, SceneSpec& spec, nlohmann::json& resolved) {
    const SpecReader shadow = root.table("shadow");
    spec.shadowResolution = static_cast<int>(shadow.integer("resolution", 2048, 64, 8192));
    spec.shadowPcfRadius = static_cast<int>(shadow.integer("pcf_radius", 1, 0, 4));
    resolved["shadow"] = {{"resolution", spec.shadowResolution}, {"pcf_radius", spec.shadowPcfRadius}};
}

// [environment]: an HDR file or a constant radiance, and the background.
void readEnvironment(const SpecReader& root, const PathResolver& paths, SceneSpec& spec, nlohmann::json& resolved) {
    const SpecReader environment = root.table("environment");
    EnvironmentSpec& e = spec.environment;
    const std::string environmentFile = environment.string("file", "");
    e.file = paths.resolve(environment, "file", environmentFile);
    if (!environmentFile.empty() && environment.has("radiance"))
        environment.fail("radiance", "only applies without environment.file (a constant environment)");
    e.radiance = toVec3(environment.vec3("radiance", {0, 0, 0}, 0.0, 1e6));
    e.intensity = environment.number("intensity", 1.0, 0.0, 1e6);
    e.rotationDeg = environment.number("rotation_deg", 0.0, -360.0, 360.0);
    e.background = environment.choice("background", "environment", {"environment", "color"});
    if (e.background != "color" && environment.has("background_color"))
        environment.fail("background_color", "only applies to environment.background = color");
    e.backgroundColor = toVec3(environment.vec3("background_color", {0, 0, 0}, 0.0, 1e6));
    e.irradiance = environment.choice("irradiance", "sh9", {"sh9", "exact"});
    resolved["environment"] = {{"file", environmentFile},    {"radiance", jsonVec3(e.radiance)},
                               {"intensity", e.intensity},   {"rotation_deg", e.rotationDeg},
                               {"background", e.background}, {"background_color", jsonVec3(e.backgroundColor)}};
    // Recorded when set: the records (and so the stimulus sets' cache keys) of scenes without it stay as they were.
    if (e.irradiance != "sh9") resolved["environment"]["irradiance"] = e.irradiance;
}

// [render]: image size and exposure.
void readRender(const SpecReader& root, SceneSpec& spec, nlohmann::json& resolved) {
    const SpecReader render = root.table("render");
    // The frame may exceed the largest image only when a window renders a part of it.
    const bool windowed = render.has("window");
    const std::int64_t largest = windowed ? kMaxWindowedFrame : kMaxImage;
    spec.frameWidth = static_cast<int>(render.integer("width", 512, 16, largest));
    spec.frameHeight = static_cast<int>(render.integer("height", 512, 16, largest));
    spec.width = spec.frameWidth;
    spec.height = spec.frameHeight;
    spec.exposureEv = render.number("exposure_ev", 0.0, -30.0, 30.0);
    resolved["render"] = {{"width", spec.width}, {"height", spec.height}, {"exposure_ev", spec.exposureEv}};
    if (windowed) {
        const SpecReader window = render.table("window");
        RenderWindow w;
        for (const char* key : {"x", "y", "width", "height"})
            if (!window.has(key)) window.fail(key, "missing (a window has x, y, width, height in pixels of the frame)");
        w.x = static_cast<int>(window.integer("x", 0, 0, spec.frameWidth - 1));
        w.y = static_cast<int>(window.integer("y", 0, 0, spec.frameHeight - 1));
        w.width = static_cast<int>(window.integer("width", 1, 1, kMaxImage));
        w.height = static_cast<int>(window.integer("height", 1, 1, kMaxImage));
        if (w.x + w.width > spec.frameWidth)
            window.fail("width", "x + width = " + std::to_string(w.x + w.width) + " exceeds render.width " +
                                     std::to_string(spec.frameWidth));
        if (w.y + w.height > spec.frameHeight)
            window.fail("height", "y + height = " + std::to_string(w.y + w.height) + " exceeds render.height " +
                                      std::to_string(spec.frameHeight));
        spec.window = w;
        spec.width = w.width;
        spec.height = w.height;
        resolved["render"]["window"] = {{"x", w.x}, {"y", w.y}, {"width", w.width}, {"height", w.height}};
    }
    // Anti-aliasing (docs/rendering.md, "Anti-aliasing"): supersampling at ssaa_factor × the size per axis,
    // resolved by a box of one output pixel; "none" samples each pixel's centre once.
    spec.antialiasing = render.choice("antialiasing", "ssaa", {"ssaa", "none"});
    resolved["render"]["antialiasing"] = spec.antialiasing;
    if (spec.antialiasing == "none") {
        for (const char* key : {"ssaa_factor", "ssaa_filter"})
            if (render.has(key)) render.fail(key, "only applies to render.antialiasing = \"ssaa\"");
        spec.ssaaFactor = 1;
        return;
    }
    spec.ssaaFactor = static_cast<int>(render.integer("ssaa_factor", kDefaultSsaaFactor, 2, kMaxSsaaFactor));
    spec.ssaaFilter = render.choice("ssaa_filter", "box", {"box"});
    const int largestSide = std::max(spec.width, spec.height);
    if (largestSide * spec.ssaaFactor > kMaxInternalSize)
        render.fail("ssaa_factor", std::to_string(spec.ssaaFactor) + " x " + std::to_string(largestSide) +
                                       " px = " + std::to_string(largestSide * spec.ssaaFactor) +
                                       " px exceeds the internal limit of " + std::to_string(kMaxInternalSize) +
                                       " px (lower it or the image size)");
    resolved["render"]["ssaa_factor"] = spec.ssaaFactor;
    resolved["render"]["ssaa_filter"] = spec.ssaaFilter;
}

// [tone_map]: the display operator.
void readToneMap(const SpecReader& root, SceneSpec& spec, nlohmann::json& resolved) {
    const SpecReader toneMap = root.table("tone_map");
    spec.toneMapper =
        toneMap.choice("operator", "filmic", {"linear", "exponential", "reinhard", "reinhard-rgb", "filmic"});
    spec.exponentialK = toneMap.number("exponential_k", 1.0, 1e-3, 1e3);
    spec.filmicWhite = toneMap.number("filmic_white", 11.2, 1.0, 1e3);
    spec.reinhardKey = toneMap.number("reinhard_key", 0.18, 1e-3, 10.0);
    const std::string display = toneMap.choice("display", "srgb", {"srgb"});
    resolved["tone_map"] = {{"operator", spec.toneMapper},
                            {"exponential_k", spec.exponentialK},
                            {"filmic_white", spec.filmicWhite},
                            {"reinhard_key", spec.reinhardKey},
                            {"display", display}};
}

// [sss], [transmittance], [pathtraced] and [eevee]: read by their typed records in renderer/sss; [pathtraced] and
// [eevee] are recorded in `resolved` only for the method that renders with them.
void readMethodTables(const SpecReader& root, SceneSpec& spec, nlohmann::json& resolved) {
    spec.sss = sss::readSssParams(root);
    spec.transmittance = sss::readTransmittanceParams(root);
    resolved["sss"] = spec.sss.toJson();
    resolved["transmittance"] = spec.transmittance.toJson();
    spec.pathtraced = pathtraced::readPathtracedParams(root);
    spec.eevee = pathtraced::readEeveeParams(root);
    if (spec.antialiasing == "ssaa") {
        // The Blender conditions get the rasterizer's reconstruction (docs/rendering.md, "Anti-aliasing"): Cycles
        // its box filter of one pixel, EEVEE the Blackman-Harris filter of the same variance (kEeveeBoxMatchedFilterPx);
        // their own filter width is then not a choice.
        for (const char* table : {"pathtraced", "eevee"})
            if (const SpecReader t = root.table(table); t.has("filter_width_px"))
                t.fail("filter_width_px", "only applies to render.antialiasing = \"none\" (with \"ssaa\" Blender "
                                          "gets the same one-pixel box filter as the rasterizer)");
        spec.pathtraced.filterWidthPx = 1.0;
        spec.eevee.filterWidthPx = kEeveeBoxMatchedFilterPx;
    }
    if (sss::methodInfo(spec.sss.method).execution == sss::Execution::Cycles)
        resolved["pathtraced"] = spec.pathtraced.toJson();
    if (sss::methodInfo(spec.sss.method).execution == sss::Execution::Eevee) resolved["eevee"] = spec.eevee.toJson();
}

// The spec's TOML with the overrides applied, and the folder its relative paths are relative to.
struct SpecSource {
    toml::table table;
    std::filesystem::path directory = std::filesystem::current_path();
};

SpecSource readSpecSource(const std::string& scene, const std::vector<std::string>& overrides) {
    SpecSource source;
    if (scene.rfind("builtin:", 0) == 0) {
        const auto text = builtinSceneText(scene.substr(8));
        if (!text) {
            std::string names;
            for (const auto& name : builtinSceneNames()) names += (names.empty() ? "builtin:" : ", builtin:") + name;
            throw InputError("unknown built-in scene '" + scene + "' (known: " + names + ")");
        }
        source.table = parseTomlString(*text, scene);
    } else {
        std::error_code error;
        if (!std::filesystem::is_regular_file(scene, error))
            throw InputError(scene + ": scene spec not found (give a TOML file or builtin:NAME)");
        source.table = parseTomlFile(scene);
        source.directory = std::filesystem::absolute(scene).parent_path();
    }
    for (const auto& assignment : overrides) applyOverride(source.table, assignment, "--set");
    return source;
}

} // namespace

SceneSpec loadSceneSpec(const std::string& scene, const std::vector<std::string>& overrides,
                        const std::filesystem::path& assetsDirectoryIn) {
    SceneSpec spec;
    spec.source = scene;
    SpecSource source = readSpecSource(scene, overrides);
    std::filesystem::path assetsDirectory = assetsDirectoryIn;
    if (assetsDirectory.empty())
        if (const char* environment = std::getenv("SKINLAB_ASSETS"); environment && *environment)
            assetsDirectory = environment;

    // Errors name the spec file (or builtin:NAME) the way the user wrote it.
    SpecReader root(source.table, scene, "");
    PathResolver paths{&root, source.directory, assetsDirectory};
    nlohmann::json resolved;
    resolved["scene"] = scene;
    spec.mmPerUnit = root.number("mm_per_unit", 1.0, 1e-6, 1e6);
    resolved["mm_per_unit"] = spec.mmPerUnit;
    readModel(root, paths, spec, resolved);
    readTextures(root, paths, spec, resolved);
    readMaterials(root, spec, resolved);
    readCamera(root, spec, resolved);
    readLights(root, spec, resolved);
    readShadow(root, spec, resolved);
    readEnvironment(root, paths, spec, resolved);
    readRender(root, spec, resolved);
    readToneMap(root, spec, resolved);
    readMethodTables(root, spec, resolved);
    spec.skin = readSkinTable(root, resolved);
    if (spec.skin) sss::applySkinTone(*spec.skin, spec.sss);
    root.finish();
    spec.resolved = resolved;
    return spec;
}

CameraPose frameCamera(const CameraSpec& camera, const glm::vec3& frameMin, const glm::vec3& frameMax,
                       const glm::vec3& sceneMin, const glm::vec3& sceneMax, int width, int height,
                       const std::optional<RenderWindow>& window) {
    CameraPose pose;
    pose.fovYRadians = static_cast<float>(glm::radians(camera.fovDeg));
    const float tanHalf = std::tan(pose.fovYRadians * 0.5f);
    const glm::vec3 centre = 0.5f * (frameMin + frameMax);
    const float radius = std::max(0.5f * glm::length(frameMax - frameMin), 1e-6f);
    if (camera.view == "explicit") {
        pose.position = camera.position;
        pose.target = camera.target;
        pose.up = glm::normalize(camera.up);
    } else {
        // Fraction of the image height the bounding sphere's silhouette fills.
        const float fill = camera.view == "far" ? 0.4f : camera.view == "mid" ? 0.9f : 1.8f;
        const float angularRadius = std::atan(fill * tanHalf);
        const float distance = radius / std::sin(angularRadius);
        const float yaw = static_cast<float>(glm::radians(camera.yawDeg));
        const float pitch = static_cast<float>(glm::radians(camera.pitchDeg));
        const glm::vec3 offset{std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch)};
        pose.target = centre;
        pose.position = centre + distance * offset;
        pose.up = {0, 1, 0};
    }
    pose.view = glm::lookAt(pose.position, pose.target, pose.up);
    // Near/far enclose the whole scene's bounding sphere (depth along the view axis), the near plane never
    // closer than 1e-4 of the far plane (depth precision).
    const glm::vec3 sceneCentre = 0.5f * (sceneMin + sceneMax);
    const float sceneRadius = std::max(0.5f * glm::length(sceneMax - sceneMin), 1e-6f);
    const float centreDepth = -(pose.view * glm::vec4(sceneCentre, 1.0f)).z;
    pose.farPlane = std::max(centreDepth + sceneRadius * 1.05f, 1e-3f);
    pose.nearPlane = std::max(centreDepth - sceneRadius * 1.05f, pose.farPlane * 1e-4f);
    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    pose.projection = glm::perspective(pose.fovYRadians, aspect, pose.nearPlane, pose.farPlane);
    pose.focalLengthPixels = 0.5f * static_cast<float>(height) / tanHalf;
    pose.principalPoint = {0.5f * static_cast<float>(width), 0.5f * static_cast<float>(height)};
    if (window) {
        // Frame NDC → window NDC: x_w = (W/w) x_f + (W − 2x − w)/w; y counted from the bottom (GL), the window's
        // bottom row is H − y − h of the frame, so y_w = (H/h) y_f + (2y + h − H)/h. Applied in clip space (the
        // offsets scale with w_clip), it is the off-axis frustum through the window's edges.
        const auto W = static_cast<float>(width), H = static_cast<float>(height);
        const auto x = static_cast<float>(window->x), y = static_cast<float>(window->y);
        const auto w = static_cast<float>(window->width), h = static_cast<float>(window->height);
        glm::mat4 toWindow(1.0f);
        toWindow[0][0] = W / w;
        toWindow[1][1] = H / h;
        toWindow[3][0] = (W - 2.0f * x - w) / w;
        toWindow[3][1] = (2.0f * y + h - H) / h;
        pose.projection = toWindow * pose.projection;
        pose.principalPoint = {0.5f * W - x, y + h - 0.5f * H};
    }
    return pose;
}

} // namespace skinlab::renderer
