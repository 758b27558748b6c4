#pragma once
// What the observer bootstrap (bootstrap.h) and the model-based intervals (profile_likelihood.h) both need: the
// observer-cluster-robust covariance of the scores and the normal quantile. The bootstrap falls back on the
// profile intervals, so bootstrap depends on profile_likelihood and both depend on this file, never the reverse.
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/pairwise_model.h"

#include <Eigen/Dense>

namespace skinlab::analysis::scaling {

// Observer-cluster-robust covariance of the mean-zero scores at `fit`, from observers weighted by `weights`
// (multiplicities). Centred score contributions, small-sample factor N/(N−1) with N = Σ weights.
Eigen::MatrixXd robustCovariance(const BlockData& block, const Eigen::VectorXd& weights, const FitResult& fit,
                                 Model model);

// Φ⁻¹(probability), 0 < probability < 1 (bisection on erfc to double precision).
double normalQuantile(double probability);

} // namespace skinlab::analysis::scaling
