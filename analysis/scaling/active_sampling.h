#pragma once
// Active sampling of pairwise comparisons (ASAP: Mikhailiuk, Wilmot, Perez-Ortiz, Yue & Mantiuk, "Active sampling
// for pairwise comparisons via approximate message passing and information gain maximization", ICPR 2020).
//
// Model: Thurstone Case V in JOD units, P(i ≻ j) = Φ((q_i − q_j)/σ) with σ = 1.4826 (1 JOD = 75 % preference),
// the model `analyze scale` fits. The scores have a joint Gaussian posterior N(μ, Σ) starting from the prior
// N(0, v₀ I). Every answer is a probit factor on q_winner − q_loser; all answers to one pair form one factor
// Φ(d/σ)^a Φ(−d/σ)^b on its difference d, folded in by expectation propagation (Minka 2001): each compared pair
// keeps a Gaussian site message in d, and sweeps over the pairs (in a canonical order) replace a site by the
// moment-matched one (moments of the one-dimensional tilted distribution by quadrature) — a rank-one update of Σ
// — until the posterior no longer moves. Cost per sweep: O(p m²) for p compared pairs, independent of the number
// of answers. The full covariance matters: a fully factorised (TrueSkill-style)
// posterior treats every difference as equally well known once each score is, so the planner would keep
// comparing neighbours along a chain and the scale's ends would drift apart (measured: 2.9× the full design's
// RMSE at m = 30). The result depends only on the multiset of answers, never on their arrival order, so a posterior
// rebuilt from a stored database is identical to the one before.
//
// Expected information gain of comparing i with j (ASAP eq. 6): the expected Kullback–Leibler divergence of the
// posterior after the answer from the posterior now, averaged over the two answers with their predictive
// probabilities. An answer only reshapes the distribution of d = q_i − q_j (the rest given d is unchanged), so
// the gain is a one-dimensional KL of d's marginal. It is largest for close pairs (the answer is uncertain) whose
// difference is uncertain (the answer moves it). The study server ranks pairs by the expected reduction of the
// summed variance of the centred scores instead (below; it saved more trials over seeds). A batch is the minimum
// spanning tree of the complete graph weighted by 1/value: m − 1 pairs that touch every condition (a connected
// comparison graph) and favour the valuable pairs.
#include <cstdint>
#include <utility>
#include <vector>

namespace skinlab::analysis::scaling::active {

inline constexpr double kThurstoneSigma = 1.4826;

// One answer: `winner` was chosen over `loser` (condition indices).
struct Comparison {
    int winner = 0;
    int loser = 0;
};

struct PosteriorOptions {
    // Prior N(0, v₀) on every score, sd 1 JOD. The prior steers the first batches: a prior much wider than the
    // true spread spreads the early posterior means too far apart, and the gain then favours near neighbours, which
    // chains the comparison graph (measured at m = 30, true sd 1 JOD, 1740 comparisons: RMSE 0.266 with a prior sd
    // of 2 JOD, 0.220 with 1 JOD).
    double priorVariance = 1.0;
    // Empirical Bayes: the prior's variance estimated from the answers (EM on the marginal likelihood), at least
    // `priorVariance` and at most `maxPriorVariance`: a study does not know its scores' spread in advance, and the
    // best fixed prior is the true spread (docs/benchmarks.md, "Active sampling").
    bool empiricalPrior = false;
    double maxPriorVariance = 9.0;
    // Sweeps stop when no mean or standard deviation moved more than `tolerance` JOD in a sweep.
    int maxSweeps = 50;
    double tolerance = 1e-6;
};

struct ScorePosterior {
    std::vector<double> mean;       // JOD
    std::vector<double> covariance; // JOD², m × m, row-major
    int comparisons = 0;
    int sweeps = 0;
    bool converged = true;
    double priorVariance = 1.0; // the prior the posterior was fitted with (estimated with empiricalPrior)
    int conditions() const { return static_cast<int>(mean.size()); }
    double cov(int i, int j) const {
        return covariance[static_cast<std::size_t>(i) * mean.size() + static_cast<std::size_t>(j)];
    }
    double variance(int i) const { return cov(i, i); }
    // A posterior with independent scores (tests, and the prior).
    static ScorePosterior independent(const std::vector<double>& mean, const std::vector<double>& variance);
};

// The posterior of `conditions` scores given the answers (any order; indices must be in [0, conditions)).
ScorePosterior fitPosterior(int conditions, const std::vector<Comparison>& answers,
                            const PosteriorOptions& options = {});

// The same sites under another prior N(0, priorVariance) per score: the covariance (Σ⁻¹ − I/v + I/priorVariance)⁻¹
// with v the prior `posterior` was fitted with; the means are kept. A batch planned from the posterior under a wide
// prior values the comparisons by what the answers, not the prior, will have told the scale (the scale is fitted
// with a weak prior): with the fitted sd-1 prior, the differences between far-apart conditions look known from the
// prior alone.
ScorePosterior withPrior(const ScorePosterior& posterior, double priorVariance);

// All answers to one pair: i < j, i chosen `iWon` times over j, j `jWon` times over i.
struct PairCount {
    int i = 0, j = 0;
    double iWon = 0.0, jWon = 0.0;
    bool operator==(const PairCount&) const = default;
};
// The same posterior from answer counts per pair (pairs in increasing (i, j) order, each at most once, some answer
// each): fitPosterior(answers) counts its answers and calls this, so both give identical results.
ScorePosterior fitPosteriorFromCounts(int conditions, const std::vector<PairCount>& counts,
                                      const PosteriorOptions& options = {});

// Expected information gain (nats) of one more comparison of i and j under `posterior`.
double expectedInformationGain(const ScorePosterior& posterior, int i, int j);

// All pairs' gains, gains[i][j] = gains[j][i]; the diagonal is 0.
std::vector<std::vector<double>> informationGains(const ScorePosterior& posterior);

// What a batch maximises, per pair: the expected information gain of the pair (above), or the expected reduction
// of the summed posterior variance of the mean-centred scores (A-optimal design: what the scale's RMSE depends on),
// i.e. π/(1 + π v) ‖C Σ a‖² with π the expected precision of one answer on d, v = Var d, C the centring matrix.
enum class BatchCriterion { informationGain, varianceReduction };

// Every pair's value under `criterion`, values[i][j] = values[j][i]; the diagonal is 0.
std::vector<std::vector<double>> pairValues(const ScorePosterior& posterior, BatchCriterion criterion);

// The next batch: the minimum spanning tree over 1/value (Prim's algorithm, O(m²)), as (i, j) pairs with i < j,
// in decreasing order of value. `tieSeed` breaks ties deterministically (equal values, e.g. before any answer):
// each weight is scaled by a factor in [1, 1 + 1e-6] drawn from the seed, so different participants starting
// together get different trees, and a given seed always the same one.
// The study server plans with the variance-reduction criterion (docs/benchmarks.md, "Active sampling": over
// seeds it saved more than the information gain at m = 20–40).
std::vector<std::pair<int, int>> spanningTreeBatch(const ScorePosterior& posterior, std::uint64_t tieSeed,
                                                   BatchCriterion criterion = BatchCriterion::varianceReduction);

// An alternative batch (compared in bench_active_sampling; the server uses the spanning tree): `size` pairs chosen
// greedily, each the pair of highest gain under the posterior updated for the pairs already chosen. The update of
// a chosen pair is the one its answer will make to the covariance (a probit answer's precision on d, averaged over
// the two answers; the means are left as they are, the answer being unknown), so a batch does not spend several
// trials on one uncertain region. Ties broken by `tieSeed` as above.
std::vector<std::pair<int, int>> greedyBatch(const ScorePosterior& posterior, int size, std::uint64_t tieSeed,
                                             BatchCriterion criterion = BatchCriterion::informationGain);

// An alternative batch (bench_active_sampling --selection tree-sequential; the server uses spanningTreeBatch): a
// spanning tree grown from a seeded root, each edge the most valuable (variance reduction) pair joining a new
// condition, the values recomputed after each edge under the covariance its answer will leave (as greedyBatch).
std::vector<std::pair<int, int>> sequentialTreeBatch(const ScorePosterior& posterior, std::uint64_t tieSeed);

} // namespace skinlab::analysis::scaling::active
