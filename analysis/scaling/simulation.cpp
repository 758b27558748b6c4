#include "analysis/scaling/simulation.h"

#include "analysis/scaling/pairwise_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace skinlab::analysis::scaling {

SimulatedBlock simulateBlock(const SimulationDesign& design, std::uint64_t seed) {
    const int m = static_cast<int>(design.trueScores.size());
    const int n = design.observers;
    SimulatedBlock simulated;
    BlockData& block = simulated.block;
    block.name = "simulated";
    for (int i = 0; i < m; ++i) block.conditions.push_back("c" + std::to_string(i));
    for (int k = 0; k < n; ++k) {
        char name[16];
        std::snprintf(name, sizeof name, "o%03d", k + 1);
        block.observers.push_back(name);
    }
    const int groups = std::max(1, design.groups);
    for (int i = 0; i < m; ++i)
        for (int j = i + 1; j < m; ++j)
            if (i * groups / m == j * groups / m) block.pairs.emplace_back(i, j);
    const auto pairCount = static_cast<Eigen::Index>(block.pairs.size());
    block.winsFirst = Eigen::MatrixXd::Zero(n, pairCount);
    block.winsSecond = Eigen::MatrixXd::Zero(n, pairCount);
    block.sideCounts.assign(block.pairs.size(), {0, 0, 0, 0});
    block.leftChosen = Eigen::VectorXd::Zero(n);
    block.sideTrials = Eigen::VectorXd::Zero(n);

    std::mt19937_64 random(seed);
    std::normal_distribution<double> noise(0.0, kThurstoneSigma / std::sqrt(2.0));
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    // The bad observers are the last ones (the analysis never sees the order as meaningful).
    for (int k = 0; k < n; ++k) {
        SimulatedObserverKind kind = SimulatedObserverKind::Genuine;
        if (k >= n - design.randomObservers - design.invertedObservers) kind = SimulatedObserverKind::Random;
        if (k >= n - design.invertedObservers) kind = SimulatedObserverKind::Inverted;
        simulated.kinds.push_back(kind);
        const double bias = design.sideBiasStandardDeviation > 0
                                ? std::normal_distribution<double>(0.0, design.sideBiasStandardDeviation)(random)
                                : 0.0;
        const double sign = kind == SimulatedObserverKind::Inverted ? -1.0 : 1.0;
        for (Eigen::Index p = 0; p < pairCount; ++p) {
            const auto [i, j] = block.pairs[p];
            // Drawn only for incomplete designs, so complete ones keep their random stream.
            if (design.pairFraction < 1.0 && uniform(random) >= design.pairFraction) continue;
            for (int t = 0; t < design.trialsPerPair; ++t) {
                const bool firstOnLeft = t % 2 == 0;
                bool firstChosen;
                if (kind == SimulatedObserverKind::Random || uniform(random) < design.lapseRate) {
                    firstChosen = uniform(random) < 0.5;
                } else {
                    const double first = sign * design.trueScores[i] + noise(random) + (firstOnLeft ? bias : 0.0);
                    const double second = sign * design.trueScores[j] + noise(random) + (firstOnLeft ? 0.0 : bias);
                    firstChosen = first > second;
                }
                (firstChosen ? block.winsFirst : block.winsSecond)(k, p) += 1.0;
                block.sideCounts[p][(firstOnLeft ? 0 : 2) + (firstChosen ? 0 : 1)] += 1.0;
                block.sideTrials[k] += 1.0;
                if (firstChosen == firstOnLeft) block.leftChosen[k] += 1.0;
            }
        }
    }
    return simulated;
}

} // namespace skinlab::analysis::scaling
