// The recipe of docs/methods.md, "Adding a method", followed for a throwaway method: a box kernel (equal weights
// over ±box_half_width_mm on the surface) with one key of its own. Its file, box_method.cpp (compiled into this
// test only), holds its class and its row; the line below registers it, as a built-in's line in method_table.cpp
// does. Nothing else of skinlab changes: the reader, the resolved record, the listings, the renderer's shared blur
// passes and the metrics' support radius all take it from the table (label gl).
#include "../gl/render_test_support.h"
#include "common/error.h"
#include "renderer/renderer.h"
#include "renderer/sss/cpu_blur.h"
#include "renderer/sss/method.h"

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>

namespace skinlab::renderer::sss {
MethodInfo boxMethod();             // box_method.cpp
SKINLAB_REGISTER_METHOD(boxMethod); // the registration line
} // namespace skinlab::renderer::sss

namespace skinlab::renderer {
namespace {
const sss::SssMethod kBox = sss::methodId("box");
} // namespace

TEST(MethodRecipe, TheRowReachesEveryListing) {
    const auto names = sss::methodNames();
    EXPECT_NE(std::find(names.begin(), names.end(), "box"), names.end());
    const auto blur = sss::blurPassMethodNames();
    EXPECT_NE(std::find(blur.begin(), blur.end(), "box"), blur.end());
    ASSERT_NE(sss::findMethod("box"), nullptr);
    EXPECT_EQ(sss::findMethod("box")->method, kBox);
    EXPECT_EQ(&sss::methodInfo(kBox), &sss::methodTable().back()); // after the built-ins, without an enumerator
    EXPECT_TRUE(sss::methodInfo(kBox).interactive);
    const auto keys = sss::methodKeys(kBox);
    EXPECT_NE(std::find(keys.begin(), keys.end(), "box_half_width_mm"), keys.end());
    EXPECT_EQ(sss::sssKeyDefaults(kBox).at("box_half_width_mm"), 2.0);
    EXPECT_EQ(sss::keyInfoJson(sss::sssKey("box_half_width_mm")).at("unit"), "mm");
    // sss.method accepts it (the choices of the key declaration follow the table).
    const auto& choices = sss::sssKey("method").choices;
    EXPECT_NE(std::find(choices.begin(), choices.end(), "box"), choices.end());
    // A second row of the same name is refused.
    EXPECT_THROW(sss::registerMethod(sss::boxMethod()), RuntimeError);
}

TEST(MethodRecipe, ItsKeysAreReadCheckedAndRecorded) {
    const sss::SssParams params =
        sss::sssParamsFromJson({{"method", "box"}, {"box_half_width_mm", 3.0}, {"samples", 7}});
    EXPECT_EQ(params.method, kBox);
    EXPECT_EQ(params.samples, 7);
    EXPECT_EQ(params.own.at("box_half_width_mm"), 3.0);
    const nlohmann::json record = params.toJson();
    EXPECT_EQ(record.at("box_half_width_mm"), 3.0);
    EXPECT_FALSE(record.contains("profile")); // another method's key is not recorded
    EXPECT_EQ(sss::sssParamsFromJson(record), params);
    // The declared range, one line naming the key.
    try {
        sss::sssParamsFromJson({{"method", "box"}, {"box_half_width_mm", 50.0}}, "scene.toml");
        ADD_FAILURE() << "out-of-range value accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("sss.box_half_width_mm"), std::string::npos) << e.what();
    }
    // Another method's key with box, and box's key with another method, are errors naming the key.
    EXPECT_THROW(sss::sssParamsFromJson({{"method", "box"}, {"artistic_falloff", {1.0, 1.0, 1.0}}}), InputError);
    try {
        sss::sssParamsFromJson({{"method", "separable"}, {"box_half_width_mm", 1.0}}, "scene.toml");
        ADD_FAILURE() << "box's key accepted by separable";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("not a parameter of method 'separable'"), std::string::npos) << e.what();
    }
    // Its kernel and support, prepared once per parameter set.
    const auto prepared = sss::prepareMethod(params);
    EXPECT_EQ(prepared, sss::prepareMethod(params));
    EXPECT_DOUBLE_EQ(prepared->supportRadiusMm, 3.0);
    EXPECT_EQ(prepared->kernel.method, kBox);
    EXPECT_EQ(prepared->kernel.stages.at(0).taps.size(), 7u);
}

TEST(MethodRecipe, RendersThroughTheSharedPassesLikeItsCpuMirror) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    test::TempFolder folder("method-recipe");
    const std::string scene = "builtin:halo-grey-backdrop";
    test::renderToExr(*renderer, scene, "none", {}, 64, 48, folder / "none.exr");
    const RenderResult result =
        test::renderToExr(*renderer, scene, "box", {"sss.box_half_width_mm=2.5"}, 64, 48, folder / "box.exr");
    (void)result;
    const test::ExrImage none = test::readExr(folder / "none.exr");
    const test::ExrImage box = test::readExr(folder / "box.exr");
    EXPECT_FLOAT_EQ(box.floats.at("skinlab:sss_radius_mm"), 2.5f);
    const auto resolved = nlohmann::json::parse(box.strings.at("skinlab:resolved"));
    EXPECT_EQ(resolved.at("sss").at("box_half_width_mm"), 2.5);

    // The CPU mirror of the blur passes on the input the SSS stage got (method none copies it through).
    sss::SurfaceBuffers surface;
    surface.width = none.width;
    surface.height = none.height;
    surface.depth = none.channels.at("depth.Z");
    surface.mask = none.channels.at("mask.Y");
    surface.focalLengthPixels = none.floats.at("skinlab:f_px");
    surface.mmPerUnit = none.floats.at("skinlab:mm_per_unit");
    std::vector<sss::Rgb> input(surface.mask.size());
    for (std::size_t i = 0; i < input.size(); ++i)
        input[i] = {none.channels.at("diffuse.R")[i], none.channels.at("diffuse.G")[i],
                    none.channels.at("diffuse.B")[i]};
    sss::SssParams params = sss::sssParamsFromJson(resolved.at("sss"));
    const std::vector<sss::Rgb> expected =
        sss::applyKernel(surface, input, sss::makeKernel(params), sss::blurSettingsFromParams(params));
    double worst = 0.0, changed = 0.0;
    const char* channels[] = {"diffuse.R", "diffuse.G", "diffuse.B"};
    for (std::size_t i = 0; i < input.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const float got = box.channels.at(channels[c])[i];
            worst = std::max(worst, static_cast<double>(std::abs(got - expected[i][static_cast<std::size_t>(c)])));
            changed += std::abs(got - input[i][static_cast<std::size_t>(c)]);
        }
    EXPECT_LE(worst, 1e-3) << "GL passes differ from the CPU mirror";
    EXPECT_GT(changed, 0.0) << "the box method changed nothing";
}

} // namespace skinlab::renderer
