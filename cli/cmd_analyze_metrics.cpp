// `skinlab analyze metrics`: image-difference metrics of renders against a reference (docs/metrics.md).
#include "analysis/metrics/debiased_error.h"
#include "analysis/metrics/metrics_run.h"
#include "analysis/metrics/seed_mean.h"
#include "analysis/scaling/renderer_effects.h"
#include "cli/commands.h"
#include "cli/options.h"
#include "common/error.h"
#include "common/files.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

namespace skinlab::cli {
namespace {

struct AnalyzeMetricsArguments {
    std::string reference;
    std::vector<std::string> referenceSeeds;
    std::string compareReference;
    std::string compareMetrics;
    int competitive = 16;
    int bootstrapReplicates = 2000;
    std::vector<std::string> tests;
    std::string stimulusFolder;
    std::string outputFolder;
    double exposure = 1.0;
    std::optional<double> sssRadiusMillimetres;
    double heatmapMax = 0.0;
    bool noHeatmaps = false;
    std::string encoding = "auto";
    DisplayArguments display; // --display, --ppd, --display-* (cli/options.h)
};

// --reference-seeds: every test against the path-traced truth without its noise (docs/metrics.md).
void runDebiased(const AnalyzeMetricsArguments& arguments) {
    if (!arguments.reference.empty())
        throwInput("--reference", "", "cannot be combined with --reference-seeds (the seeds are the reference)");
    if (!arguments.stimulusFolder.empty())
        throwInput("--stimuli", "", "cannot be combined with --reference-seeds; give the test renders as files");
    std::vector<std::filesystem::path> seeds(arguments.referenceSeeds.begin(), arguments.referenceSeeds.end());
    std::vector<std::filesystem::path> tests(arguments.tests.begin(), arguments.tests.end());
    metrics::DebiasedRunOptions options;
    options.exposure = arguments.exposure;
    if (arguments.sssRadiusMillimetres) {
        if (!(*arguments.sssRadiusMillimetres > 0.0))
            throwInput("--sss-radius-mm", "", std::to_string(*arguments.sssRadiusMillimetres) + " must be positive");
        options.sssRadiusMillimetres = *arguments.sssRadiusMillimetres;
    }
    options.compareReference = arguments.compareReference;
    options.compareMetrics = arguments.compareMetrics;
    if (arguments.competitive < 2)
        throwInput("--competitive", "", std::to_string(arguments.competitive) + " must be at least 2");
    if (arguments.bootstrapReplicates < 0)
        throwInput("--bootstrap", "", std::to_string(arguments.bootstrapReplicates) + " must be 0 or more");
    options.agreement.competitiveCount = static_cast<std::size_t>(arguments.competitive);
    options.agreement.bootstrapReplicates = static_cast<std::size_t>(arguments.bootstrapReplicates);
    const auto run = metrics::runDebiasedMetrics(seeds, tests, options, arguments.outputFolder);
    spdlog::info("metrics: {} render(s) scored against {} path-traced seeds; {}/debiased.csv and debiased.json",
                 run.tests.size(), seeds.size(), arguments.outputFolder);
}

// One line per block of a stimulus set whose test renders come from different renderers (skinlab's rasterizer,
// EEVEE, Cycles): their scores against one reference also differ by what the renderers do apart from SSS.
void warnAboutMixedRenderers(const std::filesystem::path& stimulusFolder) {
    nlohmann::json manifest;
    try {
        manifest = nlohmann::json::parse(readFile(stimulusFolder / "manifest.json"));
    } catch (const nlohmann::json::exception&) {
        return; // the plan has checked the manifest already
    }
    std::map<std::string, std::pair<std::vector<std::string>, std::vector<nlohmann::json>>> blocks;
    for (const nlohmann::json& s : manifest.value("stimuli", nlohmann::json::array())) {
        if (!s.is_object() || s.value("reference", false)) continue;
        auto& [names, resolved] = blocks[s.value("block", "")];
        names.push_back(s.value("id", ""));
        resolved.push_back(s.value("resolved", nlohmann::json::object()));
    }
    for (const auto& [block, conditions] : blocks) {
        const auto effects = analysis::scaling::sssEffectsWithinRenderers(
            block, conditions.first, conditions.second, std::vector<double>(conditions.first.size(), 0.0));
        if (effects.warning) spdlog::warn("metrics: {}", *effects.warning);
    }
}

void runAnalyzeMetrics(const AnalyzeMetricsArguments& arguments) {
    if (!arguments.referenceSeeds.empty()) return runDebiased(arguments);
    if (!arguments.compareReference.empty()) throwInput("--compare-reference", "", "only with --reference-seeds");
    if (!arguments.compareMetrics.empty()) throwInput("--compare-metrics", "", "only with --reference-seeds");
    metrics::CvvdpDisplay display = arguments.display.resolve(); // option errors before any file is read
    std::string displaySource = arguments.display.name ? "--display" : "default";
    metrics::ComparisonPlan plan;
    if (!arguments.stimulusFolder.empty()) {
        if (!arguments.tests.empty())
            throwInput(arguments.tests.front(), "",
                       "test files cannot be combined with --stimuli (the set lists its renders)");
        std::optional<std::string> referenceId;
        if (!arguments.reference.empty()) referenceId = arguments.reference;
        plan = metrics::planStimulusSetComparisons(arguments.stimulusFolder, referenceId);
        warnAboutMixedRenderers(arguments.stimulusFolder);
        // The set's viewing geometry: the display its predictions were made for, unless --display says otherwise.
        if (plan.display && !arguments.display.name) {
            const metrics::CvvdpDisplayOverrides changes = arguments.display.changes();
            display = metrics::applyCvvdpOverrides(*plan.recordedDisplay(), changes);
            displaySource = "the set's predictions (manifest.json predicted.display)";
        } else if (plan.display && *arguments.display.name != *plan.display) {
            spdlog::warn("metrics: the set's predictions are on {}, these metrics on --display {}: their "
                         "ColorVideoVDP will differ from the manifest's predicted JOD",
                         *plan.display, *arguments.display.name);
        }
    } else {
        if (arguments.reference.empty())
            throwInput("--reference", "", "required: the reference EXR (or use --stimuli DIR)");
        if (arguments.tests.empty())
            throwInput("TEST.exr", "", "required: at least one render to compare with the reference");
        std::vector<std::filesystem::path> tests(arguments.tests.begin(), arguments.tests.end());
        plan = metrics::planFileComparisons(arguments.reference, tests);
    }
    metrics::MetricsRunOptions options;
    options.metric.exposure = arguments.exposure;
    options.metric.sssRadiusMillimetres = arguments.sssRadiusMillimetres;
    options.metric.encoding = metrics::parseImageEncoding(arguments.encoding);
    options.metric.display = display;
    options.heatmapMax = arguments.heatmapMax;
    options.heatmaps = !arguments.noHeatmaps;
    if (arguments.display.changed()) displaySource += " with --display-*/--ppd changes";
    options.displaySource = displaySource;
    if (!arguments.stimulusFolder.empty() && arguments.exposure != 1.0)
        throwInput("--exposure", "",
                   std::to_string(arguments.exposure) +
                       " cannot be combined with --stimuli (the presented images are scored as observers see them)");
    const bool presented = !plan.jobs.empty() && !plan.jobs.front().referencePresented.empty();
    auto records = metrics::runMetrics(plan, options, arguments.outputFolder);
    spdlog::info("metrics: {} comparison(s) written to {}/metrics.csv and metrics.json; viewing geometry {} ({}) for "
                 "FLIP and ColorVideoVDP; display-referred scores on {}",
                 records.size(), arguments.outputFolder, metrics::describeCvvdpDisplay(display), displaySource,
                 presented ? "the presented PNGs" : "the renders");
}

} // namespace

void registerAnalyzeMetrics(CLI::App& analyze) {
    auto arguments = std::make_shared<AnalyzeMetricsArguments>();
    CLI::App* command = analyze.add_subcommand(
        "metrics",
        "Compare renders with a reference: PSNR, SSIM, CIEDE2000, LDR-FLIP and ColorVideoVDP on the image and on skin, "
        "and halo/bleed/"
        "spill/interior band scores; plain images (PNG, JPEG, RGB-only EXR) get the image-wide scores "
        "(docs/metrics.md)");
    command->add_option("tests", arguments->tests,
                        "Test renders (skinlab EXRs with their layers) or plain images (PNG, JPEG, EXR, ...) to "
                        "compare with --reference");
    command->add_option("--reference", arguments->reference,
                        "Reference EXR (with depth.Z, mask.Y and skinlab:f_px/mm_per_unit/sss_radius_mm); with "
                        "--stimuli: the id of the reference stimulus (default: each block's \"reference\": true)");
    command
        ->add_option("--reference-seeds", arguments->referenceSeeds,
                     "Path-traced renders of one scene with different seeds (two or more; four or more for "
                     "standard errors): score the tests against the noise-free image without the noise's bias "
                     "(debiased.csv, debiased.json); comma-separated or repeated")
        ->delimiter(',')
        ->allow_extra_args(false);
    command->add_option("--compare-reference", arguments->compareReference,
                        "With --reference-seeds: another ground truth of the same scene (e.g. the object-space "
                        "reference render): each test's paired difference from it, and the agreement of the tests' "
                        "rankings under the two truths (Kendall's tau with its interval)");
    command->add_option("--compare-metrics", arguments->compareMetrics,
                        "With --compare-reference: metrics.json of analyze metrics --reference on the same test "
                        "files; the agreement of each of its band scores (leak energies, dE00 means and excesses) "
                        "with the truth's ranking (table_score_agreement)");
    command->add_option("--competitive", arguments->competitive,
                        "With --compare-reference: the competitive conditions, this many closest to the truth "
                        "(default 16)");
    command->add_option("--bootstrap", arguments->bootstrapReplicates,
                        "With --compare-reference: bootstrap replicates of the tau intervals (default 2000; 0: none)");
    command->add_option("--stimuli", arguments->stimulusFolder,
                        "Stimulus set folder (manifest.json): compare every stimulus with its block's reference");
    command
        ->add_option("-o,--output", arguments->outputFolder,
                     "Output folder: metrics.csv, metrics.json, heatmaps/<test>.png")
        ->required();
    command->add_option("--exposure", arguments->exposure,
                        "Linear multiplier before the display encoding for dE00/PSNR/SSIM (default 1: the render's "
                        "own exposure)");
    command->add_option("--sss-radius-mm", arguments->sssRadiusMillimetres,
                        "SSS support radius in mm for the bands (default: the reference's skinlab:sss_radius_mm)");
    command->add_option("--heatmap-max", arguments->heatmapMax,
                        "dE00 at the top of the heat map's colour scale (default 0: each map's scale from its own "
                        "data, the 99th percentile rounded up; FLIP and ColorVideoVDP maps always so)");
    command->add_flag("--no-heatmaps", arguments->noHeatmaps, "Write only metrics.csv and metrics.json");
    command->add_option("--encoding", arguments->encoding,
                        "How pixel values map to linear light: auto (default: float files linear, 8/16-bit sRGB unless "
                        "the file says linear), srgb, linear");
    addDisplayOptions(*command, arguments->display,
                      "Display model, the viewing geometry of FLIP and ColorVideoVDP (default: with --stimuli the "
                      "display of the set's predictions, else standard_fhd)");
    command->callback([arguments] { runAnalyzeMetrics(*arguments); });
}

void registerAnalyzeSeedMean(CLI::App& analyze) {
    struct Arguments {
        std::vector<std::string> seeds;
        std::string output;
    };
    auto arguments = std::make_shared<Arguments>();
    CLI::App* command = analyze.add_subcommand(
        "seed-mean",
        "Average path-traced renders of one scene with independent seeds into one EXR, the path-traced truth for "
        "analyze metrics --reference (skinlab:truth records the seeds; docs/metrics.md)");
    command->add_option("seeds", arguments->seeds, "Path-traced renders (sss.method = \"pathtraced\"), one per seed")
        ->required();
    command->add_option("-o,--output", arguments->output, "The seed mean, an EXR with the seeds' layout")->required();
    command->callback([arguments] {
        const std::vector<std::filesystem::path> seeds(arguments->seeds.begin(), arguments->seeds.end());
        const auto truth = metrics::writeSeedMean(seeds, arguments->output);
        spdlog::info("seed-mean: {} seeds {} averaged into {}", seeds.size(), truth["seeds"].dump(), arguments->output);
    });
}

} // namespace skinlab::cli
