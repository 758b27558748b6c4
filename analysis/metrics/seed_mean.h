#pragma once
// The path-traced truth for error metrics: the mean of S path-traced renders of one scene with independent seeds,
// written as a skinlab EXR that `skinlab analyze metrics --reference` scores against like any reference. Its noise
// variance is the single seed's over S, so where the object-space reference is further from Cycles than the
// conditions it ranks, the seed mean is the truth precise enough (docs/metrics.md, "The path-traced truth").
//
// The beauty (R, G, B) and the light layers (diffuse.*, specular.*) are averaged; every other channel (depth,
// mask, the rasterizer's AOVs) is the first seed's, as the geometry is the same in every seed. The metadata are the
// first seed's, without its seed, and `skinlab:truth` (JSON) says what the file is: {"kind":
// "pathtraced-seed-mean", "seeds": [...], "files": [...], "samples": N, "averaged_channels": [...]}.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skinlab::metrics {

// The metadata key that names a render's role as a truth (absent on plain renders).
inline constexpr const char* truthAttribute = "skinlab:truth";

// Reads and checks the seeds (at least two; skinlab path-traced renders of the same resolved scene apart from
// `pathtraced.seed`, with distinct seeds, the same size and channels), then writes their mean to `output`
// atomically. Returns the `skinlab:truth` record written. InputError names the file and what differs.
nlohmann::json writeSeedMean(const std::vector<std::filesystem::path>& seeds, const std::filesystem::path& output);

// What a reference render is as a truth, for manifests and metrics.json: its `skinlab:truth` record, or
// {"kind": "render", "method": sss.method of its skinlab:resolved} for a skinlab render, or {"kind": "image"} for a
// plain image.
nlohmann::json describeTruth(const std::filesystem::path& reference);

} // namespace skinlab::metrics
