#include "analysis/scaling/active_sampling.h"

#include "common/error.h"
#include "common/seeded_random.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

namespace skinlab::analysis::scaling::active {

namespace {

// λ(z) = φ(z)/Φ(z), the inverse Mills ratio, stable for very negative z (an answer the posterior finds nearly
// impossible), where φ and Φ both underflow: erfcx would do, but the asymptotic series is enough here.
double millsRatio(double z) {
    if (z < -30.0) {
        const double z2 = z * z;
        return -z / (1.0 - 1.0 / z2 + 3.0 / (z2 * z2));
    }
    const double pdf = std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI);
    const double cdf = 0.5 * std::erfc(-z / std::sqrt(2.0));
    return pdf / cdf;
}

double normalCdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

// Moments of d ~ N(m, v) after one probit answer "d > 0 preferred", i.e. the tilted N(d; m, v)·Φ(d/σ): with
// s² = σ² + v, z = m/s, λ = φ(z)/Φ(z):  m' = m + v λ/s,  v' = v − v² λ(λ + z)/s².
struct Moments {
    double mean, variance;
};
Moments afterAnswer(double m, double v) {
    const double s2 = kThurstoneSigma * kThurstoneSigma + v;
    const double s = std::sqrt(s2);
    const double z = m / s;
    const double lambda = millsRatio(z);
    const double delta = std::clamp(lambda * (lambda + z), 0.0, 1.0);
    return {m + v * lambda / s, v * (1.0 - v * delta / s2)};
}

double gaussianKl(double mNew, double vNew, double mOld, double vOld) {
    const double d = mNew - mOld;
    return 0.5 * (vNew / vOld + d * d / vOld - 1.0 - std::log(vNew / vOld));
}

// Moments of the tilted distribution N(d; m, v)·Φ(d/σ)^a·Φ(−d/σ)^b: all answers to one pair (i won a times,
// j won b times) as one factor on d = q_i − q_j. The log density is concave (Φ is log-concave): Newton's method
// finds its mode, and the trapezoidal rule on 49 points over ±8 Laplace standard deviations around the mode gives
// the moments (for a smooth unimodal integrand the rule converges exponentially; far below the 1e-6 used here).
Moments tiltedMoments(double m, double v, double a, double b) {
    const double sigma = kThurstoneSigma;
    auto logDensity = [&](double d) {
        const double z = d / sigma;
        return -0.5 * (d - m) * (d - m) / v + a * std::log(std::max(normalCdf(z), 1e-300)) +
               b * std::log(std::max(normalCdf(-z), 1e-300));
    };
    double mode = m, curvature = -1.0 / v;
    for (int iteration = 0; iteration < 50; ++iteration) {
        const double z = mode / sigma;
        const double lp = millsRatio(z), ln = millsRatio(-z);
        const double slope = -(mode - m) / v + (a * lp - b * ln) / sigma;
        curvature = -1.0 / v - (a * lp * (lp + z) + b * ln * (ln - z)) / (sigma * sigma);
        const double step = -slope / curvature;
        mode += step;
        if (std::abs(step) < 1e-10) break;
    }
    const double spread = 1.0 / std::sqrt(-curvature);
    constexpr int kPoints = 49;
    constexpr double kHalfWidth = 8.0;
    const double peak = logDensity(mode);
    double weight = 0.0, first = 0.0, second = 0.0;
    for (int k = 0; k < kPoints; ++k) {
        const double x = -kHalfWidth + 2.0 * kHalfWidth * k / (kPoints - 1);
        const double d = mode + spread * x;
        const double w = std::exp(logDensity(d) - peak);
        weight += w;
        first += w * d;
        second += w * d * d;
    }
    const double mean = first / weight;
    return {mean, std::max(second / weight - mean * mean, 1e-12)};
}

// The inverse of a symmetric positive-definite n × n matrix (row-major) by Cholesky, A = L Lᵀ (lower, in place),
// then the columns of A⁻¹ by forward and back substitution.
std::vector<double> inverseOfPositiveDefinite(std::size_t n, std::vector<double> a) {
    // Cholesky A = L Lᵀ (lower, in place).
    for (std::size_t j = 0; j < n; ++j) {
        double d = a[j * n + j];
        for (std::size_t k = 0; k < j; ++k) d -= a[j * n + k] * a[j * n + k];
        if (!(d > 0.0)) throw RuntimeError("active sampling: posterior precision is not positive definite");
        const double root = std::sqrt(d);
        a[j * n + j] = root;
        for (std::size_t i = j + 1; i < n; ++i) {
            double x = a[i * n + j];
            for (std::size_t k = 0; k < j; ++k) x -= a[i * n + k] * a[j * n + k];
            a[i * n + j] = x / root;
        }
    }
    // Columns of A⁻¹ by forward and back substitution.
    std::vector<double> inverse(n * n, 0.0);
    std::vector<double> column(n);
    for (std::size_t c = 0; c < n; ++c) {
        for (std::size_t i = 0; i < n; ++i) {
            double x = i == c ? 1.0 : 0.0;
            for (std::size_t k = 0; k < i; ++k) x -= a[i * n + k] * column[k];
            column[i] = x / a[i * n + i];
        }
        for (std::size_t i = n; i-- > 0;) {
            double x = column[i];
            for (std::size_t k = i + 1; k < n; ++k) x -= a[k * n + i] * column[k];
            column[i] = x / a[i * n + i];
        }
        for (std::size_t i = 0; i < n; ++i) inverse[i * n + c] = column[i];
    }
    return inverse;
}

// Σ = (Λ₀ + Σ_k π̃_k a_k a_kᵀ)⁻¹ and μ = Σ η, recomputed from the sites after every sweep (Cholesky), so that the
// rounding of thousands of rank-one updates never accumulates across sweeps.
void recompute(int m, double priorPrecision, const std::vector<Comparison>& answers,
               const std::vector<double>& sitePrecision, const std::vector<double>& siteShift,
               std::vector<double>& mean, std::vector<double>& covariance) {
    const auto n = static_cast<std::size_t>(m);
    std::vector<double> a(n * n, 0.0), eta(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) a[i * n + i] = priorPrecision;
    for (std::size_t k = 0; k < answers.size(); ++k) {
        const auto w = static_cast<std::size_t>(answers[k].winner), l = static_cast<std::size_t>(answers[k].loser);
        const double p = sitePrecision[k];
        a[w * n + w] += p;
        a[l * n + l] += p;
        a[w * n + l] -= p;
        a[l * n + w] -= p;
        eta[w] += siteShift[k];
        eta[l] -= siteShift[k];
    }
    covariance = inverseOfPositiveDefinite(n, std::move(a));
    mean.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) mean[i] += covariance[i * n + j] * eta[j];
}

} // namespace

ScorePosterior ScorePosterior::independent(const std::vector<double>& mean, const std::vector<double>& variance) {
    ScorePosterior p;
    p.mean = mean;
    const std::size_t n = mean.size();
    p.covariance.assign(n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i) p.covariance[i * n + i] = variance[i];
    return p;
}

ScorePosterior withPrior(const ScorePosterior& posterior, double priorVariance) {
    if (!(priorVariance > 0.0) || !(posterior.priorVariance > 0.0))
        throw RuntimeError("active sampling: a prior variance must be positive");
    const std::size_t n = posterior.mean.size();
    if (n == 0 || priorVariance == posterior.priorVariance) return posterior;
    // Σ⁻¹ = Λ₀ + Σ_k π̃_k a_k a_kᵀ: replace the prior's precision on the diagonal.
    std::vector<double> precision = inverseOfPositiveDefinite(n, posterior.covariance);
    for (std::size_t i = 0; i < n; ++i) precision[i * n + i] += 1.0 / priorVariance - 1.0 / posterior.priorVariance;
    ScorePosterior out = posterior;
    out.covariance = inverseOfPositiveDefinite(n, std::move(precision));
    out.priorVariance = priorVariance;
    return out;
}

ScorePosterior fitPosterior(int conditions, const std::vector<Comparison>& answers, const PosteriorOptions& options) {
    if (conditions < 1) throw RuntimeError("active sampling: a block needs at least one condition");
    std::vector<Comparison> sorted = answers;
    for (const Comparison& c : sorted)
        if (c.winner < 0 || c.loser < 0 || c.winner >= conditions || c.loser >= conditions || c.winner == c.loser)
            throw RuntimeError("active sampling: answer (" + std::to_string(c.winner) + ", " + std::to_string(c.loser) +
                               ") does not name two of " + std::to_string(conditions) + " conditions");
    // All answers to one pair form one factor (a site per compared pair, at most m(m−1)/2 of them), in a canonical
    // order: the fixed point EP reaches, and the path to it, depend only on the multiset of answers.
    std::map<std::pair<int, int>, std::pair<double, double>> counts; // (i < j) → (i won, j won)
    for (const Comparison& c : sorted) {
        auto& entry = counts[{std::min(c.winner, c.loser), std::max(c.winner, c.loser)}];
        (c.winner < c.loser ? entry.first : entry.second) += 1.0;
    }
    std::vector<PairCount> pairs;
    for (const auto& [pair, won] : counts) pairs.push_back({pair.first, pair.second, won.first, won.second});
    return fitPosteriorFromCounts(conditions, pairs, options);
}

namespace {
ScorePosterior fitWithFixedPrior(int conditions, const std::vector<PairCount>& counts, const PosteriorOptions& options);
} // namespace

ScorePosterior fitPosteriorFromCounts(int conditions, const std::vector<PairCount>& counts,
                                      const PosteriorOptions& options) {
    ScorePosterior posterior = fitWithFixedPrior(conditions, counts, options);
    posterior.priorVariance = options.priorVariance;
    if (!options.empiricalPrior || counts.empty()) return posterior;
    // Empirical Bayes: the prior variance that maximises the marginal likelihood, by EM — v ← mean_i E[s_i²] =
    // mean_i (μ_i² + Σ_ii) under the current posterior — kept within [priorVariance, maxPriorVariance].
    PosteriorOptions current = options;
    for (int step = 0; step < 8; ++step) {
        double second = 0.0;
        for (int i = 0; i < conditions; ++i)
            second += posterior.mean[static_cast<std::size_t>(i)] * posterior.mean[static_cast<std::size_t>(i)] +
                      posterior.variance(i);
        const double next = std::clamp(second / conditions, options.priorVariance,
                                       std::max(options.priorVariance, options.maxPriorVariance));
        const bool settled = std::abs(next - current.priorVariance) < 0.01 * current.priorVariance;
        current.priorVariance = next;
        posterior = fitWithFixedPrior(conditions, counts, current);
        posterior.priorVariance = next;
        if (settled) break;
    }
    return posterior;
}

namespace {
ScorePosterior fitWithFixedPrior(int conditions, const std::vector<PairCount>& counts,
                                 const PosteriorOptions& options) {
    if (conditions < 1) throw RuntimeError("active sampling: a block needs at least one condition");
    std::vector<Comparison> ends; // site k is a function of d_k = q_ends[k].winner − q_ends[k].loser
    std::vector<double> iWon, jWon;
    double total = 0.0;
    for (std::size_t k = 0; k < counts.size(); ++k) {
        const PairCount& c = counts[k];
        if (c.i < 0 || c.j >= conditions || !(c.i < c.j) ||
            !(c.iWon >= 0.0 && c.jWon >= 0.0 && c.iWon + c.jWon > 0.0) ||
            (k > 0 && !(std::pair(counts[k - 1].i, counts[k - 1].j) < std::pair(c.i, c.j))))
            throw RuntimeError("active sampling: answer counts of pair (" + std::to_string(c.i) + ", " +
                               std::to_string(c.j) + ") are not sorted, unique, non-empty pairs of " +
                               std::to_string(conditions) + " conditions");
        ends.push_back({c.i, c.j});
        iWon.push_back(c.iWon);
        jWon.push_back(c.jWon);
        total += c.iWon + c.jWon;
    }
    const auto n = static_cast<std::size_t>(conditions);
    const double priorPrecision = 1.0 / options.priorVariance;
    ScorePosterior out =
        ScorePosterior::independent(std::vector<double>(n, 0.0), std::vector<double>(n, options.priorVariance));
    out.comparisons = static_cast<int>(total);
    out.converged = true;
    if (ends.empty()) return out;
    out.converged = false;

    // Site k: a Gaussian in d_k with precision π̃_k and shift τ̃_k (natural parameters).
    std::vector<double> sitePrecision(ends.size(), 0.0), siteShift(ends.size(), 0.0);
    std::vector<double>& mu = out.mean;
    std::vector<double>& sigma = out.covariance;
    std::vector<double> sa(n);
    std::vector<double> lastMean = mu, lastSd(n, std::sqrt(options.priorVariance));
    for (int sweep = 0; sweep < options.maxSweeps; ++sweep) {
        for (std::size_t k = 0; k < ends.size(); ++k) {
            const auto w = static_cast<std::size_t>(ends[k].winner), l = static_cast<std::size_t>(ends[k].loser);
            for (std::size_t i = 0; i < n; ++i) sa[i] = sigma[i * n + w] - sigma[i * n + l]; // Σ a
            const double md = mu[w] - mu[l];
            const double vd = sa[w] - sa[l]; // aᵀ Σ a
            // Cavity of d: the marginal without this site.
            const double cavityPrecision = 1.0 / vd - sitePrecision[k];
            const double cavityShift = md / vd - siteShift[k];
            if (!(cavityPrecision > 0.0)) continue; // cannot happen for log-concave sites (π̃ ≤ 1/vd); kept safe
            const double cv = 1.0 / cavityPrecision;
            const Moments tilted = tiltedMoments(cavityShift * cv, cv, iWon[k], jWon[k]);
            const double newPrecision = std::max(0.0, 1.0 / tilted.variance - cavityPrecision);
            const double newShift = tilted.mean / tilted.variance - cavityShift;
            const double dp = newPrecision - sitePrecision[k];
            const double dt = newShift - siteShift[k];
            sitePrecision[k] = newPrecision;
            siteShift[k] = newShift;
            // Σ ← Σ − dp/(1 + dp vd) (Σa)(Σa)ᵀ;  μ ← μ + (dt − dp md)/(1 + dp vd) Σa.
            const double denominator = 1.0 + dp * vd;
            const double gainCov = dp / denominator;
            const double gainMean = (dt - dp * md) / denominator;
            for (std::size_t i = 0; i < n; ++i) {
                mu[i] += gainMean * sa[i];
                const double si = gainCov * sa[i];
                double* row = &sigma[i * n];
                for (std::size_t j = 0; j < n; ++j) row[j] -= si * sa[j];
            }
        }
        recompute(conditions, priorPrecision, ends, sitePrecision, siteShift, mu, sigma);
        double change = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double sd = std::sqrt(sigma[i * n + i]);
            change = std::max({change, std::abs(mu[i] - lastMean[i]), std::abs(sd - lastSd[i])});
            lastMean[i] = mu[i];
            lastSd[i] = sd;
        }
        out.sweeps = sweep + 1;
        if (change < options.tolerance) {
            out.converged = true;
            break;
        }
    }
    return out;
}

} // namespace

double expectedInformationGain(const ScorePosterior& p, int i, int j) {
    const double md = p.mean[static_cast<std::size_t>(i)] - p.mean[static_cast<std::size_t>(j)];
    const double vd = std::max(p.cov(i, i) + p.cov(j, j) - 2.0 * p.cov(i, j), 1e-12);
    const double pi = normalCdf(md / std::sqrt(kThurstoneSigma * kThurstoneSigma + vd)); // predictive P(i wins)
    const Moments iWins = afterAnswer(md, vd);
    const Moments jWins = afterAnswer(-md, vd); // in terms of −d
    return pi * gaussianKl(iWins.mean, iWins.variance, md, vd) +
           (1.0 - pi) * gaussianKl(jWins.mean, jWins.variance, -md, vd);
}

std::vector<std::vector<double>> informationGains(const ScorePosterior& posterior) {
    const int m = posterior.conditions();
    std::vector<std::vector<double>> gains(static_cast<std::size_t>(m),
                                           std::vector<double>(static_cast<std::size_t>(m), 0.0));
    for (int i = 0; i < m; ++i)
        for (int j = i + 1; j < m; ++j)
            gains[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] =
                gains[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] =
                    expectedInformationGain(posterior, i, j);
    return gains;
}

namespace {
// Expected precision one answer adds to d = q_i − q_j (the variance after either answer, weighted by the
// predictive probabilities).
double answerPrecision(double md, double vd) {
    const double pi = normalCdf(md / std::sqrt(kThurstoneSigma * kThurstoneSigma + vd));
    const double vAfter = pi * afterAnswer(md, vd).variance + (1.0 - pi) * afterAnswer(-md, vd).variance;
    return std::max(0.0, 1.0 / vAfter - 1.0 / vd);
}

// Row means of Σ (for the centring: C Σ a = Σa − mean(Σa)).
std::vector<double> rowMeans(const ScorePosterior& p) {
    const std::size_t n = p.mean.size();
    std::vector<double> out(n, 0.0);
    for (std::size_t r = 0; r < n; ++r) {
        for (std::size_t c = 0; c < n; ++c) out[r] += p.covariance[c * n + r];
        out[r] /= static_cast<double>(n);
    }
    return out;
}

// π/(1 + π v) ‖C Σ a‖² for the pair (i, j).
double varianceReduction(const ScorePosterior& p, const std::vector<double>& rowMean, int i, int j) {
    const std::size_t n = p.mean.size();
    const auto ui = static_cast<std::size_t>(i), uj = static_cast<std::size_t>(j);
    const double vd =
        std::max(p.covariance[ui * n + ui] + p.covariance[uj * n + uj] - 2.0 * p.covariance[ui * n + uj], 1e-12);
    const double precision = answerPrecision(p.mean[ui] - p.mean[uj], vd);
    const double shift = rowMean[ui] - rowMean[uj];
    double norm = 0.0;
    for (std::size_t r = 0; r < n; ++r) {
        const double x = p.covariance[r * n + ui] - p.covariance[r * n + uj] - shift;
        norm += x * x;
    }
    return precision / (1.0 + precision * vd) * norm;
}
} // namespace

std::vector<std::vector<double>> pairValues(const ScorePosterior& posterior, BatchCriterion criterion) {
    if (criterion == BatchCriterion::informationGain) return informationGains(posterior);
    const int m = posterior.conditions();
    const std::vector<double> rowMean = rowMeans(posterior);
    std::vector<std::vector<double>> values(static_cast<std::size_t>(m),
                                            std::vector<double>(static_cast<std::size_t>(m), 0.0));
    for (int i = 0; i < m; ++i)
        for (int j = i + 1; j < m; ++j)
            values[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] =
                values[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] =
                    varianceReduction(posterior, rowMean, i, j);
    return values;
}

std::vector<std::pair<int, int>> spanningTreeBatch(const ScorePosterior& posterior, std::uint64_t tieSeed,
                                                   BatchCriterion criterion) {
    const int m = posterior.conditions();
    if (m < 2) return {};
    const auto gains = pairValues(posterior, criterion);
    const auto n = static_cast<std::size_t>(m);
    // Edge weights 1/gain with a seeded multiplicative jitter in [1, 1 + 1e-6] (ties only).
    SeededRandom random(tieSeed);
    std::vector<std::vector<double>> weight(n, std::vector<double>(n, 0.0));
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) {
            const double gain = std::max(gains[i][j], std::numeric_limits<double>::min());
            weight[i][j] = weight[j][i] = (1.0 / gain) * (1.0 + 1e-6 * random.unit());
        }
    // Prim's algorithm from a seeded root on the complete graph.
    std::vector<bool> inTree(n, false);
    std::vector<double> best(n, std::numeric_limits<double>::infinity());
    std::vector<std::size_t> parent(n, n);
    std::size_t current = static_cast<std::size_t>(random.below(n));
    inTree[current] = true;
    std::vector<std::pair<int, int>> edges;
    for (std::size_t added = 1; added < n; ++added) {
        for (std::size_t v = 0; v < n; ++v)
            if (!inTree[v] && weight[current][v] < best[v]) {
                best[v] = weight[current][v];
                parent[v] = current;
            }
        std::size_t next = n;
        for (std::size_t v = 0; v < n; ++v)
            if (!inTree[v] && (next == n || best[v] < best[next])) next = v;
        inTree[next] = true;
        edges.emplace_back(static_cast<int>(std::min(next, parent[next])),
                           static_cast<int>(std::max(next, parent[next])));
        current = next;
    }
    std::stable_sort(edges.begin(), edges.end(), [&gains](const auto& x, const auto& y) {
        return gains[static_cast<std::size_t>(x.first)][static_cast<std::size_t>(x.second)] >
               gains[static_cast<std::size_t>(y.first)][static_cast<std::size_t>(y.second)];
    });
    return edges;
}

namespace {
// The covariance after an answer to (i, j) not yet given: d's variance shrinks as after either answer (weighted by
// their predictive probabilities); as a site of precision π on d, Σ ← Σ − π/(1 + π v) (Σa)(Σa)ᵀ. The means are
// left as they are. `sa` is scratch space of m values.
void foldExpectedAnswer(ScorePosterior& p, std::size_t i, std::size_t j, std::vector<double>& sa) {
    const std::size_t n = p.mean.size();
    for (std::size_t r = 0; r < n; ++r) sa[r] = p.covariance[r * n + i] - p.covariance[r * n + j];
    const double vd = std::max(sa[i] - sa[j], 1e-12);
    const double precision = answerPrecision(p.mean[i] - p.mean[j], vd);
    const double gain = precision / (1.0 + precision * vd);
    for (std::size_t r = 0; r < n; ++r)
        for (std::size_t c = 0; c < n; ++c) p.covariance[r * n + c] -= gain * sa[r] * sa[c];
}
} // namespace

std::vector<std::pair<int, int>> greedyBatch(const ScorePosterior& posterior, int size, std::uint64_t tieSeed,
                                             BatchCriterion criterion) {
    const int m = posterior.conditions();
    if (m < 2 || size < 1) return {};
    const auto n = static_cast<std::size_t>(m);
    ScorePosterior p = posterior;
    SeededRandom random(tieSeed);
    std::vector<double> jitter(n * n);
    for (double& j : jitter) j = 1.0 + 1e-6 * random.unit();
    std::vector<std::pair<int, int>> out;
    std::vector<double> sa(n);
    for (int k = 0; k < size; ++k) {
        double best = -1.0;
        int bi = 0, bj = 1;
        const std::vector<double> rowMean =
            criterion == BatchCriterion::varianceReduction ? rowMeans(p) : std::vector<double>{};
        for (int i = 0; i < m; ++i)
            for (int j = i + 1; j < m; ++j) {
                const double value = criterion == BatchCriterion::informationGain ? expectedInformationGain(p, i, j)
                                                                                  : varianceReduction(p, rowMean, i, j);
                const double g = value * jitter[static_cast<std::size_t>(i) * n + static_cast<std::size_t>(j)];
                if (g > best) {
                    best = g;
                    bi = i;
                    bj = j;
                }
            }
        out.emplace_back(bi, bj);
        foldExpectedAnswer(p, static_cast<std::size_t>(bi), static_cast<std::size_t>(bj), sa);
    }
    return out;
}

std::vector<std::pair<int, int>> sequentialTreeBatch(const ScorePosterior& posterior, std::uint64_t tieSeed) {
    const int m = posterior.conditions();
    if (m < 2) return {};
    const auto n = static_cast<std::size_t>(m);
    ScorePosterior p = posterior;
    SeededRandom random(tieSeed);
    std::vector<double> jitter(n * n);
    for (double& j : jitter) j = 1.0 + 1e-6 * random.unit();
    std::vector<bool> inTree(n, false);
    inTree[static_cast<std::size_t>(random.below(n))] = true;
    std::vector<std::pair<int, int>> out;
    std::vector<double> sa(n);
    for (std::size_t added = 1; added < n; ++added) {
        const std::vector<double> rowMean = rowMeans(p);
        double best = -1.0;
        std::size_t bi = 0, bj = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (!inTree[i]) continue;
            for (std::size_t j = 0; j < n; ++j) {
                if (inTree[j]) continue;
                const double g = varianceReduction(p, rowMean, static_cast<int>(i), static_cast<int>(j)) *
                                 jitter[std::min(i, j) * n + std::max(i, j)];
                if (g > best) best = g, bi = i, bj = j;
            }
        }
        inTree[bj] = true;
        out.emplace_back(static_cast<int>(std::min(bi, bj)), static_cast<int>(std::max(bi, bj)));
        foldExpectedAnswer(p, bi, bj, sa);
    }
    return out;
}

} // namespace skinlab::analysis::scaling::active
