// Halo and bleed scores of the screen-space methods and the artifact extensions (docs/extensions.md,
// "Scores on renders"), on real renders through the renderer's public API, scored by analysis/metrics against the
// object-space `reference` method of the same scene, camera and size (label gl; llvmpipe in CI; 128² renders).
//
// Set-ups (why they look like this is in docs/extensions.md):
//  - halo: builtin:halo with the backdrop made skin (`materials=[{name = "*", skin = true}]`) for the test renders
//    AND the reference: the screen-space passes replace non-skin taps by the centre colour, so with the default
//    materials no light would cross the silhouette; with a skin backdrop only the depth step separates the two
//    surfaces (chin over neck). Explicit close camera (the sphere fills half the frame), key light without shadow
//    (so the error away from the silhouette stays at the reference's own level), gaps of 5 and 200 mm;
//  - bleed: builtin:bleed's test renders with the paint squares inside the skin mask (a mask coarser than the
//    material, as a per-mesh skin flag over eyebrows or lips) and the reference with the true materials (paint
//    non-skin), so the bands come from the true mask;
//  - curvature: the strategies on a flat plane (curvature.Y = 0) and on builtin:halo's sphere (c ≈ 0.5).
#include "../gl/render_test_support.h"
#include "analysis/metrics/render_comparison.h"
#include "renderer/renderer.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <string>
#include <vector>

namespace skinlab::renderer {
namespace {

using test::TempFolder;

constexpr int kSize = 128; // pixels, square

const std::vector<std::string> kScreenSpaceMethods = renderer::sss::screenSpaceMethodNames();

std::filesystem::path renderExr(Renderer& renderer, const TempFolder& folder, const std::string& name,
                                const std::string& scene, const std::string& method,
                                std::vector<std::string> overrides) {
    test::renderToExr(renderer, scene, method, std::move(overrides), kSize, kSize, folder / (name + ".exr"));
    return folder / (name + ".exr");
}

metrics::PreparedReference prepare(const std::filesystem::path& referenceExr) {
    return metrics::prepareReference(metrics::loadMetricRender(referenceExr, metrics::RenderRole::reference),
                                     metrics::MetricOptions{});
}

// The leak energy Σ_band |Y_T − Y_R| / Σ_skin Y_R of one band (docs/metrics.md).
double leakEnergy(const metrics::PreparedReference& reference, const std::filesystem::path& testExr,
                  metrics::Band band) {
    const metrics::MetricRender test = metrics::loadMetricRender(testExr, metrics::RenderRole::test);
    return metrics::compareWithReference(reference, test, metrics::MetricOptions{}).band(band).leakEnergy;
}

std::vector<std::string> with(std::vector<std::string> base, std::initializer_list<std::string> more) {
    base.insert(base.end(), more);
    return base;
}

} // namespace

TEST(ExtensionScores, FollowSurfaceAndCbfAgainstTheHaloOfEveryScreenSpaceMethod) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("extension-scores-halo");
    for (const double gapMm : {5.0, 200.0}) {
        const std::vector<std::string> scene{
            "materials=[{name = \"*\", skin = true}]",
            "camera.view=explicit",
            "camera.position=[0.0, 0.0, 300.0]",
            "camera.target=[0.0, 0.0, 0.0]",
            "lights=[{type = \"directional\", direction = [0.45, -0.45, -0.77], intensity = 1.2, shadow = false}]",
            "model.depth_gap_mm=" + std::to_string(gapMm)};
        const std::string gap = std::to_string(static_cast<int>(gapMm));
        // 2 mm reference edges: the skin backdrop is 600 × 600 mm, and 1 mm edges take 3–4× as long (11 s per
        // reference); 4 mm edges moved the halo scores by < 10 % and changed none of the comparisons below.
        const auto referenceExr = renderExr(*renderer, folder, "reference-" + gap, "builtin:halo-grey-backdrop",
                                            "reference", with(scene, {"sss.reference_edge_mm=2"}));
        const metrics::PreparedReference reference = prepare(referenceExr);
        for (const auto& method : kScreenSpaceMethods) {
            auto halo = [&](const std::string& name, std::initializer_list<std::string> overrides) {
                return leakEnergy(reference,
                                  renderExr(*renderer, folder, method + "-" + gap + "-" + name,
                                            "builtin:halo-grey-backdrop", method, with(scene, overrides)),
                                  metrics::Band::halo);
            };
            const double off = halo("off", {"sss.follow_surface=false"});
            const double follow = halo("follow", {"sss.follow_surface=true"});
            const double followCbf = halo("follow-cbf", {"sss.follow_surface=true", "sss.cbf=true"});
            // A weak follow-surface (k = 0.02/mm: full stop only at 50 mm of depth difference) leaves residual
            // light across the steep depth gradient next to the silhouette; sss.cbf must cut it.
            // pscbf's depth weight has no k (its σ follows the profile; the method does not read follow_surface_k):
            // its "weak" case is its default follow-surface.
            const bool hasK = sss::methodUsesKey(sss::findMethod(method)->method, "follow_surface_k");
            const std::string weakK = hasK ? "sss.follow_surface_k=0.02" : "sss.follow_surface=true";
            const double weak = halo("weak", {"sss.follow_surface=true", weakK});
            const double weakCbf = halo("weak-cbf", {"sss.follow_surface=true", weakK, "sss.cbf=true"});
            std::printf("  gap %3s mm %-13s halo leak energy: off %.3e, follow %.3e, follow+cbf %.3e (x %.3f) | "
                        "k=0.02/mm: follow %.3e, follow+cbf %.3e (x %.3f)\n",
                        gap.c_str(), method.c_str(), off, follow, followCbf, followCbf / follow, weak, weakCbf,
                        weakCbf / weak);
            EXPECT_GT(off, 1e-4) << method << " gap " << gap << ": no halo to remove";
            EXPECT_LE(follow, 0.25 * off) << method << " gap " << gap;
            // With the default k every tap across the silhouette is already replaced by the centre colour, so
            // there is no crossing light left for cbf to remove: its weights then only shrink the blur along the
            // curved sphere (F = cos φ_i / cos φ_j changes across it), which moves the score by +0.3 … +2.7 % at
            // this size and up to +21 % at 256² (gaussian-sum; docs/extensions.md). What must hold is that cbf
            // never lets the halo back: the bound on follow-surface alone holds with cbf added.
            EXPECT_LE(followCbf, 0.25 * off) << method << " gap " << gap;
            EXPECT_LE(weakCbf, 0.9 * weak) << method << " gap " << gap << ": cbf did not cut the residual";
        }
    }
}

TEST(ExtensionScores, LabWeightCutsTheBleedOfTheSeparableMethods) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("extension-scores-bleed");
    const metrics::PreparedReference reference =
        prepare(renderExr(*renderer, folder, "reference", "builtin:bleed-true-mask", "reference", {}));
    const std::vector<std::string> coarseMask{"materials=[{name = \"*\", skin = true}]"};
    struct Case {
        std::string method;
        double beta; // the thesis's β: 0.09 for the separable methods, 0.5 for the sum of Gaussians
    };
    for (const Case& c :
         std::vector<Case>{{"separable", 0.09}, {"artistic", 0.09}, {"pscbf", 0.09}, {"gaussian-sum", 0.5}}) {
        const double off = leakEnergy(
            reference, renderExr(*renderer, folder, c.method + "-off", "builtin:bleed-true-mask", c.method, coarseMask),
            metrics::Band::bleed);
        const double lab =
            leakEnergy(reference,
                       renderExr(*renderer, folder, c.method + "-lab", "builtin:bleed-true-mask", c.method,
                                 with(coarseMask, {"sss.lab_weight=" + std::to_string(c.beta)})),
                       metrics::Band::bleed);
        std::printf("  %-13s bleed leak energy: %.3e without, %.3e with sss.lab_weight = %.2f (x %.4f)\n",
                    c.method.c_str(), off, lab, c.beta, lab / off);
        EXPECT_GT(off, 1e-4) << c.method << ": no bleeding to remove";
        EXPECT_LE(lab, 0.5 * off) << c.method;
    }
}

TEST(ExtensionScores, CurvatureStrategiesOnAFlatPlane) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("extension-scores-curvature");
    // builtin:bleed with the paint inside the skin mask: a flat plane (curvature AOV ≈ 0) whose only blur signal is
    // the paint's edges. Measured: the total change of the diffuse luminance against method none. `reduce` must
    // leave the plane unblurred (thesis: flat areas lose SSS), `reduce-floor` keep part of the blur, `increase`
    // (× (1 + c), c ≈ 0) leave it as with the strategy off.
    const std::vector<std::string> coarseMask{"materials=[{name = \"*\", skin = true}]"};
    auto diffuseLuminance = [](const test::ExrImage& image, int x, int y) {
        return 0.2126 * image.at("diffuse.R", x, y) + 0.7152 * image.at("diffuse.G", x, y) +
               0.0722 * image.at("diffuse.B", x, y);
    };
    const test::ExrImage none =
        test::readExr(renderExr(*renderer, folder, "none", "builtin:bleed-true-mask", "none", coarseMask));
    for (const std::string method : {"separable", "gaussian-sum"}) {
        auto blur = [&](const std::string& strategy) {
            const test::ExrImage image =
                test::readExr(renderExr(*renderer, folder, method + "-" + strategy, "builtin:bleed-true-mask", method,
                                        with(coarseMask, {"sss.curvature=" + strategy, "sss.curvature_floor=0.5"})));
            double change = 0.0, curvature = 0.0;
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x) {
                    change += std::abs(diffuseLuminance(image, x, y) - diffuseLuminance(none, x, y));
                    curvature = std::max(curvature, double(image.at("curvature.Y", x, y)));
                }
            std::printf("  %-13s curvature %-12s: total luminance change %.4g (max curvature.Y %.3g /mm)\n",
                        method.c_str(), strategy.c_str(), change, curvature);
            return change;
        };
        const double off = blur("off");
        const double reduce = blur("reduce");
        const double reduceFloor = blur("reduce-floor");
        const double increase = blur("increase");
        EXPECT_GT(off, 1.0) << method << ": nothing to blur";
        EXPECT_LE(reduce, 1e-3 * off) << method;
        // Width × 0.5: the blur of an edge grows with the width but not linearly (the taps' interpolation and
        // the tails), so a wide bracket around ½.
        EXPECT_GT(reduceFloor, 0.3 * off) << method;
        EXPECT_LT(reduceFloor, 0.8 * off) << method;
        EXPECT_NEAR(increase, off, 0.02 * off) << method;
    }
}

TEST(ExtensionScores, CurvatureStrategiesOnTheHaloSphere) {
    SKINLAB_REQUIRE_RENDERER(renderer);
    TempFolder folder("extension-scores-curvature-sphere");
    // builtin:halo's sphere (radius 40 mm: curvature.Y ≈ 1/40 mm, c ≈ 0.5) seen close, with its shadowed side: the
    // blur signal is the terminator. The footprint multipliers at c = 0.5 are increase 1.5, off 1, reduce-floor
    // (floor 0.5) 0.75, reduce 0.5, so the total change of the sphere's diffuse luminance against method none must
    // order the same way, and reduce must not switch SSS off on a curved surface.
    const std::vector<std::string> scene{"camera.view=explicit", "camera.position=[0.0, 0.0, 300.0]",
                                         "camera.target=[0.0, 0.0, 0.0]"};
    auto diffuseLuminance = [](const test::ExrImage& image, int x, int y) {
        return 0.2126 * image.at("diffuse.R", x, y) + 0.7152 * image.at("diffuse.G", x, y) +
               0.0722 * image.at("diffuse.B", x, y);
    };
    const test::ExrImage none =
        test::readExr(renderExr(*renderer, folder, "none", "builtin:halo-grey-backdrop", "none", scene));
    auto blur = [&](const std::string& strategy) {
        const test::ExrImage image =
            test::readExr(renderExr(*renderer, folder, strategy, "builtin:halo-grey-backdrop", "separable",
                                    with(scene, {"sss.curvature=" + strategy, "sss.curvature_floor=0.5"})));
        double change = 0.0, curvature = 0.0;
        int sphere = 0;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                if (image.at("mask.Y", x, y) < 1.0f) continue; // the sphere (the backdrop is not skin)
                change += std::abs(diffuseLuminance(image, x, y) - diffuseLuminance(none, x, y));
                curvature += image.at("curvature.Y", x, y);
                ++sphere;
            }
        std::printf("  separable curvature %-12s: sphere luminance change %.4g (mean curvature.Y %.4f /mm, "
                    "%d px)\n",
                    strategy.c_str(), change, curvature / sphere, sphere);
        return change;
    };
    const double increase = blur("increase");
    const double off = blur("off");
    const double reduceFloor = blur("reduce-floor");
    const double reduce = blur("reduce");
    EXPECT_GT(increase, off);
    EXPECT_GT(off, reduceFloor);
    EXPECT_GT(reduceFloor, reduce);
    EXPECT_GT(reduce, 0.1 * off) << "reduce switched SSS off on a curved surface";
}

} // namespace skinlab::renderer
