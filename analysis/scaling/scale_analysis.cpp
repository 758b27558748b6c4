#include "analysis/scaling/scale_analysis.h"

#include "analysis/scaling/profile_likelihood.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <functional>
#include <map>

namespace skinlab::analysis::scaling {
namespace {

// Connected components of the undirected comparison graph (pairs with at least one trial).
std::vector<std::vector<int>> components(const BlockData& block, const PairCounts& totals) {
    const int m = block.conditionCount();
    std::vector<int> label(m, -1);
    std::vector<std::vector<int>> neighbours(m);
    for (size_t p = 0; p < block.pairs.size(); ++p) {
        if (totals.first[p] + totals.second[p] <= 0) continue;
        neighbours[block.pairs[p].first].push_back(block.pairs[p].second);
        neighbours[block.pairs[p].second].push_back(block.pairs[p].first);
    }
    std::vector<std::vector<int>> result;
    for (int start = 0; start < m; ++start) {
        if (label[start] >= 0) continue;
        result.emplace_back();
        std::vector<int> stack{start};
        label[start] = static_cast<int>(result.size()) - 1;
        while (!stack.empty()) {
            const int node = stack.back();
            stack.pop_back();
            result.back().push_back(node);
            for (int next : neighbours[node])
                if (label[next] < 0) {
                    label[next] = label[start];
                    stack.push_back(next);
                }
        }
        std::sort(result.back().begin(), result.back().end());
    }
    return result;
}

// The ML estimate (without prior) exists iff the directed graph "i beat j at least once" is strongly connected
// (Zermelo 1929; Ford 1957): reachable from condition 0 along wins and along losses.
bool winGraphStronglyConnected(const BlockData& block, const PairCounts& totals) {
    const int m = block.conditionCount();
    auto reachesAll = [&](bool forward) {
        std::vector<std::vector<int>> edges(m);
        for (size_t p = 0; p < block.pairs.size(); ++p) {
            const auto [i, j] = block.pairs[p];
            const bool iBeatJ = totals.first[p] > 0, jBeatI = totals.second[p] > 0;
            if (iBeatJ) (forward ? edges[i] : edges[j]).push_back(forward ? j : i);
            if (jBeatI) (forward ? edges[j] : edges[i]).push_back(forward ? i : j);
        }
        std::vector<bool> seen(m, false);
        std::vector<int> stack{0};
        seen[0] = true;
        int count = 1;
        while (!stack.empty()) {
            const int node = stack.back();
            stack.pop_back();
            for (int next : edges[node])
                if (!seen[next]) {
                    seen[next] = true;
                    ++count;
                    stack.push_back(next);
                }
        }
        return count == m;
    };
    return m < 2 || (reachesAll(true) && reachesAll(false));
}

} // namespace

BlockAnalysis analyzeBlock(const BlockData& block, const AnalysisOptions& options) {
    BlockAnalysis result;
    result.name = block.name;
    result.conditions = block.conditions;
    result.observers = block.observers;
    result.counts = block.countMatrix();
    const int m = block.conditionCount();
    const int n = block.observerCount();
    const PairCounts totals = block.totalCounts();

    FitOptions thurstoneOptions = options.fit;
    thurstoneOptions.model = Model::Thurstone;
    FitOptions bradleyTerryOptions = options.fit;
    bradleyTerryOptions.model = Model::BradleyTerry;
    result.thurstone = fitScores(totals, thurstoneOptions);
    result.bradleyTerry = fitScores(totals, bradleyTerryOptions);

    // Design flags.
    result.components = components(block, totals);
    if (result.components.size() > 1) {
        std::string groups;
        for (const auto& component : result.components) {
            groups += groups.empty() ? "{" : " {";
            for (size_t k = 0; k < component.size(); ++k) groups += (k ? "," : "") + block.conditions[component[k]];
            groups += "}";
        }
        result.warnings.push_back("the comparison graph is disconnected (" + groups +
                                  "): distances between these groups are set by the prior only, not by the data");
    }
    for (size_t p = 0; p < block.pairs.size(); ++p)
        if ((totals.first[p] > 0) != (totals.second[p] > 0)) result.unanimousPairs.push_back(block.pairs[p]);
    result.mleExists = winGraphStronglyConnected(block, totals);
    if (!result.mleExists && result.components.size() == 1)
        result.warnings.push_back("some conditions won or lost every comparison with the rest (unanimous answers): "
                                  "their distance is bounded by the prior and is a lower bound");

    // Intervals and tests.
    std::vector<double> pValues;
    if (n >= 2 && options.intervals == IntervalMethod::bootstrap) {
        const BootstrapResult bootstrap =
            bootstrapObservers(block, result.thurstone, thurstoneOptions, options.bootstrap);
        result.intervalMethod = "studentized-bootstrap";
        result.bootstrapSamples = bootstrap.samples;
        result.standardError = bootstrap.standardError;
        result.low = bootstrap.low;
        result.high = bootstrap.high;
        result.percentileLow = bootstrap.percentileLow;
        result.percentileHigh = bootstrap.percentileHigh;
        result.intervalFlags = bootstrap.scoreDiagnoses;
        for (const DifferenceTest& test : bootstrap.differences) result.pairs.push_back({test});
        result.bradleyTerryStandardError =
            robustCovariance(block, Eigen::VectorXd::Ones(n), result.bradleyTerry, Model::BradleyTerry)
                .diagonal()
                .cwiseMax(0.0)
                .cwiseSqrt();
        if (n < 5)
            result.warnings.push_back("only " + std::to_string(n) +
                                      " observers: bootstrap intervals are unreliable below about 10");
        std::map<std::string, int> reasons;
        int fallbacks = 0;
        for (const IntervalDiagnosis& diagnosis : result.intervalFlags) {
            fallbacks += diagnosis.fallback;
            for (const std::string& reason : diagnosis.reasons) ++reasons[reason];
        }
        if (fallbacks > 0) {
            std::string why;
            for (const auto& [reason, count] : reasons) why += (why.empty() ? "" : ", ") + reason;
            result.warnings.push_back(std::to_string(fallbacks) + " of " + std::to_string(m) +
                                      " score intervals are percentile+profile intervals instead of studentized "
                                      "ones (" +
                                      why + ")");
        }
    } else {
        // One observer or a bare count matrix: nothing to resample; or an adaptive design, where resampling
        // observers is not valid. Profile-posterior intervals (asymmetric where the data are, finite under the
        // prior) and score tests, both model-based (the score test with the observer-robust variance when there are
        // observers).
        result.intervalMethod = "profile-likelihood";
        const Eigen::MatrixXd& v = result.thurstone.inverseInformation;
        result.standardError = v.diagonal().cwiseMax(0.0).cwiseSqrt();
        result.low.resize(m);
        result.high.resize(m);
        result.intervalFlags.assign(m, {});
        for (int i = 0; i < m; ++i) {
            Eigen::VectorXd contrast = Eigen::VectorXd::Constant(m, -1.0 / m);
            contrast[i] += 1.0;
            const ProfileInterval profile =
                profileInterval(totals, thurstoneOptions, result.thurstone, contrast, options.bootstrap.level);
            result.low[i] = profile.low;
            result.high[i] = profile.high;
            if (profile.lowAtCap || profile.highAtCap)
                result.intervalFlags[i].reasons.emplace_back("bound-at-search-cap");
        }
        result.percentileLow = Eigen::VectorXd::Constant(m, NAN);
        result.percentileHigh = Eigen::VectorXd::Constant(m, NAN);
        result.bradleyTerryStandardError = result.bradleyTerry.inverseInformation.diagonal().cwiseMax(0.0).cwiseSqrt();
        for (int i = 0; i < m; ++i)
            for (int j = i + 1; j < m; ++j) {
                DifferenceTest test;
                test.first = i;
                test.second = j;
                test.difference = result.thurstone.scores[i] - result.thurstone.scores[j];
                test.standardError = std::sqrt(std::max(v(i, i) + v(j, j) - 2.0 * v(i, j), 0.0));
                Eigen::VectorXd contrast = Eigen::VectorXd::Zero(m);
                contrast[i] = 1.0;
                contrast[j] = -1.0;
                const ProfileInterval profile =
                    profileInterval(totals, thurstoneOptions, result.thurstone, contrast, options.bootstrap.level);
                test.low = profile.low;
                test.high = profile.high;
                if (profile.lowAtCap || profile.highAtCap) test.diagnosis.reasons.emplace_back("bound-at-search-cap");
                test.pValue =
                    scoreTestPValue(n >= 2 ? &block : nullptr, totals, thurstoneOptions, result.thurstone, i, j);
                result.pairs.push_back({test});
            }
        if (block.hasObservers && n < 2)
            result.warnings.push_back("a single observer: intervals are profile-likelihood intervals");
    }
    for (PairTest& pair : result.pairs) {
        pair.comparisons =
            result.counts(pair.test.first, pair.test.second) + result.counts(pair.test.second, pair.test.first);
        pValues.push_back(pair.test.pValue);
    }
    const std::vector<double> adjusted = adjustPValues(pValues, options.correction);
    for (size_t k = 0; k < result.pairs.size(); ++k) {
        result.pairs[k].adjustedPValue = adjusted[k];
        result.pairs[k].significant = adjusted[k] < options.alpha;
    }

    // Consistency, agreement, side bias, screening.
    result.kendallU = kendallU(block);
    result.sideBias = estimateSideBias(block, result.thurstone.scores, Model::Thurstone);
    const HeldOutLikelihood heldOut = heldOutLikelihood(block, result.thurstone, thurstoneOptions);
    for (int k = 0; k < n; ++k) {
        ObserverInBlock stats;
        stats.trials = heldOut.trials[k];
        stats.heldOutLogLikelihood = heldOut.logLikelihood[k];
        if (block.hasObservers) stats.consistency = kendallZeta(block, k);
        stats.sideTrials = block.sideTrials[k];
        stats.leftChosen = block.leftChosen[k];
        result.observerStats.push_back(stats);
    }
    return result;
}

Analysis analyzeDataset(const Dataset& dataset, const AnalysisOptions& options) {
    Analysis analysis;
    analysis.file = dataset.file;
    analysis.format = dataset.format;
    analysis.options = options;
    std::map<std::string, size_t> observerIndex;
    auto observer = [&](const std::string& name) -> ObserverSummary& {
        const auto [it, inserted] = observerIndex.emplace(name, analysis.observers.size());
        if (inserted) analysis.observers.push_back({name});
        return analysis.observers[it->second];
    };
    for (const ObserverAttention& attention : dataset.attention) {
        ObserverSummary& summary = observer(attention.observer);
        summary.catchTrials = attention.catchTrials;
        summary.catchFailures = attention.catchFailures;
    }
    std::map<std::string, double> heldOutSum;
    for (const BlockData& block : dataset.blocks) {
        spdlog::debug("scaling block '{}': {} conditions, {} observers", block.name, block.conditionCount(),
                      block.observerCount());
        analysis.blocks.push_back(analyzeBlock(block, options));
        const BlockAnalysis& result = analysis.blocks.back();
        for (const std::string& warning : result.warnings) analysis.warnings.push_back(block.name + ": " + warning);
        if (!block.hasObservers) continue;
        for (int k = 0; k < block.observerCount(); ++k) {
            ObserverSummary& summary = observer(block.observers[k]);
            summary.trials += result.observerStats[k].trials;
            summary.sideTrials += result.observerStats[k].sideTrials;
            summary.leftChosen += result.observerStats[k].leftChosen;
            heldOutSum[block.observers[k]] += result.observerStats[k].heldOutLogLikelihood;
        }
    }
    std::vector<double> perTrial;
    for (ObserverSummary& summary : analysis.observers) {
        if (summary.trials > 0 && heldOutSum.count(summary.observer) && analysis.observers.size() >= 2)
            summary.heldOutPerTrial = heldOutSum[summary.observer] / summary.trials;
        perTrial.push_back(summary.heldOutPerTrial);
    }
    const std::vector<bool> flags = lowOutliers(perTrial, options.screeningWhisker, &analysis.screeningRule);
    for (size_t k = 0; k < analysis.observers.size(); ++k) {
        analysis.observers[k].flagged = flags[k];
        if (flags[k])
            analysis.warnings.push_back("observer '" + analysis.observers[k].observer +
                                        "' is an outlier (held-out log-likelihood per trial " +
                                        std::to_string(analysis.observers[k].heldOutPerTrial) + " < " +
                                        std::to_string(analysis.screeningRule.threshold) + ")");
        if (analysis.observers[k].catchFailures > 0)
            analysis.warnings.push_back("observer '" + analysis.observers[k].observer + "' failed " +
                                        std::to_string(analysis.observers[k].catchFailures) + " of " +
                                        std::to_string(analysis.observers[k].catchTrials) + " catch trials");
    }
    return analysis;
}

} // namespace skinlab::analysis::scaling
