#include "analysis/scaling/pairwise_model.h"

#include <algorithm>
#include <cmath>

namespace skinlab::analysis::scaling {
namespace {

constexpr double kInverseSqrt2 = 0.70710678118654752440;
constexpr double kInverseSqrt2Pi = 0.39894228040143267794;
// ln 3: with P = 1/(1 + e^(−ln3·d)), P(1 JOD) = 3/4, the same anchor as Thurstone's σ = 1.4826.
constexpr double kLogThree = 1.09861228866810969140;
// Beyond |x| = 35 the normal tail underflows double precision; the clamp only matters for absurd scores.
constexpr double kProbitClamp = 35.0;

LinkValues probit(double difference) {
    const double x = std::clamp(difference / kThurstoneSigma, -kProbitClamp, kProbitClamp);
    const double cdf = 0.5 * std::erfc(-x * kInverseSqrt2); // accurate in the lower tail, unlike 1 − erfc
    const double density = kInverseSqrt2Pi * std::exp(-0.5 * x * x);
    const double mills = density / cdf; // inverse Mills ratio λ(x) = φ(x)/Φ(x)
    return {std::log(cdf), mills / kThurstoneSigma, -mills * (x + mills) / (kThurstoneSigma * kThurstoneSigma)};
}

LinkValues logistic(double difference) {
    const double z = kLogThree * difference;
    // log F = −log(1 + e^(−z)), written so neither branch overflows.
    const double logProbability = z >= 0 ? -std::log1p(std::exp(-z)) : z - std::log1p(std::exp(z));
    const double probability = std::exp(logProbability);
    return {logProbability, kLogThree * (1.0 - probability),
            -kLogThree * kLogThree * probability * (1.0 - probability)};
}

// Connected components of the compared pairs (a total above 0): a label per condition, 0 … count − 1.
std::vector<int> componentLabels(const PairCounts& counts, int* count) {
    std::vector<int> label(counts.conditions);
    for (int i = 0; i < counts.conditions; ++i) label[i] = i;
    auto root = [&](int i) {
        while (label[i] != i) i = label[i] = label[label[i]];
        return i;
    };
    for (size_t p = 0; p < counts.pairs.size(); ++p)
        if (counts.first[p] + counts.second[p] > 0) label[root(counts.pairs[p].first)] = root(counts.pairs[p].second);
    std::vector<int> number(counts.conditions, -1);
    int next = 0;
    for (int i = 0; i < counts.conditions; ++i) {
        const int r = root(i);
        if (number[r] < 0) number[r] = next++;
    }
    std::vector<int> result(counts.conditions);
    for (int i = 0; i < counts.conditions; ++i) result[i] = number[root(i)];
    if (count) *count = next;
    return result;
}

// The mean penalty: −½ (Σ q)² (Gaussian prior, which ties every pair), or −½ Σ_c (Σ_{i∈c} q_i)² over the connected
// components (pwcmp's prior only involves compared pairs, so each component is centred on its own mean).
double meanPenalty(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& q) {
    if (options.prior == Prior::Gaussian) return 0.5 * q.sum() * q.sum();
    int count = 0;
    const std::vector<int> label = componentLabels(counts, &count);
    Eigen::VectorXd sums = Eigen::VectorXd::Zero(count);
    for (int i = 0; i < counts.conditions; ++i) sums[label[i]] += q[i];
    return 0.5 * sums.squaredNorm();
}

// Log posterior = log-likelihood + log prior − mean penalty; returns the data log-likelihood through `dataTerm`.
double objective(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& q, double* dataTerm) {
    double data = 0.0;
    for (size_t p = 0; p < counts.pairs.size(); ++p) {
        const double d = q[counts.pairs[p].first] - q[counts.pairs[p].second];
        if (counts.first[p] > 0) data += counts.first[p] * linkValues(options.model, d).logProbability;
        if (counts.second[p] > 0) data += counts.second[p] * linkValues(options.model, -d).logProbability;
    }
    if (dataTerm) *dataTerm = data;
    double prior = 0.0;
    if (options.prior == Prior::Gaussian) {
        const double m = static_cast<double>(q.size());
        const double sum = q.sum();
        // Σ_{i<j} (q_i − q_j)² = m Σ q² − (Σ q)²
        prior = -0.5 * options.priorPrecision * (m * q.squaredNorm() - sum * sum);
    } else {
        prior = pwcmpLogPrior(counts, q, nullptr, options.model);
    }
    return data + prior - meanPenalty(counts, options, q);
}

} // namespace

const char* modelName(Model model) { return model == Model::Thurstone ? "thurstone" : "bradley-terry"; }

const char* priorName(Prior prior) { return prior == Prior::Gaussian ? "gaussian" : "pwcmp"; }

double priorPrecisionPerScore(const FitOptions& options, int conditions) {
    return options.prior == Prior::Gaussian ? options.priorPrecision * conditions : NAN;
}

double pwcmpLogPrior(const PairCounts& counts, const Eigen::VectorXd& scores, Eigen::VectorXd* gradient, Model model) {
    // Every compared pair in both orders, as pw_scale's matrices: o = (i, j) with k_o answers for i out of n_o.
    struct Ordered {
        int i, j;
        double k, n;
    };
    std::vector<Ordered> ordered;
    for (size_t p = 0; p < counts.pairs.size(); ++p) {
        const double n = counts.first[p] + counts.second[p];
        if (n <= 0) continue;
        double k = counts.first[p];
        double kReverse = counts.second[p];
        // pw_scale's D_wUA: a unanimous pair is moved one answer toward a tie (0 → 1, n → n − 1).
        if (k == 0 || kReverse == 0) {
            k = k == 0 ? 1.0 : k - 1.0;
            kReverse = kReverse == 0 ? 1.0 : kReverse - 1.0;
        }
        ordered.push_back({counts.pairs[p].first, counts.pairs[p].second, k, n});
        ordered.push_back({counts.pairs[p].second, counts.pairs[p].first, kReverse, n});
    }
    const auto size = static_cast<Eigen::Index>(ordered.size());
    if (gradient) gradient->setZero(counts.conditions);
    if (size == 0) return 0.0;
    // Per distance o: log P_o, log(1 − P_o) and their derivatives in d_o = q_i − q_j.
    Eigen::VectorXd logP(size), logQ(size), slopeP(size), slopeQ(size);
    for (Eigen::Index o = 0; o < size; ++o) {
        const double d = scores[ordered[o].i] - scores[ordered[o].j];
        const LinkValues forward = linkValues(model, d), backward = linkValues(model, -d);
        logP[o] = forward.logProbability;
        logQ[o] = backward.logProbability;
        slopeP[o] = forward.slope;
        slopeQ[o] = -backward.slope;
    }
    // R(o, b) = P_o^k_b (1 − P_o)^(n_b − k_b) / Σ_o' (same): the probability of outcome b at distance o, normalised
    // over the distances (a softmax over o, computed in logs so that large counts do not underflow). The exponent is
    // the rank-2 matrix log P kᵀ + log(1 − P) (n − k)ᵀ.
    // `ordered` holds each compared pair in both orders, forward at 2h, reversed at 2h + 1, with the reversed
    // outcome k' = n − k and d' = −d: outcome 2h + 1 at distance o has the likelihood of outcome 2h at distance
    // swap(o) (2h ↔ 2h + 1). So R(o, 2h + 1) = R(swap(o), 2h), and only the forward columns are computed (half the
    // exponentials); sums over all outcomes b are sums over the forward ones of R(o, ·) and R(swap(o), ·).
    const Eigen::Index half = size / 2;
    Eigen::VectorXd k(half), rest(half);
    for (Eigen::Index h = 0; h < half; ++h) {
        k[h] = ordered[2 * h].k;
        rest[h] = ordered[2 * h].n - ordered[2 * h].k;
    }
    Eigen::MatrixXd share(size, half);
    share.noalias() = logP * k.transpose();
    share.noalias() += logQ * rest.transpose();
    const Eigen::RowVectorXd top = share.colwise().maxCoeff();
    share.rowwise() -= top;
    share = share.array().exp().matrix();
    const Eigen::RowVectorXd columnSums = share.colwise().sum();
    share.array().rowwise() /= columnSums.array();
    auto swapped = [&](const Eigen::VectorXd& v) { // v at swap(o)
        Eigen::VectorXd out(v.size());
        for (Eigen::Index h = 0; h < half; ++h) out[2 * h] = v[2 * h + 1], out[2 * h + 1] = v[2 * h];
        return out;
    };
    const Eigen::VectorXd forwardSums = share.rowwise().sum();
    const Eigen::VectorXd prior = forwardSums + swapped(forwardSums); // π_o
    // Each unordered pair appears twice with π equal in both orders; pw_scale's objective also counts the data
    // twice, so its log posterior is this sum halved.
    const double value = 0.5 * (prior.array() + 0.1).log().sum();
    if (gradient) {
        // ∂π_o/∂d_c = δ_oc Σ_b R(o,b) ℓ'_b(d_o) − Σ_b R(o,b) R(c,b) ℓ'_b(d_c), ℓ_b = k_b log P + (n_b − k_b) log(1 − P),
        // so ∂/∂d_c ½ Σ_o log(π_o + 0.1) = ½ Σ_b R(c,b) ℓ'_b(d_c) (w_c − u_b), w = 1/(π + 0.1), u_b = Σ_o w_o R(o,b);
        // with ℓ'_b(d_c) = k_b P'_c + (n_b − k_b) Q'_c that is ½ [P'_c (w_c (R k)_c − (R (k∘u))_c) + Q'_c (same with
        // n − k)]: matrix–vector products with the forward columns, the reversed ones by swap (u is the same for
        // both orders of an outcome, since w is).
        const Eigen::VectorXd w = (prior.array() + 0.1).inverse();
        const Eigen::VectorXd u = share.transpose() * w;
        const Eigen::VectorXd sk = share * k, sr = share * rest;
        const Eigen::VectorXd sku = share * k.cwiseProduct(u), sru = share * rest.cwiseProduct(u);
        const Eigen::VectorXd shareK = sk + swapped(sr), shareRest = sr + swapped(sk);
        const Eigen::VectorXd shareKU = sku + swapped(sru), shareRestU = sru + swapped(sku);
        for (Eigen::Index c = 0; c < size; ++c) {
            const double total =
                slopeP[c] * (w[c] * shareK[c] - shareKU[c]) + slopeQ[c] * (w[c] * shareRest[c] - shareRestU[c]);
            (*gradient)[ordered[c].i] += 0.5 * total;
            (*gradient)[ordered[c].j] -= 0.5 * total;
        }
    }
    return value;
}

LinkValues linkValues(Model model, double difference) {
    return model == Model::Thurstone ? probit(difference) : logistic(difference);
}

double preferenceProbability(Model model, double difference) {
    if (model == Model::Thurstone) return 0.5 * std::erfc(-difference / kThurstoneSigma * kInverseSqrt2);
    return 1.0 / (1.0 + std::exp(-kLogThree * difference));
}

double logLikelihood(Model model, const std::vector<std::pair<int, int>>& pairs, const Eigen::VectorXd& first,
                     const Eigen::VectorXd& second, const Eigen::VectorXd& scores) {
    double total = 0.0;
    for (size_t p = 0; p < pairs.size(); ++p) {
        const double d = scores[pairs[p].first] - scores[pairs[p].second];
        if (first[p] > 0) total += first[p] * linkValues(model, d).logProbability;
        if (second[p] > 0) total += second[p] * linkValues(model, -d).logProbability;
    }
    return total;
}

namespace {

// Adds the mean penalty's gradient and negative Hessian: 1 1ᵀ (Gaussian prior) or Σ_c 1_c 1_cᵀ (pwcmp's).
void addMeanPenalty(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& q,
                    Eigen::VectorXd& gradient, Eigen::MatrixXd& information) {
    const int m = counts.conditions;
    int count = 1;
    const std::vector<int> label =
        options.prior == Prior::Gaussian ? std::vector<int>(m, 0) : componentLabels(counts, &count);
    Eigen::VectorXd sums = Eigen::VectorXd::Zero(count);
    for (int i = 0; i < m; ++i) sums[label[i]] += q[i];
    for (int i = 0; i < m; ++i) {
        gradient[i] -= sums[label[i]];
        for (int j = 0; j < m; ++j)
            if (label[i] == label[j]) information(i, j) += 1.0;
    }
}

void addData(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& q, Eigen::VectorXd& gradient,
             Eigen::MatrixXd& information);

// Gradient and negative Hessian (plus the mean penalty's) of the log posterior at q.
// `priorInformation` (pwcmp's prior only, optional): the prior's negative Hessian to use instead of differencing
// its gradient (the bootstrap passes the full-data fit's); Newton's method then still converges to the same
// optimum. `priorInformationOut` (optional) receives the prior's negative Hessian that was used.
// `priorGradient` false: the prior's gradient is not needed (only the information), which saves its evaluation.
void assemble(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& q, Eigen::VectorXd& gradient,
              Eigen::MatrixXd& information, const Eigen::MatrixXd* priorInformation = nullptr,
              Eigen::MatrixXd* priorInformationOut = nullptr, bool priorGradient = true) {
    const int m = counts.conditions;
    const double md = static_cast<double>(m);
    gradient.setZero(m);
    information.setZero(m, m);
    if (options.prior == Prior::Gaussian) {
        // prior: −τ/2 Σ_{i<j}(q_i − q_j)²  ⇒  gradient −τ(m q − Σq), negative Hessian τ(m I − 1 1ᵀ).
        gradient = -options.priorPrecision * (md * q - Eigen::VectorXd::Constant(m, q.sum()));
        information.setConstant(m, m, -options.priorPrecision);
        information.diagonal().array() += options.priorPrecision * md;
    } else {
        // pwcmp's prior: analytic gradient; its Hessian by central differences of the gradient (the prior is a
        // smooth function of the distances; h = 10⁻⁵ JOD leaves an error near 10⁻¹⁰).
        if (priorGradient) pwcmpLogPrior(counts, q, &gradient, options.model);
        if (priorInformation != nullptr && priorInformation->rows() == m) {
            information = *priorInformation;
        } else {
            constexpr double h = 1e-5;
            Eigen::VectorXd up(m), down(m);
            for (int k = 0; k < m; ++k) {
                Eigen::VectorXd shifted = q;
                shifted[k] += h;
                pwcmpLogPrior(counts, shifted, &up, options.model);
                shifted[k] -= 2.0 * h;
                pwcmpLogPrior(counts, shifted, &down, options.model);
                information.col(k) = -(up - down) / (2.0 * h);
            }
            information = 0.5 * (information + information.transpose()).eval();
        }
        if (priorInformationOut) *priorInformationOut = information;
    }
    addMeanPenalty(counts, options, q, gradient, information);
    addData(counts, options, q, gradient, information);
}

// The data term's gradient and negative Hessian.
void addData(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& q, Eigen::VectorXd& gradient,
             Eigen::MatrixXd& information) {
    for (size_t p = 0; p < counts.pairs.size(); ++p) {
        const auto [i, j] = counts.pairs[p];
        const double d = q[i] - q[j];
        double slope = 0.0, weight = 0.0;
        if (counts.first[p] > 0) {
            const LinkValues v = linkValues(options.model, d);
            slope += counts.first[p] * v.slope;
            weight -= counts.first[p] * v.curvature;
        }
        if (counts.second[p] > 0) {
            const LinkValues v = linkValues(options.model, -d);
            slope -= counts.second[p] * v.slope;
            weight -= counts.second[p] * v.curvature;
        }
        gradient[i] += slope;
        gradient[j] -= slope;
        information(i, i) += weight;
        information(j, j) += weight;
        information(i, j) -= weight;
        information(j, i) -= weight;
    }
}

// LDLT of the information for a Newton step. pwcmp's prior is not concave: where the information is not positive
// definite, a multiple of the identity is added until it is (Levenberg), so the step still ascends.
Eigen::LDLT<Eigen::MatrixXd> newtonSolver(const Eigen::MatrixXd& information) {
    Eigen::LDLT<Eigen::MatrixXd> solver(information);
    double damping = 1e-6 * std::max(1.0, information.diagonal().cwiseAbs().maxCoeff());
    while (solver.info() != Eigen::Success || solver.vectorD().minCoeff() <= 0.0) {
        solver.compute(information + damping * Eigen::MatrixXd::Identity(information.rows(), information.cols()));
        damping *= 10.0;
        if (damping > 1e12) break;
    }
    return solver;
}

} // namespace

double logPosterior(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& scores) {
    return objective(counts, options, scores, nullptr);
}

FitResult fitScores(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd* start,
                    const Eigen::MatrixXd* priorInformation) {
    const int m = counts.conditions;
    FitResult result;
    result.scores = start ? *start : Eigen::VectorXd::Zero(m);
    Eigen::VectorXd gradient(m);
    Eigen::MatrixXd information(m, m); // negative Hessian of the log posterior, plus 1 1ᵀ for the mean
    double current = 0.0;
    bool stale = true; // `current` is not (yet) the posterior at result.scores: evaluated when a step needs it

    // pwcmp's prior without a given Hessian: differenced at the first two steps, then reused (the prior changes
    // slowly near the optimum; the gradient is exact, so the optimum is the same), and differenced again at the
    // optimum for inverseInformation.
    Eigen::MatrixXd lastPriorInformation;
    for (result.iterations = 0; result.iterations < options.maxIterations; ++result.iterations) {
        const bool reuse = options.prior == Prior::Pwcmp && priorInformation == nullptr && result.iterations >= 2;
        assemble(
            counts, options, result.scores, gradient, information, reuse ? &lastPriorInformation : priorInformation,
            options.prior == Prior::Pwcmp && priorInformation == nullptr && !reuse ? &lastPriorInformation : nullptr);
        const Eigen::LDLT<Eigen::MatrixXd> solver = newtonSolver(information);
        Eigen::VectorXd step = solver.solve(gradient);
        // Backtracking: the log posterior is concave, so a full Newton step is accepted except far from the
        // optimum (large unanimous differences), where halving keeps every iteration an ascent. With pwcmp's prior
        // and a given prior Hessian (a warm-started resample near its optimum), a step below 0.25 JOD is taken
        // without evaluating the posterior: the gradient alone decides convergence, at half the cost a step.
        double scale = 1.0;
        Eigen::VectorXd candidate = result.scores + step;
        if (priorInformation != nullptr && options.prior == Prior::Pwcmp && step.cwiseAbs().maxCoeff() < 0.25) {
            result.scores = candidate;
            stale = true;
            if (step.cwiseAbs().maxCoeff() < options.tolerance) {
                result.converged = true;
                ++result.iterations;
                break;
            }
            continue;
        }
        if (stale) current = objective(counts, options, result.scores, nullptr);
        stale = false;
        double value = objective(counts, options, candidate, nullptr);
        while (value < current - 1e-12 * std::abs(current) && scale > 1e-6) {
            scale *= 0.5;
            candidate = result.scores + scale * step;
            value = objective(counts, options, candidate, nullptr);
        }
        result.scores = candidate;
        current = value;
        if ((scale * step).cwiseAbs().maxCoeff() < options.tolerance) {
            result.converged = true;
            ++result.iterations;
            break;
        }
    }
    assemble(counts, options, result.scores, gradient, information, priorInformation,
             options.prior == Prior::Pwcmp ? &result.priorInformation : nullptr, false);
    result.inverseInformation = newtonSolver(information).solve(Eigen::MatrixXd::Identity(m, m));
    // `information` has eigenvalue |c| along 1_c/√|c| for the mean penalty of each centred group c (all conditions
    // under the Gaussian prior, each connected component under pwcmp's); remove those directions so the matrix is
    // the covariance of the centred scores.
    int groups = 1;
    const std::vector<int> label =
        options.prior == Prior::Gaussian ? std::vector<int>(m, 0) : componentLabels(counts, &groups);
    std::vector<double> groupSize(groups, 0.0);
    for (int i = 0; i < m; ++i) groupSize[label[i]] += 1.0;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j)
            if (label[i] == label[j])
                result.inverseInformation(i, j) -= 1.0 / (groupSize[label[i]] * groupSize[label[i]]);
    result.logLikelihood = logLikelihood(options.model, counts.pairs, counts.first, counts.second, result.scores);
    return result;
}

ConstrainedFit fitConstrained(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& contrast,
                              double value, const Eigen::VectorXd& start) {
    const int m = counts.conditions;
    ConstrainedFit result;
    result.scores = start + contrast * ((value - contrast.dot(start)) / contrast.squaredNorm());
    Eigen::VectorXd gradient(m);
    Eigen::MatrixXd information(m, m);
    double current = objective(counts, options, result.scores, nullptr);
    for (int iteration = 0; iteration < options.maxIterations; ++iteration) {
        assemble(counts, options, result.scores, gradient, information);
        // Newton step of the Lagrangian: maximise along the directions that keep aᵀq fixed,
        // step = I⁻¹(g − μ a) with μ chosen so that aᵀ step = 0.
        const Eigen::LDLT<Eigen::MatrixXd> solver = newtonSolver(information);
        const Eigen::VectorXd towardOptimum = solver.solve(gradient);
        const Eigen::VectorXd alongContrast = solver.solve(contrast);
        const Eigen::VectorXd step =
            towardOptimum - alongContrast * (contrast.dot(towardOptimum) / contrast.dot(alongContrast));
        double scale = 1.0;
        Eigen::VectorXd candidate = result.scores + step;
        double candidateValue = objective(counts, options, candidate, nullptr);
        while (candidateValue < current - 1e-12 * std::abs(current) && scale > 1e-6) {
            scale *= 0.5;
            candidate = result.scores + scale * step;
            candidateValue = objective(counts, options, candidate, nullptr);
        }
        result.scores = candidate;
        current = candidateValue;
        if ((scale * step).cwiseAbs().maxCoeff() < options.tolerance) {
            result.converged = true;
            break;
        }
    }
    assemble(counts, options, result.scores, gradient, information);
    result.logPosterior = current;
    result.gradient = gradient;
    result.information = information;
    return result;
}

} // namespace skinlab::analysis::scaling
