// `skinlab analyze scale RESPONSES -o DIR` and `skinlab analyze validate` (docs/analysis.md).
#include "analysis/scaling/multiple_comparisons.h"
#include "analysis/scaling/scale_analysis.h"
#include "analysis/scaling/scale_report.h"
#include "analysis/scaling/screening.h"
#include "analysis/scaling/validation.h"
#include "cli/commands.h"
#include "common/error.h"
#include "common/files.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

namespace skinlab::cli {
namespace {

namespace scaling = skinlab::analysis::scaling;

struct ScaleArguments {
    std::string responses;
    std::string output;
    int bootstrap = 1000;
    std::uint64_t seed = 1;
    int threads = 2;
    double level = 0.95;
    std::string correction = "holm";
    double alpha = 0.05;
    double whisker = 1.5;
    double priorPrecision = 0.002;
    std::string prior = "gaussian";
    bool pwcmpOutliers = false;
    std::vector<std::string> columns;
    std::string block;
    bool singleBlock = false;
    std::vector<std::string> conditions;
    bool dropFlagged = false;
    bool keepExcluded = false;
    std::string intervals = "auto";
};

void runScale(const ScaleArguments& arguments) {
    scaling::DatasetOptions datasetOptions;
    datasetOptions.conditionOrder = arguments.conditions;
    datasetOptions.onlyBlock = arguments.block;
    datasetOptions.singleBlock = arguments.singleBlock;
    scaling::AnalysisOptions options;
    options.fit.priorPrecision = arguments.priorPrecision;
    options.fit.prior = arguments.prior == "pwcmp" ? scaling::Prior::Pwcmp : scaling::Prior::Gaussian;
    options.pwcmpOutliers = arguments.pwcmpOutliers;
    options.bootstrap.samples = arguments.bootstrap;
    options.bootstrap.seed = arguments.seed;
    options.bootstrap.threads = arguments.threads;
    options.bootstrap.level = arguments.level;
    options.correction = scaling::parseCorrection(arguments.correction);
    options.alpha = arguments.alpha;
    options.screeningWhisker = arguments.whisker;

    scaling::ReadOptions readOptions;
    const std::vector<std::string>& roles = scaling::mappableColumns();
    for (const std::string& entry : arguments.columns) {
        const size_t equals = entry.find('=');
        const std::string role = entry.substr(0, equals);
        if (equals == std::string::npos || equals + 1 == entry.size() ||
            std::find(roles.begin(), roles.end(), role) == roles.end()) {
            std::string names;
            for (const std::string& name : roles) names += (names.empty() ? "" : ", ") + name;
            throwInput("--columns", "", "'" + entry + "' is not ROLE=COLUMN with ROLE one of " + names);
        }
        readOptions.columns.emplace_back(role, entry.substr(equals + 1));
    }
    scaling::ResponseTable table = scaling::readResponses(arguments.responses, readOptions);
    if (!table.ignoredColumns.empty()) {
        std::string names;
        for (const std::string& name : table.ignoredColumns) names += (names.empty() ? "" : ", ") + name;
        std::fprintf(stderr, "note: %s: ignored column(s) %s (--columns selects other ones)\n", table.file.c_str(),
                     names.c_str());
    }
    if (arguments.dropFlagged) {
        const scaling::DroppedFlagged dropped = scaling::dropFlagged(table);
        if (dropped.recorded)
            std::printf("dropped %zu flagged trials (page hidden or focus lost while shown), %zu responses left\n",
                        dropped.dropped, table.responses.size());
        else std::printf("dropped 0 flagged trials: %s records no page-hidden or focus flags\n", table.file.c_str());
    }
    if (!arguments.keepExcluded)
        for (const scaling::ExcludedObserver& e : scaling::excludeObservers(table))
            std::printf("excluded observer %s: %s (the protocol's rule; --no-exclusion keeps them)\n",
                        e.observer.c_str(), e.reason.c_str());
    // Active designs get the union of the studentized observer bootstrap and the profile-likelihood intervals:
    // neither alone covers 95 % at every number of observers when each observer's pairs depend on earlier answers
    // (docs/analysis.md, "Validation of active designs").
    if (arguments.intervals == "percentile") {
        options.intervals = scaling::IntervalMethod::percentile;
        options.intervalReason = "--intervals percentile";
    } else if (arguments.intervals == "profile") {
        options.intervals = scaling::IntervalMethod::profile;
        options.intervalReason = "--intervals profile";
    } else if (arguments.intervals == "bootstrap+profile") {
        options.intervals = scaling::IntervalMethod::bootstrapAndProfile;
        options.intervalReason = "--intervals bootstrap+profile";
    } else if (arguments.intervals == "bootstrap") {
        options.intervalReason = "--intervals bootstrap";
    } else {
        options.intervals = scaling::defaultIntervals(table.adaptiveDesign);
        options.intervalReason = table.adaptiveDesign ? "active design" : "fixed design";
    }
    if (arguments.intervals == "auto" && table.adaptiveDesign)
        std::printf("active design (pairs chosen from earlier answers): the union of the studentized bootstrap and "
                    "profile-likelihood intervals\n");
    const scaling::Dataset dataset = scaling::buildDataset(table, datasetOptions);
    const scaling::Analysis analysis = scaling::analyzeDataset(dataset, options);
    for (const std::string& warning : analysis.warnings) spdlog::warn("{}", warning);
    scaling::writeScaleOutputs(analysis, arguments.output);

    for (const scaling::BlockAnalysis& block : analysis.blocks) {
        std::printf("%s (%zu observers, %s)\n", block.name.c_str(), block.observers.size(),
                    block.intervalMethod.c_str());
        for (size_t i = 0; i < block.conditions.size(); ++i) {
            const auto k = static_cast<Eigen::Index>(i);
            std::string note;
            if (i < block.intervalFlags.size() && block.intervalFlags[i].fallback) {
                for (const std::string& reason : block.intervalFlags[i].reasons)
                    note += (note.empty() ? "" : ", ") + reason;
                note = "  percentile+profile (" + note + ")";
            }
            if (i < block.measured.size() && !block.measured[i]) {
                std::printf("  %-24s not measured (never compared)\n", block.conditions[i].c_str());
                continue;
            }
            char interval[96];
            const double low = block.low[k], high = block.high[k];
            if (std::isfinite(low) && std::isfinite(high))
                std::snprintf(interval, sizeof interval, "[%+.3f, %+.3f]", low, high);
            else if (std::isfinite(low)) std::snprintf(interval, sizeof interval, "at least %+.3f", low);
            else if (std::isfinite(high)) std::snprintf(interval, sizeof interval, "at most %+.3f", high);
            else std::snprintf(interval, sizeof interval, "not measured");
            const bool priorDriven = i < block.intervalFlags.size() && block.intervalFlags[i].priorDriven;
            std::printf("  %-24s %+7.3f JOD%s  %s%s\n", block.conditions[i].c_str(), block.thurstone.scores[k],
                        priorDriven ? " (value set by the prior)" : "", interval, note.c_str());
        }
        const auto significant = std::count_if(block.pairs.begin(), block.pairs.end(),
                                               [](const scaling::PairTest& pair) { return pair.significant; });
        std::printf("  significant pairs: %td of %zu (correction over the block's pairs: %s)\n", significant,
                    block.pairs.size(), scaling::correctionName(options.correction));
    }
    for (const scaling::ObserverSummary& observer : analysis.observers)
        if (arguments.pwcmpOutliers && !std::isnan(observer.pwcmpDistance))
            std::printf("pwcmp outlier analysis: %-16s log10 likelihood per pair %.4f  dist_L %.3f%s\n",
                        observer.observer.c_str(), observer.pwcmpLogLikelihood, observer.pwcmpDistance,
                        observer.pwcmpOutlier ? "  outlier" : "");
    std::printf("wrote %s\n", (std::filesystem::path(arguments.output) / "scale.json").c_str());
}

struct ValidateArguments {
    std::string prior = "gaussian";
    std::string output;
    scaling::ValidationOptions options;
    std::string correction = "holm";
    bool check = false;
};

// The validation targets (docs/analysis.md, "Validation"); returns the failed ones.
std::vector<std::string> failedTargets(const scaling::ValidationReport& report) {
    std::vector<std::string> failed;
    char line[256];
    for (const scaling::ValidationRow& row : report.rows) {
        auto fail = [&](const char* what, double value) {
            std::snprintf(line, sizeof line, "%s, %d observers: %s = %.4f", row.scenario.c_str(), row.observers, what,
                          value);
            failed.push_back(line);
        };
        if (row.scenario == "thurstone") {
            if (row.coverage < 0.945) fail("coverage < 0.945", row.coverage);
            if (row.observers == 20 && row.rmse > 0.16) fail("RMSE > 0.16", row.rmse);
            if (row.significantReversed > 0.002) fail("significant & reversed > 0.002", row.significantReversed);
        }
        if (row.scenario == "sparse" || row.scenario == "disconnected" || row.scenario == "near-unanimous" ||
            row.scenario == "active") {
            if (row.coverage < 0.93) fail("coverage < 0.93", row.coverage);
        }
        if (!(row.maximumHalfWidth <= 250.0)) fail("an interval wider than the prior allows", row.maximumHalfWidth);
        if (row.scenario == "screening") {
            if (row.randomHitRate < 0.9) fail("random caught < 0.9", row.randomHitRate);
            if (row.invertedHitRate >= 0 && row.invertedHitRate < 1.0) fail("inverted caught < 1", row.invertedHitRate);
            if (row.falseAlarmRate > 0.02) fail("false alarms > 0.02", row.falseAlarmRate);
        }
    }
    return failed;
}

void runValidate(ValidateArguments& arguments) {
    arguments.options.correction = scaling::parseCorrection(arguments.correction);
    arguments.options.prior = arguments.prior == "pwcmp" ? scaling::Prior::Pwcmp : scaling::Prior::Gaussian;
    const std::vector<std::string>& known = scaling::validationScenarios();
    std::string names;
    for (const std::string& name : known) names += (names.empty() ? "" : ", ") + name;
    for (const std::string& scenario : arguments.options.scenarios)
        if (std::find(known.begin(), known.end(), scenario) == known.end())
            throwInput("--scenarios", "", "'" + scenario + "' is not one of " + names);
    if (arguments.options.trueScores.size() < 2) throwInput("--scores", "", "needs at least 2 true scores");
    if (2 * static_cast<size_t>(arguments.options.disconnectedGroups) > arguments.options.trueScores.size())
        throwInput("--groups", "",
                   std::to_string(arguments.options.disconnectedGroups) + " groups need at least 2 true scores each");
    for (int observers : arguments.options.observerCounts)
        if (observers < 2 + arguments.options.randomObservers + arguments.options.invertedObservers)
            throwInput("--observers", "", std::to_string(observers) + " is too few (at least 2 genuine observers)");
    const scaling::ValidationReport report = scaling::runValidation(arguments.options);
    const std::string markdown = scaling::validationMarkdown(report);
    std::printf("%s", markdown.c_str());
    std::printf("\n%.1f s\n", report.seconds);
    if (!arguments.output.empty()) {
        ensureDirectory(arguments.output);
        writeFileAtomic(std::filesystem::path(arguments.output) / "validation.md", markdown);
        writeFileAtomic(std::filesystem::path(arguments.output) / "validation.json",
                        scaling::validationJson(report).dump(2) + "\n");
    }
    if (arguments.check) {
        const std::vector<std::string> failed = failedTargets(report);
        for (const std::string& failure : failed) std::fprintf(stderr, "target missed: %s\n", failure.c_str());
        if (!failed.empty()) throw RuntimeError("validation: " + std::to_string(failed.size()) + " target(s) missed");
        std::printf("all targets met\n");
    }
}

// `skinlab analyze scale`: its options and what it runs.
void addScale(CLI::App& analyze) {
    auto scaleArguments = std::make_shared<ScaleArguments>();
    CLI::App* scale = analyze.add_subcommand(
        "scale", "Scale 2AFC responses to JOD (Thurstone Case V) with bootstrap intervals, tests and screening");
    scale
        ->add_option("responses", scaleArguments->responses,
                     "study.db (SQLite, view responses_long), a CSV export, a pwcmp long CSV or a count-matrix CSV")
        ->required();
    scale->add_option("-o,--output", scaleArguments->output, "output folder")->required();
    scale->add_option("--bootstrap", scaleArguments->bootstrap, "bootstrap samples over observers")
        ->check(CLI::Range(100, 1000000))
        ->capture_default_str();
    scale->add_option("--seed", scaleArguments->seed, "bootstrap seed")->capture_default_str();
    scale->add_option("--threads", scaleArguments->threads, "bootstrap threads")
        ->check(CLI::Range(1, 256))
        ->capture_default_str();
    scale->add_option("--level", scaleArguments->level, "confidence level of the intervals")
        ->check(CLI::Range(0.5, 0.999))
        ->capture_default_str();
    scale->add_option("--correction", scaleArguments->correction, "multiple-comparison correction")
        ->check(CLI::IsMember({"holm", "bonferroni", "none"}))
        ->capture_default_str();
    scale->add_option("--alpha", scaleArguments->alpha, "significance level after correction")
        ->check(CLI::Range(1e-6, 0.5))
        ->capture_default_str();
    scale->add_option("--whisker", scaleArguments->whisker, "inter-quartile rule factor w of the observer screening")
        ->check(CLI::Range(0.0, 10.0))
        ->capture_default_str();
    scale
        ->add_option("--prior-precision", scaleArguments->priorPrecision,
                     "precision (1/JOD^2) of the Gaussian prior on every pairwise difference")
        ->check(CLI::Range(1e-6, 10.0))
        ->capture_default_str();
    scale
        ->add_option("--prior", scaleArguments->prior,
                     "gaussian (--prior-precision on every pairwise difference) or pwcmp (pwcmp's pw_scale default "
                     "prior and mean-zero regularisation)")
        ->check(CLI::IsMember({"gaussian", "pwcmp"}))
        ->capture_default_str();
    scale->add_flag("--pwcmp-outliers", scaleArguments->pwcmpOutliers,
                    "also run pwcmp's outlier analysis (leave-one-observer-out dist_L, flagged above 1.5)");
    scale
        ->add_option("--columns", scaleArguments->columns,
                     "long CSVs: ROLE=COLUMN for the roles observer, scene, condition_A, condition_B, is_A_selected "
                     "(other columns are ignored with a note)")
        ->delimiter(',');
    scale->add_option("--block", scaleArguments->block, "analyse only this block (scene)");
    scale->add_flag("--single-block", scaleArguments->singleBlock, "the file must hold one block only");
    scale
        ->add_option("--conditions", scaleArguments->conditions,
                     "the conditions in display order; any other condition in the file is an error")
        ->delimiter(',');
    scale->add_flag(
        "--no-exclusion", scaleArguments->keepExcluded,
        "scale every observer, also those the protocol's rule excludes (no scaled answers, or more than "
        "one failed catch trial in four; by default they are left out, as in the dashboard and the report)");
    scale->add_flag("--drop-flagged", scaleArguments->dropFlagged,
                    "leave out trials during which the page was hidden or lost the focus (online studies)");
    scale
        ->add_option("--intervals", scaleArguments->intervals,
                     "bootstrap (studentized, over observers), profile (profile likelihood), bootstrap+profile (the "
                     "union of the two), percentile (pwcmp's percentile bootstrap over observers), or auto: "
                     "bootstrap, and bootstrap+profile for active designs")
        ->check(CLI::IsMember({"auto", "bootstrap", "profile", "bootstrap+profile", "percentile"}))
        ->capture_default_str();
    scale->callback([scaleArguments] { runScale(*scaleArguments); });
}

// `skinlab analyze validate`: its options and what it runs.
void addValidate(CLI::App& analyze) {
    auto validateArguments = std::make_shared<ValidateArguments>();
    scaling::ValidationOptions& o = validateArguments->options;
    CLI::App* validate = analyze.add_subcommand(
        "validate", "Simulation study of the scaling: coverage, RMSE, tests and screening against known scores");
    validate->add_option("-o,--output", validateArguments->output, "folder for validation.md and validation.json");
    validate->add_option("--experiments", o.experiments, "simulated experiments per scenario and observer count")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    validate->add_option("--observers", o.observerCounts, "observer counts")->delimiter(',')->capture_default_str();
    validate->add_option("--scores", o.trueScores, "true scores (JOD)")->delimiter(',')->capture_default_str();
    validate->add_option("--trials-per-pair", o.trialsPerPair, "trials per pair per observer (sides alternate)")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    validate->add_option("--bootstrap", o.bootstrapSamples, "bootstrap samples per experiment")
        ->check(CLI::Range(100, 100000))
        ->capture_default_str();
    validate->add_option("--seed", o.seed, "simulation seed")->capture_default_str();
    validate->add_option("--threads", o.threads, "worker threads")->check(CLI::Range(1, 256))->capture_default_str();
    validate->add_option("--lapse", o.lapseRate, "lapse rate of genuine observers (non-ideal scenarios)")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    validate->add_option("--side-bias", o.sideBiasStandardDeviation, "sd of the per-observer side bias (JOD)")
        ->check(CLI::Range(0.0, 10.0))
        ->capture_default_str();
    validate->add_option("--random", o.randomObservers, "random observers in the screening scenario")
        ->check(CLI::Range(0, 1000))
        ->capture_default_str();
    validate->add_option("--inverted", o.invertedObservers, "inverted observers in the screening scenario")
        ->check(CLI::Range(0, 1000))
        ->capture_default_str();
    validate->add_option("--correction", validateArguments->correction, "multiple-comparison correction")
        ->check(CLI::IsMember({"holm", "bonferroni", "none"}))
        ->capture_default_str();
    validate->add_option("--prior", validateArguments->prior, "prior of the fits: gaussian or pwcmp")
        ->check(CLI::IsMember({"gaussian", "pwcmp"}))
        ->capture_default_str();
    validate->add_option("--whisker", o.screeningWhisker, "inter-quartile rule factor w")
        ->check(CLI::Range(0.0, 10.0))
        ->capture_default_str();
    validate->add_option("--pair-fraction", o.sparsePairFraction, "share of the pairs each observer judges (sparse)")
        ->check(CLI::Range(0.05, 1.0))
        ->capture_default_str();
    validate->add_option("--groups", o.disconnectedGroups, "groups of conditions never compared (disconnected)")
        ->check(CLI::Range(2, 100))
        ->capture_default_str();
    validate->add_option("--stretch", o.nearUnanimousStretch, "factor on the true scores (near-unanimous)")
        ->check(CLI::Range(1.0, 100.0))
        ->capture_default_str();
    validate
        ->add_option("--active-trials", o.activeTrials,
                     "trials per observer in the active scenario (0: as many as the full design)")
        ->check(CLI::Range(0, 100000))
        ->capture_default_str();
    validate->add_option("--active-stretch", o.activeStretch, "factor on the true scores (active)")
        ->check(CLI::Range(0.1, 100.0))
        ->capture_default_str();
    validate
        ->add_option("--scenarios", o.scenarios,
                     "thurstone, lapses+side-bias, screening, sparse, disconnected, near-unanimous, active")
        ->delimiter(',')
        ->capture_default_str();
    validate->add_flag("--check", validateArguments->check,
                       "exit 1 unless the validation targets are met (coverage, RMSE, reversals, screening, "
                       "finite intervals)");
    validate->callback([validateArguments] { runValidate(*validateArguments); });
}

} // namespace

void registerAnalyzeScale(CLI::App& analyze) {
    addScale(analyze);
    addValidate(analyze);
}

} // namespace skinlab::cli
