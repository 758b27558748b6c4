#include "report/study_report.h"

#include "analysis/agreement/metric_agreement.h"
#include "analysis/metrics/metrics_run.h"
#include "analysis/scaling/renderer_effects.h"
#include "analysis/scaling/responses.h"
#include "analysis/scaling/screening.h"
#include "analysis/scaling/scale_analysis.h"
#include "analysis/scaling/scale_report.h"
#include "common/error.h"
#include "common/files.h"
#include "common/process.h"
#include "common/html.h"
#include "common/version.h"
#include "experiments/study_store.h"
#include "formats/stimulus_manifest.h"
#include "report/prediction_section.h"
#include "report/report_plots.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

namespace skinlab::report {
namespace fs = std::filesystem;
namespace scaling = skinlab::analysis::scaling;
namespace agreement = skinlab::analysis::agreement;
namespace experiments = skinlab::experiments;

namespace {

std::string h(const std::string& text) { return escapeHtml(text); }
std::string num(double value, int digits = 2) { return formatNumber(value, digits); }
std::string slug(const std::string& block) { return scaling::blockSlug(block); }

// A number on the page that links to the table it comes from.
std::string linked(const std::string& anchor, const std::string& text) {
    return "<a class=\"num\" href=\"#" + anchor + "\">" + text + "</a>";
}

void copyFileAtomic(const fs::path& from, const fs::path& to) {
    if (!fs::is_regular_file(from)) throwInput(from.string(), "", "file not found");
    ensureDirectory(to.parent_path());
    AtomicOutput output(to);
    fs::copy_file(from, output.tempPath(), fs::copy_options::overwrite_existing);
    output.commit();
}

void writePngAtomic(const fs::path& path, const cv::Mat& image) {
    ensureDirectory(path.parent_path());
    AtomicOutput output(path);
    if (!cv::imwrite(output.tempPath().string() + ".png", image))
        throw RuntimeError(path.string() + ": cannot write PNG");
    fs::rename(output.tempPath().string() + ".png", output.tempPath());
    output.commit();
}

struct Observer {
    std::string label;
    int answered = 0, total = 0, catchAnswered = 0, catchCorrect = 0;
    bool excluded = false;
    std::string reason;
    bool screeningFlag = false;
    double heldOutPerTrial = NAN;
};

struct ConditionImages {
    std::string condition, stimulus, png; // png relative to the report folder
};

struct Crop {
    cv::Rect window;
    std::map<std::string, std::string> files; // condition → crop PNG relative to the report folder
};

// The window (a square about a fifth of the image height) where the conditions differ most: the largest box mean
// of the per-pixel range (max − min over conditions, summed over channels).
Crop cropWhereTheyDiffer(const std::vector<cv::Mat>& images, const std::vector<std::string>& names,
                         const fs::path& folder, const std::string& prefix) {
    Crop crop;
    if (images.size() < 2) return crop;
    cv::Mat low, high;
    images[0].convertTo(low, CV_32FC3);
    high = low.clone();
    for (std::size_t i = 1; i < images.size(); ++i) {
        cv::Mat f;
        images[i].convertTo(f, CV_32FC3);
        low = cv::min(low, f);
        high = cv::max(high, f);
    }
    cv::Mat range;
    cv::transform(high - low, range, cv::Matx13f(1.f, 1.f, 1.f));
    const int side = std::max(8, std::min(images[0].rows, images[0].cols) / 5);
    cv::Mat boxed;
    cv::boxFilter(range, boxed, CV_32F, {side, side}, {-1, -1}, true, cv::BORDER_CONSTANT);
    // Keep the window inside the image.
    cv::Rect inner(side / 2, side / 2, std::max(1, images[0].cols - side), std::max(1, images[0].rows - side));
    cv::Point best;
    cv::minMaxLoc(boxed(inner), nullptr, nullptr, nullptr, &best);
    crop.window = cv::Rect(best.x, best.y, side, side) & cv::Rect(0, 0, images[0].cols, images[0].rows);
    for (std::size_t i = 0; i < images.size(); ++i) {
        cv::Mat enlarged;
        cv::resize(images[i](crop.window), enlarged, {}, 2.0, 2.0, cv::INTER_NEAREST);
        std::string file = "crops/" + prefix + "-" + slug(names[i]) + ".png";
        writePngAtomic(folder / file, enlarged);
        crop.files[names[i]] = file;
    }
    return crop;
}

const char* const styleSheet = R"CSS(
:root { --ink:#1d2330; --muted:#5b6475; --line:#d9dee7; --accent:#2f5fb3; --sig:#dcefdc; --ns:#f6f7f9; }
* { box-sizing: border-box; }
body { font: 15px/1.5 "DejaVu Sans", "Liberation Sans", Arial, sans-serif; color: var(--ink); margin: 0; background:#fff; }
main { max-width: 1100px; margin: 0 auto; padding: 28px 32px 60px; }
h1 { font-size: 26px; margin: 0 0 4px; } h2 { font-size: 20px; margin: 34px 0 10px; border-bottom: 2px solid var(--line); padding-bottom: 4px; }
h3 { font-size: 16px; margin: 22px 0 8px; }
.sub { color: var(--muted); margin: 0 0 18px; }
.question { font-size: 18px; background: #eef3fb; border-left: 4px solid var(--accent); padding: 10px 14px; margin: 12px 0 18px; }
table { border-collapse: collapse; margin: 8px 0 14px; font-size: 13.5px; }
th, td { border: 1px solid var(--line); padding: 4px 8px; text-align: right; vertical-align: middle; }
th { background: #f1f3f7; } td.l, th.l { text-align: left; }
td.sig { background: var(--sig); font-weight: 600; } td.ns { background: var(--ns); color: var(--muted); } td.diag { background: #e9ebef; }
.findings li { margin: 6px 0; } a.num { color: var(--accent); text-decoration: none; border-bottom: 1px dotted var(--accent); }
.thumbs { display: flex; flex-wrap: wrap; gap: 12px; }
.thumbs figure { margin: 0; width: 250px; } .thumbs img { width: 250px; border: 1px solid var(--line); display: block; }
.crops figure { width: 170px; } .crops img { width: 170px; image-rendering: pixelated; }
figcaption { font-size: 12.5px; color: var(--muted); margin-top: 3px; }
.heat img { width: 330px; }
.scatters { display: flex; flex-wrap: wrap; gap: 16px; } .scatters figure { margin: 0; width: 350px; }
svg.plot { font-size: 11px; } svg .grid { stroke: #e3e6ec; } svg .identity { stroke: #888; stroke-dasharray: 4 3; } svg .bar { stroke: var(--accent); stroke-width: 2.5; }
svg .dot { fill: var(--accent); } svg .clip { fill: #c0392b; } svg .tick { text-anchor: middle; fill: var(--muted); }
svg .ytick { text-anchor: end; } svg .label { text-anchor: end; fill: var(--ink); font-size: 12px; }
svg .axis { text-anchor: middle; fill: var(--ink); font-size: 12px; } svg .point { fill: var(--muted); font-size: 10px; }
.note { color: var(--muted); font-size: 13px; }
.banner { background: #fff4e0; border: 1px solid #e0b060; border-left: 5px solid #d08a00; padding: 10px 14px; margin: 14px 0; }
@media print {
  main { padding: 0; max-width: none; }
  h1, h2, h3, p.note { break-after: avoid; page-break-after: avoid; }
  h2 + p, h2 + ul, h3 + p, h3 + table, h3 + div, p.note + table, p.note + div { break-before: avoid; page-break-before: avoid; }
  figure, svg, tr, li, .banner, .question { break-inside: avoid; page-break-inside: avoid; }
  table { break-inside: auto; }
  tbody tr:nth-last-child(-n+2), tbody tr:nth-child(-n+2) { break-before: avoid; page-break-before: avoid; }
}
)CSS";

// Every participant with their answers and catch trials, the response table the scale is computed from, and the
// viewing conditions the browsers recorded.
struct Participants {
    std::vector<Observer> observers;
    std::map<std::string, std::size_t> index; // label → observers[index]
    scaling::ResponseTable table;
    std::set<std::pair<int, int>> viewports;
    std::set<double> pixelRatios;
    int included = 0;
    int excluded() const { return static_cast<int>(observers.size()) - included; }
};

// Participants and exclusions: the protocol's rule (scaling::excludeObservers: no scaled answers, or more than one
// failed catch trial in four), applied to the same responses as `analyze scale` and the dashboard.
Participants readParticipants(experiments::StudyStore& store, const ReportOptions& options) {
    Participants p;
    for (const experiments::ParticipantStatus& status : store.status()) {
        Observer o;
        o.label = status.participant.label;
        o.answered = status.progress.answered;
        o.total = status.progress.total;
        o.catchAnswered = status.catchAnswered;
        o.catchCorrect = status.catchCorrect;
        p.index[o.label] = p.observers.size();
        p.observers.push_back(o);
    }
    // The browsers' viewports and pixel ratios, from the store's rows.
    for (const experiments::ResponseRow& row : store.responses()) {
        p.viewports.insert({row.viewportWidth, row.viewportHeight});
        p.pixelRatios.insert(row.devicePixelRatio);
    }
    // The responses by the one reader of a study file's rows (analysis/scaling/responses.h: the view
    // responses_long), as `analyze scale` and the dashboard read them.
    if (store.responseCount() > 0) {
        p.table = scaling::readResponses(options.study);
    } else {
        p.table.file = options.study.string();
        p.table.format = scaling::ResponseFormat::StudyDatabase;
        p.table.adaptiveDesign = store.definition().design.activePairs;
        for (const experiments::StudyBlock& block : store.definition().blocks)
            p.table.designConditionOrder[block.name] = block.conditions;
    }
    std::set<std::string> answering;
    for (const scaling::Response& r : p.table.responses) answering.insert(r.observer);
    for (const scaling::ExcludedObserver& e : scaling::excludeObservers(p.table)) {
        auto found = p.index.find(e.observer);
        if (found == p.index.end()) continue;
        p.observers[found->second].excluded = true;
        p.observers[found->second].reason = e.reason;
    }
    // A participant without a single answer is not in the responses: the rule's "no answers".
    for (Observer& o : p.observers)
        if (!answering.count(o.label)) {
            o.excluded = true;
            o.reason = scaling::exclusionReason(0, 0, 0).value_or("no answers");
        }
    p.included = static_cast<int>(
        std::count_if(p.observers.begin(), p.observers.end(), [](const Observer& o) { return !o.excluded; }));
    if (p.included < 2)
        throwInput(options.study.string(), "",
                   "fewer than 2 observers with answers to analyse (" + std::to_string(p.included) + ")");
    return p;
}

struct Scale {
    scaling::AnalysisOptions options;
    scaling::Dataset dataset;
    scaling::Analysis analysis;
};

// The scale (the analysis of `analyze scale`, with its interval choice), written to scale.json; each observer's
// screening result goes back to the participants.
Scale scaleStudy(Participants& participants, const ReportOptions& options, const fs::path& out) {
    Scale scale;
    scale.options.intervals = scaling::defaultIntervals(participants.table.adaptiveDesign); // as `analyze scale`
    scale.options.intervalReason = participants.table.adaptiveDesign ? "active design" : "fixed design";
    scale.options.bootstrap.samples = options.bootstrapSamples;
    scale.options.bootstrap.seed = options.seed;
    scale.options.bootstrap.threads = options.threads;
    spdlog::info("report: scaling {} responses of {} observers", participants.table.responses.size(),
                 participants.included);
    scale.dataset = scaling::buildDataset(participants.table, {});
    scale.analysis = scaling::analyzeDataset(scale.dataset, scale.options);
    writeFileAtomic(out / "scale.json", scaling::analysisJson(scale.analysis).dump(2) + "\n");
    for (const scaling::ObserverSummary& summary : scale.analysis.observers) {
        auto found = participants.index.find(summary.observer);
        if (found == participants.index.end()) continue;
        participants.observers[found->second].screeningFlag = summary.flagged;
        participants.observers[found->second].heldOutPerTrial = summary.heldOutPerTrial;
    }
    return scale;
}

struct StimulusImages {
    std::map<std::string, std::vector<ConditionImages>> imagesOfBlock;
    std::map<std::string, std::pair<std::string, std::string>> conditionOfStimulus; // id → (block, condition)
    std::map<std::string, Crop> cropOfBlock;
    std::map<std::string, ConditionImages> referenceOfBlock;
};

// Stimuli: copies, and crops where the conditions differ most; the set's reference render of each block
// ("reference": true in the manifest), shown beside the conditions.
StimulusImages copyStimuli(const experiments::StudyDefinition& definition, const fs::path& stimuliFolder,
                           const fs::path& out) {
    StimulusImages stimuli;
    auto& imagesOfBlock = stimuli.imagesOfBlock;
    auto& conditionOfStimulus = stimuli.conditionOfStimulus;
    auto& cropOfBlock = stimuli.cropOfBlock;
    auto& referenceOfBlock = stimuli.referenceOfBlock;
    for (const experiments::StudyBlock& block : definition.blocks) {
        std::vector<cv::Mat> images;
        std::vector<std::string> names;
        for (std::size_t c = 0; c < block.conditions.size(); ++c) {
            const experiments::StudyStimulus& s =
                definition.stimuli[static_cast<std::size_t>(block.conditionStimulus[c])];
            std::string file = "stimuli/" + slug(s.id) + ".png";
            copyFileAtomic(stimuliFolder / s.pngPath, out / file);
            imagesOfBlock[block.name].push_back({block.conditions[c], s.id, file});
            conditionOfStimulus[s.id] = {block.name, block.conditions[c]};
            images.push_back(cv::imread((stimuliFolder / s.pngPath).string(), cv::IMREAD_COLOR));
            names.push_back(block.conditions[c]);
        }
        cropOfBlock[block.name] = cropWhereTheyDiffer(images, names, out, slug(block.name));
    }
    // The set's manifest, by the one strict reader of contract 2 (formats/stimulus_manifest.h).
    for (const formats::ManifestEntry& s : formats::readStimulusManifest(stimuliFolder).stimuli) {
        if (!s.reference || s.files.png.empty()) continue;
        if (!imagesOfBlock.count(s.block) || referenceOfBlock.count(s.block)) continue;
        std::string file = "stimuli/" + slug(s.id) + ".png";
        copyFileAtomic(stimuliFolder / s.files.png, out / file);
        referenceOfBlock[s.block] = {"reference", s.id, file};
    }
    return stimuli;
}

struct Metrics {
    nlohmann::json json;
    fs::path folder;                                 // empty: no metrics
    std::map<std::string, std::string> referencePng; // block → reference (when computed here)
    std::vector<agreement::ConditionMetrics> conditions;
    std::map<std::string, std::string> heatmapOf, flipHeatmapOf, cvvdpHeatmapOf; // stimulus → copied heat map
    std::map<std::string, std::string> scaleOf; // copied heat map → its colour scale ("0–0.05")
};

// Metrics against the set's references (given, or computed here for the study's stimuli), their heat maps copied.
Metrics readMetrics(const ReportOptions& options, const fs::path& stimuliFolder, const fs::path& out,
                    const std::map<std::string, std::pair<std::string, std::string>>& conditionOfStimulus) {
    Metrics m;
    nlohmann::json& metricsJson = m.json;
    fs::path& metricsFolder = m.folder;
    std::map<std::string, std::string>& referencePng = m.referencePng;
    std::vector<agreement::ConditionMetrics>& conditionMetrics = m.conditions;
    auto& heatmapOf = m.heatmapOf;
    auto& flipHeatmapOf = m.flipHeatmapOf;
    auto& cvvdpHeatmapOf = m.cvvdpHeatmapOf;
    auto& scaleOf = m.scaleOf;
    metricsFolder = options.metrics;
    if (metricsFolder.empty()) {
        metrics::ComparisonPlan plan;
        try {
            plan = metrics::planStimulusSetComparisons(stimuliFolder, std::nullopt);
        } catch (const InputError& e) {
            spdlog::warn("report: no image metrics ({})", e.what());
        }
        std::erase_if(plan.jobs,
                      [&](const metrics::ComparisonJob& job) { return !conditionOfStimulus.count(job.testName); });
        if (!plan.jobs.empty()) {
            metricsFolder = out / "metrics";
            metrics::MetricsRunOptions metricOptions;
            // One viewing geometry: the display the set's predictions were made for (docs/metrics.md).
            // --display names another model; --ppd and --display-* change it.
            metricOptions.metric.display = metrics::applyCvvdpOverrides(
                options.display ? metrics::cvvdpDisplay(*options.display)
                                : plan.recordedDisplay().value_or(metrics::cvvdpDisplay("standard_fhd")),
                options.displayChanges);
            metricOptions.displaySource = options.display ? "--display"
                                          : plan.display  ? "the set's predictions (manifest.json predicted.display)"
                                                          : "default";
            metrics::CvvdpDisplayOverrides beyondPpd = options.displayChanges;
            beyondPpd.pixelsPerDegree.reset();
            if (options.displayChanges.any())
                metricOptions.displaySource += beyondPpd.any() ? " with --display-*/--ppd changes" : " with --ppd";
            spdlog::info("report: image metrics of {} stimuli against their block's reference", plan.jobs.size());
            metrics::runMetrics(plan, metricOptions, metricsFolder);
            // The references, for the stimulus section.
            for (const auto& job : plan.jobs) referencePng[job.block] = job.referenceName;
        }
    }
    if (!metricsFolder.empty()) {
        const fs::path file = metricsFolder / "metrics.json";
        try {
            metricsJson = nlohmann::json::parse(readFile(file));
        } catch (const nlohmann::json::exception& e) {
            throwInput(file.string(), "", std::string("not valid JSON (") + e.what() + ")");
        }
        conditionMetrics = agreement::conditionMetricsFromJson(metricsJson, file.string(), conditionOfStimulus);
        for (const nlohmann::json& comparison : metricsJson["comparisons"]) {
            std::string name = comparison["test"].value("name", "");
            if (!conditionOfStimulus.count(name)) continue;
            const struct {
                const char* key;
                const char* suffix;
                const char* scale;
                std::map<std::string, std::string>* of;
            } maps[] = {{"heatmap", ".png", "delta_e00", &heatmapOf},
                        {"flip_heatmap", ".flip.png", "flip", &flipHeatmapOf},
                        {"cvvdp_heatmap", ".cvvdp.png", "cvvdp", &cvvdpHeatmapOf}};
            for (const auto& map : maps) {
                if (!comparison.contains(map.key) || !comparison[map.key].is_string()) continue;
                std::string copied = "heatmaps/" + slug(name) + map.suffix;
                copyFileAtomic(metricsFolder / comparison[map.key].get<std::string>(), out / copied);
                (*map.of)[name] = copied;
                if (comparison.contains("heatmap_scale") && comparison["heatmap_scale"].is_object() &&
                    comparison["heatmap_scale"].contains(map.scale))
                    scaleOf[copied] = "0–" + num(comparison["heatmap_scale"][map.scale].get<double>(), 3);
            }
        }
    }
    return m;
}

// What the page is written from.
struct ReportData {
    const ReportOptions& options;
    experiments::StudyStore& store;
    const experiments::StudyDefinition& definition;
    const std::vector<std::string>& simulated;
    const fs::path& stimuliFolder;
    const Participants& participants;
    const Scale& scale;
    StimulusImages& stimuli;
    const Metrics& metrics;
    const agreement::AgreementOptions& agreementOptions;
    const agreement::AgreementResult& agreement;
    const nlohmann::json& storedManifest; // the manifest stored in the study file (predictions)
    const std::vector<PredictionAgreement>& predictions;
    const std::string& predictionDisplay;
};

// Title, the question, the contents and, for simulated observers, the banner that says so first.
void writeTitle(std::ostringstream& html, const ReportData& r) {
    const experiments::StudyDesign& design = r.definition.design;
    html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" << h(design.title)
         << " — study report</title><style>" << styleSheet << "</style></head><body><main>\n";
    html << "<h1>" << h(design.title) << "</h1><p class=\"sub\">Study report · "
         << h(r.options.study.filename().string()) << " · stimulus set " << h(r.store.meta("stimulus_set"))
         << " · skinlab " << h(version()) << "</p>\n";
    html << "<p class=\"question\">Question put to observers: <strong>" << h(design.question) << "</strong></p>\n";
    html << "<nav class=\"note\">Contents: <a href=\"#findings\">Findings</a> · <a href=\"#design\">Design</a> · "
            "<a href=\"#participants\">Participants</a> · <a href=\"#stimuli\">Stimuli</a> · <a "
            "href=\"#scale\">Scale</a>"
            " · <a href=\"#metrics\">Objective errors</a> · <a href=\"#agreement\">Metrics vs. perception</a>"
         << (r.predictions.empty() ? "" : " · <a href=\"#prediction\">Predicted and measured</a>") << "</nav>\n";

    // Observers sent by `study simulate` answer from a model, not from what they saw: said first, in a banner.
    if (!r.simulated.empty()) {
        html << "<div class=\"banner\"><strong>Simulated observers.</strong> " << r.simulated.size() << " of "
             << r.store.status().size()
             << " participants were simulated by <code>skinlab study simulate</code> (their answers come from a "
                "model of the observer, not from people looking at the stimuli): ";
        for (std::size_t i = 0; i < r.simulated.size() && i < 8; ++i) html << (i ? ", " : "") << h(r.simulated[i]);
        if (r.simulated.size() > 8) html << ", …";
        html << ". The findings below describe the simulation.</div>\n";
    }
}

// One block's finding on the scale: the best condition against the next, the range, the separated pairs.
void writeScaleFinding(std::ostringstream& html, const scaling::Analysis& analysis,
                       const scaling::BlockAnalysis& block) {
    const std::string anchor = "scale-" + slug(block.name);
    std::vector<int> order(block.conditions.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return block.thurstone.scores[a] > block.thurstone.scores[b]; });
    int best = order.front(), worst = order.back();
    int significant = 0;
    std::vector<std::string> beaten, tied; // below the best significantly / not separated from it
    const scaling::PairTest* runnerUp = nullptr;
    for (const scaling::PairTest& pair : block.pairs) {
        if (pair.significant) ++significant;
        int other = pair.test.first == best ? pair.test.second : pair.test.second == best ? pair.test.first : -1;
        if (other < 0) continue;
        (pair.significant ? beaten : tied).push_back(block.conditions[static_cast<std::size_t>(other)]);
        if (order.size() > 1 && other == order[1]) runnerUp = &pair;
    }
    const std::size_t pairCount = block.pairs.size();
    // Differences, not scores against the block mean: the best against the next, and which conditions it is
    // tied with (their difference is not significant).
    html << "<li><strong>" << h(block.name) << "</strong>: <em>" << h(block.conditions[static_cast<std::size_t>(best)])
         << "</em> scored highest";
    if (runnerUp) {
        const double sign = runnerUp->test.first == best ? 1.0 : -1.0;
        const double low = sign > 0 ? runnerUp->test.low : -runnerUp->test.high;
        const double high = sign > 0 ? runnerUp->test.high : -runnerUp->test.low;
        html << ", " << linked(anchor, num(sign * runnerUp->test.difference) + " JOD") << " ["
             << linked(anchor, num(low)) << ", " << linked(anchor, num(high)) << "] above the next, <em>"
             << h(block.conditions[static_cast<std::size_t>(order[1])]) << "</em> ("
             << (runnerUp->significant ? "significant" : "not significant")
             << ", adjusted p = " << num(runnerUp->adjustedPValue, 3) << ")";
    }
    html << "; <em>" << h(block.conditions[static_cast<std::size_t>(worst)]) << "</em> lowest, "
         << linked(anchor, num(block.thurstone.scores[best] - block.thurstone.scores[worst]) + " JOD")
         << " below the best. " << linked("pairs-" + slug(block.name), std::to_string(significant)) << " of "
         << pairCount << " pairs are separated significantly ("
         << h(scaling::correctionName(analysis.options.correction))
         << "-corrected, α = " << num(analysis.options.alpha, 2) << ")";
    if (!tied.empty()) {
        html << "; the best is <strong>tied</strong> (not separated) with ";
        for (std::size_t i = 0; i < tied.size(); ++i) html << (i ? ", " : "") << "<em>" << h(tied[i]) << "</em>";
    }
    if (!beaten.empty()) {
        html << "; it is significantly above ";
        for (std::size_t i = 0; i < beaten.size(); ++i) html << (i ? ", " : "") << "<em>" << h(beaten[i]) << "</em>";
    }
    html << ".</li>\n";
}

// The metric that predicts this block's scale best: highest Spearman oriented so that + means agreement.
void writeMetricFinding(std::ostringstream& html, const ReportData& r, const scaling::BlockAnalysis& block) {
    const agreement::AgreementResult& agreementResult = r.agreement;
    const std::vector<agreement::ConditionMetrics>& conditionMetrics = r.metrics.conditions;
    const agreement::MetricAgreement* bestMetric = nullptr;
    auto oriented = [](const agreement::MetricAgreement& row) {
        return (row.metric.higherIsBetter ? 1.0 : -1.0) * row.spearman;
    };
    auto orientedPearson = [](const agreement::MetricAgreement& row) {
        return (row.metric.higherIsBetter ? 1.0 : -1.0) * row.pearson;
    };
    for (const agreement::MetricAgreement& row : agreementResult.rows) {
        if (row.block != block.name || row.conditions < 3 || !std::isfinite(row.spearman) ||
            !std::isfinite(row.pearson))
            continue;
        if (!bestMetric || oriented(row) > oriented(*bestMetric) ||
            (oriented(row) == oriented(*bestMetric) && orientedPearson(row) > orientedPearson(*bestMetric)))
            bestMetric = &row;
    }
    if (bestMetric) {
        const std::string a = "agreement-" + slug(block.name);
        const int compared = static_cast<int>(
            std::count_if(agreementResult.rows.begin(), agreementResult.rows.end(),
                          [&](const auto& row) { return row.block == block.name && std::isfinite(row.spearmanP); }));
        html << "<li>In <strong>" << h(block.name) << "</strong> the metric that agrees best with the scale is <em>"
             << h(bestMetric->metric.label) << "</em> (" << (bestMetric->metric.higherIsBetter ? "higher" : "lower")
             << " is better): Spearman ρ = " << linked(a, num(bestMetric->spearman)) << " "
             << linked(a, correlationIntervalText(bestMetric->spearmanLow, bestMetric->spearmanHigh,
                                                  bestMetric->conditions))
             << ", p = " << num(bestMetric->spearmanP) << " (" << num(bestMetric->spearmanPHolm)
             << " after Holm's correction for choosing the best of " << compared
             << " metrics), Pearson r = " << linked(a, num(bestMetric->pearson)) << " over " << bestMetric->conditions
             << " conditions";
        if (bestMetric->conditions < agreement::kFewConditions)
            html << " — with so few conditions the intervals are wide and the choice of the best metric is "
                    "weakly determined";
        if (!(bestMetric->spearmanPHolm < 0.05))
            html << "; no metric agrees significantly once the choice is "
                    "accounted for";
        if (bestMetric->significantPairs > 0)
            html << "; it orders " << linked(a, std::to_string(bestMetric->predictedPairs)) << " of "
                 << linked(a, std::to_string(bestMetric->significantPairs))
                 << " significantly separated pairs as the observers did";
        html << ".</li>\n";
    } else if (!conditionMetrics.empty()) {
        html << "<li>" << h(block.name) << ": too few conditions with metric values for a correlation.</li>\n";
    }
}

// Findings (generated).
void writeFindings(std::ostringstream& html, const ReportData& r) {
    const scaling::Analysis& analysis = r.scale.analysis;
    const int included = r.participants.included, excluded = r.participants.excluded();
    html << "<h2 id=\"findings\">Findings</h2><ul class=\"findings\">\n";
    html << "<li>" << linked("participants", std::to_string(included)) << " observers analysed";
    if (excluded > 0)
        html << "; " << linked("participants", std::to_string(excluded)) << " excluded (reasons in the table)";
    html << ".</li>\n";
    for (const scaling::BlockAnalysis& block : analysis.blocks) {
        writeScaleFinding(html, analysis, block);
        writeMetricFinding(html, r, block);
    }
    if (r.metrics.conditions.empty())
        html << "<li>No image metrics: the stimulus set has no reference render for the study's blocks (add a "
                "<code>[[reference]]</code> to the set's spec, or give <code>--metrics DIR</code>).</li>\n";
    html << "</ul>\n";
}

// The Gaussian prior's strength on each score, which grows with the number of conditions m (τ·m); empty for pwcmp's.
std::string priorStrengthText(const scaling::Analysis& analysis) {
    int conditions = 0;
    for (const auto& block : analysis.blocks)
        conditions = std::max(conditions, static_cast<int>(block.conditions.size()));
    const double precision = scaling::priorPrecisionPerScore(analysis.options.fit, conditions);
    if (!std::isfinite(precision)) return "";
    return " (precision " + num(analysis.options.fit.priorPrecision, 3) +
           " JOD⁻² on every difference, so τ·m = " + num(precision, 3) + " JOD⁻² on each of the " +
           std::to_string(conditions) + " scores: sd " + num(1.0 / std::sqrt(precision), 1) +
           " JOD, stronger with more conditions)";
}

void writeDesign(std::ostringstream& html, const ReportData& r) {
    const experiments::StudyDefinition& definition = r.definition;
    const experiments::StudyDesign& design = definition.design;
    const scaling::Analysis& analysis = r.scale.analysis;
    html << "<h2 id=\"design\">Design</h2><table><tbody>"
         << "<tr><th class=\"l\">Task</th><td class=\"l\">two-alternative forced choice, side by side"
         << (design.showReference ? ", with the reference shown above the pair" : "") << "</td></tr>"
         << "<tr><th class=\"l\">Condition factor</th><td class=\"l\">" << h(design.conditionFactor) << "</td></tr>"
         << "<tr><th class=\"l\">Blocks</th><td class=\"l\">";
    for (std::size_t b = 0; b < definition.blocks.size(); ++b)
        html << (b ? "; " : "") << h(definition.blocks[b].name) << " (" << definition.blocks[b].conditions.size()
             << " conditions, " << definition.blocks[b].pairs.size() << " pairs)";
    html << "</td></tr><tr><th class=\"l\">Repetitions per pair</th><td class=\"l\">" << design.repetitions
         << " (both left/right orders)</td></tr>"
         << "<tr><th class=\"l\">Trials per participant</th><td class=\"l\">" << definition.testTrialCount()
         << " test, " << definition.repeatTrialCount() << " repeat, " << definition.catchTrialCount() << " catch, "
         << design.practiceTrials << " practice (not analysed)</td></tr>"
         << "<tr><th class=\"l\">Seed</th><td class=\"l\">" << design.seed << "</td></tr>"
         << "<tr><th class=\"l\">Design / manifest sha256</th><td class=\"l\"><code>"
         << h(r.store.meta("design_sha256").substr(0, 16)) << "…</code> / <code>"
         << h(r.store.meta("manifest_sha256").substr(0, 16)) << "…</code></td></tr>"
         << "<tr><th class=\"l\">Analysis</th><td class=\"l\">Thurstone Case V in JOD (1 JOD = 75 % preference), "
         << h(scaling::priorName(analysis.options.fit.prior)) << " prior" << priorStrengthText(analysis) << ", "
         << h(analysis.blocks.empty() ? std::string("—") : analysis.blocks.front().intervalMethod) << " intervals ("
         << r.options.bootstrapSamples << " resamples, " << num(100.0 * r.scale.options.bootstrap.level, 0)
         << " %), pairwise tests " << h(scaling::correctionName(analysis.options.correction)) << "-corrected</td></tr>"
         << "</tbody></table>\n";
}

void writeParticipants(std::ostringstream& html, const ReportData& r) {
    const Participants& p = r.participants;
    const int included = p.included, excluded = p.excluded();
    html << "<h2 id=\"participants\">Participants</h2><p>" << p.observers.size() << " joined, " << included
         << " analysed, " << excluded << " excluded. Exclusion rule (decided before the study, "
         << "as the protocol recommends): more than one failed catch trial in four, or no answers. Screening "
         << "(held-out log-likelihood per trial, low outliers by the inter-quartile rule) is reported, not used to "
         << "exclude.</p>\n<table><thead><tr><th class=\"l\">observer</th><th>answered</th><th>catch correct</th>"
            "<th>held-out log-lik./trial</th><th class=\"l\">screening</th><th "
            "class=\"l\">status</th></tr></thead><tbody>\n";
    for (const Observer& o : p.observers)
        html << "<tr><td class=\"l\">" << h(o.label) << "</td><td>" << o.answered << " / " << o.total << "</td><td>"
             << o.catchCorrect << " / " << o.catchAnswered << "</td><td>" << num(o.heldOutPerTrial, 3)
             << "</td><td class=\"l\">"
             << (o.excluded        ? "—"
                 : o.screeningFlag ? "low outlier (flagged)"
                                   : "ok")
             << "</td><td class=\"l\">" << (o.excluded ? "excluded: " + h(o.reason) : std::string("included"))
             << "</td></tr>\n";
    html << "</tbody></table>\n<p><strong>Viewing conditions.</strong> Recorded per answer by the browser"
         << (r.simulated.empty() ? std::string()
                                 : std::string(" (the simulated observers report a fixed 1920×1080 viewport; nobody "
                                               "looked at a screen)"))
         << ": viewports ";
    {
        int shown = 0;
        for (const auto& [w, hgt] : p.viewports) {
            if (shown++ == 6) {
                html << ", …";
                break;
            }
            html << (shown > 1 ? ", " : "") << w << "×" << hgt;
        }
        if (p.viewports.empty()) html << "—";
        html << "; device pixel ratio ";
        shown = 0;
        for (double ratio : p.pixelRatios) html << (shown++ ? ", " : "") << num(ratio, 2);
        if (p.pixelRatios.empty()) html << "—";
    }
    html << ". Images are shown at one image pixel per device pixel. Display, room lighting and viewing distance are "
            "not stored in the study file; see the lab notes.</p>\n";
}

void writeStimuli(std::ostringstream& html, const ReportData& r) {
    const experiments::StudyDesign& design = r.definition.design;
    auto& imagesOfBlock = r.stimuli.imagesOfBlock;
    auto& cropOfBlock = r.stimuli.cropOfBlock;
    auto& referenceOfBlock = r.stimuli.referenceOfBlock;
    html << "<h2 id=\"stimuli\">Stimuli</h2><p class=\"note\">Click a thumbnail for the image at full size (1:1). "
            "Crops: the window where the conditions differ most, enlarged 2× without smoothing.</p>\n";
    for (const experiments::StudyBlock& block : r.definition.blocks) {
        html << "<h3>" << h(block.name) << "</h3><div class=\"thumbs\">";
        if (referenceOfBlock.count(block.name)) {
            const ConditionImages& image = referenceOfBlock[block.name];
            html << "<figure><a href=\"" << h(image.png) << "\"><img src=\"" << h(image.png)
                 << "\" alt=\"reference\" loading=\"eager\"></a><figcaption><strong>reference</strong> ("
                 << (design.showReference ? "shown above each pair" : "not shown to observers") << ") · "
                 << h(image.stimulus) << "</figcaption></figure>";
        }
        for (const ConditionImages& image : imagesOfBlock[block.name])
            html << "<figure><a href=\"" << h(image.png) << "\"><img src=\"" << h(image.png) << "\" alt=\""
                 << h(image.condition) << "\" loading=\"eager\"></a><figcaption><strong>" << h(image.condition)
                 << "</strong> · " << h(image.stimulus) << "</figcaption></figure>";
        html << "</div>\n";
        const Crop& crop = cropOfBlock[block.name];
        if (!crop.files.empty()) {
            html << "<p class=\"note\">Window " << crop.window.width << "×" << crop.window.height << " at ("
                 << crop.window.x << ", " << crop.window.y << ").</p><div class=\"thumbs crops\">";
            for (const ConditionImages& image : imagesOfBlock[block.name])
                html << "<figure><img src=\"" << h(crop.files.at(image.condition)) << "\" alt=\"crop of "
                     << h(image.condition) << "\"><figcaption>" << h(image.condition) << "</figcaption></figure>";
            html << "</div>\n";
        }
    }
}

// Pairwise significance matrix of one block, rows and columns in `order`.
void writePairMatrix(std::ostringstream& html, const scaling::BlockAnalysis& block, const std::vector<int>& order) {
    std::map<std::pair<int, int>, const scaling::PairTest*> pairOf;
    for (const scaling::PairTest& pair : block.pairs) pairOf[{pair.test.first, pair.test.second}] = &pair;
    html << "<table id=\"pairs-" << slug(block.name) << "\"><thead><tr><th class=\"l\">row − column</th>";
    for (int j : order) html << "<th>" << h(block.conditions[static_cast<std::size_t>(j)]) << "</th>";
    html << "</tr></thead><tbody>";
    for (int i : order) {
        html << "<tr><th class=\"l\">" << h(block.conditions[static_cast<std::size_t>(i)]) << "</th>";
        for (int j : order) {
            if (i == j) {
                html << "<td class=\"diag\"></td>";
                continue;
            }
            auto found = pairOf.find({std::min(i, j), std::max(i, j)});
            if (found == pairOf.end()) {
                html << "<td class=\"ns\">—</td>";
                continue;
            }
            const scaling::PairTest& pair = *found->second;
            double difference = block.thurstone.scores[i] - block.thurstone.scores[j];
            html << "<td class=\"" << (pair.significant ? "sig" : "ns")
                 << "\" title=\"adjusted p = " << num(pair.adjustedPValue, 4) << "\">" << num(difference)
                 << "<br><span class=\"note\">p=" << num(pair.adjustedPValue, 3) << (pair.comparisons > 0 ? "" : " n/c")
                 << "</span></td>";
        }
        html << "</tr>";
    }
    html << "</tbody></table>\n";
}

// Where a block mixes renderers (skinlab's rasterizer, EEVEE, Cycles): a one-line warning, and each SSS
// condition's effect against its own renderer's no-SSS baseline in JOD.
void writeRendererEffects(std::ostringstream& html, const ReportData& r, const scaling::BlockAnalysis& block) {
    std::map<std::string, nlohmann::json> resolvedOf;
    for (const nlohmann::json& s : r.storedManifest.value("stimuli", nlohmann::json::array()))
        resolvedOf[s.value("id", "")] = s.value("resolved", nlohmann::json::object());
    const auto images = r.stimuli.imagesOfBlock.find(block.name);
    if (images == r.stimuli.imagesOfBlock.end()) return;
    std::vector<std::string> conditions;
    std::vector<nlohmann::json> resolved;
    std::vector<double> scores;
    for (std::size_t c = 0; c < block.conditions.size(); ++c) {
        const auto image = std::find_if(images->second.begin(), images->second.end(),
                                        [&](const ConditionImages& i) { return i.condition == block.conditions[c]; });
        if (image == images->second.end() || (c < block.measured.size() && !block.measured[c])) continue;
        conditions.push_back(block.conditions[c]);
        resolved.push_back(resolvedOf[image->stimulus]);
        scores.push_back(block.thurstone.scores[static_cast<Eigen::Index>(c)]);
    }
    const scaling::RendererEffects effects =
        scaling::sssEffectsWithinRenderers(block.name, conditions, resolved, scores);
    if (!effects.warning) return;
    spdlog::warn("report: {}", *effects.warning);
    html << "<p class=\"note warn\">Warning: " << h(*effects.warning) << ".</p>";
    if (effects.effects.empty()) return;
    html << "<table><thead><tr><th class=\"l\">SSS effect within each renderer</th><th class=\"l\">renderer</th>"
            "<th class=\"l\">baseline (no SSS)</th><th>JOD − baseline</th></tr></thead><tbody>";
    for (const scaling::SssEffect& effect : effects.effects)
        html << "<tr><td class=\"l\">" << h(effect.condition) << "</td><td class=\"l\">" << h(effect.renderer)
             << "</td><td class=\"l\">" << h(effect.baseline) << "</td><td>" << num(effect.effect) << "</td></tr>";
    html << "</tbody></table>";
    if (!effects.withoutBaseline.empty()) {
        std::string names;
        for (const std::string& name : effects.withoutBaseline) names += (names.empty() ? "" : ", ") + name;
        html << "<p class=\"note\">Without a no-SSS baseline of their renderer in this block: " << h(names) << ".</p>";
    }
}

void writeScale(std::ostringstream& html, const ReportData& r) {
    html << "<h2 id=\"scale\">Perceptual scale (JOD)</h2><p class=\"note\">Higher = chosen more often. Bars: "
         << num(100.0 * r.scale.options.bootstrap.level, 0) << " % confidence intervals; bars running off the axis end "
         << "in a red arrow. Conditions sorted by score here (design order elsewhere). Matrix: row − column in JOD; "
            "green = significant after correction, grey = not; n/c = never compared directly.</p>\n";
    for (const scaling::BlockAnalysis& block : r.scale.analysis.blocks) {
        std::vector<int> order(block.conditions.size());
        std::iota(order.begin(), order.end(), 0);
        std::sort(order.begin(), order.end(),
                  [&](int a, int b) { return block.thurstone.scores[a] > block.thurstone.scores[b]; });
        std::vector<IntervalPoint> points;
        for (int i : order)
            points.push_back({block.conditions[static_cast<std::size_t>(i)], block.thurstone.scores[i], block.low[i],
                              block.high[i]});
        html << "<h3 id=\"scale-" << slug(block.name) << "\">" << h(block.name) << " (" << block.observers.size()
             << " observers)</h3>" << scaleSvg(points);
        html << "<table><thead><tr><th class=\"l\">condition</th><th>JOD</th><th>low</th><th>high</th><th>SE</th></tr>"
                "</thead><tbody>";
        for (int i : order) {
            // A condition no pair of which was compared has no score: the prior alone put it at the mean.
            const bool measured = std::any_of(block.pairs.begin(), block.pairs.end(), [&](const auto& pair) {
                return (pair.test.first == i || pair.test.second == i) && pair.comparisons > 0;
            });
            // Where the interval fell back (percentile ∪ profile), the bootstrap SE means nothing: not shown.
            const bool fallback = static_cast<std::size_t>(i) < block.intervalFlags.size() &&
                                  block.intervalFlags[static_cast<std::size_t>(i)].fallback;
            html << "<tr><td class=\"l\">" << h(block.conditions[static_cast<std::size_t>(i)]) << "</td>";
            if (!measured) html << "<td colspan=\"4\" class=\"l\">not measured (never compared)</td></tr>";
            else
                html << "<td>" << num(block.thurstone.scores[i]) << "</td><td>" << num(block.low[i]) << "</td><td>"
                     << num(block.high[i]) << (fallback ? " †" : "") << "</td><td>"
                     << (fallback ? std::string("—") : num(block.standardError[i])) << "</td></tr>";
        }
        if (std::any_of(block.intervalFlags.begin(), block.intervalFlags.end(),
                        [](const auto& f) { return f.fallback; }))
            html << "<p class=\"note\">† interval from the hull of the percentile and profile-likelihood intervals "
                    "(the studentized bootstrap is degenerate there); no standard error is given for it.</p>";
        html << "</tbody></table>";
        for (const std::string& warning : block.warnings) html << "<p class=\"note\">Note: " << h(warning) << "</p>";
        writeRendererEffects(html, r, block);
        writePairMatrix(html, block, order);
    }
}

// Predicted and measured (when the stimulus set recorded predictions).
void writePredictions(std::ostringstream& html, const ReportData& r) {
    std::vector<std::pair<std::string, double>> calibrated; // (observer, pixels per degree) from the card calibration
    if (!r.predictions.empty())
        for (const experiments::SessionViewing& session : r.store.viewingConditions())
            if (session.viewing && session.viewing->pixelsPerDegree &&
                std::none_of(calibrated.begin(), calibrated.end(),
                             [&](const auto& c) { return c.first == session.observer; }))
                calibrated.emplace_back(session.observer, *session.viewing->pixelsPerDegree);
    html << predictionSectionHtml(r.predictions, r.predictionDisplay,
                                  participantPredictions(r.storedManifest, r.stimuliFolder, calibrated),
                                  static_cast<int>(r.simulated.size()));
}

// One sentence naming the one viewing geometry of the metrics and what they were computed on.
std::string viewingGeometry(const nlohmann::json& metricsJson) {
    const nlohmann::json settings = metricsJson.value("settings", nlohmann::json::object());
    std::ostringstream text;
    if (settings.contains("viewing")) {
        const nlohmann::json& v = settings["viewing"];
        text << "Viewing geometry: display " << h(v.value("display", std::string("?"))) << ", "
             << num(v.value("pixels_per_degree", NAN), 1) << " pixels per degree (FLIP and ColorVideoVDP alike; from "
             << h(v.value("source", std::string("?"))) << ")";
        const nlohmann::json referred = settings.value("display_referred", nlohmann::json::object());
        if (referred.contains("input"))
            text << "; display-referred scores on " << h(referred["input"].get<std::string>());
        text << ".";
    } else {
        // metrics.json of an earlier skinlab: FLIP and ColorVideoVDP had their own geometries.
        text << "FLIP at " << num(settings.contains("flip") ? settings["flip"].value("pixels_per_degree", NAN) : NAN, 1)
             << " pixels per degree, ColorVideoVDP at "
             << num(settings.contains("cvvdp") ? settings["cvvdp"].value("pixels_per_degree", NAN) : NAN, 1) << ".";
    }
    return text.str();
}

void writeObjectiveErrors(std::ostringstream& html, const ReportData& r) {
    const Metrics& m = r.metrics;
    const std::vector<agreement::ConditionMetrics>& conditionMetrics = m.conditions;
    auto& imagesOfBlock = r.stimuli.imagesOfBlock;
    html << "<h2 id=\"metrics\">Objective errors against the reference</h2>\n";
    if (conditionMetrics.empty()) {
        html << "<p>Not available: the stimulus set has no reference render for the study's blocks.</p>\n";
    } else {
        html << "<p class=\"note\">Each stimulus against its block's reference render";
        if (!m.referencePng.empty()) {
            html << " (";
            int k = 0;
            for (const auto& [block, reference] : m.referencePng)
                html << (k++ ? ", " : "") << h(block) << ": " << h(reference);
            html << ")";
        }
        html << ". ΔE00 and FLIP: lower is better; PSNR, SSIM and ColorVideoVDP (10 = indistinguishable): higher is "
                "better. Heat maps: each on its own colour scale (printed under it). Bands: mean ΔE00 in the halo, "
                "bleed, spill and interior bands (docs/metrics.md). "
             << viewingGeometry(m.json) << "</p>\n";
        for (const experiments::StudyBlock& block : r.definition.blocks) {
            html << "<h3 id=\"metrics-" << slug(block.name) << "\">" << h(block.name) << "</h3><table><thead><tr>"
                 << "<th class=\"l\">condition</th><th>PSNR (dB)</th><th>SSIM</th><th>mean ΔE00</th><th>p95 ΔE00</th>"
                    "<th>mean FLIP</th><th>skin FLIP</th><th>halo ΔE00</th><th>bleed ΔE00</th><th>spill ΔE00</th>"
                    "<th>interior ΔE00</th><th>ColorVideoVDP (JOD)</th></tr></thead><tbody>";
            for (const agreement::ConditionMetrics& row : conditionMetrics) {
                if (row.block != block.name) continue;
                auto v = [&](const char* key) { return row.values.at(key); };
                html << "<tr><td class=\"l\">" << h(row.condition) << "</td><td>" << num(v("image.psnr_db"))
                     << "</td><td>" << num(v("image.ssim"), 4) << "</td><td>" << num(v("image.delta_e00_mean"), 3)
                     << "</td><td>" << num(v("image.delta_e00_p95"), 3) << "</td><td>" << num(v("image.flip_mean"), 4)
                     << "</td><td>" << num(v("skin.flip_mean"), 4) << "</td><td>"
                     << num(v("bands.halo.delta_e00_mean"), 3) << "</td><td>" << num(v("bands.bleed.delta_e00_mean"), 3)
                     << "</td><td>" << num(v("bands.spill.delta_e00_mean"), 3) << "</td><td>"
                     << num(v("bands.interior.delta_e00_mean"), 3) << "</td><td>" << num(v("cvvdp_jod"), 2)
                     << "</td></tr>";
            }
            html << "</tbody></table><div class=\"thumbs heat\">";
            for (const ConditionImages& image : imagesOfBlock[block.name]) {
                // Each map on its own colour scale (from its data), printed under it.
                for (const auto& [of, what] : {std::pair{&m.heatmapOf, "ΔE00"}, std::pair{&m.flipHeatmapOf, "FLIP"},
                                               std::pair{&m.cvvdpHeatmapOf, "ColorVideoVDP (JOD loss)"}}) {
                    const auto found = of->find(image.stimulus);
                    if (found == of->end()) continue;
                    const auto scale = m.scaleOf.find(found->second);
                    html << "<figure><a href=\"" << h(found->second) << "\"><img src=\"" << h(found->second)
                         << "\" alt=\"" << what << " of " << h(image.condition) << "\"></a><figcaption>" << what << ", "
                         << h(image.condition)
                         << (scale == m.scaleOf.end() ? std::string() : ", scale " + scale->second)
                         << "</figcaption></figure>";
                }
            }
            html << "</div>\n";
        }
    }
}

void writeAgreement(std::ostringstream& html, const ReportData& r) {
    const std::vector<agreement::ConditionMetrics>& conditionMetrics = r.metrics.conditions;
    const agreement::AgreementOptions& agreementOptions = r.agreementOptions;
    const agreement::AgreementResult& agreementResult = r.agreement;
    html << "<h2 id=\"agreement\">Metrics against perception</h2>\n";
    if (conditionMetrics.empty()) {
        html << "<p>Not available without image metrics.</p>\n";
    } else {
        html
            << "<p class=\"note\">Correlation of each metric with the JOD scale over the block's conditions (raw sign: "
               "an error metric that agrees with the observers correlates negatively). The conditions are the sample "
               "(n per row). Intervals: "
            << num(100.0 * agreementOptions.level, 0)
            << " % Fisher z over the conditions (Spearman: Bonett–Wright), widened by the variance of a bootstrap "
               "over observers ("
            << agreementOptions.samples << " resamples, the scale re-fitted each time); below "
            << agreement::kFewConditions
            << " conditions Spearman's interval also spans its exact interval, so that it excludes 0 only where the "
               "exact p does. p: no association, exact over every ordering of up to 8 "
               "conditions; Holm: corrected over the block's metrics. Pairs: of the pairs the "
               "observers separated significantly, how many the metric orders the same way (ties count as not). "
               "Also in agreement.csv and agreement.json.</p>\n";
        static const std::vector<std::string> plotted = {"image.psnr_db",        "image.ssim",
                                                         "image.delta_e00_mean", "image.flip_mean",
                                                         "skin.flip_mean",       "bands.halo.delta_e00_mean"};
        for (const scaling::BlockAnalysis& block : r.scale.analysis.blocks) {
            html << "<h3 id=\"agreement-" << slug(block.name) << "\">" << h(block.name) << "</h3><table><thead><tr>"
                 << "<th class=\"l\">metric</th><th>better</th><th>n</th><th>Pearson r</th><th>95 % interval</th>"
                    "<th>Spearman ρ</th><th>95 % interval</th><th>p</th><th>p (Holm)</th><th>pairs ordered</th></tr>"
                    "</thead><tbody>";
            std::vector<const agreement::MetricAgreement*> shown;
            for (const agreement::MetricAgreement& row : agreementResult.rows) {
                if (row.block != block.name || row.conditions == 0) continue;
                shown.push_back(&row);
                html << "<tr><td class=\"l\">" << h(row.metric.label) << "</td><td>"
                     << (row.metric.higherIsBetter ? "higher" : "lower") << "</td><td>" << row.conditions << "</td><td>"
                     << num(row.pearson) << "</td><td>"
                     << correlationIntervalText(row.pearsonLow, row.pearsonHigh, row.conditions) << "</td><td>"
                     << num(row.spearman) << "</td><td>"
                     << correlationIntervalText(row.spearmanLow, row.spearmanHigh, row.conditions) << "</td><td>"
                     << num(row.spearmanP) << "</td><td>" << num(row.spearmanPHolm) << "</td><td>"
                     << (row.significantPairs
                             ? std::to_string(row.predictedPairs) + " / " + std::to_string(row.significantPairs)
                             : std::string("—"))
                     << "</td></tr>";
            }
            html << "</tbody></table><div class=\"scatters\">";
            for (const agreement::MetricAgreement* row : shown) {
                if (std::find(plotted.begin(), plotted.end(), row->metric.key) == plotted.end()) continue;
                std::vector<ScatterPoint> points;
                for (const agreement::ConditionMetrics& metricRow : conditionMetrics) {
                    if (metricRow.block != block.name) continue;
                    auto it = std::find(block.conditions.begin(), block.conditions.end(), metricRow.condition);
                    if (it == block.conditions.end()) continue;
                    auto i = static_cast<Eigen::Index>(it - block.conditions.begin());
                    points.push_back({metricRow.condition, metricRow.values.at(row->metric.key),
                                      block.thurstone.scores[i], block.low[i], block.high[i]});
                }
                html << "<figure>" << scatterSvg(points, row->metric.label) << "<figcaption>" << h(row->metric.label)
                     << ": r = " << num(row->pearson) << " "
                     << correlationIntervalText(row->pearsonLow, row->pearsonHigh, row->conditions)
                     << ", ρ = " << num(row->spearman) << "</figcaption></figure>";
            }
            html << "</div>\n";
        }
        for (const std::string& warning : agreementResult.warnings)
            html << "<p class=\"note\">Note: " << h(warning) << "</p>";
    }
}

// PDF through headless Chromium (a fresh profile in a temporary folder); empty when none was written.
fs::path writePdf(const ReportOptions& options, const fs::path& out) {
    const fs::path profile = fs::temp_directory_path() / ("skinlab-report-chromium-" + std::to_string(::getpid()));
    fs::remove_all(profile);
    const fs::path pdf = out / "report.pdf";
    const fs::path temp = out / (".report.pdf.tmp-" + std::to_string(::getpid()));
    // Chromium under coreutils' timeout (a hung browser ends the report without a PDF, not the program).
    const fs::path timeout = findProgram("timeout");
    const fs::path chromium = findProgram(options.chromium);
    int status = -1;
    if (!timeout.empty() && !chromium.empty()) {
        try {
            status = waitProcess(spawnProcess(
                timeout, {"180", chromium.string(), "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                          "--no-first-run", "--disable-background-networking", "--disable-component-update",
                          "--disable-sync", "--no-pdf-header-footer", "--user-data-dir=" + profile.string(),
                          "--print-to-pdf=" + temp.string(), "file://" + fs::absolute(out / "index.html").string()}));
        } catch (const RuntimeError& e) {
            spdlog::warn("report: {}", e.what());
        }
    }
    fs::remove_all(profile);
    std::error_code ec;
    if (status == 0 && fs::is_regular_file(temp, ec) && fs::file_size(temp, ec) > 0) {
        fs::rename(temp, pdf);
        return pdf;
    }
    fs::remove(temp, ec);
    spdlog::warn("report: no PDF ({} failed or is not installed; give --chromium PATH or --no-pdf)", options.chromium);
    return {};
}

} // namespace

ReportSummary writeStudyReport(const ReportOptions& options) {
    const auto started = std::chrono::steady_clock::now();
    if (!fs::is_regular_file(options.study)) throwInput(options.study.string(), "", "file not found");
    if (options.output.empty()) throwInput("-o", "", "required: the report folder");
    experiments::StudyStore store(options.study);
    const experiments::StudyDefinition& definition = store.definition();
    const std::vector<std::string> simulated = store.simulatedLabels();
    const fs::path stimuliFolder = options.stimuli.empty() ? fs::path(store.meta("stimuli_dir")) : options.stimuli;
    if (!fs::is_regular_file(stimuliFolder / "manifest.json"))
        throwInput((stimuliFolder / "manifest.json").string(), "",
                   "file not found (the study's stimulus folder; give --stimuli DIR if it moved)");
    if (!options.metrics.empty() && !fs::is_regular_file(options.metrics / "metrics.json"))
        throwInput((options.metrics / "metrics.json").string(), "",
                   "file not found (run `skinlab analyze metrics` first)");
    for (const experiments::StudyStimulus& s : definition.stimuli)
        if (!fs::is_regular_file(stimuliFolder / s.pngPath))
            throwInput((stimuliFolder / s.pngPath).string(), "", "file not found (stimulus " + s.id + ")");

    const fs::path out = options.output;
    ensureDirectory(out);

    Participants participants = readParticipants(store, options);
    const Scale scale = scaleStudy(participants, options, out);
    StimulusImages stimuli = copyStimuli(definition, stimuliFolder, out);
    const Metrics metrics = readMetrics(options, stimuliFolder, out, stimuli.conditionOfStimulus);
    agreement::AgreementOptions agreementOptions;
    agreementOptions.samples = options.bootstrapSamples;
    agreementOptions.seed = options.seed;
    const agreement::AgreementResult agreementResult = agreement::computeAgreement(
        scale.dataset, scale.analysis, metrics.conditions, scale.options.fit, agreementOptions);
    if (!metrics.conditions.empty()) {
        writeFileAtomic(out / "agreement.json", agreement::agreementJson(agreementResult).dump(2) + "\n");
        writeFileAtomic(out / "agreement.csv", agreement::agreementCsv(agreementResult));
    }
    // Predicted JOD (ColorVideoVDP, recorded by `stimuli build`) against the measured scale.
    const nlohmann::json storedManifest = nlohmann::json::parse(store.meta("manifest_json"));
    const std::vector<PredictionAgreement> predictions =
        predictionAgreement(definition, storedManifest, scale.analysis, &scale.dataset,
                            {options.bootstrapSamples, options.seed, scale.options.bootstrap.level, scale.options.fit});
    std::string predictionDisplay;
    for (const formats::ManifestEntry& s : storedManifestEntries(storedManifest))
        if (s.predicted && !s.predicted->display.empty()) predictionDisplay = s.predicted->display;

    const ReportData data{options,         store,          definition,  simulated,        stimuliFolder,
                          participants,    scale,          stimuli,     metrics,          agreementOptions,
                          agreementResult, storedManifest, predictions, predictionDisplay};
    std::ostringstream html;
    writeTitle(html, data);
    writeFindings(html, data);
    writeDesign(html, data);
    writeParticipants(html, data);
    writeStimuli(html, data);
    writeScale(html, data);
    writePredictions(html, data);
    writeObjectiveErrors(html, data);
    writeAgreement(html, data);
    html << "<p class=\"note\">Written by <code>skinlab report</code> from " << h(options.study.filename().string())
         << ". Tables: scale.json" << (metrics.conditions.empty() ? "" : ", agreement.csv, agreement.json")
         << (options.metrics.empty() && !metrics.folder.empty() ? ", metrics/" : "")
         << ".</p>\n</main></body></html>\n";
    writeFileAtomic(out / "index.html", html.str());

    ReportSummary summary;
    summary.html = out / "index.html";
    summary.observers = participants.included;
    summary.excluded = participants.excluded();
    summary.metrics = !metrics.conditions.empty();
    if (options.pdf) summary.pdf = writePdf(options, out);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    spdlog::info("report: written in {:.1f} s", seconds);
    return summary;
}

} // namespace skinlab::report
