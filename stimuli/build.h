#pragma once
// `skinlab stimuli build`: expands a set spec, checks everything that can be checked without rendering (spec,
// factor levels against the scene spec, assets, output folder), then renders each missing or changed stimulus
// (EXR with AOVs + display PNG, written atomically), rewriting the manifest atomically after each one.
#include "analysis/metrics/cvvdp.h"
#include "stimuli/expansion.h"
#include "stimuli/manifest.h"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace skinlab::stimuli {

struct BuildOptions {
    std::filesystem::path spec;
    std::vector<std::string> specOverrides; // --set key=value on the set spec
    std::filesystem::path outputDir;
    std::optional<Shard> shard;
    int jobs = 1;                    // parallel renderers (one EGL context each)
    std::filesystem::path assetsDir; // empty: $SKINLAB_ASSETS
    bool contactSheet = true;
    enum class ProgressStyle { automatic, bar, lines } progress = ProgressStyle::automatic;
    // Predicted visibility (stimuli/prediction.h): each stimulus against its block's reference, on this display (a
    // named model or a custom one, recorded in the manifest).
    bool predict = true;
    metrics::CvvdpDisplay display = metrics::cvvdpDisplay("standard_fhd");
};

// The checked plan of a build: what would be rendered, and each stimulus's resolved scene parameters.
struct BuildPlan {
    SetSpec spec;
    std::vector<Stimulus> all;            // the whole set
    std::vector<Stimulus> selected;       // this shard's slice (all of it without --shard)
    std::vector<nlohmann::json> resolved; // per selected stimulus: resolveScene()'s JSON of what is rendered
    // Per selected stimulus: the scene overrides rendered, its own and those of a native presentation
    // (presentation.h: render.width/height × magnification, render.window).
    std::vector<std::vector<std::string>> renderOverrides;
};

// Reads the spec, expands it and resolves every selected stimulus (no GL). Throws InputError for bad input:
// "SPEC: factor 'method': level 'x': <scene error>", "SPEC: stimulus 'id': <scene error>", ...
BuildPlan planBuild(const std::filesystem::path& spec, const std::vector<std::string>& specOverrides,
                    const std::optional<Shard>& shard, const std::filesystem::path& assetsDir);

struct BuildSummary {
    size_t stimuli = 0;  // in this folder's selection
    size_t rendered = 0; // rendered by this run
    size_t kept = 0;     // unchanged from an earlier run
    double wallSeconds = 0.0;
    std::filesystem::path manifest;
    std::filesystem::path contactHtml;    // empty when no contact sheet was written
    std::vector<std::string> predictions; // one line per block with a reference, and warnings (prediction.h)
    bool invisibleBlock = false;          // some block's conditions all lie within 0.25 JOD of each other
};

BuildSummary buildSet(const BuildOptions& options);

// The render size the stimulus' crop is given in (the set's render size): the resolved render's, or for a native
// presentation (rendered as a render.window of a frame magnification × that size) the frame's / magnification.
std::pair<int, int> presentationFrame(const Stimulus& stimulus, const nlohmann::json& resolved);

// The manifest entry of a stimulus (everything but the render-derived fields: sha256, width, height, timings).
formats::ManifestEntry stimulusEntry(const Stimulus& stimulus, const nlohmann::json& resolved);
// Its JSON before rendering (`stimuli list --format json`): the entry without the render-derived keys.
nlohmann::json plannedEntryJson(const Stimulus& stimulus, const nlohmann::json& resolved);

} // namespace skinlab::stimuli
