#include "analysis/scaling/screening.h"

#include "analysis/scaling/bootstrap.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace skinlab::analysis::scaling {

HeldOutLikelihood heldOutLikelihood(const BlockData& block, const FitResult& full, const FitOptions& options) {
    const int n = block.observerCount();
    HeldOutLikelihood result;
    result.logLikelihood = Eigen::VectorXd::Zero(n);
    result.trials = (block.winsFirst + block.winsSecond).rowwise().sum();
    if (n < 2) return result;
    Eigen::VectorXd weights = Eigen::VectorXd::Ones(n);
    for (int k = 0; k < n; ++k) {
        weights[k] = 0.0;
        const FitResult without = fitScores(block.weightedCounts(weights), options, &full.scores,
                                            options.prior == Prior::Pwcmp ? &full.priorInformation : nullptr);
        weights[k] = 1.0;
        result.logLikelihood[k] = logLikelihood(options.model, block.pairs, block.winsFirst.row(k).transpose(),
                                                block.winsSecond.row(k).transpose(), without.scores);
    }
    return result;
}

std::vector<bool> lowOutliers(const std::vector<double>& values, double whisker, OutlierRule* rule) {
    std::vector<double> sorted;
    for (double v : values)
        if (!std::isnan(v)) sorted.push_back(v);
    std::sort(sorted.begin(), sorted.end());
    OutlierRule computed;
    computed.whisker = whisker;
    std::vector<bool> flags(values.size(), false);
    if (sorted.size() >= 4) { // quartiles of fewer than 4 values say nothing about outliers
        computed.firstQuartile = sortedQuantile(sorted, 0.25);
        computed.thirdQuartile = sortedQuantile(sorted, 0.75);
        computed.threshold = computed.firstQuartile - whisker * (computed.thirdQuartile - computed.firstQuartile);
        for (size_t k = 0; k < values.size(); ++k) flags[k] = !std::isnan(values[k]) && values[k] < computed.threshold;
    } else {
        computed.threshold = -INFINITY;
    }
    if (rule) *rule = computed;
    return flags;
}

std::optional<std::string> exclusionReason(int scaledAnswers, int catchTrials, int catchFailures) {
    if (scaledAnswers <= 0) return std::string("no answers");
    if (catchTrials > 0 && 4 * catchFailures > catchTrials)
        return "failed " + std::to_string(catchFailures) + " of " + std::to_string(catchTrials) + " catch trials";
    return std::nullopt;
}

std::vector<ExcludedObserver> excludeObservers(ResponseTable& table) {
    struct Counts {
        int scaled = 0, catchTrials = 0, catchFailures = 0;
    };
    std::vector<std::string> order;
    std::map<std::string, Counts> counts;
    for (const Response& r : table.responses) {
        auto [entry, added] = counts.try_emplace(r.observer);
        if (added) order.push_back(r.observer);
        if (r.kind == TrialKind::catchTrial) {
            ++entry->second.catchTrials;
            if (r.correct && !*r.correct) ++entry->second.catchFailures;
        } else if (r.kind != TrialKind::practice) {
            ++entry->second.scaled;
        }
    }
    std::vector<ExcludedObserver> excluded;
    std::set<std::string> names;
    for (const std::string& observer : order) {
        const Counts& c = counts.at(observer);
        if (auto reason = exclusionReason(c.scaled, c.catchTrials, c.catchFailures)) {
            excluded.push_back({observer, *reason});
            names.insert(observer);
        }
    }
    if (!names.empty()) std::erase_if(table.responses, [&](const Response& r) { return names.count(r.observer) > 0; });
    table.excludedObservers.insert(table.excludedObservers.end(), excluded.begin(), excluded.end());
    return excluded;
}

} // namespace skinlab::analysis::scaling
