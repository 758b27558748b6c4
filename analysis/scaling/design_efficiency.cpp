#include "analysis/scaling/design_efficiency.h"

#include "analysis/scaling/pairwise_model.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <utility>

namespace skinlab::analysis::scaling {

// Fisher information of one comparison at true difference δ: φ(z)² / (σ² Φ(z) Φ(−z)), z = δ/σ. Both tails by
// erfc, so that a pair many σ apart keeps its (tiny) information instead of 1 − Φ(z) rounding to 0.
double comparisonInformation(double delta) {
    const double z = delta / kThurstoneSigma;
    const double pdf = std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI);
    const double upper = 0.5 * std::erfc(-z / std::sqrt(2.0)), lower = 0.5 * std::erfc(z / std::sqrt(2.0));
    const double product = upper * lower;
    if (!(product > 0.0)) return 0.0;
    return pdf * pdf / (kThurstoneSigma * kThurstoneSigma * product);
}

// The least share of the full design's comparisons that any allocation of comparisons to pairs needs for the full
// design's asymptotic mean squared error of the centred scores (Cramér–Rao; the oracle design that knows the true
// scores). With a share w_p of N comparisons on pair p, the information is N·F(w), F(w) = Σ_p w_p I(δ_p) a_p a_pᵀ,
// and the summed variance φ(w)/N with φ(w) = tr F(w)⁺ (convex in w). The full design is w = uniform. The
// A-optimal w is found by the multiplicative algorithm w_p ← w_p (d_p / φ(w))^½, d_p = I(δ_p) a_pᵀ F⁺² a_p
// (Silvey, Titterington & Torsney 1978; the exponent ½ makes it monotone for A-optimality, Yu 2010, Ann. Statist.
// 38(3); with exponent 1 it can settle on a point that is not optimal); by convexity, φ(w*) ≥ 2 φ(w) − max_p d_p for any w (Σ_p w_p d_p = φ(w)),
// so the ratio returned, (2 φ(w) − max_p d_p) / φ(uniform), is a lower bound whether or not the iteration has
// converged. Asymptotic: it holds for unbiased estimators at large budgets, not for a prior-regularised fit at a
// small one.
namespace {
struct Allocation {
    std::vector<double> weights; // per pair (i < j), in increasing (i, j) order
    double share = 1.0;
};

Allocation optimise(const std::vector<double>& truth) {
    const int m = static_cast<int>(truth.size());
    std::vector<std::pair<int, int>> pairs;
    std::vector<double> information;
    for (int i = 0; i < m; ++i)
        for (int j = i + 1; j < m; ++j) {
            pairs.emplace_back(i, j);
            information.push_back(
                comparisonInformation(truth[static_cast<std::size_t>(i)] - truth[static_cast<std::size_t>(j)]));
        }
    const std::size_t count = pairs.size();
    std::vector<double> w(count, 1.0 / static_cast<double>(count)), d(count);
    // φ(w) and d_p; F⁺ = (F + J/m)⁻¹ − J/m for a connected F, and J/m vanishes against every a_p.
    auto evaluate = [&]() {
        Eigen::MatrixXd f = Eigen::MatrixXd::Constant(m, m, 1.0 / m);
        for (std::size_t p = 0; p < count; ++p) {
            const auto [i, j] = pairs[p];
            const double x = w[p] * information[p];
            f(i, i) += x;
            f(j, j) += x;
            f(i, j) -= x;
            f(j, i) -= x;
        }
        const Eigen::MatrixXd g = f.ldlt().solve(Eigen::MatrixXd::Identity(m, m));
        const Eigen::MatrixXd g2 = g * g;
        for (std::size_t p = 0; p < count; ++p) {
            const auto [i, j] = pairs[p];
            d[p] = information[p] * (g2(i, i) + g2(j, j) - 2.0 * g2(i, j));
        }
        return g.trace() - 1.0;
    };
    const double full = evaluate();
    double phi = full, bound = 0.0;
    for (int iteration = 0; iteration < 1000; ++iteration) {
        const double largest = *std::max_element(d.begin(), d.end());
        bound = std::max(bound, 2.0 * phi - largest);
        if (largest <= phi * (1.0 + 1e-3)) break; // then the bound is within 0.1 % of φ(w)
        double total = 0.0;
        for (std::size_t p = 0; p < count; ++p) total += (w[p] *= std::sqrt(d[p] / phi));
        for (double& x : w) x /= total;
        phi = evaluate();
    }
    return {w, bound / full};
}
} // namespace

double optimalAllocationShare(const std::vector<double>& truth) {
    if (truth.size() < 3) return 1.0; // one pair (or none): nothing to choose
    return optimise(truth).share;
}

std::vector<double> optimalAllocation(const std::vector<double>& truth) {
    if (truth.size() < 2) return {};
    if (truth.size() == 2) return {1.0};
    return optimise(truth).weights;
}

} // namespace skinlab::analysis::scaling
