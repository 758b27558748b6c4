#include "common/error.h"
#include "common/spec.h"

#include <gtest/gtest.h>

using skinlab::SpecReader;

namespace {
std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const skinlab::InputError& e) {
        return e.what();
    }
    return "(no error)";
}
const char* kSpec = R"(
[camera]
view = "close"
fov_deg = 30
[[lights]]
type = "directional"
intensity = 3.5
)";
} // namespace

TEST(Spec, ReadsValuesAndAcceptsFullyReadSpec) {
    toml::table t = skinlab::parseTomlString(kSpec, "scene.toml");
    SpecReader r(t, "scene.toml");
    SpecReader cam = r.table("camera");
    EXPECT_EQ(cam.choice("view", "mid", {"close", "mid", "far"}), "close");
    EXPECT_DOUBLE_EQ(cam.number("fov_deg", 40, 1, 179), 30.0);
    EXPECT_DOUBLE_EQ(cam.number("near", 0.1, 0, 10), 0.1);
    auto lights = r.tables("lights");
    ASSERT_EQ(lights.size(), 1u);
    EXPECT_EQ(lights[0].string("type", ""), "directional");
    EXPECT_DOUBLE_EQ(lights[0].number("intensity", 1, 0, 100), 3.5);
    EXPECT_NO_THROW(r.finish());
}

TEST(Spec, ErrorsNameFileAndKeyWordForWord) {
    toml::table t = skinlab::parseTomlString(kSpec, "scene.toml");
    SpecReader r(t, "scene.toml");
    EXPECT_EQ(errorOf([&] { r.table("camera").number("fov_deg", 40, 1, 20); }),
              "scene.toml: camera.fov_deg: 30 is out of range [1, 20]");
    EXPECT_EQ(errorOf([&] { r.table("camera").number("view", 40, 1, 20); }),
              "scene.toml: camera.view: expected a number, got string \"close\"");
    EXPECT_EQ(errorOf([&] {
                  r.table("camera").choice("view", "mid", {"mid", "far"});
              }),
              "scene.toml: camera.view: 'close' is not one of: mid, far");
    EXPECT_EQ(errorOf([&] { r.tables("lights")[0].integer("intensity", 1, 0, 9); }),
              "scene.toml: lights[0].intensity: expected an integer, got float 3.5");
    SpecReader fresh(t, "scene.toml");
    fresh.table("camera").string("view", "");
    EXPECT_EQ(errorOf([&] { fresh.finish(); }), "scene.toml: camera.fov_deg: unknown key");
    EXPECT_EQ(errorOf([] { skinlab::parseTomlString("a = = 1", "bad.toml"); }).rfind("bad.toml:1:", 0), 0u);
}

// An unknown key a slip away from a key the reader asked for names it; one far from every asked key does not.
TEST(Spec, UnknownKeyNamesTheNearestKeyAsked) {
    toml::table t =
        skinlab::parseTomlString("[camera]\nfov_dge = 30\nview = \"close\"\n[render]\nwidht = 3\n", "scene.toml");
    SpecReader r(t, "scene.toml");
    r.table("camera").number("fov_deg", 40, 1, 179);
    r.table("camera").string("view", "");
    r.table("camera").number("near_mm", 1, 0, 10);
    EXPECT_EQ(errorOf([&] { r.finish(); }), "scene.toml: camera.fov_dge: unknown key (did you mean fov_deg?)");
    SpecReader far(t, "scene.toml");
    far.table("camera").number("fov_dge", 40, 1, 179);
    far.table("camera").string("view", "");
    far.table("render").integer("height", 4, 1, 9);
    EXPECT_EQ(errorOf([&] { far.finish(); }), "scene.toml: render.widht: unknown key");
    EXPECT_EQ(skinlab::nearestKey("widht", {"width", "height"}), "width");
    EXPECT_EQ(skinlab::nearestKey("x", {"y", "z"}), "");
    EXPECT_EQ(skinlab::nearestKey("colour", {"color", "intensity"}), "color");
}

TEST(Spec, OverridesParseTomlValuesOrBareStrings) {
    toml::table t = skinlab::parseTomlString(kSpec, "scene.toml");
    skinlab::applyOverride(t, "camera.view=far");
    skinlab::applyOverride(t, "camera.fov_deg=45.5");
    skinlab::applyOverride(t, "sss.samples=21");
    skinlab::applyOverride(t, "sss.enabled=true");
    skinlab::applyOverride(t, "sss.color=[1, 0.5, 0.25]");
    SpecReader r(t, "scene.toml");
    EXPECT_EQ(r.table("camera").string("view", ""), "far");
    EXPECT_DOUBLE_EQ(r.table("camera").number("fov_deg", 0, 0, 90), 45.5);
    EXPECT_EQ(r.table("sss").integer("samples", 0, 0, 100), 21);
    EXPECT_TRUE(r.table("sss").boolean("enabled", false));
    EXPECT_EQ(r.table("sss").vec3("color", {0, 0, 0}, 0, 1)[1], 0.5);
    EXPECT_EQ(errorOf([&] { skinlab::applyOverride(t, "camera"); }), "--set: 'camera': expected key=value");
    EXPECT_EQ(errorOf([&] { skinlab::applyOverride(t, "camera.view.x=1"); }),
              "--set: camera.view: is not a table, cannot set 'camera.view.x'");
}

TEST(Spec, OverridesIndexExistingArrays) {
    toml::table t = skinlab::parseTomlString(kSpec, "scene.toml");
    skinlab::applyOverride(t, "lights[0].intensity=2");
    skinlab::applyOverride(t, "lights[0].shadow=false");
    skinlab::applyOverride(t, "camera.position=[1, 2, 3]");
    skinlab::applyOverride(t, "camera.position[2]=30");
    SpecReader r(t, "scene.toml");
    auto lights = r.tables("lights");
    ASSERT_EQ(lights.size(), 1u);
    EXPECT_DOUBLE_EQ(lights[0].number("intensity", 1, 0, 100), 2.0);
    EXPECT_FALSE(lights[0].boolean("shadow", true));
    EXPECT_EQ(lights[0].string("type", ""), "directional"); // the rest of the light is kept
    EXPECT_EQ(r.table("camera").vec3("position", {0, 0, 0}, -100, 100)[2], 30.0);
    EXPECT_EQ(r.table("camera").vec3("position", {0, 0, 0}, -100, 100)[0], 1.0);
    EXPECT_EQ(errorOf([&] { skinlab::applyOverride(t, "lights[1].intensity=2"); }),
              "--set: lights: has 1 element(s); index 1 is out of range");
    EXPECT_EQ(errorOf([&] { skinlab::applyOverride(t, "camera[0].view=far"); }),
              "--set: camera: is not an array, cannot index it in 'camera[0].view'");
    EXPECT_EQ(errorOf([&] { skinlab::applyOverride(t, "lights[x].intensity=2"); }),
              "--set: 'lights[x].intensity=2': index 'x' is not a non-negative integer");
    EXPECT_EQ(errorOf([&] { skinlab::applyOverride(t, "lights[0.intensity=2"); }),
              "--set: 'lights[0.intensity=2': expected NAME[INDEX] in 'lights[0'");
}

TEST(Spec, TomlToJson) {
    toml::table t = skinlab::parseTomlString(kSpec, "scene.toml");
    nlohmann::json j = skinlab::tomlToJson(t);
    EXPECT_EQ(j["camera"]["view"], "close");
    EXPECT_EQ(j["lights"][0]["intensity"], 3.5);
}
