// Wall-clock time of the scaling of one block with 1000 bootstrap samples over observers (targets:
// 6 conditions × 30 observers < 1 s, 20 × 30 < 10 s on 2 cores). Simulated full designs; each case runs
// `--repeat` times (default 5) and prints the median and the minimum, for the bootstrap alone and for the whole
// block analysis (Thurstone and Bradley–Terry fits, bootstrap, tests, leave-one-out screening, consistency).
// Usage: bench_scaling [--repeat N] [--threads T] [--samples B]
#include "analysis/scaling/bootstrap.h"
#include "analysis/scaling/scale_analysis.h"
#include "analysis/scaling/simulation.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <thread>
#include <vector>

using namespace skinlab::analysis::scaling;

namespace {

double seconds(const std::chrono::steady_clock::time_point& start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Process CPU time (all threads), seconds: less sensitive than wall time to other jobs on a shared machine.
double cpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

} // namespace

int main(int argc, char** argv) {
    int repeat = 5, threads = 2, samples = 1000;
    for (int k = 1; k + 1 < argc; k += 2) {
        if (!std::strcmp(argv[k], "--repeat")) repeat = std::atoi(argv[k + 1]);
        else if (!std::strcmp(argv[k], "--threads")) threads = std::atoi(argv[k + 1]);
        else if (!std::strcmp(argv[k], "--samples")) samples = std::atoi(argv[k + 1]);
    }
    std::printf("hardware threads %u, bootstrap threads %d, %d samples, %d repeats\n",
                std::thread::hardware_concurrency(), threads, samples, repeat);
    std::printf(
        "| conditions | observers | trials/pair/observer | bootstrap wall median (s) | bootstrap wall min (s) | "
        "bootstrap CPU median (s) | whole block wall median (s) | whole block wall min (s) |\n"
        "|---|---|---|---|---|---|---|---|\n");
    for (const int conditions : {6, 20}) {
        SimulationDesign design;
        for (int i = 0; i < conditions; ++i) design.trueScores.push_back(0.15 * i);
        design.observers = 30;
        design.trialsPerPair = conditions == 6 ? 6 : 2;
        const SimulatedBlock simulated = simulateBlock(design, 42);
        AnalysisOptions options;
        options.bootstrap.samples = samples;
        options.bootstrap.threads = threads;
        std::vector<double> bootstrapTimes, bootstrapCpu, wholeTimes;
        for (int r = 0; r < repeat; ++r) {
            auto start = std::chrono::steady_clock::now();
            const double cpuStart = cpuSeconds();
            const FitResult fit = fitScores(simulated.block.totalCounts(), options.fit);
            const BootstrapResult bootstrap = bootstrapObservers(simulated.block, fit, options.fit, options.bootstrap);
            bootstrapTimes.push_back(seconds(start));
            bootstrapCpu.push_back(cpuSeconds() - cpuStart);
            start = std::chrono::steady_clock::now();
            const BlockAnalysis analysis = analyzeBlock(simulated.block, options);
            wholeTimes.push_back(seconds(start));
            if (bootstrap.low.size() != conditions || analysis.low.size() != conditions) return 1;
        }
        std::sort(bootstrapTimes.begin(), bootstrapTimes.end());
        std::sort(wholeTimes.begin(), wholeTimes.end());
        std::sort(bootstrapCpu.begin(), bootstrapCpu.end());
        std::printf("| %d | %d | %d | %.3f | %.3f | %.3f | %.3f | %.3f |\n", conditions, design.observers,
                    design.trialsPerPair, bootstrapTimes[bootstrapTimes.size() / 2], bootstrapTimes.front(),
                    bootstrapCpu[bootstrapCpu.size() / 2], wholeTimes[wholeTimes.size() / 2], wholeTimes.front());
    }
    return 0;
}
