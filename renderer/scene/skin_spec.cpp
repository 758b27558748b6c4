#include "renderer/scene/skin_spec.h"

#include "common/spec.h"

namespace skinlab::renderer {

std::optional<sss::SkinOptics> readSkinTable(const SpecReader& root, nlohmann::json& resolved) {
    if (!root.has("skin")) return std::nullopt;
    const SpecReader skin = root.table("skin");
    sss::SkinTone tone;
    if (skin.has("tone")) {
        if (skin.has("melanin")) skin.fail("melanin", "give skin.tone or skin.melanin, not both");
        std::vector<std::string> names;
        for (const auto& level : sss::skinToneLevels()) names.emplace_back(level.name);
        tone = *sss::skinToneForLevel(skin.choice("tone", names.front(), names));
    } else if (!skin.has("melanin")) {
        skin.fail("melanin", "missing ([skin] needs tone = \"I\" … \"VI\" or melanin)");
    }
    tone.melanin = skin.number("melanin", tone.melanin, sss::kMelaninMin, sss::kMelaninMax);
    tone.haemoglobin = skin.number("haemoglobin", tone.haemoglobin, sss::kHaemoglobinMin, sss::kHaemoglobinMax);
    tone.melaninBlend = skin.number("melanin_blend", tone.melaninBlend, 0.0, 1.0);
    sss::SkinOptics optics = sss::skinOptics(tone, skin.file());
    nlohmann::json lobes = nlohmann::json::array();
    for (const auto& lobe : optics.lobes)
        lobes.push_back({{"variance_mm2", lobe.varianceMm2}, {"weight", lobe.weight}});
    resolved["skin"] = {{"tone", tone.level},
                        {"melanin", tone.melanin},
                        {"haemoglobin", tone.haemoglobin},
                        {"melanin_blend", tone.melaninBlend},
                        {"albedo", optics.albedo},
                        {"luminance", optics.luminance},
                        {"burley_shape_mm", optics.burleyShapeMm},
                        {"lobes", lobes}};
    return optics;
}

} // namespace skinlab::renderer
