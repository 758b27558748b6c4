// Strict scene specs: defaults, overrides, and every error message word for word (renderer/scene/scene_spec.h).
#include "common/error.h"
#include "renderer/scene/builtin_scenes.h"
#include "renderer/scene/scene_spec.h"
#include "renderer/sss/methods/artistic.h"
#include "tests/common/temp_folder.h"

#include <cmath>
#include <fstream>
#include <gtest/gtest.h>
#include <unistd.h>

namespace skinlab::renderer {
namespace {

// The InputError message of loading `scene` with `overrides` ("" when it loads).
std::string errorOf(const std::string& scene, const std::vector<std::string>& overrides,
                    const std::filesystem::path& assets = {}) {
    try {
        loadSceneSpec(scene, overrides, assets);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

using test_support::TempFolder;

TEST(SceneSpec, EveryBuiltinSceneLoadsWithItsDefaults) {
    for (const std::string& name : builtinSceneNames()) {
        const SceneSpec spec = loadSceneSpec("builtin:" + name, {}, {});
        // The named variants (halo-grey-backdrop, bleed-true-mask) render the model their name starts with.
        EXPECT_EQ(spec.modelSource, "builtin:" + name.substr(0, name.find('-')));
        EXPECT_EQ(spec.mmPerUnit, 1.0) << name; // built-in models are in millimetres (builtin_geometry.h)
        EXPECT_FALSE(spec.lights.empty()) << name;
        EXPECT_EQ(spec.resolved["scene"], "builtin:" + name);
        EXPECT_EQ(spec.resolved["sss"]["method"], "none");
        EXPECT_EQ(spec.resolved["render"]["width"], spec.width);
    }
}

TEST(SceneSpec, AntialiasingIsSupersamplingByDefaultAndItsKeysAreStrict) {
    const SceneSpec defaults = loadSceneSpec("builtin:halo", {}, {});
    EXPECT_EQ(defaults.antialiasing, "ssaa");
    EXPECT_EQ(defaults.ssaaFactor, kDefaultSsaaFactor);
    EXPECT_EQ(defaults.resolved["render"]["antialiasing"], "ssaa");
    EXPECT_EQ(defaults.resolved["render"]["ssaa_factor"], kDefaultSsaaFactor);
    EXPECT_EQ(defaults.resolved["render"]["ssaa_filter"], "box");
    // With "ssaa" the Blender conditions get the one-pixel box (Cycles) and its variance-matched filter (EEVEE).
    EXPECT_EQ(defaults.pathtraced.filterWidthPx, 1.0);
    EXPECT_EQ(defaults.eevee.filterWidthPx, kEeveeBoxMatchedFilterPx);

    const SceneSpec off = loadSceneSpec("builtin:halo", {"render.antialiasing=none"}, {});
    EXPECT_EQ(off.ssaaFactor, 1);
    EXPECT_EQ(off.resolved["render"]["antialiasing"], "none");
    EXPECT_FALSE(off.resolved["render"].contains("ssaa_factor"));
    EXPECT_EQ(off.pathtraced.filterWidthPx, 0.01); // the narrow Gaussian: pixel centres, as the rasterizer then
    EXPECT_EQ(loadSceneSpec("builtin:halo", {"render.ssaa_factor=4"}, {}).ssaaFactor, 4);

    EXPECT_EQ(errorOf("builtin:halo", {"render.antialiasing=fxaa"}),
              "builtin:halo: render.antialiasing: 'fxaa' is not one of: ssaa, none");
    EXPECT_EQ(errorOf("builtin:halo", {"render.ssaa_factor=1"}),
              "builtin:halo: render.ssaa_factor: 1 is out of range [2, 8]");
    EXPECT_EQ(errorOf("builtin:halo", {"render.ssaa_factor=9"}),
              "builtin:halo: render.ssaa_factor: 9 is out of range [2, 8]");
    EXPECT_EQ(errorOf("builtin:halo", {"render.ssaa_filter=lanczos"}),
              "builtin:halo: render.ssaa_filter: 'lanczos' is not one of: box");
    EXPECT_EQ(errorOf("builtin:halo", {"render.antialiasing=none", "render.ssaa_factor=2"}),
              "builtin:halo: render.ssaa_factor: only applies to render.antialiasing = \"ssaa\"");
    EXPECT_EQ(errorOf("builtin:halo", {"render.width=4096", "render.ssaa_factor=8"}),
              "builtin:halo: render.ssaa_factor: 8 x 4096 px = 32768 px exceeds the internal limit of 16384 px "
              "(lower it or the image size)");
    EXPECT_EQ(errorOf("builtin:halo", {"pathtraced.filter_width_px=0.5"}),
              "builtin:halo: pathtraced.filter_width_px: only applies to render.antialiasing = \"none\" (with "
              "\"ssaa\" Blender gets the same one-pixel box filter as the rasterizer)");
    EXPECT_EQ(errorOf("builtin:halo", {"render.antialiasing=none", "eevee.filter_width_px=0.5"}), "");
}

TEST(SceneSpec, OverridesChangeValuesAndAreRecordedInTheResolvedParameters) {
    const SceneSpec spec = loadSceneSpec(
        "builtin:head",
        {"camera.view=close", "render.width=320", "tone_map.operator=reinhard", "render.exposure_ev=-1.5"}, {});
    EXPECT_EQ(spec.camera.view, "close");
    EXPECT_EQ(spec.width, 320);
    EXPECT_EQ(spec.toneMapper, "reinhard");
    EXPECT_DOUBLE_EQ(spec.exposureEv, -1.5);
    EXPECT_EQ(spec.resolved["camera"]["view"], "close");
    EXPECT_EQ(spec.resolved["render"]["width"], 320);
    EXPECT_EQ(spec.resolved["tone_map"]["operator"], "reinhard");
    // Later overrides win.
    EXPECT_EQ(loadSceneSpec("builtin:halo", {"render.height=100", "render.height=64"}, {}).height, 64);
    // environment.irradiance: recorded when set, so the records of scenes without it stay as they were.
    EXPECT_EQ(spec.environment.irradiance, "sh9");
    EXPECT_FALSE(spec.resolved["environment"].contains("irradiance"));
    const SceneSpec exact = loadSceneSpec("builtin:head", {"environment.irradiance=\"exact\""}, {});
    EXPECT_EQ(exact.environment.irradiance, "exact");
    EXPECT_EQ(exact.resolved["environment"]["irradiance"], "exact");
    EXPECT_EQ(errorOf("builtin:head", {"environment.irradiance=\"sh3\""}),
              "builtin:head: environment.irradiance: 'sh3' is not one of: sh9, exact");
}

TEST(SceneSpec, ErrorMessagesNameFileKeyAndValue) {
    EXPECT_EQ(errorOf("builtin:head", {"camera.fvo=3"}), "builtin:head: camera.fvo: unknown key");
    EXPECT_EQ(errorOf("builtin:head", {"camera.fov_deg=\"wide\""}),
              "builtin:head: camera.fov_deg: expected a number, got string \"wide\"");
    EXPECT_EQ(errorOf("builtin:head", {"camera.fov_deg=200"}),
              "builtin:head: camera.fov_deg: 200 is out of range [1, 179]");
    EXPECT_EQ(errorOf("builtin:head", {"camera.view=sideways"}),
              "builtin:head: camera.view: 'sideways' is not one of: close, mid, far, explicit");
    EXPECT_EQ(errorOf("builtin:head", {"render.width=8"}), "builtin:head: render.width: 8 is out of range [16, 8192]");
    EXPECT_EQ(
        errorOf("builtin:head", {"tone_map.operator=aces"}),
        "builtin:head: tone_map.operator: 'aces' is not one of: linear, exponential, reinhard, reinhard-rgb, filmic");
    EXPECT_EQ(errorOf("builtin:head", {"lights=3"}),
              "builtin:head: lights: expected an array of tables, got integer 3");
    EXPECT_EQ(errorOf("builtin:ear", {"model.depth_gap_mm=10"}),
              "builtin:ear: model.depth_gap_mm: only applies to builtin:halo");
    EXPECT_EQ(errorOf("builtin:head", {"camera.position=[0, 0, 1]"}),
              "builtin:head: camera.position: only applies to camera.view = explicit");
    EXPECT_EQ(errorOf("builtin:head", {"camera.view=explicit"}),
              "builtin:head: camera.position: missing (camera.view = explicit needs position and target)");
    EXPECT_EQ(errorOf("builtin:head", {"model.source=builtin:torso"}),
              "builtin:head: model.source: unknown built-in model 'builtin:torso' (known: builtin:halo, builtin:bleed, "
              "builtin:ear, builtin:head)");
    EXPECT_EQ(errorOf("builtin:head", {"environment.file=assets:envmaps/x.hdr"}, ""),
              errorOf("builtin:head", {"environment.file=assets:envmaps/x.hdr"}, "")); // stable
    EXPECT_EQ(errorOf("builtin:nope", {}),
              "unknown built-in scene 'builtin:nope' (known: builtin:halo, builtin:bleed, builtin:ear, builtin:head, "
              "builtin:halo-grey-backdrop, builtin:bleed-true-mask)");
    EXPECT_EQ(errorOf("/nonexistent/scene.toml", {}),
              "/nonexistent/scene.toml: scene spec not found (give a TOML file or builtin:NAME)");
}

// --set (the overrides) and scene files: an [sss] key the chosen method does not read is an error naming the key and
// the method; the scene holds the typed values and records the method's keys only.
TEST(SceneSpec, SssKeyOfAnotherMethodIsAnError) {
    const std::string separable = "sss.method=separable";
    EXPECT_EQ(errorOf("builtin:head", {separable, "sss.artistic_falloff=[1.0, 0.5, 0.5]"})
                  .rfind("builtin:head: sss.artistic_falloff: not a parameter of method 'separable' (its keys: ", 0),
              0u);
    EXPECT_EQ(errorOf("builtin:head", {"sss.samples=31"})
                  .rfind("builtin:head: sss.samples: not a parameter of method 'none'", 0),
              0u);
    TempFolder folder;
    const auto file = folder.write(
        "scene.toml",
        "[model]\nsource = \"builtin:head\"\n[sss]\nmethod = \"separable\"\nartistic_strength = [1, 1, 1]\n");
    const std::string fromFile = errorOf(file.string(), {});
    EXPECT_EQ(fromFile.rfind(file.string() + ": sss.artistic_strength: not a parameter of method 'separable'", 0), 0u)
        << fromFile;
    const SceneSpec spec =
        loadSceneSpec("builtin:head", {"sss.method=artistic", "sss.artistic_falloff=[1.0, 0.5, 0.5]"}, {});
    EXPECT_EQ(spec.sss.method, sss::methodId("artistic"));
    EXPECT_EQ(sss::artisticParams(spec.sss).falloff[1], 0.5);
    EXPECT_EQ(spec.resolved["sss"]["artistic_falloff"][1], 0.5);
    EXPECT_FALSE(spec.resolved["sss"].contains("profile")); // separable's key, not artistic's
}

TEST(SceneSpec, LightsAreValidatedPerType) {
    // --set replaces an array of tables as a whole (TOML inline tables).
    EXPECT_EQ(errorOf("builtin:bleed", {"lights=[{type = \"spot\", direction = [0, 0, -1]}]"}),
              "builtin:bleed: lights[0].direction: does not apply to type = spot (give position and target)");
    EXPECT_EQ(errorOf("builtin:bleed", {"lights=[{type = \"spot\", position = [0, 0, 9]}]"}), "");
    EXPECT_EQ(errorOf("builtin:bleed", {"lights=[{type = \"spot\"}]"}),
              "builtin:bleed: lights[0].position: missing (a spot light needs position and target)");
    EXPECT_EQ(errorOf("builtin:bleed", {"lights=[{}, {intensity = -1}]"}),
              "builtin:bleed: lights[1].intensity: -1 is out of range [0, 1e+06]");
    EXPECT_EQ(errorOf("builtin:bleed", {"lights=[{direction = [0, 0, 0]}]"}),
              "builtin:bleed: lights[0].direction: must not be the zero vector");
    EXPECT_EQ(errorOf("builtin:bleed", {"lights=[{colour = [1, 1, 1]}]"}),
              "builtin:bleed: lights[0].colour: unknown key (did you mean color?)");
    EXPECT_EQ(errorOf("builtin:bleed", {"lights=[{}, {}, {}, {}, {}]"}),
              "builtin:bleed: lights: at most 4 lights, got 5");
    EXPECT_EQ(loadSceneSpec("builtin:bleed", {"lights=[]"}, {}).lights.size(), 0u);
}

TEST(SceneSpec, FilePathsResolveAgainstTheSpecFolderAndTheAssetsFolder) {
    TempFolder folder;
    const auto spec = folder.write("scene.toml", "[model]\nsource = \"head.obj\"\n");
    const std::string path = spec.string();
    EXPECT_EQ(errorOf(path, {}), path + ": model.source: file not found: " + (folder.path() / "head.obj").string());
    folder.write("head.obj", "v 0 0 0\n");
    EXPECT_EQ(errorOf(path, {}), "");
    EXPECT_EQ(loadSceneSpec(path, {}, {}).modelSource, (folder.path() / "head.obj").string());

    // "assets:" paths need --assets / $SKINLAB_ASSETS.
    ::unsetenv("SKINLAB_ASSETS");
    EXPECT_EQ(
        errorOf(path, {"textures.albedo=assets:skin.jpg"}),
        path + ": textures.albedo: 'assets:skin.jpg' needs the assets folder: pass --assets DIR or set SKINLAB_ASSETS");
    EXPECT_EQ(errorOf(path, {"textures.albedo=assets:skin.jpg"}, folder.path()),
              path + ": textures.albedo: file not found: " + (folder.path() / "skin.jpg").string());
    folder.write("skin.jpg", "not really a jpeg: checked when rendering");
    EXPECT_EQ(loadSceneSpec(path, {"textures.albedo=assets:skin.jpg"}, folder.path()).textures.albedo,
              folder.path() / "skin.jpg");
}

TEST(SceneSpec, MalformedTomlNamesFileLineAndColumn) {
    TempFolder folder;
    const auto spec = folder.write("broken.toml", "[model]\nsource = \n");
    const std::string message = errorOf(spec.string(), {});
    EXPECT_EQ(message.rfind(spec.string() + ":2:", 0), 0u) << message;
}

TEST(CameraFraming, FocalLengthAndNamedViewDistances) {
    CameraSpec camera;
    camera.fovDeg = 30.0;
    const glm::vec3 lo{-1, -1, -1}, hi{1, 1, 1};
    const float radius = std::sqrt(3.0f);
    float previous = 0;
    for (const char* view : {"close", "mid", "far"}) {
        camera.view = view;
        const CameraPose pose = frameCamera(camera, lo, hi, lo, hi, 640, 480);
        // f_px = (H/2) / tan(fovY/2)
        EXPECT_NEAR(pose.focalLengthPixels, 240.0f / std::tan(glm::radians(15.0f)), 1e-3f);
        const float distance = glm::length(pose.position);
        EXPECT_GT(distance, radius) << view;   // never inside the bounding sphere
        EXPECT_GT(distance, previous) << view; // close < mid < far
        previous = distance;
        EXPECT_LT(pose.nearPlane, distance - radius);
        EXPECT_GT(pose.farPlane, distance + radius);
        // The sphere's silhouette fills the documented fraction of the image height.
        const float fill = std::tan(std::asin(radius / distance)) / std::tan(glm::radians(15.0f));
        const float expected = std::string(view) == "far" ? 0.4f : std::string(view) == "mid" ? 0.9f : 1.8f;
        EXPECT_NEAR(fill, expected, 1e-4f) << view;
    }
    camera.view = "mid";
    camera.yawDeg = 90.0; // orbit to +X
    const CameraPose side = frameCamera(camera, lo, hi, lo, hi, 100, 100);
    EXPECT_NEAR(side.position.z, 0.0f, 1e-4f);
    EXPECT_GT(side.position.x, radius);
}

// render.window: the off-axis projection puts every point at the pixel it has in the whole frame, shifted by the
// window's corner (y counted from the top), with the frame's focal length and the principal point moved with it.
TEST(CameraFraming, WindowProjectsEveryPointWhereTheWholeFrameDoes) {
    CameraSpec camera;
    const glm::vec3 lo{-1, -1, -1}, hi{1, 1, 1};
    const int W = 640, H = 480;
    const RenderWindow window{100, 60, 200, 150};
    const CameraPose whole = frameCamera(camera, lo, hi, lo, hi, W, H);
    const CameraPose part = frameCamera(camera, lo, hi, lo, hi, W, H, window);
    EXPECT_EQ(part.focalLengthPixels, whole.focalLengthPixels);
    EXPECT_EQ(part.view, whole.view);
    // Pixel coordinates (x from the left, y from the top) of a world point in an image of w × h.
    auto pixel = [](const CameraPose& pose, const glm::vec3& p, float w, float h) {
        const glm::vec4 clip = pose.projection * pose.view * glm::vec4(p, 1.0f);
        return glm::vec2((clip.x / clip.w * 0.5f + 0.5f) * w, (0.5f - clip.y / clip.w * 0.5f) * h);
    };
    for (const glm::vec3& p :
         {glm::vec3{0.1f, 0.2f, 0.3f}, glm::vec3{-0.5f, 0.4f, -0.2f}, glm::vec3{0.7f, -0.6f, 0.0f}}) {
        const glm::vec2 inWhole = pixel(whole, p, W, H), inPart = pixel(part, p, 200.0f, 150.0f);
        EXPECT_NEAR(inPart.x, inWhole.x - 100.0f, 1e-3f);
        EXPECT_NEAR(inPart.y, inWhole.y - 60.0f, 1e-3f);
    }
    // The view axis meets the frame at its centre: (320, 240) from the top, (320, 240) from the bottom; in the
    // window (rows from the bottom, its bottom row 480 − 60 − 150 = 270 of the frame) at (220, −30).
    EXPECT_EQ(whole.principalPoint, glm::vec2(320.0f, 240.0f));
    EXPECT_EQ(part.principalPoint, glm::vec2(220.0f, -30.0f));
}

TEST(SceneSpec, WindowIsReadRecordedAndCheckedAgainstTheFrame) {
    const SceneSpec spec = loadSceneSpec(
        "builtin:head",
        {"render.width=512", "render.height=256", "render.window={ x = 10, y = 20, width = 100, height = 50 }"}, {});
    EXPECT_EQ(spec.width, 100);
    EXPECT_EQ(spec.height, 50);
    EXPECT_EQ(spec.frameWidth, 512);
    EXPECT_EQ(spec.frameHeight, 256);
    EXPECT_EQ(spec.resolved["render"]["width"], 512);
    EXPECT_EQ(spec.resolved["render"]["window"],
              (nlohmann::json{{"x", 10}, {"y", 20}, {"width", 100}, {"height", 50}}));
    EXPECT_FALSE(loadSceneSpec("builtin:head", {}, {}).resolved["render"].contains("window"));
    // A frame over 8192 only with a window.
    EXPECT_EQ(errorOf("builtin:head", {"render.width=9000"}),
              "builtin:head: render.width: 9000 is out of range [16, 8192]");
    EXPECT_EQ(errorOf("builtin:head", {"render.width=9000", "render.window={ x = 8000, y = 0, width = 1000, "
                                                            "height = 100 }"}),
              "");
    EXPECT_EQ(errorOf("builtin:head", {"render.window={ x = 500, y = 0, width = 100, height = 100 }"}),
              "builtin:head: render.window.width: x + width = 600 exceeds render.width 512");
    EXPECT_EQ(errorOf("builtin:head", {"render.window={ x = 0, y = 500, width = 100, height = 100 }"}),
              "builtin:head: render.window.height: y + height = 600 exceeds render.height 512");
    EXPECT_EQ(errorOf("builtin:head", {"render.window={ x = 0, y = 0, width = 100 }"}),
              "builtin:head: render.window.height: missing (a window has x, y, width, height in pixels of the frame)");
    EXPECT_EQ(errorOf("builtin:head", {"render.window={ x = 0, y = 0, width = 100, height = 100, z = 1 }"}),
              "builtin:head: render.window.z: unknown key");
    EXPECT_EQ(errorOf("builtin:head", {"render.window=3"}),
              "builtin:head: render.window: expected a table, got integer 3");
}

} // namespace
} // namespace skinlab::renderer
