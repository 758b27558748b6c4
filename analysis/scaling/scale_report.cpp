#include "analysis/scaling/scale_report.h"

#include "common/html.h"

#include "common/csv.h"
#include "analysis/scaling/plots.h"
#include "common/files.h"
#include "common/version.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace skinlab::analysis::scaling {
namespace {

std::string number(double value, int digits = 6) {
    if (!std::isfinite(value)) return "";
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    return buffer;
}

std::string fixed(double value, int decimals) {
    if (!std::isfinite(value)) return "–";
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
    return buffer;
}

nlohmann::json finite(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

std::string base64(const std::string& bytes) {
    static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t k = 0;
    for (; k + 2 < bytes.size(); k += 3) {
        const unsigned v = (static_cast<unsigned char>(bytes[k]) << 16) |
                           (static_cast<unsigned char>(bytes[k + 1]) << 8) | static_cast<unsigned char>(bytes[k + 2]);
        out += {alphabet[(v >> 18) & 63], alphabet[(v >> 12) & 63], alphabet[(v >> 6) & 63], alphabet[v & 63]};
    }
    if (k + 1 == bytes.size()) {
        const unsigned v = static_cast<unsigned char>(bytes[k]) << 16;
        out += {alphabet[(v >> 18) & 63], alphabet[(v >> 12) & 63], '=', '='};
    } else if (k + 2 == bytes.size()) {
        const unsigned v =
            (static_cast<unsigned char>(bytes[k]) << 16) | (static_cast<unsigned char>(bytes[k + 1]) << 8);
        out += {alphabet[(v >> 18) & 63], alphabet[(v >> 12) & 63], alphabet[(v >> 6) & 63], '='};
    }
    return out;
}

// Per-interval method: the block's method unless the interval fell back (bootstrap.h).
std::string scoreMethod(const BlockAnalysis& block, size_t i) {
    return i < block.intervalFlags.size() && block.intervalFlags[i].fallback ? "percentile+profile"
                                                                             : block.intervalMethod;
}
std::string pairMethod(const BlockAnalysis& block, const PairTest& pair) {
    return pair.test.diagnosis.fallback ? "percentile+profile" : block.intervalMethod;
}
std::string joined(const std::vector<std::string>& values, const char* separator) {
    std::string out;
    for (const std::string& value : values) out += (out.empty() ? "" : separator) + value;
    return out;
}
std::vector<std::string> scoreReasons(const BlockAnalysis& block, size_t i) {
    return i < block.intervalFlags.size() ? block.intervalFlags[i].reasons : std::vector<std::string>{};
}

bool measured(const BlockAnalysis& block, size_t i) { return i >= block.measured.size() || block.measured[i]; }
bool measured(const BlockAnalysis& block, const PairTest& pair) {
    return measured(block, static_cast<size_t>(pair.test.first)) &&
           measured(block, static_cast<size_t>(pair.test.second));
}
// A value of a measured condition (or pair), null/empty for one never compared.
nlohmann::json measuredJson(bool isMeasured, double value) { return isMeasured ? finite(value) : nlohmann::json(); }
std::string measuredNumber(bool isMeasured, double value, int digits) {
    return isMeasured ? number(value, digits) : "";
}

bool scorePriorDriven(const BlockAnalysis& block, size_t i) {
    return i < block.intervalFlags.size() && block.intervalFlags[i].priorDriven;
}

std::string scoreBound(const BlockAnalysis& block, size_t i) {
    return i < block.intervalFlags.size() ? block.intervalFlags[i].bound : std::string("two-sided");
}
// An interval as text: "[a, b]", "≥ a" (bound from below only), "≤ b", or "not measured".
std::string intervalText(double low, double high) {
    if (std::isfinite(low) && std::isfinite(high)) return "[" + fixed(low, 3) + ", " + fixed(high, 3) + "]";
    if (std::isfinite(low)) return "at least " + fixed(low, 3);
    if (std::isfinite(high)) return "at most " + fixed(high, 3);
    return "not measured";
}
std::string priorText(const FitOptions& fit) {
    if (fit.prior == Prior::Pwcmp) return "pwcmp's prior (pw_scale's default)";
    return "Gaussian prior of precision " + number(fit.priorPrecision, 6) + " JOD⁻² on every difference";
}

std::string plotName(size_t index, const std::string& kind, const std::string& block) {
    char prefix[16];
    std::snprintf(prefix, sizeof prefix, "%02zu-", index + 1); // the index keeps names unique after slugging
    return "plots/" + kind + "_" + prefix + blockSlug(block) + ".png";
}

// The settings the analysis ran with.
nlohmann::json settingsJson(const AnalysisOptions& o) {
    return {
        {"model", "thurstone-case-v"},
        {"sigma", kThurstoneSigma},
        {"unit", "JOD (1 JOD = 75 % preference), mean of each block's scores = 0"},
        {"prior", priorName(o.fit.prior)},
        {"prior_precision", o.fit.prior == Prior::Gaussian ? nlohmann::json(o.fit.priorPrecision) : nlohmann::json()},
        {"interval", o.intervals == IntervalMethod::percentile
                         ? "percentile bootstrap over observers (pwcmp's pw_scale_bootstrp), bootstrap p-values"
                     : o.intervals == IntervalMethod::profile ? "profile-posterior intervals and score tests"
                     : o.intervals == IntervalMethod::bootstrapAndProfile
                         ? "union of the symmetric studentized bootstrap over observers and the profile-posterior "
                           "interval; a pair's p-value the larger of the bootstrap and score tests' (active designs)"
                         : "symmetric studentized bootstrap over observers, cluster-robust SE; where the "
                           "studentization is degenerate (flagged per interval) the hull of the percentile "
                           "and the profile-posterior intervals, with a score test; ends the data do not set are "
                           "open (bound)"},
        {"intervals", intervalsName(o.intervals)},
        {"intervals_reason", o.intervalReason},
        {"level", o.bootstrap.level},
        {"bootstrap_samples", o.bootstrap.samples},
        {"seed", o.bootstrap.seed},
        {"correction", correctionName(o.correction)},
        {"alpha", o.alpha},
        {"screening", "leave-one-out held-out log-likelihood per trial, low outliers by Q1 - w*IQR"},
        {"screening_whisker", o.screeningWhisker},
        {"pwcmp_outliers", o.pwcmpOutliers}};
}

// The block's comparison counts, row by row.
nlohmann::json countsJson(const BlockAnalysis& block) {
    nlohmann::json counts = nlohmann::json::array();
    for (Eigen::Index i = 0; i < block.counts.rows(); ++i) {
        std::vector<double> row(block.counts.cols());
        for (Eigen::Index j = 0; j < block.counts.cols(); ++j) row[j] = block.counts(i, j);
        counts.push_back(row);
    }
    return counts;
}

// b["scores"]: one entry per condition (absent when the block has none).
void addScores(nlohmann::json& b, const BlockAnalysis& block) {
    for (size_t i = 0; i < block.conditions.size(); ++i) {
        const auto k = static_cast<Eigen::Index>(i);
        const bool is = measured(block, i);
        b["scores"].push_back({{"condition", block.conditions[i]},
                               {"measured", is},
                               {"jod", measuredJson(is, block.thurstone.scores[k])},
                               {"standard_error", measuredJson(is, block.standardError[k])},
                               {"ci_low", measuredJson(is, block.low[k])},
                               {"ci_high", measuredJson(is, block.high[k])},
                               {"bound", scoreBound(block, i)},
                               {"prior_driven", scorePriorDriven(block, i)},
                               {"interval_method", scoreMethod(block, i)},
                               {"fallback_reasons", scoreReasons(block, i)},
                               {"percentile_low", measuredJson(is, block.percentileLow[k])},
                               {"percentile_high", measuredJson(is, block.percentileHigh[k])},
                               {"bradley_terry_jod", measuredJson(is, block.bradleyTerry.scores[k])},
                               {"bradley_terry_standard_error", measuredJson(is, block.bradleyTerryStandardError[k])}});
    }
}

// The design's flags: connectedness, its components, MLE existence, unanimous pairs.
nlohmann::json flagsJson(const BlockAnalysis& block) {
    nlohmann::json components = nlohmann::json::array();
    for (const auto& component : block.components) {
        std::vector<std::string> names;
        for (int c : component) names.push_back(block.conditions[c]);
        components.push_back(names);
    }
    nlohmann::json unanimous = nlohmann::json::array();
    for (const auto& [i, j] : block.unanimousPairs) unanimous.push_back({block.conditions[i], block.conditions[j]});
    return {{"connected", block.components.size() == 1},
            {"components", components},
            {"mle_exists", block.mleExists},
            {"unanimous_pairs", unanimous}};
}

// Each pair's difference, interval and (corrected) test.
nlohmann::json pairsJson(const BlockAnalysis& block) {
    nlohmann::json pairs = nlohmann::json::array();
    for (const PairTest& pair : block.pairs)
        pairs.push_back({{"condition_A", block.conditions[pair.test.first]},
                         {"condition_B", block.conditions[pair.test.second]},
                         {"difference_jod", measuredJson(measured(block, pair), pair.test.difference)},
                         {"standard_error", finite(pair.test.standardError)},
                         {"ci_low", finite(pair.test.low)},
                         {"ci_high", finite(pair.test.high)},
                         {"bound", pair.test.diagnosis.bound},
                         {"prior_driven", pair.test.diagnosis.priorDriven},
                         {"comparisons", pair.comparisons},
                         {"interval_method", pairMethod(block, pair)},
                         {"fallback_reasons", pair.test.diagnosis.reasons},
                         {"p_value", pair.test.pValue},
                         {"p_adjusted", pair.adjustedPValue},
                         {"significant", pair.significant}});
    return pairs;
}

// The left/right bias of the block (null values where it is not measured).
nlohmann::json sideBiasJson(const BlockAnalysis& block) {
    return {{"available", block.sideBias.available},
            {"trials", block.sideBias.trials},
            {"left_rate", block.sideBias.available ? nlohmann::json(block.sideBias.leftRate) : nlohmann::json()},
            {"left_chosen", block.sideBias.available ? nlohmann::json(block.sideBias.leftChosen) : nlohmann::json()},
            // null where every answer was on one side (no finite estimate; see left_rate and p_value)
            {"bias_jod", block.sideBias.available ? finite(block.sideBias.bias) : nlohmann::json()},
            {"standard_error", block.sideBias.available ? finite(block.sideBias.standardError) : nlohmann::json()},
            {"test", "exact binomial, left rate = 1/2, two-sided"},
            {"p_value", block.sideBias.available ? nlohmann::json(block.sideBias.pValue) : nlohmann::json()}};
}

// Each observer's fit and consistency within the block.
nlohmann::json observerStatsJson(const BlockAnalysis& block) {
    nlohmann::json stats = nlohmann::json::array();
    for (size_t k = 0; k < block.observerStats.size(); ++k) {
        const ObserverInBlock& s = block.observerStats[k];
        stats.push_back({{"observer", block.observers[k]},
                         {"trials", s.trials},
                         {"held_out_loglik_per_trial", s.trials > 0 && block.observers.size() > 1
                                                           ? nlohmann::json(s.heldOutLogLikelihood / s.trials)
                                                           : nlohmann::json()},
                         {"complete", s.consistency.complete},
                         {"circular_triads",
                          s.consistency.complete ? nlohmann::json(s.consistency.circularTriads) : nlohmann::json()},
                         {"zeta", s.consistency.zeta ? nlohmann::json(*s.consistency.zeta) : nlohmann::json()}});
    }
    return stats;
}

// The prior's strength on this block's scores (the Gaussian prior strengthens with the number of conditions).
nlohmann::json priorJson(const BlockAnalysis& block, const FitOptions& fit) {
    const double precision = priorPrecisionPerScore(fit, static_cast<int>(block.conditions.size()));
    if (!std::isfinite(precision)) return {{"name", priorName(fit.prior)}, {"data_dependent", true}};
    return {{"name", priorName(fit.prior)},
            {"precision_per_difference", fit.priorPrecision},
            {"precision_per_score", precision},
            {"sd_per_score_jod", 1.0 / std::sqrt(precision)}};
}

// One block of the analysis: data, fit, scores, flags, pairs, side bias and observers.
nlohmann::json blockJson(const BlockAnalysis& block, const FitOptions& fit) {
    nlohmann::json b;
    b["name"] = block.name;
    b["conditions"] = block.conditions;
    b["prior"] = priorJson(block, fit);
    b["observers"] = static_cast<int>(block.observers.size());
    b["counts"] = countsJson(block);
    b["interval_method"] = block.intervalMethod;
    b["bootstrap_samples"] = block.bootstrapSamples;
    b["fit"] = {{"converged", block.thurstone.converged},
                {"iterations", block.thurstone.iterations},
                {"log_likelihood", block.thurstone.logLikelihood},
                {"bradley_terry_log_likelihood", block.bradleyTerry.logLikelihood}};
    addScores(b, block);
    b["flags"] = flagsJson(block);
    b["pairs"] = pairsJson(block);
    b["kendall_u"] = block.kendallU ? nlohmann::json(*block.kendallU) : nlohmann::json();
    b["side_bias"] = sideBiasJson(block);
    b["observer_stats"] = observerStatsJson(block);
    b["warnings"] = block.warnings;
    return b;
}

// Every observer's summary across blocks.
nlohmann::json observersJson(const Analysis& analysis) {
    nlohmann::json observers = nlohmann::json::array();
    for (const ObserverSummary& s : analysis.observers)
        observers.push_back(
            {{"observer", s.observer},
             {"trials", s.trials},
             {"held_out_loglik_per_trial", finite(s.heldOutPerTrial)},
             {"flagged", s.flagged},
             {"pwcmp_log10_likelihood_per_pair", finite(s.pwcmpLogLikelihood)},
             {"pwcmp_dist_l", finite(s.pwcmpDistance)},
             {"pwcmp_outlier", std::isnan(s.pwcmpDistance) ? nlohmann::json() : nlohmann::json(s.pwcmpOutlier)},
             {"catch_trials", s.catchTrials},
             {"catch_failures", s.catchFailures},
             {"left_rate", s.sideTrials > 0 ? nlohmann::json(s.leftChosen / s.sideTrials) : nlohmann::json()},
             {"side_p_value", finite(s.sidePValue)},
             {"side_p_adjusted", finite(s.sidePAdjusted)},
             {"side_biased", s.sideBiased}});
    return observers;
}

// The report section's observer table: screening, catch trials, side (exact binomial test), pwcmp's outliers.
void observersHtml(std::ostringstream& html, const Analysis& analysis) {
    const AnalysisOptions& o = analysis.options;
    html << "<h3>Observers</h3>\n<table>\n<tr><th>observer</th><th>trials</th><th>held-out log-likelihood / trial</th>"
            "<th>outlier</th><th>catch failures</th><th>left chosen</th><th>side bias (p, "
         << correctionName(o.correction) << ")</th></tr>\n";
    for (const ObserverSummary& s : analysis.observers)
        html << "<tr><td>" << escapeHtml(s.observer) << "</td><td>" << s.trials << "</td><td>"
             << fixed(s.heldOutPerTrial, 3) << "</td><td>" << (s.flagged ? "<strong>yes</strong>" : "no") << "</td><td>"
             << s.catchFailures << " / " << s.catchTrials << "</td><td>"
             << (s.sideTrials > 0 ? fixed(100.0 * s.leftChosen / s.sideTrials, 1) + " %" : std::string("–"))
             << "</td><td>"
             << (s.sideTrials > 0
                     ? (s.sideBiased ? "<strong>yes</strong> (" : "no (") + number(s.sidePAdjusted, 3) + ")"
                     : std::string("–"))
             << "</td></tr>\n";
    html << "</table>\n<p>Outlier rule: held-out log-likelihood per trial below Q1 − " << o.screeningWhisker
         << "·IQR = " << fixed(analysis.screeningRule.threshold, 3) << ".</p>\n";
    if (o.pwcmpOutliers) {
        std::string flagged;
        for (const ObserverSummary& s : analysis.observers)
            if (s.pwcmpOutlier)
                flagged +=
                    (flagged.empty() ? "" : ", ") + escapeHtml(s.observer) + " (" + fixed(s.pwcmpDistance, 2) + ")";
        html << "<p>pwcmp's outlier analysis (dist_L &gt; 1.5): " << (flagged.empty() ? "no observer" : flagged)
             << ".</p>\n";
    }
}

} // namespace

std::string blockSlug(const std::string& name) {
    std::string slug;
    for (unsigned char c : name) {
        const bool keep = std::isalnum(c) || c == '_' || c == '.';
        if (keep) slug += static_cast<char>(c);
        else if (!slug.empty() && slug.back() != '-') slug += '-';
    }
    while (!slug.empty() && slug.back() == '-') slug.pop_back();
    return slug.empty() ? "block" : slug;
}

nlohmann::json analysisJson(const Analysis& analysis) {
    const AnalysisOptions& o = analysis.options;
    nlohmann::json json;
    json["format"] = "skinlab-scaling";
    json["version"] = 1;
    json["skinlab_version"] = skinlab::version();
    json["input"] = {{"file", analysis.file}, {"format", responseFormatName(analysis.format)}};
    json["settings"] = settingsJson(o);
    for (const BlockAnalysis& block : analysis.blocks) json["blocks"].push_back(blockJson(block, o.fit));
    json["observers"] = observersJson(analysis);
    json["excluded_observers"] = nlohmann::json::array();
    for (const ExcludedObserver& e : analysis.excluded)
        json["excluded_observers"].push_back({{"observer", e.observer}, {"reason", e.reason}});
    json["screening"] = {{"first_quartile", finite(analysis.screeningRule.firstQuartile)},
                         {"third_quartile", finite(analysis.screeningRule.thirdQuartile)},
                         {"threshold", finite(analysis.screeningRule.threshold)},
                         {"whisker", analysis.screeningRule.whisker}};
    json["warnings"] = analysis.warnings;
    return json;
}

std::string reportSectionHtml(const Analysis& analysis) {
    const AnalysisOptions& o = analysis.options;
    std::ostringstream html;
    // Styled on its own (the rules apply inside the section only), so the file reads well opened alone and embedded.
    html << "<section class=\"skinlab-scaling\">\n<meta charset=\"utf-8\">\n<style>\n"
            ".skinlab-scaling { font-family: system-ui, sans-serif; max-width: 60em; margin: 1em auto; color: #222; "
            "line-height: 1.4; }\n"
            ".skinlab-scaling table { border-collapse: collapse; margin: 0.5em 0 1.5em; }\n"
            ".skinlab-scaling th, .skinlab-scaling td { border: 1px solid #ccc; padding: 0.2em 0.6em; "
            "text-align: left; }\n"
            ".skinlab-scaling th { background: #f2f2f2; }\n"
            ".skinlab-scaling img { max-width: 100%; margin: 0.3em 0.5em 0.3em 0; vertical-align: top; }\n"
            ".skinlab-scaling .warning { color: #8a4b00; }\n"
            ".skinlab-scaling code { background: #f4f4f4; padding: 0 0.2em; }\n"
            "</style>\n";
    html << "<h2>Perceptual scaling (Thurstone Case V, JOD)</h2>\n"
         << "<p>Input <code>" << escapeHtml(analysis.file) << "</code> (" << responseFormatName(analysis.format)
         << "). Scores in JOD (1 JOD = 75 % preference, each block's mean = 0), fitted with " << priorText(o.fit)
         << "; " << fixed(100 * o.bootstrap.level, 0)
         << (o.intervals == IntervalMethod::profile
                 ? " % profile-likelihood intervals (" + o.intervalReason + ") and score tests; "
             : o.intervals == IntervalMethod::bootstrapAndProfile
                 ? " % intervals that are the union of a symmetric studentized bootstrap over observers (" +
                       std::to_string(o.bootstrap.samples) + " samples, seed " + std::to_string(o.bootstrap.seed) +
                       ") and the profile-likelihood interval (" + o.intervalReason +
                       "), with the larger of the bootstrap and score tests' p-values; "
             : o.intervals == IntervalMethod::percentile
                 ? " % percentile bootstrap intervals over observers (pwcmp's construction, " +
                       std::to_string(o.bootstrap.samples) + " samples) and bootstrap p-values; "
                 : " % intervals by a symmetric studentized bootstrap over observers (" +
                       std::to_string(o.bootstrap.samples) + " samples, seed " + std::to_string(o.bootstrap.seed) +
                       "); where studentization is degenerate (marked †) the hull of the percentile and "
                       "profile-posterior intervals, and a score test; ")
         << "pairwise tests with " << correctionName(o.correction) << " correction at α = " << o.alpha << ".</p>\n";
    for (size_t b = 0; b < analysis.blocks.size(); ++b) {
        const BlockAnalysis& block = analysis.blocks[b];
        html << "<h3>" << escapeHtml(block.name) << "</h3>\n<p>" << block.observers.size() << " observer(s), "
             << block.conditions.size() << " conditions, intervals: " << block.intervalMethod;
        const double precision = priorPrecisionPerScore(o.fit, static_cast<int>(block.conditions.size()));
        if (std::isfinite(precision))
            html << ", prior on each score: precision τ·m = " << number(precision, 3) << " JOD⁻² (sd "
                 << fixed(1.0 / std::sqrt(precision), 1) << " JOD)";
        if (block.kendallU) html << ", Kendall's u = " << fixed(*block.kendallU, 3);
        if (block.sideBias.available)
            html << ", left image chosen in " << fixed(100 * block.sideBias.leftRate, 1) << " % of "
                 << block.sideBias.trials << " trials (exact binomial p = " << number(block.sideBias.pValue, 3)
                 << "; side bias "
                 << (std::isfinite(block.sideBias.bias) ? fixed(block.sideBias.bias, 3) + " JOD toward the left"
                                                        : std::string("without a finite estimate: every answer on one "
                                                                      "side"))
                 << ")";
        html << ".</p>\n";
        for (const std::string& warning : block.warnings)
            html << "<p class=\"warning\"><strong>Warning:</strong> " << escapeHtml(warning) << "</p>\n";
        html << "<img alt=\"scores of " << escapeHtml(block.name) << "\" src=\"data:image/png;base64,"
             << base64(encodePng(plotScores(block))) << "\">\n";
        html << "<img alt=\"preference matrix of " << escapeHtml(block.name) << "\" src=\"data:image/png;base64,"
             << base64(encodePng(plotPreferenceMatrix(block))) << "\">\n";
        html << "<table>\n<tr><th>condition</th><th>JOD</th><th>95 % interval</th><th>interval method</th>"
                "<th>Bradley–Terry (JOD)</th></tr>\n";
        for (size_t i = 0; i < block.conditions.size(); ++i) {
            const auto k = static_cast<Eigen::Index>(i);
            if (!measured(block, i)) {
                html << "<tr><td>" << escapeHtml(block.conditions[i])
                     << "</td><td colspan=\"4\">not measured (never compared)</td></tr>\n";
                continue;
            }
            html << "<tr><td>" << escapeHtml(block.conditions[i]) << "</td><td>" << fixed(block.thurstone.scores[k], 3)
                 << (scorePriorDriven(block, i) ? " (prior)" : "") << "</td><td>"
                 << intervalText(block.low[k], block.high[k]) << "</td><td>" << escapeHtml(scoreMethod(block, i))
                 << (scoreReasons(block, i).empty() ? std::string()
                                                    : " † (" + escapeHtml(joined(scoreReasons(block, i), ", ")) + ")")
                 << "</td><td>" << fixed(block.bradleyTerry.scores[k], 3) << "</td></tr>\n";
        }
        html << "</table>\n";
        if (std::any_of(block.intervalFlags.begin(), block.intervalFlags.end(),
                        [](const IntervalDiagnosis& d) { return d.priorDriven; }))
            html << "<p>(prior): the data bound this value on one side only (unanimous answers) or not at all; the "
                    "value shown is set by the prior, not measured; its interval's open end says so.</p>\n";
        html << "<table>\n<tr><th>A</th><th>B</th><th>A − B (JOD)</th><th>95 % "
                "interval</th><th>method</th><th>p</th>"
                "<th>p ("
             << correctionName(o.correction) << ")</th><th>significant</th></tr>\n";
        for (const PairTest& pair : block.pairs)
            html << "<tr><td>" << escapeHtml(block.conditions[pair.test.first]) << "</td><td>"
                 << escapeHtml(block.conditions[pair.test.second]) << "</td><td>"
                 << (measured(block, pair) ? fixed(pair.test.difference, 3) : std::string("not measured"))
                 << (pair.test.diagnosis.priorDriven && measured(block, pair) ? " (prior)" : "") << "</td><td>"
                 << intervalText(pair.test.low, pair.test.high) << "</td><td>" << escapeHtml(pairMethod(block, pair))
                 << (pair.test.diagnosis.reasons.empty()
                         ? std::string()
                         : " † (" + escapeHtml(joined(pair.test.diagnosis.reasons, ", ")) + ")")
                 << "</td><td>" << number(pair.test.pValue, 3) << "</td><td>" << number(pair.adjustedPValue, 3)
                 << "</td><td>" << (pair.significant ? "yes" : "no") << "</td></tr>\n";
        html << "</table>\n";
    }
    observersHtml(html, analysis);
    html << "</section>\n";
    return html.str();
}

void writeScaleOutputs(const Analysis& analysis, const std::filesystem::path& folder) {
    ensureDirectory(folder);
    ensureDirectory(folder / "plots");
    std::string scores =
        "block,condition,jod,ci_low,ci_high,standard_error,interval_method,percentile_low,"
        "percentile_high,bradley_terry_jod,bradley_terry_standard_error,fallback_reasons,bound,prior,prior_driven\n";
    std::string pairs = "block,condition_A,condition_B,difference_jod,ci_low,ci_high,standard_error,comparisons,"
                        "p_value,p_adjusted,correction,significant,interval_method,fallback_reasons,bound,"
                        "prior_driven\n";
    std::string counts = "block,condition_row,condition_column,count_row_chosen\n";
    std::string consistency = "block,observer,trials,held_out_loglik_per_trial,complete,circular_triads,zeta\n";
    for (size_t b = 0; b < analysis.blocks.size(); ++b) {
        const BlockAnalysis& block = analysis.blocks[b];
        const std::string name = csvField(block.name);
        for (size_t i = 0; i < block.conditions.size(); ++i) {
            const auto k = static_cast<Eigen::Index>(i);
            const bool is = measured(block, i);
            scores += name + "," + csvField(block.conditions[i]) + "," +
                      measuredNumber(is, block.thurstone.scores[k], 8) + "," + measuredNumber(is, block.low[k], 8) +
                      "," + measuredNumber(is, block.high[k], 8) + "," + measuredNumber(is, block.standardError[k], 8) +
                      "," + scoreMethod(block, i) + "," + measuredNumber(is, block.percentileLow[k], 8) + "," +
                      measuredNumber(is, block.percentileHigh[k], 8) + "," +
                      measuredNumber(is, block.bradleyTerry.scores[k], 8) + "," +
                      measuredNumber(is, block.bradleyTerryStandardError[k], 8) + "," +
                      csvField(joined(scoreReasons(block, i), ";")) + "," + scoreBound(block, i) + "," +
                      priorName(analysis.options.fit.prior) + "," + (scorePriorDriven(block, i) ? "1" : "0") + "\n";
            for (size_t j = 0; j < block.conditions.size(); ++j)
                if (i != j)
                    counts += name + "," + csvField(block.conditions[i]) + "," + csvField(block.conditions[j]) + "," +
                              number(block.counts(k, static_cast<Eigen::Index>(j)), 10) + "\n";
        }
        for (const PairTest& pair : block.pairs)
            pairs += name + "," + csvField(block.conditions[pair.test.first]) + "," +
                     csvField(block.conditions[pair.test.second]) + "," +
                     measuredNumber(measured(block, pair), pair.test.difference, 8) + "," + number(pair.test.low, 8) +
                     "," + number(pair.test.high, 8) + "," + number(pair.test.standardError, 8) + "," +
                     number(pair.comparisons, 10) + "," + number(pair.test.pValue, 6) + "," +
                     number(pair.adjustedPValue, 6) + "," + correctionName(analysis.options.correction) + "," +
                     (pair.significant ? "1" : "0") + "," + pairMethod(block, pair) + "," +
                     csvField(joined(pair.test.diagnosis.reasons, ";")) + "," + pair.test.diagnosis.bound + "," +
                     (pair.test.diagnosis.priorDriven ? "1" : "0") + "\n";
        for (size_t k = 0; k < block.observerStats.size(); ++k) {
            const ObserverInBlock& s = block.observerStats[k];
            consistency +=
                name + "," + csvField(block.observers[k]) + "," + number(s.trials, 10) + "," +
                (s.trials > 0 && block.observers.size() > 1 ? number(s.heldOutLogLikelihood / s.trials, 8) : "") + "," +
                (s.consistency.complete ? "1" : "0") + "," +
                (s.consistency.complete ? number(s.consistency.circularTriads, 6) : "") + "," +
                (s.consistency.zeta ? number(*s.consistency.zeta, 6) : "") + "\n";
        }
        writeFileAtomic(folder / plotName(b, "scores", block.name), encodePng(plotScores(block)));
        writeFileAtomic(folder / plotName(b, "matrix", block.name), encodePng(plotPreferenceMatrix(block)));
    }
    std::string observers = "observer,trials,held_out_loglik_per_trial,flagged,catch_trials,catch_failures,left_rate,"
                            "pwcmp_dist_l,pwcmp_outlier,side_p_value,side_p_adjusted,side_biased\n";
    for (const ObserverSummary& s : analysis.observers)
        observers +=
            csvField(s.observer) + "," + number(s.trials, 10) + "," + number(s.heldOutPerTrial, 8) + "," +
            (s.flagged ? "1" : "0") + "," + std::to_string(s.catchTrials) + "," + std::to_string(s.catchFailures) +
            "," + (s.sideTrials > 0 ? number(s.leftChosen / s.sideTrials, 6) : "") + "," + number(s.pwcmpDistance, 6) +
            "," + (std::isnan(s.pwcmpDistance) ? "" : (s.pwcmpOutlier ? "1" : "0")) + "," + number(s.sidePValue, 6) +
            "," + number(s.sidePAdjusted, 6) + "," + (s.sideTrials > 0 ? (s.sideBiased ? "1" : "0") : "") + "\n";
    writeFileAtomic(folder / "scores.csv", scores);
    writeFileAtomic(folder / "pairs.csv", pairs);
    writeFileAtomic(folder / "counts.csv", counts);
    writeFileAtomic(folder / "consistency.csv", consistency);
    writeFileAtomic(folder / "observers.csv", observers);
    writeFileAtomic(folder / "report_section.html", reportSectionHtml(analysis));
    nlohmann::json json = analysisJson(analysis);
    for (size_t b = 0; b < analysis.blocks.size(); ++b)
        json["blocks"][b]["plots"] = {{"scores", plotName(b, "scores", analysis.blocks[b].name)},
                                      {"matrix", plotName(b, "matrix", analysis.blocks[b].name)}};
    writeFileAtomic(folder / "scale.json", json.dump(2) + "\n"); // last: marks the folder complete
}

} // namespace skinlab::analysis::scaling
