// Active sampling against the alternatives (docs/benchmarks.md, "Active sampling"; docs/analysis.md,
// "Validation of active designs"). Simulated Thurstone observers answer designs of conditions with known true
// scores (drawn from N(0, sd²) JOD and centred):
//  - full:   every pair once per round, rounds repeated (each round in a random order);
//  - random: each comparison a uniformly random pair (an incomplete random design);
//  - active: batches of m − 1 pairs, each the minimum spanning tree over 1/(expected reduction of the summed
//            variance of the centred scores) of the posterior built from every answer so far
//            (analysis/scaling/active_sampling.h, as the study server plans them; --selection picks another).
// Each observer answers m − 1 consecutive comparisons (one active batch). The scale is fitted exactly as
// `analyze scale` fits it (Thurstone Case V MAP, analysis/scaling) and its RMSE against the truth (both
// mean-zero) recorded.
//
// --sweep (the saving, as docs/benchmarks.md reports it): for every (m, sd, budget) cell and each of --seeds
// seeds, one true scale, one full design up to the budget and one active design up to --horizon × the largest
// budget, its RMSE after every observer. The saving at a budget B (in full rounds of m(m−1)/2 comparisons) is
// 1 − N/B, N the comparisons after which the active design first reaches the full design's RMSE at B
// (interpolated between observers):
//  - pooled: the mean squared errors averaged over the seeds first (the expected accuracy of a study of that
//    size), with a 95 % percentile interval from resampling the seeds;
//  - per seed: the same seed's active curve against its own full design — the spread a single study sees; a
//    seed whose active design never reaches the target within the horizon counts as a saving below
//    1 − horizon·B/B and stays in the quantiles and shares.
// Also per cell: the asymptotic upper bound on the saving of any allocation of comparisons to pairs
// (analysis/scaling/design_efficiency.h), averaged over the seeds' true scales.
//
// Default mode: per m = 10, 20, 30, the RMSE curves averaged over --experiments experiments, coverage of the
// studentized bootstrap and profile-likelihood intervals at a few budgets, and the planning time of one batch
// at m = 30 with 200 participants' answers (the server's request path).
//
// Usage: bench_active_sampling [--experiments E] [--coverage-experiments C] [--bootstrap B] [--spread S]
//                              [--truth normal|uniform] [--prior-sd P]
//                              [--selection mst-variance|mst-gain|greedy|variance|tree-sequential|oracle] [--batch K]
//                              [--plan-prior-sd P] [--empirical-prior] [--rounds R] [--threads T]
//                              [--seed N] [--timing 0|1] [--coverage-rounds 1,2] [--plot FILE.png]
//        bench_active_sampling --sweep [--seeds S] [--ms 10,20,30,40] [--spreads 1,2,3] [--budgets 1,2]
//                              [--horizon H] [--selection ...] [--batch K] [--prior-sd P] [--plan-prior-sd P]
//                              [--threads T] [--seed N]
// --batch K: only the first K pairs of each planned batch are used before re-planning (the design's active_batch);
// --plan-prior-sd P: pairs valued under a prior of sd P (same sites, ac::withPrior); --selection oracle: the
// A-optimal allocation for the true scores (sc::optimalAllocation), each trial the pair furthest behind its share;
// --selection tree-sequential: ac::sequentialTreeBatch.
#include "analysis/scaling/bootstrap.h"
#include "analysis/scaling/design_efficiency.h"
#include "analysis/scaling/pairwise_model.h"
#include "analysis/scaling/profile_likelihood.h"
#include "analysis/scaling/active_sampling.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <thread>
#include <vector>

using namespace skinlab;
namespace sc = skinlab::analysis::scaling;
namespace ac = skinlab::analysis::scaling::active;

namespace {

struct Trial {
    int first = 0, second = 0; // first < second
    bool firstWins = true;
};

struct Settings {
    int experiments = 60;
    int coverageExperiments = 30;
    int bootstrap = 200;
    double spread = 1.0; // true scores ~ N(0, spread²) JOD, or uniform with this sd
    std::string truth = "normal";
    double priorSd = 1.0;        // prior sd of the active design's posterior (JOD)
    bool empiricalPrior = false; // --empirical-prior: the prior's sd estimated from the answers (≥ priorSd)
    std::string selection = "mst-variance"; // active batches (the server's), mst-gain, greedy or variance
    double planPriorSd = 0.0; // --plan-prior-sd P: batches valued under a prior of sd P (0: the fitted prior)
    int batch = 0; // --batch K: trials used from each planned batch before re-planning (0: the whole batch, m − 1)
    bool timing = true;
    std::vector<double> coverageRounds = {0.6, 1.0, 1.2, 2.0, 2.4}; // coverage budgets, in full rounds
    int rounds = 4;                                                 // longest design, in full-design rounds m(m−1)/2
    int threads = 2;
    std::uint64_t seed = 1;
    std::string plot;
    // --sweep: the saving per seed and pooled, over `seeds` seeds per (m, spread, budget) cell.
    bool sweep = false;
    int seeds = 100;
    std::vector<double> ms = {10, 20, 30, 40};
    std::vector<double> spreads = {1, 2, 3};
    std::vector<double> budgets = {1, 2}; // in full rounds
    double horizon = 1.5;                 // the active design runs to horizon × the largest budget
    int intervalResamples = 2000;         // bootstrap over seeds for the pooled saving's interval
};

const char* kDesigns[] = {"full", "random", "active"};

bool answer(std::mt19937_64& random, const std::vector<double>& truth, int i, int j) {
    std::normal_distribution<double> noise(0.0, ac::kThurstoneSigma / std::sqrt(2.0));
    return truth[static_cast<std::size_t>(i)] + noise(random) > truth[static_cast<std::size_t>(j)] + noise(random);
}

Trial make(std::mt19937_64& random, const std::vector<double>& truth, int i, int j) {
    if (i > j) std::swap(i, j);
    return {i, j, answer(random, truth, i, j)};
}

// The block as the analysis sees it: observers of `perObserver` consecutive trials, compared pairs only.
sc::BlockData blockOf(const std::vector<Trial>& trials, std::size_t count, int m, int perObserver) {
    sc::BlockData block;
    block.name = "simulated";
    for (int i = 0; i < m; ++i) block.conditions.push_back("c" + std::to_string(i));
    const int observers =
        static_cast<int>((count + static_cast<std::size_t>(perObserver) - 1) / static_cast<std::size_t>(perObserver));
    for (int k = 0; k < observers; ++k) block.observers.push_back("o" + std::to_string(k));
    std::map<std::pair<int, int>, int> column;
    for (std::size_t t = 0; t < count; ++t) {
        const auto key = std::make_pair(trials[t].first, trials[t].second);
        if (!column.count(key)) {
            column.emplace(key, static_cast<int>(block.pairs.size()));
            block.pairs.push_back(key);
        }
    }
    const auto pairs = static_cast<Eigen::Index>(block.pairs.size());
    block.winsFirst = Eigen::MatrixXd::Zero(observers, pairs);
    block.winsSecond = Eigen::MatrixXd::Zero(observers, pairs);
    block.sideCounts.assign(block.pairs.size(), {0, 0, 0, 0});
    block.leftChosen = Eigen::VectorXd::Zero(observers);
    block.sideTrials = Eigen::VectorXd::Zero(observers);
    for (std::size_t t = 0; t < count; ++t) {
        const int k = static_cast<int>(t / static_cast<std::size_t>(perObserver));
        const int p = column.at({trials[t].first, trials[t].second});
        (trials[t].firstWins ? block.winsFirst : block.winsSecond)(k, p) += 1.0;
    }
    return block;
}

// The active design's selection as the server would run it, or an alternative (--selection).
std::vector<std::pair<int, int>> plan(const ac::ScorePosterior& fitted, int m, std::uint64_t tieSeed,
                                      const Settings& settings) {
    const ac::ScorePosterior posterior =
        settings.planPriorSd > 0.0 ? ac::withPrior(fitted, settings.planPriorSd * settings.planPriorSd) : fitted;
    if (settings.selection == "greedy") return ac::greedyBatch(posterior, m - 1, tieSeed);
    if (settings.selection == "variance")
        return ac::greedyBatch(posterior, m - 1, tieSeed, ac::BatchCriterion::varianceReduction);
    if (settings.selection == "tree-sequential") return ac::sequentialTreeBatch(posterior, tieSeed);
    if (settings.selection == "mst-gain")
        return ac::spanningTreeBatch(posterior, tieSeed, ac::BatchCriterion::informationGain);
    return ac::spanningTreeBatch(posterior, tieSeed, ac::BatchCriterion::varianceReduction);
}

std::vector<Trial> simulateDesign(int design, const std::vector<double>& truth, std::size_t length, std::uint64_t seed,
                                  const Settings& settings) {
    const int m = static_cast<int>(truth.size());
    std::mt19937_64 random(seed);
    std::vector<Trial> trials;
    trials.reserve(length);
    if (design == 0) {
        std::vector<std::pair<int, int>> pairs;
        for (int i = 0; i < m; ++i)
            for (int j = i + 1; j < m; ++j) pairs.emplace_back(i, j);
        while (trials.size() < length) {
            std::shuffle(pairs.begin(), pairs.end(), random);
            for (const auto& [i, j] : pairs)
                if (trials.size() < length) trials.push_back(make(random, truth, i, j));
        }
    } else if (design == 1) {
        std::uniform_int_distribution<int> pick(0, m - 1);
        while (trials.size() < length) {
            const int i = pick(random);
            int j = pick(random);
            while (j == i) j = pick(random);
            trials.push_back(make(random, truth, i, j));
        }
    } else if (settings.selection == "oracle") {
        // The A-optimal allocation for the true scores (what no study knows): each trial the pair furthest behind its
        // share, so the counts follow the shares at every length.
        const std::vector<double> share = sc::optimalAllocation(truth);
        std::vector<std::pair<int, int>> pairs;
        for (int i = 0; i < m; ++i)
            for (int j = i + 1; j < m; ++j) pairs.emplace_back(i, j);
        std::vector<double> count(pairs.size(), 0.0);
        while (trials.size() < length) {
            const double next = static_cast<double>(trials.size() + 1);
            std::size_t best = 0;
            for (std::size_t p = 1; p < pairs.size(); ++p)
                if (share[p] * next - count[p] > share[best] * next - count[best]) best = p;
            count[best] += 1.0;
            trials.push_back(make(random, truth, pairs[best].first, pairs[best].second));
        }
    } else {
        std::vector<ac::Comparison> answers;
        std::uint64_t batch = 0;
        ac::PosteriorOptions posteriorOptions;
        posteriorOptions.priorVariance = settings.priorSd * settings.priorSd;
        posteriorOptions.empiricalPrior = settings.empiricalPrior;
        while (trials.size() < length) {
            const ac::ScorePosterior posterior = ac::fitPosterior(m, answers, posteriorOptions);
            const std::uint64_t tieSeed = seed * 1000003u + batch++;
            auto pairs = plan(posterior, m, tieSeed, settings);
            if (settings.batch > 0 && pairs.size() > static_cast<std::size_t>(settings.batch))
                pairs.resize(static_cast<std::size_t>(settings.batch));
            for (const auto& [i, j] : pairs) {
                if (trials.size() >= length) break;
                const Trial t = make(random, truth, i, j);
                trials.push_back(t);
                answers.push_back(t.firstWins ? ac::Comparison{t.first, t.second} : ac::Comparison{t.second, t.first});
            }
        }
    }
    return trials;
}

double rmse(const Eigen::VectorXd& scores, const std::vector<double>& truth) {
    double sum = 0.0;
    for (Eigen::Index i = 0; i < scores.size(); ++i) {
        const double d = scores[i] - truth[static_cast<std::size_t>(i)];
        sum += d * d;
    }
    return std::sqrt(sum / static_cast<double>(scores.size()));
}

struct Curve {
    std::vector<double> comparisons;
    std::vector<double> sumSquared; // Σ over experiments of the mean squared error
    std::vector<double> rmse() const {
        std::vector<double> out;
        for (double s : sumSquared) out.push_back(s);
        return out;
    }
};

// Interpolated number of comparisons at which `curve` first reaches `target` (−1 if never).
double reachedAt(const std::vector<double>& x, const std::vector<double>& y, double target) {
    for (std::size_t k = 0; k < y.size(); ++k) {
        if (y[k] <= target) {
            if (k == 0) return x[0];
            const double f = (y[k - 1] - target) / (y[k - 1] - y[k]);
            return x[k - 1] + f * (x[k] - x[k - 1]);
        }
    }
    return -1.0;
}

struct CoverageCell {
    double covered = 0, total = 0;
    std::vector<double> widths;
    // Median width: a mean is dominated by the few experiments whose ML estimate does not exist (a condition that
    // always won or always lost) at small budgets, where the interval is as wide as the prior lets it be.
    double medianWidth() const {
        std::vector<double> sorted = widths;
        std::sort(sorted.begin(), sorted.end());
        return sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
    }
};

void drawPlot(const std::string& file, const std::vector<int>& ms,
              const std::vector<std::vector<std::vector<double>>>& curves, const std::vector<std::vector<double>>& xs,
              const Settings& settings) {
    const int panelW = 420, panelH = 340, left = 70, top = 50, bottom = 60;
    cv::Mat image(panelH + top + bottom, static_cast<int>(ms.size()) * panelW + 20, CV_8UC3, cv::Scalar(255, 255, 255));
    const cv::Scalar colours[] = {cv::Scalar(40, 40, 40), cv::Scalar(30, 140, 230), cv::Scalar(180, 90, 30)};
    const int font = cv::FONT_HERSHEY_SIMPLEX;
    char buf[128];
    std::snprintf(buf, sizeof buf, "Scale RMSE (JOD) vs comparisons; true scores ~ N(0, %.1f^2) JOD, %d experiments",
                  settings.spread, settings.experiments);
    cv::putText(image, buf, {20, 22}, font, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    for (std::size_t p = 0; p < ms.size(); ++p) {
        const int x0 = static_cast<int>(p) * panelW + left, y0 = top, w = panelW - left - 20, h = panelH - 20;
        double ymax = 0;
        for (const auto& c : curves[p])
            for (std::size_t k = 0; k < c.size(); ++k) ymax = std::max(ymax, c[k]);
        ymax = std::min(ymax, 1.5);
        const double xmax = xs[p].back();
        auto px = [&](double x) { return x0 + static_cast<int>(std::lround(w * x / xmax)); };
        auto py = [&](double y) { return y0 + h - static_cast<int>(std::lround(h * std::min(y, ymax) / ymax)); };
        cv::rectangle(image, {x0, y0}, {x0 + w, y0 + h}, cv::Scalar(150, 150, 150));
        const int M = ms[p] * (ms[p] - 1) / 2;
        for (int r = 1; r <= settings.rounds; ++r) {
            const int gx = px(static_cast<double>(r * M));
            cv::line(image, {gx, y0}, {gx, y0 + h}, cv::Scalar(225, 225, 225));
            std::snprintf(buf, sizeof buf, "%d", r * M);
            cv::putText(image, buf, {gx - 14, y0 + h + 18}, font, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
        }
        for (int t = 0; t <= 4; ++t) {
            const double y = ymax * t / 4.0;
            std::snprintf(buf, sizeof buf, "%.2f", y);
            cv::putText(image, buf, {x0 - 42, py(y) + 4}, font, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
            cv::line(image, {x0, py(y)}, {x0 + w, py(y)}, cv::Scalar(235, 235, 235));
        }
        for (std::size_t d = 0; d < 3; ++d) {
            const auto& c = curves[p][d];
            for (std::size_t k = 1; k < c.size(); ++k)
                cv::line(image, {px(xs[p][k - 1]), py(c[k - 1])}, {px(xs[p][k]), py(c[k])}, colours[d], 2, cv::LINE_AA);
            cv::line(image, {x0 + w - 110, y0 + 18 + 18 * static_cast<int>(d)},
                     {x0 + w - 85, y0 + 18 + 18 * static_cast<int>(d)}, colours[d], 2, cv::LINE_AA);
            cv::putText(image, kDesigns[d], {x0 + w - 78, y0 + 22 + 18 * static_cast<int>(d)}, font, 0.45, colours[d],
                        1, cv::LINE_AA);
        }
        std::snprintf(buf, sizeof buf, "m = %d (grid: full rounds)", ms[p]);
        cv::putText(image, buf, {x0 + 10, y0 + h + 42}, font, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    }
    cv::imwrite(file, image);
}

// RMSE of `analyze scale`'s fit after each of `points` prefixes of `trials` (prefix lengths ascending).
std::vector<double> rmseAt(const std::vector<Trial>& trials, const std::vector<std::size_t>& points,
                           const std::vector<double>& truth) {
    const int m = static_cast<int>(truth.size());
    std::map<std::pair<int, int>, std::pair<double, double>> tally;
    std::vector<double> out;
    sc::FitOptions fitOptions;
    Eigen::VectorXd warm;
    std::size_t done = 0;
    for (const std::size_t point : points) {
        for (; done < point; ++done) {
            auto& entry = tally[{trials[done].first, trials[done].second}];
            (trials[done].firstWins ? entry.first : entry.second) += 1.0;
        }
        sc::PairCounts counts;
        counts.conditions = m;
        counts.first.resize(static_cast<Eigen::Index>(tally.size()));
        counts.second.resize(static_cast<Eigen::Index>(tally.size()));
        Eigen::Index k = 0;
        for (const auto& [pair, won] : tally) {
            counts.pairs.push_back(pair);
            counts.first[k] = won.first;
            counts.second[k++] = won.second;
        }
        const sc::FitResult fit = sc::fitScores(counts, fitOptions, warm.size() == m ? &warm : nullptr);
        warm = fit.scores;
        out.push_back(rmse(fit.scores, truth));
    }
    return out;
}

// One seed of one (m, spread) cell: the full design's RMSE at each budget, the active design's after every
// observer (m − 1 trials) up to the horizon, and the oracle bound.
struct SeedOutcome {
    std::vector<double> full;   // MSE at each budget
    std::vector<double> active; // MSE after each observer
    double boundRatio = 0.0;
};

// Number of comparisons at which a curve of MSEs (after every `step` comparisons) first reaches `target` (linear
// interpolation in RMSE); −1 if never.
double firstReach(const std::vector<double>& mse, double step, double target) {
    std::vector<double> x, y;
    for (std::size_t k = 0; k < mse.size(); ++k) {
        x.push_back(step * static_cast<double>(k + 1));
        y.push_back(std::sqrt(mse[k]));
    }
    return reachedAt(x, y, std::sqrt(target));
}

// q-quantile of values where −∞ stands for "never reached" (nearest rank on the sorted values).
double quantile(std::vector<double> values, double q) {
    std::sort(values.begin(), values.end());
    const auto k = static_cast<std::size_t>(
        std::clamp(std::floor(q * static_cast<double>(values.size())), 0.0, static_cast<double>(values.size() - 1)));
    return values[k];
}

std::string percent(double saving, double floor) {
    char buffer[32];
    if (!std::isfinite(saving)) std::snprintf(buffer, sizeof buffer, "< %.0f %%", 100.0 * floor);
    else std::snprintf(buffer, sizeof buffer, "%.0f %%", 100.0 * saving);
    return buffer;
}

int runSweep(const Settings& s) {
    const auto start = std::chrono::steady_clock::now();
    const double largestBudget = *std::max_element(s.budgets.begin(), s.budgets.end());
    std::printf("Saving of the active design (%s batches, prior sd %.2f JOD%s) against the full design, %d seeds per "
                "cell; true scores ~ N(0, sd^2) JOD; observers answer m-1 trials each; active runs to %.2f x the "
                "largest budget (%.1f full rounds); hardware threads %u, %d worker threads.\n\n",
                s.selection.c_str(), s.priorSd, s.empiricalPrior ? ", empirical Bayes above it" : "", s.seeds,
                s.horizon, s.horizon * largestBudget, std::thread::hardware_concurrency(), s.threads);
    std::printf("| m | sd | budget: rounds (observers, trials) | RMSE full | RMSE active | pooled saving [95 %% CI] | "
                "per-seed saving: median [10 %%, 90 %%] | seeds >= 40 %% | seeds never | A-opt bound | time (s) |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const double mValue : s.ms) {
        const int m = static_cast<int>(mValue);
        const int M = m * (m - 1) / 2;
        const int step = m - 1;
        std::vector<std::size_t> budgetTrials;
        for (const double r : s.budgets)
            budgetTrials.push_back(static_cast<std::size_t>(std::lround(r * M / step)) *
                                   static_cast<std::size_t>(step));
        const std::size_t fullLength = *std::max_element(budgetTrials.begin(), budgetTrials.end());
        const std::size_t observersToHorizon =
            static_cast<std::size_t>(std::ceil(s.horizon * static_cast<double>(fullLength) / step));
        const std::size_t activeLength = observersToHorizon * static_cast<std::size_t>(step);
        std::vector<std::size_t> grid;
        for (std::size_t k = 1; k <= observersToHorizon; ++k) grid.push_back(k * static_cast<std::size_t>(step));
        for (std::size_t spreadIndex = 0; spreadIndex < s.spreads.size(); ++spreadIndex) {
            const auto cellStart = std::chrono::steady_clock::now();
            const double spread = s.spreads[spreadIndex];
            std::vector<SeedOutcome> outcomes(static_cast<std::size_t>(s.seeds));
            std::atomic<int> next{0};
            auto work = [&] {
                for (int e = next++; e < s.seeds; e = next++) {
                    const std::uint64_t stream = static_cast<std::uint64_t>(m) * 100000000u +
                                                 static_cast<std::uint64_t>(spreadIndex) * 1000000u +
                                                 static_cast<std::uint64_t>(e);
                    std::mt19937_64 truthRandom(sc::mixSeed(s.seed, stream));
                    std::normal_distribution<double> draw(0.0, spread);
                    std::vector<double> truth(static_cast<std::size_t>(m));
                    double mean = 0;
                    for (double& q : truth) mean += (q = draw(truthRandom));
                    for (double& q : truth) q -= mean / m;
                    SeedOutcome& out = outcomes[static_cast<std::size_t>(e)];
                    const std::vector<Trial> full =
                        simulateDesign(0, truth, fullLength, sc::mixSeed(s.seed + 17, stream * 3), s);
                    for (const double r : rmseAt(full, budgetTrials, truth)) out.full.push_back(r * r);
                    const std::vector<Trial> active =
                        simulateDesign(2, truth, activeLength, sc::mixSeed(s.seed + 17, stream * 3 + 2), s);
                    for (const double r : rmseAt(active, grid, truth)) out.active.push_back(r * r);
                    out.boundRatio = sc::optimalAllocationShare(truth);
                }
            };
            std::vector<std::thread> pool;
            for (int t = 1; t < std::max(1, s.threads); ++t) pool.emplace_back(work);
            work();
            for (auto& thread : pool) thread.join();
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - cellStart).count();
            double bound = 0.0;
            for (const SeedOutcome& o : outcomes) bound += o.boundRatio;
            bound /= s.seeds;
            for (std::size_t b = 0; b < budgetTrials.size(); ++b) {
                const double budget = static_cast<double>(budgetTrials[b]);
                const double floor = 1.0 - static_cast<double>(activeLength) / budget;
                const std::size_t atBudget = budgetTrials[b] / static_cast<std::size_t>(step) - 1;
                // Pooled: mean MSE curves over seeds (the expected accuracy of a study of this size).
                auto pooled = [&](const std::vector<int>& pick) {
                    double target = 0.0;
                    std::vector<double> curve(grid.size(), 0.0);
                    for (const int e : pick) {
                        const SeedOutcome& o = outcomes[static_cast<std::size_t>(e)];
                        target += o.full[b];
                        for (std::size_t k = 0; k < grid.size(); ++k) curve[k] += o.active[k];
                    }
                    const double reached = firstReach(curve, step, target);
                    return reached < 0 ? -std::numeric_limits<double>::infinity() : 1.0 - reached / budget;
                };
                std::vector<int> all(static_cast<std::size_t>(s.seeds));
                std::iota(all.begin(), all.end(), 0);
                const double pooledSaving = pooled(all);
                std::mt19937_64 resampler(sc::mixSeed(s.seed, 99));
                std::uniform_int_distribution<int> pickSeed(0, s.seeds - 1);
                std::vector<double> resampled;
                std::vector<int> pick(static_cast<std::size_t>(s.seeds));
                for (int r = 0; r < s.intervalResamples; ++r) {
                    for (int& e : pick) e = pickSeed(resampler);
                    resampled.push_back(pooled(pick));
                }
                // Per seed: that seed's active curve against that seed's full design at the budget.
                std::vector<double> perSeed;
                int met = 0, never = 0;
                double fullMse = 0.0, activeMse = 0.0;
                for (const SeedOutcome& o : outcomes) {
                    fullMse += o.full[b] / s.seeds;
                    activeMse += o.active[atBudget] / s.seeds;
                    const double reached = firstReach(o.active, step, o.full[b]);
                    const double saving =
                        reached < 0 ? -std::numeric_limits<double>::infinity() : 1.0 - reached / budget;
                    perSeed.push_back(saving);
                    met += saving >= 0.4;
                    never += reached < 0;
                }
                std::printf("| %d | %.1f | %.1f (%zu, %zu) | %.3f | %.3f | %s [%s, %s] | %s [%s, %s] | %.2f | %.2f | "
                            "%.0f %% | %.0f |\n",
                            m, spread, s.budgets[b], budgetTrials[b] / static_cast<std::size_t>(step), budgetTrials[b],
                            std::sqrt(fullMse), std::sqrt(activeMse), percent(pooledSaving, floor).c_str(),
                            percent(quantile(resampled, 0.025), floor).c_str(),
                            percent(quantile(resampled, 0.975), floor).c_str(),
                            percent(quantile(perSeed, 0.5), floor).c_str(),
                            percent(quantile(perSeed, 0.1), floor).c_str(),
                            percent(quantile(perSeed, 0.9), floor).c_str(), static_cast<double>(met) / s.seeds,
                            static_cast<double>(never) / s.seeds, 100.0 * (1.0 - bound), seconds);
                std::fflush(stdout);
            }
        }
    }
    std::printf("\ntotal %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return 0;
}

std::vector<double> parseList(const char* value) {
    std::vector<double> out;
    for (const char* p = value; *p;) {
        char* end = nullptr;
        const double x = std::strtod(p, &end);
        if (end == p) break;
        out.push_back(x);
        p = *end == ',' ? end + 1 : end;
    }
    return out;
}

} // namespace

int main(int argc, char** argv) {
    Settings s;
    for (int k = 1; k < argc; k += 2) {
        const std::string key = argv[k];
        if (key == "--sweep") {
            s.sweep = true;
            --k;
            continue;
        }
        if (key == "--empirical-prior") {
            s.empiricalPrior = true;
            --k;
            continue;
        }
        if (k + 1 >= argc) {
            std::fprintf(stderr, "bench_active_sampling: option %s needs a value\n", key.c_str());
            return 2;
        }
        const char* value = argv[k + 1];
        if (key == "--experiments") s.experiments = std::atoi(value);
        else if (key == "--coverage-experiments") s.coverageExperiments = std::atoi(value);
        else if (key == "--bootstrap") s.bootstrap = std::atoi(value);
        else if (key == "--spread") s.spread = std::atof(value);
        else if (key == "--rounds") s.rounds = std::atoi(value);
        else if (key == "--threads") s.threads = std::atoi(value);
        else if (key == "--seed") s.seed = static_cast<std::uint64_t>(std::atoll(value));
        else if (key == "--plot") s.plot = value;
        else if (key == "--truth") s.truth = value;
        else if (key == "--prior-sd") s.priorSd = std::atof(value);
        else if (key == "--selection") s.selection = value;
        else if (key == "--batch") s.batch = std::atoi(value);
        else if (key == "--plan-prior-sd") s.planPriorSd = std::atof(value);
        else if (key == "--timing") s.timing = std::atoi(value) != 0;
        else if (key == "--coverage-rounds") s.coverageRounds = parseList(value);
        else if (key == "--seeds") s.seeds = std::atoi(value);
        else if (key == "--ms") s.ms = parseList(value);
        else if (key == "--spreads") s.spreads = parseList(value);
        else if (key == "--budgets") s.budgets = parseList(value);
        else if (key == "--horizon") s.horizon = std::atof(value);
        else if (key == "--interval-resamples") s.intervalResamples = std::atoi(value);
        else {
            std::fprintf(stderr, "bench_active_sampling: unknown option %s\n", key.c_str());
            return 2;
        }
    }
    if (s.sweep) return runSweep(s);
    const auto start = std::chrono::steady_clock::now();
    std::printf(
        "hardware threads %u; %d experiments per m (coverage: %d, %d bootstrap samples); true scores ~ "
        "%s with sd %.2f JOD; designs up to %d full rounds; observers answer m-1 trials each; active: %s batches, "
        "prior sd %.2f JOD\n\n",
        std::thread::hardware_concurrency(), s.experiments, s.coverageExperiments, s.bootstrap, s.truth.c_str(),
        s.spread, s.rounds, s.selection.c_str(), s.priorSd);
    const std::vector<int> ms = {10, 20, 30};
    // Coverage budgets, in full rounds.
    const std::vector<double>& coverageRounds = s.coverageRounds;
    std::vector<std::vector<std::vector<double>>> allCurves;
    std::vector<std::vector<double>> allX;
    std::printf("| m | full rounds | comparisons (full) | RMSE full | RMSE random | RMSE active | active reaches "
                "full's RMSE at | "
                "saving | random reaches it at |\n|---|---|---|---|---|---|---|---|---|\n");
    std::vector<std::string> coverageLines, profileLines;
    for (const int m : ms) {
        const int M = m * (m - 1) / 2;
        const int step = m - 1;
        const std::size_t length = static_cast<std::size_t>(s.rounds * M);
        std::vector<double> x;
        for (std::size_t c = static_cast<std::size_t>(step); c <= length; c += static_cast<std::size_t>(step))
            x.push_back(static_cast<double>(c));
        std::vector<std::vector<double>> sumSquared(3, std::vector<double>(x.size(), 0.0));
        std::map<std::pair<int, int>, CoverageCell> coverage, profileCoverage; // (design, budget index)
        double fisherRatio = 0.0;
        sc::FitOptions fitOptions;
        sc::BootstrapOptions bootOptions;
        bootOptions.samples = s.bootstrap;
        bootOptions.threads = s.threads;
        for (int e = 0; e < s.experiments; ++e) {
            std::mt19937_64 truthRandom(sc::mixSeed(s.seed, static_cast<std::uint64_t>(m * 100000 + e)));
            std::normal_distribution<double> draw(0.0, s.spread);
            std::uniform_real_distribution<double> flat(-std::sqrt(3.0) * s.spread, std::sqrt(3.0) * s.spread);
            std::vector<double> truth(static_cast<std::size_t>(m));
            double mean = 0;
            for (double& q : truth) mean += (q = s.truth == "uniform" ? flat(truthRandom) : draw(truthRandom));
            mean /= m;
            for (double& q : truth) q -= mean;
            fisherRatio += sc::optimalAllocationShare(truth);
            for (int d = 0; d < 3; ++d) {
                const std::vector<Trial> trials = simulateDesign(
                    d, truth, length, sc::mixSeed(s.seed + 17, static_cast<std::uint64_t>(m * 100000 + e * 3 + d)), s);
                for (std::size_t k = 0; k < x.size(); ++k) {
                    const sc::BlockData block = blockOf(trials, static_cast<std::size_t>(x[k]), m, step);
                    const sc::FitResult fit = sc::fitScores(block.totalCounts(), fitOptions);
                    const double r = rmse(fit.scores, truth);
                    sumSquared[static_cast<std::size_t>(d)][k] += r * r;
                }
                if (e < s.coverageExperiments) {
                    for (std::size_t b = 0; b < coverageRounds.size(); ++b) {
                        // Budget rounded to whole observers.
                        const std::size_t count = static_cast<std::size_t>(std::lround(coverageRounds[b] * M / step)) *
                                                  static_cast<std::size_t>(step);
                        const sc::BlockData block = blockOf(trials, count, m, step);
                        const sc::FitResult fit = sc::fitScores(block.totalCounts(), fitOptions);
                        bootOptions.seed = sc::mixSeed(s.seed, static_cast<std::uint64_t>(e * 7 + d));
                        const sc::BootstrapResult boot = sc::bootstrapObservers(block, fit, fitOptions, bootOptions);
                        CoverageCell& cell = coverage[{d, static_cast<int>(b)}];
                        CoverageCell& profileCell = profileCoverage[{d, static_cast<int>(b)}];
                        const sc::PairCounts totals = block.totalCounts();
                        for (int i = 0; i < m; ++i) {
                            const double q = truth[static_cast<std::size_t>(i)];
                            cell.covered += (boot.low[i] <= q && q <= boot.high[i]) ? 1 : 0;
                            cell.widths.push_back(boot.high[i] - boot.low[i]);
                            cell.total += 1;
                            Eigen::VectorXd contrast = Eigen::VectorXd::Constant(m, -1.0 / m);
                            contrast[i] += 1.0;
                            const sc::ProfileInterval profile =
                                sc::profileInterval(totals, fitOptions, fit, contrast, 0.95);
                            profileCell.covered += (profile.low <= q && q <= profile.high) ? 1 : 0;
                            profileCell.widths.push_back(profile.high - profile.low);
                            profileCell.total += 1;
                        }
                    }
                }
            }
        }
        std::vector<std::vector<double>> curves(3, std::vector<double>(x.size()));
        for (int d = 0; d < 3; ++d)
            for (std::size_t k = 0; k < x.size(); ++k)
                curves[static_cast<std::size_t>(d)][k] =
                    std::sqrt(sumSquared[static_cast<std::size_t>(d)][k] / s.experiments);
        for (int r = 1; r <= s.rounds; ++r) {
            const std::size_t k = static_cast<std::size_t>(r * M / step) - 1; // x[k] = r·M
            const double target = curves[0][k];
            const double active = reachedAt(x, curves[2], target);
            const double random = reachedAt(x, curves[1], target);
            char activeText[64], randomText[64], saving[32];
            if (active > 0) std::snprintf(activeText, sizeof activeText, "%.0f", active);
            else std::snprintf(activeText, sizeof activeText, "> %zu", length);
            if (random > 0) std::snprintf(randomText, sizeof randomText, "%.0f", random);
            else std::snprintf(randomText, sizeof randomText, "> %zu", length);
            if (active > 0) std::snprintf(saving, sizeof saving, "%.0f %%", 100.0 * (1.0 - active / (r * M)));
            else std::snprintf(saving, sizeof saving, "n/a");
            std::printf("| %d | %d | %d | %.3f | %.3f | %.3f | %s | %s | %s |\n", m, r, r * M, target, curves[1][k],
                        curves[2][k], activeText, saving, randomText);
        }
        for (std::size_t b = 0; b < coverageRounds.size(); ++b) {
            const std::size_t count =
                static_cast<std::size_t>(std::lround(coverageRounds[b] * M / step)) * static_cast<std::size_t>(step);
            char line[256];
            const CoverageCell& f = coverage[{0, static_cast<int>(b)}];
            const CoverageCell& r = coverage[{1, static_cast<int>(b)}];
            const CoverageCell& a = coverage[{2, static_cast<int>(b)}];
            std::snprintf(line, sizeof line,
                          "| %d | %zu (%.1f rounds, %zu observers) | %.3f (%.2f) | %.3f (%.2f) | %.3f (%.2f) |", m,
                          count, coverageRounds[b], count / static_cast<std::size_t>(step), f.covered / f.total,
                          f.medianWidth(), r.covered / r.total, r.medianWidth(), a.covered / a.total, a.medianWidth());
            coverageLines.push_back(line);
            const CoverageCell& pf = profileCoverage[{0, static_cast<int>(b)}];
            const CoverageCell& pr = profileCoverage[{1, static_cast<int>(b)}];
            const CoverageCell& pa = profileCoverage[{2, static_cast<int>(b)}];
            std::snprintf(line, sizeof line,
                          "| %d | %zu (%.1f rounds, %zu observers) | %.3f (%.2f) | %.3f (%.2f) | %.3f (%.2f) |", m,
                          count, coverageRounds[b], count / static_cast<std::size_t>(step), pf.covered / pf.total,
                          pf.medianWidth(), pr.covered / pr.total, pr.medianWidth(), pa.covered / pa.total,
                          pa.medianWidth());
            profileLines.push_back(line);
        }
        std::printf(
            "| %d | A-optimal design bound (asymptotic): any design needs at least %.0f %% of the full design's "
            "comparisons (saving <= %.0f %%) |\n",
            m, 100.0 * fisherRatio / s.experiments, 100.0 * (1.0 - fisherRatio / s.experiments));
        std::fflush(stdout);
        allCurves.push_back(curves);
        allX.push_back(x);
    }
    if (s.coverageExperiments > 0) {
        std::printf("\nCoverage of the 95 %% studentized bootstrap intervals (median width, JOD):\n\n"
                    "| m | comparisons | full | random | active |\n|---|---|---|---|---|\n");
        for (const std::string& line : coverageLines) std::printf("%s\n", line.c_str());
        std::printf("\nCoverage of the 95 %% profile-likelihood intervals (median width, JOD):\n\n"
                    "| m | comparisons | full | random | active |\n|---|---|---|---|---|\n");
        for (const std::string& line : profileLines) std::printf("%s\n", line.c_str());
    }

    // Planning time of one batch at m = 30 with 200 participants' answers (as the server plans it).
    std::printf("\nPlanning one batch (posterior from every answer, pair values, spanning tree), m = 30:\n\n"
                "| participants | answers | EP sweeps | plan median (ms) | plan min (ms) |\n|---|---|---|---|---|\n");
    for (const int perParticipant : {29, 58, 100}) {
        if (!s.timing) break;
        const int m = 30;
        std::mt19937_64 random(7);
        std::vector<double> truth(m);
        std::normal_distribution<double> draw(0.0, s.spread);
        for (double& q : truth) q = draw(random);
        std::vector<ac::Comparison> answers;
        std::uniform_int_distribution<int> pick(0, m - 1);
        const int participants = 200;
        for (int t = 0; t < participants * perParticipant; ++t) {
            const int i = pick(random);
            int j = pick(random);
            while (j == i) j = pick(random);
            answers.push_back(answer(random, truth, i, j) ? ac::Comparison{i, j} : ac::Comparison{j, i});
        }
        std::vector<double> times;
        int sweeps = 0;
        for (int r = 0; r < 7; ++r) {
            const auto t0 = std::chrono::steady_clock::now();
            const ac::ScorePosterior posterior = ac::fitPosterior(m, answers);
            const auto batch = ac::spanningTreeBatch(posterior, static_cast<std::uint64_t>(r));
            times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            sweeps = posterior.sweeps;
            if (batch.size() != static_cast<std::size_t>(m - 1)) return 1;
        }
        std::sort(times.begin(), times.end());
        std::printf("| %d | %zu | %d | %.1f | %.1f |\n", participants, answers.size(), sweeps, times[times.size() / 2],
                    times.front());
    }
    if (!s.plot.empty()) {
        drawPlot(s.plot, ms, allCurves, allX, s);
        std::printf("\nplot: %s\n", s.plot.c_str());
    }
    std::printf("\ntotal %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return 0;
}
