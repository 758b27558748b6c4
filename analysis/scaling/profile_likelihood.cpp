#include "analysis/scaling/profile_likelihood.h"

#include "analysis/scaling/robust_variance.h"

#include <algorithm>
#include <cmath>

namespace skinlab::analysis::scaling {

double profileBound(const PairCounts& counts, const FitOptions& options, const FitResult& fit,
                    const Eigen::VectorXd& contrast, int side, double threshold, bool* atCap) {
    const double top = logPosterior(counts, options, fit.scores);
    const double estimate = contrast.dot(fit.scores);
    const double wald = std::sqrt(std::max(contrast.dot(fit.inverseInformation * contrast), 0.0));
    Eigen::VectorXd warm = fit.scores;
    auto drop = [&](double offset) {
        const ConstrainedFit constrained = fitConstrained(counts, options, contrast, estimate + side * offset, warm);
        warm = constrained.scores;
        return 2.0 * (top - constrained.logPosterior);
    };
    // Bracket: double the offset from about the Wald half-width until the posterior has fallen by the threshold
    // (at most ~14 doublings up to the cap), then bisect to 1e-5 JOD.
    double inside = 0.0, outside = std::clamp(std::sqrt(threshold) * wald, 0.05, kProfileSearchCap);
    bool bracketed = false;
    for (int step = 0; step < 40; ++step) {
        if (drop(outside) >= threshold) {
            bracketed = true;
            break;
        }
        inside = outside;
        if (outside >= kProfileSearchCap) break;
        outside = std::min(2.0 * outside, kProfileSearchCap);
    }
    if (bracketed) {
        for (int step = 0; step < 60 && outside - inside > 1e-5; ++step) {
            const double middle = 0.5 * (inside + outside);
            if (drop(middle) >= threshold) outside = middle;
            else inside = middle;
        }
    }
    if (atCap) *atCap = !bracketed;
    return estimate + side * outside;
}

ProfileInterval profileInterval(const PairCounts& counts, const FitOptions& options, const FitResult& fit,
                                const Eigen::VectorXd& contrast, double level) {
    const double z = normalQuantile(0.5 + 0.5 * level);
    const double target = z * z; // χ²₁ quantile at `level`
    ProfileInterval result;
    result.low = profileBound(counts, options, fit, contrast, -1, target, &result.lowAtCap);
    result.high = profileBound(counts, options, fit, contrast, 1, target, &result.highAtCap);
    return result;
}

double oneSidedProfileThreshold(double level) { return -2.0 * std::log(0.5 * (1.0 - level)); }

double scoreTestPValue(const BlockData* block, const PairCounts& counts, const FitOptions& options,
                       const FitResult& fit, int first, int second) {
    const int m = counts.conditions;
    Eigen::VectorXd contrast = Eigen::VectorXd::Zero(m);
    contrast[first] = 1.0;
    contrast[second] = -1.0;
    const ConstrainedFit null = fitConstrained(counts, options, contrast, 0.0, fit.scores);
    const Eigen::LDLT<Eigen::MatrixXd> solver(null.information);
    const Eigen::VectorXd alongContrast = solver.solve(contrast);
    // At the constrained maximum the gradient is μ·a; the efficient score of θ = q_first − q_second is
    // u = aᵀ I⁻¹ g, with model variance aᵀ I⁻¹ a and robust variance aᵀ I⁻¹ M I⁻¹ a.
    const double score = alongContrast.dot(null.gradient);
    double variance = contrast.dot(alongContrast);
    if (block != nullptr && block->hasObservers && block->observerCount() >= 2) {
        FitResult atNull;
        atNull.scores = null.scores;
        atNull.inverseInformation = solver.solve(Eigen::MatrixXd::Identity(m, m));
        atNull.inverseInformation.array() -= 1.0 / (static_cast<double>(m) * m);
        const Eigen::MatrixXd robust =
            robustCovariance(*block, Eigen::VectorXd::Ones(block->observerCount()), atNull, options.model);
        variance = std::max(variance, contrast.dot(robust * contrast));
    }
    if (!(variance > 0.0)) return 1.0;
    return std::erfc(std::abs(score) / std::sqrt(variance) / std::sqrt(2.0));
}

} // namespace skinlab::analysis::scaling
