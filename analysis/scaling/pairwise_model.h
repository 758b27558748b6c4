#pragma once
// Maximum-likelihood scaling of paired-comparison counts: Thurstone Case V in JOD units (Perez-Ortiz & Mantiuk
// 2017, "A practical guide and software for analysing pairwise comparison experiments") and Bradley–Terry
// (Bradley & Terry 1952) expressed in the same JOD units, both with a weak Gaussian prior on every pairwise
// difference (keeps unanimous and disconnected designs finite) and the scale's mean fixed at 0.
#include <Eigen/Dense>

#include <utility>
#include <vector>

namespace skinlab::analysis::scaling {

// Thurstone Case V: P(i ≻ j) = Φ((q_i − q_j)/σ) with σ = 1.4826, so a difference of 1 JOD gives 75 %
// (Φ(1/1.4826) = Φ(0.67449) = 0.75).
inline constexpr double kThurstoneSigma = 1.4826;

enum class Model {
    Thurstone,   // probit link, σ = 1.4826 (JOD)
    BradleyTerry // logistic link P = 1/(1 + 3^(−d)), so 1 JOD is also exactly 75 %
};

const char* modelName(Model model);

// Link function of a model in JOD units: F(d) = P(i ≻ j) for d = q_i − q_j, with the first two derivatives of
// log F, which are all Newton's method needs.
struct LinkValues {
    double logProbability; // log F(d)
    double slope;          // d/dd log F(d)
    double curvature;      // d²/dd² log F(d)   (≤ 0: the log-likelihood is concave)
};
LinkValues linkValues(Model model, double difference);
double preferenceProbability(Model model, double difference);

// Counts of one block aggregated over (possibly weighted) observers: for each compared pair (i < j),
// `first[p]` = times i was chosen over j, `second[p]` = times j was chosen over i.
struct PairCounts {
    int conditions = 0;
    std::vector<std::pair<int, int>> pairs;
    Eigen::VectorXd first;
    Eigen::VectorXd second;
};

// The prior on the scores (docs/analysis.md, "Model").
enum class Prior {
    // skinlab's: a zero-mean Gaussian of precision FitOptions::priorPrecision on every difference q_i − q_j.
    Gaussian,
    // pwcmp's default ("gaussian" in pw_scale.m, Perez-Ortiz & Mantiuk 2017): for every compared pair a, the
    // probability of observing each compared pair's outcome at a's distance, normalised over the distances of all
    // compared pairs and summed; log(π_a + 0.1) enters the log posterior once per compared pair. Unanimous counts
    // are moved one answer toward a tie inside the prior (pw_scale's D_wUA). Data-dependent; Thurstone only.
    Pwcmp
};
const char* priorName(Prior prior);

struct FitOptions {
    Model model = Model::Thurstone;
    Prior prior = Prior::Gaussian;
    // Precision (1/JOD²) of the zero-mean Gaussian prior put on every difference q_i − q_j, compared or not.
    // 0.002 moves the pwcmp oracle (100 trials per compared pair) by 2.5e-4 JOD (0.01 would move it by 1.2e-3),
    // yet bounds a unanimous 10:0 pair (at 4.96 JOD) and ties the components of a disconnected design together.
    double priorPrecision = 0.002;
    int maxIterations = 100;
    double tolerance = 1e-10; // stop when the largest Newton step is below this (JOD)
};

// The Gaussian prior's strength on one score: the m − 1 differences a score enters add τ·m to the precision of
// each centred score (the prior's negative Hessian is τ(m I − 1 1ᵀ)), a N(0, 1/(τ·m)) prior on each score, so the
// prior strengthens as conditions are added (docs/analysis.md, "Model"). NaN for pwcmp's data-dependent prior.
double priorPrecisionPerScore(const FitOptions& options, int conditions);

struct FitResult {
    Eigen::VectorXd scores;             // JOD, mean 0
    Eigen::MatrixXd inverseInformation; // (−∇² log posterior + 1 1ᵀ)⁻¹ at the optimum; its diagonal is the
                                        // Fisher (model-based) variance of the mean-zero scores
    double logLikelihood = 0.0;         // data term only (no prior)
    Eigen::MatrixXd priorInformation;   // pwcmp's prior only: the prior's negative Hessian used at the optimum
    int iterations = 0;
    bool converged = false;
};

// Maximum a posteriori scores. `start` (optional) warm-starts Newton's method (used by the bootstrap).
// `priorInformation` (optional, pwcmp's prior only): a negative Hessian of the prior to use in every Newton step and
// in inverseInformation instead of differencing the prior's gradient (2m gradients a step). The bootstrap and the
// held-out screening pass the full-data fit's: each resample then converges to its own optimum (the same scores)
// about 25 times faster at 25 conditions, its information approximated in the prior's part only.
FitResult fitScores(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd* start = nullptr,
                    const Eigen::MatrixXd* priorInformation = nullptr);

// The log posterior that fitScores maximises (data term − prior − mean penalty) at given scores.
double logPosterior(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& scores);

// Maximum of the log posterior subject to aᵀq = value, for a contrast a orthogonal to 1 (so the scale's mean stays
// 0): the profile of the posterior along aᵀq. Newton's method on the Lagrangian, warm-started at `start`.
struct ConstrainedFit {
    Eigen::VectorXd scores;
    double logPosterior = 0.0;
    Eigen::VectorXd gradient;    // of the log posterior at `scores` (parallel to a at the optimum)
    Eigen::MatrixXd information; // negative Hessian of the log posterior plus 1 1ᵀ, at `scores`
    bool converged = false;
};
ConstrainedFit fitConstrained(const PairCounts& counts, const FitOptions& options, const Eigen::VectorXd& contrast,
                              double value, const Eigen::VectorXd& start);

// pwcmp's log prior Σ_a log(π_a + 0.1) over the compared pairs a of `counts` (Prior::Pwcmp), with its gradient in
// the scores when `gradient` is given.
// The link is the model's (pwcmp: Thurstone).
double pwcmpLogPrior(const PairCounts& counts, const Eigen::VectorXd& scores, Eigen::VectorXd* gradient,
                     Model model = Model::Thurstone);

// Log-likelihood of counts (per pair first/second) under given scores.
double logLikelihood(Model model, const std::vector<std::pair<int, int>>& pairs, const Eigen::VectorXd& first,
                     const Eigen::VectorXd& second, const Eigen::VectorXd& scores);

} // namespace skinlab::analysis::scaling
