#include "analysis/scaling/consistency.h"

#include <algorithm>
#include <cmath>

namespace skinlab::analysis::scaling {

TriadConsistency kendallZeta(const BlockData& block, int observer) {
    TriadConsistency result;
    const int m = block.conditionCount();
    const double md = m;
    result.maximumTriads = (m % 2 == 1) ? (md * md * md - md) / 24.0 : (md * md * md - 4.0 * md) / 24.0;
    if (static_cast<int>(block.pairs.size()) != m * (m - 1) / 2) return result;
    Eigen::VectorXd score = Eigen::VectorXd::Zero(m);
    for (size_t p = 0; p < block.pairs.size(); ++p) {
        const double first = block.winsFirst(observer, static_cast<Eigen::Index>(p));
        const double second = block.winsSecond(observer, static_cast<Eigen::Index>(p));
        if (first + second <= 0) return result; // this observer skipped a pair
        const double firstScore = first > second ? 1.0 : (first < second ? 0.0 : 0.5);
        score[block.pairs[p].first] += firstScore;
        score[block.pairs[p].second] += 1.0 - firstScore;
    }
    result.complete = true;
    result.circularTriads = md * (md - 1.0) * (2.0 * md - 1.0) / 12.0 - 0.5 * score.squaredNorm();
    if (m >= 3) result.zeta = 1.0 - result.circularTriads / result.maximumTriads;
    return result;
}

std::optional<double> kendallU(const BlockData& block) {
    auto choose2 = [](double x) { return 0.5 * x * (x - 1.0); };
    const Eigen::VectorXd first = block.winsFirst.colwise().sum().transpose();
    const Eigen::VectorXd second = block.winsSecond.colwise().sum().transpose();
    double agreements = 0.0, possible = 0.0;
    for (Eigen::Index p = 0; p < first.size(); ++p) {
        agreements += choose2(first[p]) + choose2(second[p]);
        possible += choose2(first[p] + second[p]);
    }
    if (possible <= 0) return std::nullopt;
    return 2.0 * agreements / possible - 1.0;
}

SideBias estimateSideBias(const BlockData& block, const Eigen::VectorXd& scores, Model model) {
    SideBias result;
    result.trials = block.sideTrials.sum();
    if (result.trials <= 0) return result;
    result.available = true;
    result.leftChosen = block.leftChosen.sum();
    result.leftRate = result.leftChosen / result.trials;
    result.pValue = binomialHalfPValue(result.leftChosen, result.trials);
    if (result.leftChosen <= 0.0 || result.leftChosen >= result.trials) {
        // Every answer on one side: the likelihood of b increases without bound.
        result.bias = result.leftChosen > 0.0 ? INFINITY : -INFINITY;
        result.standardError = NAN;
        return result;
    }
    // Newton's method on the concave 1-D log-likelihood of b.
    double information = 0.0;
    for (int iteration = 0; iteration < 50; ++iteration) {
        double gradient = 0.0;
        information = 0.0;
        for (size_t p = 0; p < block.pairs.size(); ++p) {
            const auto& c = block.sideCounts[p];
            const double d = scores[block.pairs[p].first] - scores[block.pairs[p].second];
            const double b = result.bias;
            // (count, argument of F, sign of ∂argument/∂b)
            const double terms[4][3] = {
                {c[0], d + b, 1.0}, {c[1], -d - b, -1.0}, {c[2], d - b, -1.0}, {c[3], -d + b, 1.0}};
            for (const auto& term : terms) {
                if (term[0] <= 0) continue;
                const LinkValues v = linkValues(model, term[1]);
                gradient += term[0] * term[2] * v.slope;
                information -= term[0] * v.curvature;
            }
        }
        if (information <= 0) break;
        const double step = std::clamp(gradient / information, -1.0, 1.0);
        result.bias += step;
        if (std::abs(step) < 1e-10) break;
    }
    result.standardError = information > 0 ? 1.0 / std::sqrt(information) : NAN;
    return result;
}

double binomialHalfPValue(double successes, double trials) {
    const double n = std::round(trials);
    if (!(n > 0.0)) return 1.0;
    const double k = std::clamp(std::round(successes), 0.0, n);
    const double tail = std::min(k, n - k);
    if (2.0 * tail >= n) return 1.0;
    // P(X ≤ tail) = Σ_{x ≤ tail} C(n, x) 2^−n, summed in logs from the largest term down.
    const double logHalf = n * std::log(0.5);
    auto logTerm = [&](double x) { return std::lgamma(n + 1.0) - std::lgamma(x + 1.0) - std::lgamma(n - x + 1.0); };
    const double top = logTerm(tail);
    double sum = 0.0;
    for (double x = tail; x >= 0.0; x -= 1.0) {
        const double term = std::exp(logTerm(x) - top);
        sum += term;
        if (term < 1e-17 * sum) break;
    }
    return std::min(1.0, 2.0 * std::exp(top + logHalf + std::log(sum)));
}

} // namespace skinlab::analysis::scaling
