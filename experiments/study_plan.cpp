#include "experiments/study_plan.h"

#include "analysis/scaling/pairwise_model.h"
#include "analysis/scaling/simulation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace skinlab::experiments {
namespace scaling = skinlab::analysis::scaling;

namespace {

// Two-sided p of a standard normal statistic.
double twoSidedP(double z) { return std::erfc(std::abs(z) / std::sqrt(2.0)); }

// Which pairs (i < j, indices into the conditions) one simulated study resolves: likelihood-ratio tests of
// q_i = q_j (the fit against the fit constrained along that contrast; a Wald test from the Fisher information
// loses all power at large differences, where one side wins nearly every trial), Holm over every pair of the
// block, significant at α with the sign of the predicted difference.
std::vector<std::vector<bool>> resolvedPairs(const scaling::BlockData& block, const std::vector<double>& truth,
                                             double alpha) {
    const int m = block.conditionCount();
    const scaling::PairCounts counts = block.totalCounts();
    const scaling::FitOptions options;
    const scaling::FitResult fit = scaling::fitScores(counts, options);
    const double best = scaling::logPosterior(counts, options, fit.scores);
    struct Test {
        int i, j;
        double p;
        bool rightWay;
    };
    std::vector<Test> tests;
    for (int i = 0; i < m; ++i)
        for (int j = i + 1; j < m; ++j) {
            Eigen::VectorXd contrast = Eigen::VectorXd::Zero(m);
            contrast[i] = 1.0;
            contrast[j] = -1.0;
            const scaling::ConstrainedFit null = scaling::fitConstrained(counts, options, contrast, 0.0, fit.scores);
            const double statistic = std::max(0.0, 2.0 * (best - null.logPosterior));
            const double difference = fit.scores[i] - fit.scores[j];
            tests.push_back({i, j, twoSidedP(std::sqrt(statistic)), (difference > 0) == (truth[i] > truth[j])});
        }
    std::vector<std::size_t> order(tests.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return tests[a].p < tests[b].p; });
    std::vector<std::vector<bool>> resolved(static_cast<std::size_t>(m), std::vector<bool>(m, false));
    double running = 0.0;
    for (std::size_t k = 0; k < order.size(); ++k) {
        const Test& t = tests[order[k]];
        running = std::max(running, std::min(1.0, double(order.size() - k) * t.p));
        const bool significant = running < alpha && t.rightWay;
        resolved[t.i][t.j] = resolved[t.j][t.i] = significant;
    }
    return resolved;
}

} // namespace

StudyPlan planStudy(const StudyDefinition& definition, const SimulationTruth& truth, const PlanOptions& options) {
    StudyPlan plan;
    plan.options = options;
    plan.repetitions = definition.design.repetitions;
    plan.trialsPerObserver = definition.design.practiceTrials + definition.testTrialCount() +
                             definition.repeatTrialCount() + definition.catchTrialCount();
    for (const StudyBlock& block : definition.blocks) {
        PlannedBlock planned;
        planned.name = block.name;
        planned.conditions = block.conditions;
        for (const std::string& condition : block.conditions)
            planned.predicted.push_back(truth.quality(block.name, condition));
        const int m = static_cast<int>(block.conditions.size());
        std::vector<int> byQuality(static_cast<std::size_t>(m));
        std::iota(byQuality.begin(), byQuality.end(), 0);
        std::stable_sort(byQuality.begin(), byQuality.end(),
                         [&](int a, int b) { return planned.predicted[a] > planned.predicted[b]; });
        for (int k = 0; k + 1 < m; ++k)
            planned.neighbours.push_back({block.conditions[byQuality[k]],
                                          block.conditions[byQuality[k + 1]],
                                          planned.predicted[byQuality[k]] - planned.predicted[byQuality[k + 1]],
                                          {}});
        for (std::size_t c = 0; c < options.observerCounts.size(); ++c) {
            std::vector<int> resolvedCount(planned.neighbours.size(), 0);
            for (int s = 0; s < options.simulations; ++s) {
                scaling::SimulationDesign design;
                design.trueScores = planned.predicted;
                design.observers = options.observerCounts[c];
                design.trialsPerPair = definition.design.repetitions;
                const std::uint64_t seed = options.seed * 1000003ull + c * 7919ull + static_cast<std::uint64_t>(s);
                const scaling::SimulatedBlock simulated = scaling::simulateBlock(design, seed);
                const auto resolved = resolvedPairs(simulated.block, planned.predicted, options.alpha);
                for (std::size_t k = 0; k < planned.neighbours.size(); ++k)
                    if (resolved[byQuality[k]][byQuality[k + 1]]) ++resolvedCount[k];
            }
            for (std::size_t k = 0; k < planned.neighbours.size(); ++k)
                planned.neighbours[k].power.push_back(double(resolvedCount[k]) / options.simulations);
            const bool all = std::all_of(planned.neighbours.begin(), planned.neighbours.end(),
                                         [&](const PlannedPair& p) { return p.power.back() >= options.power; });
            if (all && planned.observersNeeded < 0) planned.observersNeeded = options.observerCounts[c];
        }
        plan.blocks.push_back(std::move(planned));
    }
    return plan;
}

std::string planText(const StudyPlan& plan) {
    std::string out;
    char line[512];
    std::snprintf(line, sizeof line,
                  "power by simulation: %d simulated studies per observer count, each pair shown %d time(s) to every "
                  "observer, Holm over each block's pairs, alpha %.3g, target power %.2g; %d trials per observer\n",
                  plan.options.simulations, plan.repetitions, plan.options.alpha, plan.options.power,
                  plan.trialsPerObserver);
    out += line;
    for (const PlannedBlock& block : plan.blocks) {
        out += "block " + block.name + ": predicted JOD";
        for (std::size_t i = 0; i < block.conditions.size(); ++i) {
            std::snprintf(line, sizeof line, "%s %s %.3f", i ? "," : "", block.conditions[i].c_str(),
                          block.predicted[i]);
            out += line;
        }
        out += "\n  neighbours (predicted order) and their power at";
        for (int n : plan.options.observerCounts) out += " " + std::to_string(n);
        out += " observers:\n";
        for (const PlannedPair& pair : block.neighbours) {
            std::snprintf(line, sizeof line, "  %s > %s (%.3f JOD):", pair.better.c_str(), pair.worse.c_str(),
                          pair.difference);
            out += line;
            for (double p : pair.power) {
                std::snprintf(line, sizeof line, " %.2f", p);
                out += line;
            }
            out += "\n";
        }
        // What a study of each size should find: the expected number of significant neighbouring pairs (the sum of
        // their powers), so that an outcome can be read against the plan.
        if (!block.neighbours.empty()) {
            out += "  significant neighbouring pairs to expect (of " + std::to_string(block.neighbours.size()) + "):";
            for (std::size_t k = 0; k < plan.options.observerCounts.size(); ++k) {
                double expected = 0.0;
                for (const PlannedPair& pair : block.neighbours)
                    expected += k < pair.power.size() ? pair.power[k] : 0.0;
                std::snprintf(line, sizeof line, " %.1f at %d%s", expected, plan.options.observerCounts[k],
                              k + 1 < plan.options.observerCounts.size() ? "," : " observers\n");
                out += line;
            }
        }
        if (block.observersNeeded > 0) {
            std::snprintf(line, sizeof line,
                          "  needs %d observers (%d trials in all) for every neighbouring pair to be resolved with "
                          "power >= %.2g\n",
                          block.observersNeeded, block.observersNeeded * plan.trialsPerObserver, plan.options.power);
            out += line;
        } else if (!block.neighbours.empty()) {
            // Not every pair: name the one that keeps the block from it (the closest); the others may well come out.
            const PlannedPair& closest = *std::min_element(
                block.neighbours.begin(), block.neighbours.end(),
                [](const PlannedPair& a, const PlannedPair& b) { return a.difference < b.difference; });
            std::snprintf(line, sizeof line,
                          "  not every neighbouring pair reaches power >= %.2g by %d observers: the closest, %s > %s "
                          "(%.3f JOD), is too small for this design; pairs further apart can still come out "
                          "significant (above)\n",
                          plan.options.power, plan.options.observerCounts.back(), closest.better.c_str(),
                          closest.worse.c_str(), closest.difference);
            out += line;
        }
    }
    return out;
}

} // namespace skinlab::experiments
