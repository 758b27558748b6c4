#pragma once
// The scene spec's [skin] table: the skin tone as a factor (docs/skin-tones.md). Absent: the scene's own skin
// (d'Eon's profile, the model's albedo) exactly as without the table.
//   tone = "I" … "VI"      a named level (sss::skinToneLevels(): melanin from Jacques' published ranges)
//   melanin = C_m          epidermal melanin fraction, [0.001, 0.5] (instead of tone)
//   haemoglobin = C_h      dermal blood fraction, [0.001, 0.1] (default 0.02)
//   melanin_blend = β_m    eumelanin share of the melanin, [0, 1] (default 0.7)
// Every method reads the tone: the profile of material "skin" (kernels, the object-space reference), the
// transmittance weights, the Blender radii; builtin models' skin materials take the tone's albedo; a model file's
// albedo map is re-toned through the model (renderer.cpp, sss::retoneAlbedo).
#include "renderer/sss/skin_model.h"

#include <nlohmann/json.hpp>
#include <optional>

namespace skinlab {
class SpecReader;
}

namespace skinlab::renderer {

// Reads [skin] (strict: ranges, tone xor melanin) and records it in resolved["skin"] with the model's outputs.
std::optional<sss::SkinOptics> readSkinTable(const SpecReader& root, nlohmann::json& resolved);

} // namespace skinlab::renderer
