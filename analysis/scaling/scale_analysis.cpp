#include "analysis/scaling/scale_analysis.h"

#include "analysis/scaling/profile_likelihood.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <functional>
#include <limits>
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

// Which ends of each interval the data set. Moving the scores along a direction v that is constant on every
// strongly connected component of the win graph and never lowers a winner below a condition it beat (v_i ≥ v_j
// when i beat j and j never beat i) never lowers the likelihood: along such a v only the prior bounds the scores.
// For a contrast aᵀq the upper end is the prior's iff some such v has aᵀv > 0 — for q_i − q_j iff j did not
// (transitively) beat i; for a score (relative to its component's mean) iff some condition of the component did
// not transitively beat it — and symmetrically for the lower end.
void applyDataBounds(BlockAnalysis& result, const PairCounts& totals, const FitOptions& options, double level) {
    const auto m = static_cast<int>(result.conditions.size());
    std::vector<int> component(m, 0);
    for (size_t c = 0; c < result.components.size(); ++c)
        for (int i : result.components[c]) component[i] = static_cast<int>(c);
    // beatenBy[i][j]: j transitively beat i (j reaches i along "won at least once" edges), i itself included.
    std::vector<std::vector<bool>> beatenBy(m, std::vector<bool>(m, false));
    for (int i = 0; i < m; ++i) {
        std::vector<int> stack{i};
        beatenBy[i][i] = true;
        while (!stack.empty()) {
            const int node = stack.back();
            stack.pop_back();
            for (int winner = 0; winner < m; ++winner)
                if (result.counts(winner, node) > 0 && !beatenBy[i][winner]) {
                    beatenBy[i][winner] = true;
                    stack.push_back(winner);
                }
        }
    }
    auto label = [](bool lowerFree, bool upperFree) {
        return lowerFree ? (upperFree ? "none" : "upper") : (upperFree ? "lower" : "two-sided");
    };
    const double infinity = std::numeric_limits<double>::infinity();
    // The finite end of an interval the data bound on one side only: the profile bound at the one-sided threshold
    // (the exact binomial bound for a single unanimous pair) where it is farther out than the end found so far.
    const double threshold = oneSidedProfileThreshold(level);
    auto oneSidedEnd = [&](double& low, double& high, double shift, const Eigen::VectorXd& contrast) {
        const int side = std::isfinite(low) ? -1 : 1;
        const double bound = shift + profileBound(totals, options, result.thurstone, contrast, side, threshold);
        if (side < 0) low = std::min(low, bound);
        else high = std::max(high, bound);
    };
    for (int i = 0; i < m; ++i) {
        if (!result.measured[i]) {
            result.low[i] = -infinity;
            result.high[i] = infinity;
            result.intervalFlags[i].bound = "not-measured";
            continue;
        }
        bool upperFree = false, lowerFree = false;
        for (int j = 0; j < m; ++j) {
            if (component[j] != component[i]) continue;
            upperFree = upperFree || !beatenBy[i][j]; // j never (transitively) beat i: i can rise above the mean
            lowerFree = lowerFree || !beatenBy[j][i]; // i never beat j: i can sink below the mean
        }
        if (upperFree) result.high[i] = infinity;
        if (lowerFree) result.low[i] = -infinity;
        result.intervalFlags[i].bound = label(lowerFree, upperFree);
        result.intervalFlags[i].priorDriven = upperFree || lowerFree;
        if (upperFree != lowerFree) {
            Eigen::VectorXd contrast = Eigen::VectorXd::Zero(m);
            int members = 0;
            for (int j = 0; j < m; ++j) members += component[j] == component[i];
            for (int j = 0; j < m; ++j)
                if (component[j] == component[i]) contrast[j] = -1.0 / members;
            contrast[i] += 1.0;
            oneSidedEnd(result.low[i], result.high[i],
                        result.thurstone.scores[i] - contrast.dot(result.thurstone.scores), contrast);
        }
    }
    for (PairTest& pair : result.pairs) {
        DifferenceTest& test = pair.test;
        const int i = test.first, j = test.second;
        const bool connected = component[i] == component[j];
        const bool upperFree = !connected || !beatenBy[i][j];
        const bool lowerFree = !connected || !beatenBy[j][i];
        if (upperFree) test.high = infinity;
        if (lowerFree) test.low = -infinity;
        test.diagnosis.bound =
            !result.measured[i] || !result.measured[j] ? "not-measured" : label(lowerFree, upperFree);
        test.diagnosis.priorDriven = upperFree || lowerFree;
        if (upperFree != lowerFree) {
            Eigen::VectorXd contrast = Eigen::VectorXd::Zero(m);
            contrast[i] = 1.0;
            contrast[j] = -1.0;
            oneSidedEnd(test.low, test.high, 0.0, contrast);
        }
        if (!connected) {
            // Not measured at all: no test either.
            test.pValue = 1.0;
            test.standardError = NAN;
            auto& reasons = test.diagnosis.reasons;
            if (std::find(reasons.begin(), reasons.end(), "disconnected") == reasons.end())
                reasons.insert(reasons.begin(), "disconnected");
        }
    }
}

// A p-value for a message: 3 significant digits ("0.0123", "1.6e-30").
std::string formatP(double p) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.3g", p);
    return buffer;
}

// Quantile as MATLAB's quantile/prctile (and Octave's default, method 5): the sorted values sit at probabilities
// (k − ½)/n, linear in between, the extremes beyond.
double quantileMethod5(std::vector<double> values, double probability) {
    std::sort(values.begin(), values.end());
    const auto n = static_cast<double>(values.size());
    const double position = probability * n - 0.5; // 0-based index
    if (position <= 0.0) return values.front();
    if (position >= n - 1.0) return values.back();
    const auto below = static_cast<size_t>(std::floor(position));
    const double fraction = position - static_cast<double>(below);
    return values[below] + fraction * (values[below + 1] - values[below]);
}

// pwcmp's pw_outlier_analysis for one block: per observer, the sum over the pairs it judged of log10 of the
// binomial probability of its counts under the scale of the other observers (fitted with pwcmp's prior), and the
// number of those pairs.
void pwcmpOutlierTerms(const BlockData& block, std::vector<double>& logLikelihood, std::vector<double>& pairs) {
    const int n = block.observerCount();
    logLikelihood.assign(n, 0.0);
    pairs.assign(n, 0.0);
    FitOptions options;
    options.prior = Prior::Pwcmp;
    for (int k = 0; k < n; ++k) {
        Eigen::VectorXd weights = Eigen::VectorXd::Ones(n);
        weights[k] = 0.0;
        const FitResult rest = fitScores(block.weightedCounts(weights), options);
        for (size_t p = 0; p < block.pairs.size(); ++p) {
            const auto column = static_cast<Eigen::Index>(p);
            const double a = block.winsFirst(k, column), b = block.winsSecond(k, column);
            if (a + b <= 0) continue;
            const double d = rest.scores[block.pairs[p].first] - rest.scores[block.pairs[p].second];
            const double logBinomial = std::lgamma(a + b + 1.0) - std::lgamma(a + 1.0) - std::lgamma(b + 1.0);
            const double logProbability = logBinomial + a * linkValues(Model::Thurstone, d).logProbability +
                                          b * linkValues(Model::Thurstone, -d).logProbability;
            logLikelihood[k] += std::max(logProbability / std::log(10.0), -200.0); // max(p, 1e-200)
            pairs[k] += 1.0;
        }
    }
}

// The studentized observer bootstrap's (or, with IntervalMethod::percentile, pwcmp's percentile bootstrap's)
// score intervals and pairwise tests, with the Bradley–Terry scores' observer-robust errors.
void bootstrapIntervals(BlockAnalysis& result, const BlockData& block, const FitOptions& thurstoneOptions,
                        const AnalysisOptions& options) {
    const int m = block.conditionCount();
    const int n = block.observerCount();
    const BootstrapResult bootstrap = bootstrapObservers(block, result.thurstone, thurstoneOptions, options.bootstrap);
    result.intervalMethod = "studentized-bootstrap";
    result.bootstrapSamples = bootstrap.samples;
    result.standardError = bootstrap.standardError;
    result.low = bootstrap.low;
    result.high = bootstrap.high;
    result.percentileLow = bootstrap.percentileLow;
    result.percentileHigh = bootstrap.percentileHigh;
    result.intervalFlags = bootstrap.scoreDiagnoses;
    for (const DifferenceTest& test : bootstrap.differences) result.pairs.push_back({test});
    if (options.intervals == IntervalMethod::percentile) {
        // pwcmp's pw_scale_bootstrp: percentiles of the resampled scores and differences.
        result.intervalMethod = "percentile-bootstrap";
        result.low = bootstrap.percentileLow;
        result.high = bootstrap.percentileHigh;
        result.intervalFlags.assign(m, {});
        for (PairTest& pair : result.pairs) {
            pair.test.low = pair.test.percentileLow;
            pair.test.high = pair.test.percentileHigh;
            pair.test.pValue = pair.test.percentilePValue;
            pair.test.diagnosis = {};
        }
    }
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
    if (fallbacks > 0 && options.intervals != IntervalMethod::percentile) {
        std::string why;
        for (const auto& [reason, count] : reasons) why += (why.empty() ? "" : ", ") + reason;
        result.warnings.push_back(std::to_string(fallbacks) + " of " + std::to_string(m) +
                                  " score intervals are percentile+profile intervals instead of studentized "
                                  "ones (" +
                                  why + ")");
    }
}

// Profile-posterior intervals (asymmetric where the data are, finite under the prior) and score tests, both
// model-based (the score test with the observer-robust variance when there are observers): for one observer or a
// bare count matrix (nothing to resample), and for adaptive designs, where resampling observers is not valid.
void profileIntervals(BlockAnalysis& result, const BlockData& block, const PairCounts& totals,
                      const FitOptions& thurstoneOptions, const AnalysisOptions& options) {
    const int m = block.conditionCount();
    const int n = block.observerCount();
    result.pairs.clear();
    result.intervalMethod = "profile-likelihood";
    const Eigen::MatrixXd& v = result.thurstone.inverseInformation;
    result.standardError = v.diagonal().cwiseMax(0.0).cwiseSqrt();
    result.low.resize(m);
    result.high.resize(m);
    result.intervalFlags.assign(m, {});
    for (int i = 0; i < m; ++i) {
        // The score relative to its own component's mean (all conditions when the design is connected).
        const std::vector<int>* members = &result.components.front();
        for (const auto& component : result.components)
            if (std::find(component.begin(), component.end(), i) != component.end()) members = &component;
        Eigen::VectorXd contrast = Eigen::VectorXd::Zero(m);
        for (int j : *members) contrast[j] = -1.0 / static_cast<double>(members->size());
        contrast[i] += 1.0;
        const double shift = result.thurstone.scores[i] - contrast.dot(result.thurstone.scores);
        const ProfileInterval profile =
            profileInterval(totals, thurstoneOptions, result.thurstone, contrast, options.bootstrap.level);
        result.low[i] = profile.low + shift;
        result.high[i] = profile.high + shift;
        if (profile.lowAtCap || profile.highAtCap) result.intervalFlags[i].reasons.emplace_back("bound-at-search-cap");
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
            test.pValue = scoreTestPValue(n >= 2 ? &block : nullptr, totals, thurstoneOptions, result.thurstone, i, j);
            result.pairs.push_back({test});
        }
    if (block.hasObservers && n < 2)
        result.warnings.push_back("a single observer: intervals are profile-likelihood intervals");
}

// The union of the two: each score's and each difference's interval from the lower of the two lower ends to the
// higher of the two upper ends, a pair's p-value the larger of the two (significant only when both tests say so).
// For adaptive designs, where neither alone reaches nominal coverage at every number of observers (docs/analysis.md,
// "Validation of active designs"). Standard errors stay the bootstrap's.
void unionIntervals(BlockAnalysis& result, const BlockData& block, const PairCounts& totals,
                    const FitOptions& thurstoneOptions, const AnalysisOptions& options) {
    bootstrapIntervals(result, block, thurstoneOptions, options);
    BlockAnalysis profiled = result;
    profileIntervals(profiled, block, totals, thurstoneOptions, options);
    result.intervalMethod = "studentized-bootstrap+profile-likelihood";
    result.low = result.low.cwiseMin(profiled.low);
    result.high = result.high.cwiseMax(profiled.high);
    for (size_t i = 0; i < result.intervalFlags.size(); ++i)
        for (const std::string& reason : profiled.intervalFlags[i].reasons)
            result.intervalFlags[i].reasons.push_back(reason);
    for (size_t k = 0; k < result.pairs.size(); ++k) {
        DifferenceTest& test = result.pairs[k].test;
        const DifferenceTest& other = profiled.pairs[k].test;
        test.low = std::min(test.low, other.low);
        test.high = std::max(test.high, other.high);
        test.pValue = std::max(test.pValue, other.pValue);
    }
}

// Per observer, the exact binomial test of the left rate = 1/2, corrected over the observers with a known side;
// per block, a warning where the panel as a whole chose one side more often than chance.
void screenSideBias(Analysis& analysis, const AnalysisOptions& options) {
    for (const BlockAnalysis& block : analysis.blocks)
        if (block.sideBias.available && block.sideBias.pValue < options.alpha)
            analysis.warnings.push_back(block.name + ": the left image was chosen in " +
                                        std::to_string(static_cast<long long>(block.sideBias.leftChosen)) + " of " +
                                        std::to_string(static_cast<long long>(block.sideBias.trials)) +
                                        " trials (exact binomial p = " + formatP(block.sideBias.pValue) +
                                        "): the panel has a side bias");
    std::vector<size_t> tested;
    std::vector<double> pValues;
    for (size_t k = 0; k < analysis.observers.size(); ++k) {
        ObserverSummary& s = analysis.observers[k];
        if (!(s.sideTrials > 0)) continue;
        s.sidePValue = binomialHalfPValue(s.leftChosen, s.sideTrials);
        tested.push_back(k);
        pValues.push_back(s.sidePValue);
    }
    const std::vector<double> adjusted = adjustPValues(pValues, options.correction);
    for (size_t t = 0; t < tested.size(); ++t) {
        ObserverSummary& s = analysis.observers[tested[t]];
        s.sidePAdjusted = adjusted[t];
        s.sideBiased = adjusted[t] < options.alpha;
        if (s.sideBiased)
            analysis.warnings.push_back("observer '" + s.observer + "' chose the left image in " +
                                        std::to_string(static_cast<long long>(s.leftChosen)) + " of " +
                                        std::to_string(static_cast<long long>(s.sideTrials)) +
                                        " trials (exact binomial p = " + formatP(s.sidePValue) + ", " +
                                        correctionName(options.correction) + " " + formatP(s.sidePAdjusted) +
                                        "): a side bias");
    }
}

} // namespace

IntervalMethod defaultIntervals(bool adaptiveDesign) {
    return adaptiveDesign ? IntervalMethod::bootstrapAndProfile : IntervalMethod::bootstrap;
}

const char* intervalsName(IntervalMethod method) {
    switch (method) {
    case IntervalMethod::bootstrap: return "bootstrap";
    case IntervalMethod::profile: return "profile";
    case IntervalMethod::percentile: return "percentile";
    case IntervalMethod::bootstrapAndProfile: return "bootstrap+profile";
    }
    return "bootstrap";
}

BlockAnalysis analyzeBlock(const BlockData& block, const AnalysisOptions& options) {
    BlockAnalysis result;
    result.name = block.name;
    result.conditions = block.conditions;
    result.observers = block.observers;
    result.counts = block.countMatrix();
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
                                  "): each group is scaled on its own, centred on its own mean; scores in different "
                                  "groups cannot be compared");
    }
    for (size_t p = 0; p < block.pairs.size(); ++p)
        if ((totals.first[p] > 0) != (totals.second[p] > 0)) result.unanimousPairs.push_back(block.pairs[p]);
    result.measured.assign(block.conditionCount(), false);
    for (size_t p = 0; p < block.pairs.size(); ++p)
        if (totals.first[p] + totals.second[p] > 0)
            result.measured[block.pairs[p].first] = result.measured[block.pairs[p].second] = true;
    for (int i = 0; i < block.conditionCount(); ++i)
        if (!result.measured[i])
            result.warnings.push_back("condition '" + block.conditions[i] +
                                      "' was never compared: not measured (no score, no interval)");
    result.mleExists = winGraphStronglyConnected(block, totals);
    if (!result.mleExists && result.components.size() == 1)
        result.warnings.push_back("some conditions won or lost every comparison with the rest (unanimous answers): "
                                  "the data bound their distance on one side only (intervals with one end)");

    // Intervals and tests.
    if (n < 2 || options.intervals == IntervalMethod::profile)
        profileIntervals(result, block, totals, thurstoneOptions, options);
    else if (options.intervals == IntervalMethod::bootstrapAndProfile)
        unionIntervals(result, block, totals, thurstoneOptions, options);
    else bootstrapIntervals(result, block, thurstoneOptions, options);
    std::vector<double> pValues;
    applyDataBounds(result, totals, thurstoneOptions, options.bootstrap.level);
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
    analysis.excluded = dataset.excluded;
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
    if (options.pwcmpOutliers && analysis.observers.size() >= 2) {
        std::map<std::string, double> logLikelihood, pairs;
        for (const BlockData& block : dataset.blocks) {
            if (!block.hasObservers || block.observerCount() < 2) continue;
            std::vector<double> blockLikelihood, blockPairs;
            pwcmpOutlierTerms(block, blockLikelihood, blockPairs);
            for (int k = 0; k < block.observerCount(); ++k) {
                logLikelihood[block.observers[k]] += blockLikelihood[k];
                pairs[block.observers[k]] += blockPairs[k];
            }
        }
        std::vector<double> values;
        for (ObserverSummary& summary : analysis.observers)
            if (pairs.count(summary.observer) && pairs[summary.observer] > 0) {
                summary.pwcmpLogLikelihood = logLikelihood[summary.observer] / pairs[summary.observer];
                values.push_back(summary.pwcmpLogLikelihood);
            }
        if (values.size() >= 2) {
            const double firstQuartile = quantileMethod5(values, 0.25);
            const double range = quantileMethod5(values, 0.75) - firstQuartile;
            for (ObserverSummary& summary : analysis.observers) {
                if (std::isnan(summary.pwcmpLogLikelihood)) continue;
                summary.pwcmpDistance = summary.pwcmpLogLikelihood < firstQuartile
                                            ? (firstQuartile - summary.pwcmpLogLikelihood) / range
                                            : 0.0;
                summary.pwcmpOutlier = summary.pwcmpDistance > kPwcmpOutlierDistance;
                if (summary.pwcmpOutlier)
                    analysis.warnings.push_back("observer '" + summary.observer +
                                                "' is an outlier by pwcmp's rule (dist_L " +
                                                std::to_string(summary.pwcmpDistance) + " > 1.5)");
            }
        }
    }
    screenSideBias(analysis, options);
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
