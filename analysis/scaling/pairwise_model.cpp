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

// Log posterior = log-likelihood − prior − mean penalty; returns the data log-likelihood through `dataTerm`.
double objective(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& q, double* dataTerm) {
    double data = 0.0;
    for (size_t p = 0; p < counts.pairs.size(); ++p) {
        const double d = q[counts.pairs[p].first] - q[counts.pairs[p].second];
        if (counts.first[p] > 0) data += counts.first[p] * linkValues(options.model, d).logProbability;
        if (counts.second[p] > 0) data += counts.second[p] * linkValues(options.model, -d).logProbability;
    }
    const double m = static_cast<double>(q.size());
    const double sum = q.sum();
    // Σ_{i<j} (q_i − q_j)² = m Σ q² − (Σ q)²
    const double sumSquaredDifferences = m * q.squaredNorm() - sum * sum;
    if (dataTerm) *dataTerm = data;
    return data - 0.5 * options.priorPrecision * sumSquaredDifferences - 0.5 * sum * sum;
}

} // namespace

const char* modelName(Model model) { return model == Model::Thurstone ? "thurstone" : "bradley-terry"; }

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

// Gradient and negative Hessian (plus 1 1ᵀ for the mean penalty) of the log posterior at q.
void assemble(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& q, Eigen::VectorXd& gradient,
              Eigen::MatrixXd& information) {
    const int m = counts.conditions;
    const double md = static_cast<double>(m);
    const double sum = q.sum();
    // prior: −τ/2 Σ_{i<j}(q_i − q_j)²  ⇒  gradient −τ(m q − Σq), negative Hessian τ(m I − 1 1ᵀ);
    // mean penalty −½(Σq)²  ⇒  gradient −Σq, negative Hessian 1 1ᵀ.
    gradient =
        -options.priorPrecision * (md * q - Eigen::VectorXd::Constant(m, sum)) - Eigen::VectorXd::Constant(m, sum);
    information.setConstant(m, m, 1.0 - options.priorPrecision);
    information.diagonal().array() += options.priorPrecision * md;
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

} // namespace

double logPosterior(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& scores) {
    return objective(counts, options, scores, nullptr);
}

FitResult fitScores(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd* start) {
    const int m = counts.conditions;
    FitResult result;
    result.scores = start ? *start : Eigen::VectorXd::Zero(m);
    Eigen::VectorXd gradient(m);
    Eigen::MatrixXd information(m, m); // negative Hessian of the log posterior, plus 1 1ᵀ for the mean
    double current = objective(counts, options, result.scores, nullptr);
    const double md = static_cast<double>(m);

    for (result.iterations = 0; result.iterations < options.maxIterations; ++result.iterations) {
        assemble(counts, options, result.scores, gradient, information);
        const Eigen::LDLT<Eigen::MatrixXd> solver(information);
        Eigen::VectorXd step = solver.solve(gradient);
        // Backtracking: the log posterior is concave, so a full Newton step is accepted except far from the
        // optimum (large unanimous differences), where halving keeps every iteration an ascent.
        double scale = 1.0;
        Eigen::VectorXd candidate = result.scores + step;
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
    assemble(counts, options, result.scores, gradient, information);
    result.inverseInformation = information.ldlt().solve(Eigen::MatrixXd::Identity(m, m));
    // `information` has eigenvalue m along 1/√m (the mean penalty); remove that direction so the matrix is the
    // covariance of the mean-zero scores.
    result.inverseInformation.array() -= 1.0 / (md * md);
    objective(counts, options, result.scores, &result.logLikelihood);
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
        const Eigen::LDLT<Eigen::MatrixXd> solver(information);
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
