// Conditions of different renderers: each SSS condition against its own renderer's no-SSS baseline, and one
// warning line where a block mixes renderers (docs/pathtraced.md, "EEVEE against the rasterizer").
#include "analysis/scaling/renderer_effects.h"
#include "common/error.h"

#include <gtest/gtest.h>

namespace skinlab::analysis::scaling {
namespace {

nlohmann::json method(const std::string& name) { return {{"sss", {{"method", name}}}}; }

TEST(RendererEffects, EachRendererAndItsNoSssBaseline) {
    EXPECT_EQ(conditionRenderer(method("separable")).renderer, "skinlab");
    EXPECT_FALSE(conditionRenderer(method("separable")).noSss);
    EXPECT_TRUE(conditionRenderer(method("none")).noSss);
    EXPECT_TRUE(conditionRenderer(nlohmann::json::object()).noSss); // no [sss]: none
    EXPECT_EQ(conditionRenderer(method("reference")).renderer, "skinlab");
    EXPECT_EQ(conditionRenderer(method("eevee")).renderer, "eevee");
    EXPECT_FALSE(conditionRenderer(method("eevee")).noSss);
    nlohmann::json eeveeOff = method("eevee");
    eeveeOff["eevee"] = {{"sss", false}};
    EXPECT_TRUE(conditionRenderer(eeveeOff).noSss);
    nlohmann::json cyclesOff = method("pathtraced");
    cyclesOff["pathtraced"] = {{"sss", false}};
    EXPECT_EQ(conditionRenderer(cyclesOff).renderer, "cycles");
    EXPECT_TRUE(conditionRenderer(cyclesOff).noSss);
}

// builtin:head, mid view, as measured: EEVEE without SSS lies far from skinlab without SSS; each SSS effect is
// taken within its renderer, never across.
TEST(RendererEffects, SssEffectsWithinARendererAndAWarningAcrossRenderers) {
    nlohmann::json eeveeOff = method("eevee");
    eeveeOff["eevee"] = {{"sss", false}};
    const RendererEffects effects = sssEffectsWithinRenderers(
        "builtin:head/mid", {"none", "separable", "eevee", "eevee-no-sss"},
        {method("none"), method("separable"), method("eevee"), eeveeOff}, {0.0, 0.4, -2.0, -2.5});
    ASSERT_EQ(effects.effects.size(), 2u);
    EXPECT_EQ(effects.effects[0].condition, "separable");
    EXPECT_EQ(effects.effects[0].baseline, "none");
    EXPECT_DOUBLE_EQ(effects.effects[0].effect, 0.4);
    EXPECT_EQ(effects.effects[1].condition, "eevee");
    EXPECT_EQ(effects.effects[1].baseline, "eevee-no-sss");
    EXPECT_DOUBLE_EQ(effects.effects[1].effect, 0.5);
    EXPECT_TRUE(effects.withoutBaseline.empty());
    ASSERT_TRUE(effects.warning);
    EXPECT_EQ(effects.warning->find('\n'), std::string::npos);
    EXPECT_NE(effects.warning->find("builtin:head/mid: conditions of different renderers (skinlab, eevee)"),
              std::string::npos)
        << *effects.warning;

    // One renderer: no warning. An EEVEE condition without its baseline is listed, not compared with skinlab's.
    EXPECT_FALSE(
        sssEffectsWithinRenderers("b", {"none", "separable"}, {method("none"), method("separable")}, {0.0, 1.0})
            .warning);
    const RendererEffects missing =
        sssEffectsWithinRenderers("b", {"none", "eevee"}, {method("none"), method("eevee")}, {0.0, -2.0});
    EXPECT_TRUE(missing.effects.empty());
    ASSERT_EQ(missing.withoutBaseline.size(), 1u);
    EXPECT_EQ(missing.withoutBaseline[0], "eevee");
    EXPECT_THROW(sssEffectsWithinRenderers("b", {"none"}, {}, {0.0}), InputError);
}

} // namespace
} // namespace skinlab::analysis::scaling
