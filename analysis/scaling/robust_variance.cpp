#include "analysis/scaling/robust_variance.h"

#include <algorithm>
#include <cmath>

namespace skinlab::analysis::scaling {

Eigen::MatrixXd robustCovariance(const BlockData& block, const Eigen::VectorXd& weights, const FitResult& fit,
                                 Model model) {
    const int m = block.conditionCount();
    const auto pairCount = static_cast<Eigen::Index>(block.pairs.size());
    Eigen::RowVectorXd slopeFirst(pairCount), slopeSecond(pairCount);
    for (Eigen::Index p = 0; p < pairCount; ++p) {
        const double d = fit.scores[block.pairs[p].first] - fit.scores[block.pairs[p].second];
        slopeFirst[p] = linkValues(model, d).slope;
        slopeSecond[p] = linkValues(model, -d).slope;
    }
    // Per observer and pair: d/d(q_i − q_j) of that observer's log-likelihood.
    const Eigen::MatrixXd pairGradient = block.winsFirst.array().rowwise() * slopeFirst.array() -
                                         block.winsSecond.array().rowwise() * slopeSecond.array();
    Eigen::MatrixXd gradient = Eigen::MatrixXd::Zero(block.observerCount(), m);
    for (Eigen::Index p = 0; p < pairCount; ++p) {
        gradient.col(block.pairs[p].first) += pairGradient.col(p);
        gradient.col(block.pairs[p].second) -= pairGradient.col(p);
    }
    const double total = weights.sum();
    const Eigen::RowVectorXd mean = (weights.transpose() * gradient) / total;
    const Eigen::MatrixXd centred = gradient.rowwise() - mean;
    const Eigen::MatrixXd meat =
        centred.transpose() * weights.asDiagonal() * centred * (total / std::max(total - 1.0, 1.0));
    return fit.inverseInformation * meat * fit.inverseInformation;
}

double normalQuantile(double probability) {
    double low = -40.0, high = 40.0;
    for (int iteration = 0; iteration < 200 && high - low > 1e-14; ++iteration) {
        const double middle = 0.5 * (low + high);
        if (0.5 * std::erfc(-middle / std::sqrt(2.0)) < probability) low = middle;
        else high = middle;
    }
    return 0.5 * (low + high);
}

} // namespace skinlab::analysis::scaling
