#pragma once
// Observer screening as in pwcmp's outlier analysis (Perez-Ortiz & Mantiuk 2017, §5): scale the block without
// observer k, then score k's own answers under that leave-one-out scale. An observer who disagrees with the
// others (random clicking, an inverted criterion) has a low held-out log-likelihood per trial. Outliers are
// flagged by the inter-quartile rule (Tukey 1977): value < Q1 − w·(Q3 − Q1), w = 1.5 by default.
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/pairwise_model.h"

#include <Eigen/Dense>

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

} // namespace skinlab::analysis::scaling
