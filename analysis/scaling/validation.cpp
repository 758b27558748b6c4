#include "analysis/scaling/validation.h"

#include "common/error.h"

#include "analysis/scaling/active_sampling.h"
#include "analysis/scaling/bootstrap.h"
#include "analysis/scaling/scale_analysis.h"
#include "analysis/scaling/screening.h"
#include "analysis/scaling/simulation.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <random>
#include <thread>

namespace skinlab::analysis::scaling {
namespace {

// Sums over the intervals/pairs/observers of one experiment; rates are formed at the end.
struct Tally {
    double intervals = 0, covered = 0, width = 0, percentileCovered = 0, percentileWidth = 0, fallbacks = 0;
    double maximumHalfWidth = 0;
    double squaredError = 0, rankCorrelation = 0, experiments = 0;
    double pairs = 0, significantCorrect = 0, significantReversed = 0;
    double randomObservers = 0, randomFlagged = 0, invertedObservers = 0, invertedFlagged = 0;
    double genuineObservers = 0, genuineFlagged = 0;
    double bootstrapCovered = 0, unionCovered = 0, unionWidth = 0;
    // Pairs' intervals; intervals with one open end (scores, pairs) and how often their finite end held.
    double pairIntervals = 0, pairCovered = 0, oneSided = 0, oneSidedCovered = 0, pairOneSided = 0,
           pairOneSidedCovered = 0;
    void add(const Tally& o) {
        pairIntervals += o.pairIntervals, pairCovered += o.pairCovered, oneSided += o.oneSided;
        oneSidedCovered += o.oneSidedCovered, pairOneSided += o.pairOneSided;
        pairOneSidedCovered += o.pairOneSidedCovered;
        bootstrapCovered += o.bootstrapCovered, unionCovered += o.unionCovered, unionWidth += o.unionWidth;
        intervals += o.intervals, covered += o.covered, width += o.width, percentileCovered += o.percentileCovered;
        fallbacks += o.fallbacks, maximumHalfWidth = std::max(maximumHalfWidth, o.maximumHalfWidth);
        percentileWidth += o.percentileWidth, squaredError += o.squaredError, rankCorrelation += o.rankCorrelation;
        experiments += o.experiments, pairs += o.pairs, significantCorrect += o.significantCorrect;
        significantReversed += o.significantReversed, randomObservers += o.randomObservers;
        randomFlagged += o.randomFlagged, invertedObservers += o.invertedObservers;
        invertedFlagged += o.invertedFlagged, genuineObservers += o.genuineObservers;
        genuineFlagged += o.genuineFlagged;
    }
};

std::vector<double> ranks(const Eigen::VectorXd& values) {
    std::vector<int> order(values.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return values[a] < values[b]; });
    std::vector<double> rank(values.size());
    for (size_t k = 0; k < order.size(); ++k) rank[order[k]] = static_cast<double>(k);
    return rank;
}

// Keeps only the observers not flagged.
BlockData withoutObservers(const BlockData& block, const std::vector<bool>& drop) {
    BlockData kept = block;
    std::vector<int> rows;
    for (int k = 0; k < block.observerCount(); ++k)
        if (!drop[k]) rows.push_back(k);
    kept.observers.clear();
    kept.winsFirst.resize(static_cast<Eigen::Index>(rows.size()), block.winsFirst.cols());
    kept.winsSecond.resize(static_cast<Eigen::Index>(rows.size()), block.winsSecond.cols());
    kept.leftChosen.resize(static_cast<Eigen::Index>(rows.size()));
    kept.sideTrials.resize(static_cast<Eigen::Index>(rows.size()));
    for (size_t r = 0; r < rows.size(); ++r) {
        kept.observers.push_back(block.observers[rows[r]]);
        kept.winsFirst.row(static_cast<Eigen::Index>(r)) = block.winsFirst.row(rows[r]);
        kept.winsSecond.row(static_cast<Eigen::Index>(r)) = block.winsSecond.row(rows[r]);
        kept.leftChosen[static_cast<Eigen::Index>(r)] = block.leftChosen[rows[r]];
        kept.sideTrials[static_cast<Eigen::Index>(r)] = block.sideTrials[rows[r]];
    }
    return kept;
}

// The "active" scenario's data: Case V observers one after another, each answering activeTrials trials in batches
// the planner chose from all earlier answers; sides alternate within an observer.
BlockData simulateActive(const ValidationOptions& options, const std::vector<double>& truth, int observers,
                         std::uint64_t seed) {
    const int m = static_cast<int>(truth.size());
    const int perObserver = options.activeTrials > 0 ? options.activeTrials : options.trialsPerPair * m * (m - 1) / 2;
    std::mt19937_64 random(seed);
    std::normal_distribution<double> noise(0.0, kThurstoneSigma / std::sqrt(2.0));
    struct Trial {
        int observer, i, j;
        bool firstChosen, firstOnLeft;
    };
    std::vector<Trial> trials;
    std::vector<active::Comparison> answers;
    for (int k = 0; k < observers; ++k) {
        int done = 0;
        for (std::uint64_t batch = 0; done < perObserver; ++batch) {
            // The study server's planner: the posterior of every earlier answer, one batch = the spanning tree over
            // 1/(expected variance reduction).
            const auto pairs = active::spanningTreeBatch(active::fitPosterior(m, answers),
                                                         mixSeed(seed, static_cast<std::uint64_t>(k) * 100000 + batch));
            if (pairs.empty()) throw RuntimeError("validate: the active planner returned no pairs");
            for (auto [i, j] : pairs) {
                if (done == perObserver) break;
                if (i > j) std::swap(i, j);
                const bool chosen = truth[i] + noise(random) > truth[j] + noise(random);
                trials.push_back({k, i, j, chosen, done % 2 == 0});
                answers.push_back(chosen ? active::Comparison{i, j} : active::Comparison{j, i});
                ++done;
            }
        }
    }
    BlockData block;
    block.name = "simulated";
    for (int i = 0; i < m; ++i) block.conditions.push_back("c" + std::to_string(i));
    for (int k = 0; k < observers; ++k) {
        char name[16];
        std::snprintf(name, sizeof name, "o%03d", k + 1);
        block.observers.push_back(name);
    }
    std::map<std::pair<int, int>, int> column;
    for (const Trial& t : trials)
        if (column.emplace(std::make_pair(t.i, t.j), static_cast<int>(block.pairs.size())).second)
            block.pairs.emplace_back(t.i, t.j);
    const auto pairCount = static_cast<Eigen::Index>(block.pairs.size());
    block.winsFirst = Eigen::MatrixXd::Zero(observers, pairCount);
    block.winsSecond = Eigen::MatrixXd::Zero(observers, pairCount);
    block.sideCounts.assign(block.pairs.size(), {0, 0, 0, 0});
    block.leftChosen = Eigen::VectorXd::Zero(observers);
    block.sideTrials = Eigen::VectorXd::Zero(observers);
    for (const Trial& t : trials) {
        const int p = column.at({t.i, t.j});
        (t.firstChosen ? block.winsFirst : block.winsSecond)(t.observer, p) += 1.0;
        block.sideCounts[p][(t.firstOnLeft ? 0 : 2) + (t.firstChosen ? 0 : 1)] += 1.0;
        block.sideTrials[t.observer] += 1.0;
        if (t.firstChosen == t.firstOnLeft) block.leftChosen[t.observer] += 1.0;
    }
    return block;
}

Tally runActiveExperiment(const ValidationOptions& options, int observers, std::uint64_t seed) {
    const int m = static_cast<int>(options.trueScores.size());
    std::vector<double> scores = options.trueScores;
    for (double& q : scores) q *= options.activeStretch;
    const BlockData block = simulateActive(options, scores, observers, seed);
    AnalysisOptions analysisOptions;
    analysisOptions.intervals = IntervalMethod::profile;
    analysisOptions.correction = options.correction;
    analysisOptions.alpha = options.alpha;
    analysisOptions.bootstrap.level = 0.95;
    analysisOptions.fit.prior = options.prior;
    const BlockAnalysis analysis = analyzeBlock(block, analysisOptions);
    // The observer bootstrap on the same data, for comparison.
    FitOptions fitOptions;
    fitOptions.prior = options.prior;
    BootstrapOptions bootstrapOptions;
    bootstrapOptions.samples = options.bootstrapSamples;
    bootstrapOptions.seed = mixSeed(seed, 1);
    bootstrapOptions.threads = 1;
    const BootstrapResult bootstrap = bootstrapObservers(block, analysis.thurstone, fitOptions, bootstrapOptions);

    Tally tally;
    tally.experiments = 1;
    Eigen::VectorXd truth = Eigen::Map<const Eigen::VectorXd>(scores.data(), m);
    truth.array() -= truth.mean();
    const Eigen::VectorXd& fit = analysis.thurstone.scores;
    for (int i = 0; i < m; ++i) {
        tally.intervals += 1;
        tally.covered += analysis.low[i] <= truth[i] && truth[i] <= analysis.high[i];
        // An end the data do not set is open (unanimous answers: docs/analysis.md, "Intervals the data
        // support"); widths and half-widths are those of the ends that are set.
        if (std::isfinite(analysis.low[i]) && std::isfinite(analysis.high[i]))
            tally.width += analysis.high[i] - analysis.low[i];
        if (std::isfinite(analysis.low[i]))
            tally.maximumHalfWidth = std::max(tally.maximumHalfWidth, fit[i] - analysis.low[i]);
        if (std::isfinite(analysis.high[i]))
            tally.maximumHalfWidth = std::max(tally.maximumHalfWidth, analysis.high[i] - fit[i]);
        tally.bootstrapCovered += bootstrap.low[i] <= truth[i] && truth[i] <= bootstrap.high[i];
        const double unionLow = std::min(analysis.low[i], bootstrap.low[i]);
        const double unionHigh = std::max(analysis.high[i], bootstrap.high[i]);
        tally.unionCovered += unionLow <= truth[i] && truth[i] <= unionHigh;
        if (std::isfinite(unionLow) && std::isfinite(unionHigh)) tally.unionWidth += unionHigh - unionLow;
        tally.percentileCovered += bootstrap.percentileLow[i] <= truth[i] && truth[i] <= bootstrap.percentileHigh[i];
        tally.percentileWidth += bootstrap.percentileHigh[i] - bootstrap.percentileLow[i];
        tally.squaredError += (fit[i] - truth[i]) * (fit[i] - truth[i]);
    }
    const std::vector<double> estimatedRank = ranks(fit), trueRank = ranks(truth);
    double rankSquares = 0;
    for (int i = 0; i < m; ++i) rankSquares += (estimatedRank[i] - trueRank[i]) * (estimatedRank[i] - trueRank[i]);
    tally.rankCorrelation = 1.0 - 6.0 * rankSquares / (static_cast<double>(m) * (m * m - 1.0));
    for (const PairTest& pair : analysis.pairs) {
        const double trueDifference = truth[pair.test.first] - truth[pair.test.second];
        tally.pairs += 1;
        if (!pair.significant || trueDifference == 0.0) continue;
        if ((pair.test.difference > 0) == (trueDifference > 0)) tally.significantCorrect += 1;
        else tally.significantReversed += 1;
    }
    return tally;
}

Tally runExperiment(const ValidationOptions& options, const std::string& scenario, int observers, int experiment) {
    SimulationDesign design;
    design.trueScores = options.trueScores;
    design.observers = observers;
    design.trialsPerPair = options.trialsPerPair;
    const int m = static_cast<int>(options.trueScores.size());
    if (scenario == "sparse") design.pairFraction = options.sparsePairFraction;
    if (scenario == "near-unanimous")
        for (double& score : design.trueScores) score *= options.nearUnanimousStretch;
    if (scenario == "disconnected") {
        // The distance between groups is not measured; the prior anchors the groups at equal means, so the
        // scores the intervals are for are the truth with each group centred.
        design.groups = options.disconnectedGroups;
        for (int g = 0; g < design.groups; ++g) {
            double sum = 0.0;
            int members = 0;
            for (int i = 0; i < m; ++i)
                if (i * design.groups / m == g) sum += design.trueScores[i], ++members;
            for (int i = 0; i < m; ++i)
                if (i * design.groups / m == g) design.trueScores[i] -= sum / members;
        }
    }
    if (scenario == "lapses+side-bias" || scenario == "screening") {
        design.lapseRate = options.lapseRate;
        design.sideBiasStandardDeviation = options.sideBiasStandardDeviation;
    }
    const bool screening = scenario == "screening";
    if (screening) {
        design.randomObservers = options.randomObservers;
        design.invertedObservers = options.invertedObservers;
    }
    const std::uint64_t scenarioIndex = static_cast<std::uint64_t>(
        std::find(options.scenarios.begin(), options.scenarios.end(), scenario) - options.scenarios.begin());
    const std::uint64_t stream = (scenarioIndex * 1000 + static_cast<std::uint64_t>(observers)) * 1000000 +
                                 static_cast<std::uint64_t>(experiment);
    const std::uint64_t seed = mixSeed(options.seed, stream);
    if (scenario == "active") return runActiveExperiment(options, observers, seed);
    const SimulatedBlock simulated = simulateBlock(design, seed);
    Tally tally;
    tally.experiments = 1;

    FitOptions fitOptions;
    fitOptions.prior = options.prior;
    BlockData block = simulated.block;
    if (screening) {
        const FitResult full = fitScores(block.totalCounts(), fitOptions);
        const HeldOutLikelihood heldOut = heldOutLikelihood(block, full, fitOptions);
        std::vector<double> perTrial(observers);
        for (int k = 0; k < observers; ++k) perTrial[k] = heldOut.logLikelihood[k] / heldOut.trials[k];
        const std::vector<bool> flags = lowOutliers(perTrial, options.screeningWhisker);
        for (int k = 0; k < observers; ++k) {
            switch (simulated.kinds[k]) {
            case SimulatedObserverKind::Genuine: tally.genuineObservers += 1, tally.genuineFlagged += flags[k]; break;
            case SimulatedObserverKind::Random: tally.randomObservers += 1, tally.randomFlagged += flags[k]; break;
            case SimulatedObserverKind::Inverted:
                tally.invertedObservers += 1, tally.invertedFlagged += flags[k];
                break;
            }
        }
        block = withoutObservers(block, flags); // the intervals below are those of the screened data
    }

    // The intervals `analyze scale` reports: the studentized bootstrap (or its fallback), with the ends the data
    // leave open open and the finite end of a one-sided interval at the one-sided profile bound.
    AnalysisOptions analysisOptions;
    analysisOptions.fit = fitOptions;
    analysisOptions.intervals = IntervalMethod::bootstrap;
    analysisOptions.bootstrap.samples = options.bootstrapSamples;
    analysisOptions.bootstrap.seed = mixSeed(seed, 1);
    analysisOptions.bootstrap.threads = 1; // experiments already run in parallel
    analysisOptions.correction = options.correction;
    analysisOptions.alpha = options.alpha;
    const BlockAnalysis analysis = analyzeBlock(block, analysisOptions);
    const Eigen::VectorXd& fit = analysis.thurstone.scores;

    Eigen::VectorXd truth = Eigen::Map<const Eigen::VectorXd>(design.trueScores.data(), m);
    truth.array() -= truth.mean();
    for (int i = 0; i < m; ++i) {
        const double low = analysis.low[i], high = analysis.high[i];
        tally.intervals += 1;
        const bool covered = low <= truth[i] && truth[i] <= high;
        tally.covered += covered;
        if (std::isfinite(low) != std::isfinite(high)) tally.oneSided += 1, tally.oneSidedCovered += covered;
        if (std::isfinite(low) && std::isfinite(high)) tally.width += high - low;
        tally.fallbacks += analysis.intervalFlags[i].fallback;
        if (std::isfinite(low)) tally.maximumHalfWidth = std::max(tally.maximumHalfWidth, fit[i] - low);
        if (std::isfinite(high)) tally.maximumHalfWidth = std::max(tally.maximumHalfWidth, high - fit[i]);
        tally.percentileCovered += analysis.percentileLow[i] <= truth[i] && truth[i] <= analysis.percentileHigh[i];
        tally.percentileWidth += analysis.percentileHigh[i] - analysis.percentileLow[i];
        tally.squaredError += (fit[i] - truth[i]) * (fit[i] - truth[i]);
    }
    const std::vector<double> estimatedRank = ranks(fit), trueRank = ranks(truth);
    double rankSquares = 0;
    for (int i = 0; i < m; ++i) rankSquares += (estimatedRank[i] - trueRank[i]) * (estimatedRank[i] - trueRank[i]);
    tally.rankCorrelation = 1.0 - 6.0 * rankSquares / (static_cast<double>(m) * (m * m - 1.0));

    for (const PairTest& pair : analysis.pairs) {
        const DifferenceTest& test = pair.test;
        const double trueDifference = truth[test.first] - truth[test.second];
        const bool covered = test.low <= trueDifference && trueDifference <= test.high;
        tally.pairIntervals += 1;
        tally.pairCovered += covered;
        if (std::isfinite(test.low) != std::isfinite(test.high))
            tally.pairOneSided += 1, tally.pairOneSidedCovered += covered;
        tally.pairs += 1;
        if (!pair.significant || trueDifference == 0.0) continue;
        if ((test.difference > 0) == (trueDifference > 0)) tally.significantCorrect += 1;
        else tally.significantReversed += 1;
    }
    return tally;
}

} // namespace

const std::vector<std::string>& validationScenarios() {
    static const std::vector<std::string> names = {"thurstone",    "lapses+side-bias", "screening", "sparse",
                                                   "disconnected", "near-unanimous",   "active"};
    return names;
}

ValidationReport runValidation(const ValidationOptions& options) {
    const auto started = std::chrono::steady_clock::now();
    ValidationReport report;
    report.options = options;
    for (const std::string& scenario : options.scenarios) {
        for (int observers : options.observerCounts) {
            std::vector<Tally> tallies(options.experiments);
            std::atomic<int> next{0};
            auto work = [&] {
                for (int e = next++; e < options.experiments; e = next++)
                    tallies[e] = runExperiment(options, scenario, observers, e);
            };
            std::vector<std::thread> pool;
            for (int t = 1; t < std::max(1, options.threads); ++t) pool.emplace_back(work);
            work();
            for (auto& thread : pool) thread.join();
            Tally total;
            for (const Tally& tally : tallies) total.add(tally); // fixed order: same sums on any thread count

            ValidationRow row;
            row.scenario = scenario;
            row.observers = observers;
            row.experiments = options.experiments;
            row.coverage = total.covered / total.intervals;
            row.meanWidth = total.width / total.intervals;
            row.fallbackShare = total.fallbacks / total.intervals;
            row.maximumHalfWidth = total.maximumHalfWidth;
            row.percentileCoverage = total.percentileCovered / total.intervals;
            row.percentileMeanWidth = total.percentileWidth / total.intervals;
            if (scenario == "active") {
                row.bootstrapCoverage = total.bootstrapCovered / total.intervals;
                row.unionCoverage = total.unionCovered / total.intervals;
                row.unionMeanWidth = total.unionWidth / total.intervals;
            }
            row.pairCoverage = total.pairIntervals > 0 ? total.pairCovered / total.pairIntervals : -1.0;
            row.oneSidedShare = total.oneSided / total.intervals;
            row.oneSidedCoverage = total.oneSided > 0 ? total.oneSidedCovered / total.oneSided : -1.0;
            row.pairOneSidedCoverage = total.pairOneSided > 0 ? total.pairOneSidedCovered / total.pairOneSided : -1.0;
            row.rmse = std::sqrt(total.squaredError / total.intervals);
            row.rankCorrelation = total.rankCorrelation / total.experiments;
            row.significantCorrect = total.significantCorrect / total.pairs;
            row.significantReversed = total.significantReversed / total.pairs;
            if (total.randomObservers > 0) row.randomHitRate = total.randomFlagged / total.randomObservers;
            if (total.invertedObservers > 0) row.invertedHitRate = total.invertedFlagged / total.invertedObservers;
            if (scenario == "screening") row.falseAlarmRate = total.genuineFlagged / total.genuineObservers;
            report.rows.push_back(row);
        }
    }
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return report;
}

std::string validationMarkdown(const ValidationReport& report) {
    const ValidationOptions& o = report.options;
    std::string scores;
    for (double s : o.trueScores) scores += (scores.empty() ? "" : ", ") + std::to_string(s).substr(0, 4);
    char line[2048];
    std::string out;
    std::string bootstrapCoverages;
    for (const ValidationRow& r : report.rows)
        if (r.bootstrapCoverage >= 0) {
            char cell[128];
            std::snprintf(cell, sizeof cell, "%s%.4f (union %.4f, width %.3f; %d observers)",
                          bootstrapCoverages.empty() ? "" : ", ", r.bootstrapCoverage, r.unionCoverage,
                          r.unionMeanWidth, r.observers);
            bootstrapCoverages += cell;
        }
    if (bootstrapCoverages.empty()) bootstrapCoverages = "not run";
    std::snprintf(
        line, sizeof line,
        "True scores [%s] JOD, full design, %d trials per pair per observer (each order %s), %d "
        "experiments per row, %d bootstrap samples, %s correction at alpha = %.2f, seed %llu.\n"
        "Lapses %.3f and side-bias sd %.2f JOD in the 'lapses+side-bias' and 'screening' scenarios; "
        "'screening' adds %d random and %d inverted observer(s) and scores the remaining ones. "
        "'sparse': each observer judges %.0f %% of the pairs; 'disconnected': %d groups never compared "
        "(truth centred per group); 'near-unanimous': true scores x %.1f. 'active': observers one after "
        "another on true scores x %.1f, %d trials each in batches chosen from all earlier answers, "
        "profile-likelihood intervals and score tests in the columns below; the studentized observer bootstrap "
        "on the same data (what `analyze scale` uses for an active study) covers: %s.\n\n",
        scores.c_str(), o.trialsPerPair, o.trialsPerPair % 2 == 0 ? "equally often" : "alternating", o.experiments,
        o.bootstrapSamples, correctionName(o.correction), o.alpha, static_cast<unsigned long long>(o.seed), o.lapseRate,
        o.sideBiasStandardDeviation, o.randomObservers, o.invertedObservers, 100.0 * o.sparsePairFraction,
        o.disconnectedGroups, o.nearUnanimousStretch, o.activeStretch,
        o.activeTrials > 0 ? o.activeTrials
                           : o.trialsPerPair * static_cast<int>(o.trueScores.size() * (o.trueScores.size() - 1) / 2),
        bootstrapCoverages.c_str());
    out += line;
    out += std::string("Prior: ") + priorName(o.prior) + ".\n\n";
    out += "| scenario | observers | coverage | pair coverage | one-sided share | one-sided coverage (scores, pairs) | "
           "mean width | fallback share | largest half-width | coverage (percentile, pwcmp) | "
           "mean width | RMSE (JOD) | Spearman | significant & correct | significant & reversed | random caught | "
           "inverted caught | false alarms |\n";
    out += "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    auto rate = [](double value) {
        if (value < 0) return std::string("—");
        char buffer[32];
        std::snprintf(buffer, sizeof buffer, "%.3f", value);
        return std::string(buffer);
    };
    for (const ValidationRow& r : report.rows) {
        std::snprintf(line, sizeof line,
                      "| %s | %d | %.4f | %s | %.3f | %s, %s | %.3f | %.3f | %.2f | %.4f | %.3f | %.4f | %.4f | %.4f | "
                      "%.4f | %s | "
                      "%s | %s |\n",
                      r.scenario.c_str(), r.observers, r.coverage, rate(r.pairCoverage).c_str(), r.oneSidedShare,
                      rate(r.oneSidedCoverage).c_str(), rate(r.pairOneSidedCoverage).c_str(), r.meanWidth,
                      r.fallbackShare, r.maximumHalfWidth, r.percentileCoverage, r.percentileMeanWidth, r.rmse,
                      r.rankCorrelation, r.significantCorrect, r.significantReversed, rate(r.randomHitRate).c_str(),
                      rate(r.invertedHitRate).c_str(), rate(r.falseAlarmRate).c_str());
        out += line;
    }
    return out;
}

nlohmann::json validationJson(const ValidationReport& report) {
    const ValidationOptions& o = report.options;
    nlohmann::json json;
    json["format"] = "skinlab-scaling-validation";
    json["version"] = 1;
    json["options"] = {{"true_scores", o.trueScores},
                       {"observer_counts", o.observerCounts},
                       {"experiments", o.experiments},
                       {"trials_per_pair", o.trialsPerPair},
                       {"bootstrap_samples", o.bootstrapSamples},
                       {"seed", o.seed},
                       {"lapse_rate", o.lapseRate},
                       {"side_bias_sd", o.sideBiasStandardDeviation},
                       {"random_observers", o.randomObservers},
                       {"inverted_observers", o.invertedObservers},
                       {"correction", correctionName(o.correction)},
                       {"alpha", o.alpha},
                       {"screening_whisker", o.screeningWhisker},
                       {"prior", priorName(o.prior)},
                       {"scenarios", o.scenarios},
                       {"sparse_pair_fraction", o.sparsePairFraction},
                       {"disconnected_groups", o.disconnectedGroups},
                       {"near_unanimous_stretch", o.nearUnanimousStretch},
                       {"active_trials", o.activeTrials},
                       {"active_stretch", o.activeStretch}};
    json["seconds"] = report.seconds;
    for (const ValidationRow& r : report.rows) {
        nlohmann::json row = {{"scenario", r.scenario},
                              {"observers", r.observers},
                              {"experiments", r.experiments},
                              {"coverage", r.coverage},
                              {"one_sided_share", r.oneSidedShare},
                              {"mean_width", r.meanWidth},
                              {"fallback_share", r.fallbackShare},
                              {"maximum_half_width", r.maximumHalfWidth},
                              {"percentile_coverage", r.percentileCoverage},
                              {"percentile_mean_width", r.percentileMeanWidth},
                              {"rmse", r.rmse},
                              {"rank_correlation", r.rankCorrelation},
                              {"significant_correct", r.significantCorrect},
                              {"significant_reversed", r.significantReversed}};
        if (r.randomHitRate >= 0) row["random_hit_rate"] = r.randomHitRate;
        if (r.invertedHitRate >= 0) row["inverted_hit_rate"] = r.invertedHitRate;
        if (r.falseAlarmRate >= 0) row["false_alarm_rate"] = r.falseAlarmRate;
        if (r.bootstrapCoverage >= 0) row["bootstrap_coverage"] = r.bootstrapCoverage;
        if (r.unionCoverage >= 0) row["union_coverage"] = r.unionCoverage;
        if (r.pairCoverage >= 0) row["pair_coverage"] = r.pairCoverage;
        if (r.oneSidedCoverage >= 0) row["one_sided_coverage"] = r.oneSidedCoverage;
        if (r.pairOneSidedCoverage >= 0) row["pair_one_sided_coverage"] = r.pairOneSidedCoverage;
        json["rows"].push_back(row);
    }
    return json;
}

} // namespace skinlab::analysis::scaling
