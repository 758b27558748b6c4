#pragma once
// Observer screening as in pwcmp's outlier analysis (Perez-Ortiz & Mantiuk 2017, §5): scale the block without
// observer k, then score k's own answers under that leave-one-out scale. An observer who disagrees with the
// others (random clicking, an inverted criterion) has a low held-out log-likelihood per trial. Outliers are
// flagged by the inter-quartile rule (Tukey 1977): value < Q1 − w·(Q3 − Q1), w = 1.5 by default.
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/pairwise_model.h"
#include "analysis/scaling/responses.h"

#include <Eigen/Dense>

#include <optional>
#include <string>
#include <vector>

namespace skinlab::analysis::scaling {

struct HeldOutLikelihood {
    Eigen::VectorXd logLikelihood; // per observer: Σ log P(answer) under the leave-one-out scale (nats)
    Eigen::VectorXd trials;        // per observer: scaled trials in this block
};

// One warm-started fit per observer. Needs ≥ 2 observers (otherwise all zeros).
HeldOutLikelihood heldOutLikelihood(const BlockData& block, const FitResult& full, const FitOptions& options);

struct OutlierRule {
    double firstQuartile = 0.0;
    double thirdQuartile = 0.0;
    double threshold = 0.0; // values below are outliers
    double whisker = 1.5;
};

// Flags low outliers of `values` (NaN values are never flagged and do not enter the quartiles).
std::vector<bool> lowOutliers(const std::vector<double>& values, double whisker, OutlierRule* rule = nullptr);

// The exclusion rule fixed before a study (docs/study-protocol.md): an observer is excluded who gave no answer
// that is scaled, or failed more than one catch trial in four (4 · failures > catch trials). Returns the reason
// ("no answers", "failed 2 of 4 catch trials"), or nothing to include the observer. `analyze scale`, the dashboard
// and `report` all decide with it, so they scale the same observers.
std::optional<std::string> exclusionReason(int scaledAnswers, int catchTrials, int catchFailures);

// Applies exclusionReason to a response table: removes every response of each excluded observer, records them in
// table.excludedObservers (first-appearance order) and returns them. Tables without catch trials lose nobody who
// answered.
std::vector<ExcludedObserver> excludeObservers(ResponseTable& table);

} // namespace skinlab::analysis::scaling
