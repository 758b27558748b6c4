#pragma once
// Writing a scaling analysis to a folder (docs/analysis.md, "Outputs"): scale.json (everything), scores.csv,
// pairs.csv, observers.csv, consistency.csv, counts.csv, plots/*.png and report_section.html (an HTML fragment,
// images embedded, for other reports to include). Every file is written atomically; scale.json is written
// last, so its presence means the folder is complete.
#include "analysis/scaling/scale_analysis.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace skinlab::analysis::scaling {

nlohmann::json analysisJson(const Analysis& analysis);
std::string reportSectionHtml(const Analysis& analysis);
void writeScaleOutputs(const Analysis& analysis, const std::filesystem::path& folder);

// File-name-safe form of a block name ("builtin:head/mid" → "builtin-head-mid").
std::string blockSlug(const std::string& name);

} // namespace skinlab::analysis::scaling
