// Wall-clock time of the scaling of one block with 1000 bootstrap samples over observers (targets:
// 6 conditions × 30 observers < 1 s, 20 × 30 < 10 s on 2 cores). Simulated full designs; each case runs
// `--repeat` times (default 5) and prints the median and the minimum, for the bootstrap alone and for the whole
// block analysis (Thurstone and Bradley–Terry fits, bootstrap, tests, leave-one-out screening, consistency).
// `--prior-comparison`: the same with the Gaussian prior and with pwcmp's on a 25-condition, 26,580-answer block.
// Usage: bench_scaling [--repeat N] [--threads T] [--samples B] [--prior-comparison]
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

// A light-field-sized block: 25 conditions 0.25 JOD apart, 30 observers × 3 trials of each of the 300 pairs
// (27,000 answers), less 420 answers taken one from each of the first 420 (observer, pair) cells: 26,580 answers.
BlockData lightFieldSized() {
    SimulationDesign design;
    for (int i = 0; i < 25; ++i) design.trueScores.push_back(0.25 * i);
    design.observers = 30;
    design.trialsPerPair = 3;
    BlockData block = simulateBlock(design, 7).block;
    int removed = 0;
    for (Eigen::Index k = 0; k < block.winsFirst.rows() && removed < 420; ++k)
        for (Eigen::Index p = 0; p < block.winsFirst.cols() && removed < 420; ++p, ++removed)
            (block.winsFirst(k, p) > 0 ? block.winsFirst : block.winsSecond)(k, p) -= 1.0;
    return block;
}

// `--prior-comparison`: the whole block analysis of lightFieldSized() with the Gaussian prior and with pwcmp's.
int priorComparison(int repeat, int threads, int samples) {
    const BlockData block = lightFieldSized();
    const double answers = block.winsFirst.sum() + block.winsSecond.sum();
    std::printf("25 conditions, %d observers, %.0f answers, %d bootstrap samples, %d threads, %d repeats\n",
                block.observerCount(), answers, samples, threads, repeat);
    std::printf("| prior | whole block wall median (s) | min (s) | CPU median (s) |\n|---|---|---|---|\n");
    double gaussian = 0.0;
    for (const Prior prior : {Prior::Gaussian, Prior::Pwcmp}) {
        AnalysisOptions options;
        options.fit.prior = prior;
        options.bootstrap.samples = samples;
        options.bootstrap.threads = threads;
        std::vector<double> wall, cpu;
        for (int r = 0; r < repeat; ++r) {
            const auto start = std::chrono::steady_clock::now();
            const double cpuStart = cpuSeconds();
            const BlockAnalysis analysis = analyzeBlock(block, options);
            wall.push_back(seconds(start));
            cpu.push_back(cpuSeconds() - cpuStart);
            if (analysis.low.size() != 25) return 1;
        }
        std::sort(wall.begin(), wall.end());
        std::sort(cpu.begin(), cpu.end());
        std::printf("| %s | %.3f | %.3f | %.3f |\n", priorName(prior), wall[wall.size() / 2], wall.front(),
                    cpu[cpu.size() / 2]);
        if (prior == Prior::Gaussian) gaussian = wall[wall.size() / 2];
        else std::printf("pwcmp / gaussian (wall medians): %.2f\n", wall[wall.size() / 2] / gaussian);
    }
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    int repeat = 5, threads = 2, samples = 1000;
    bool priors = false;
    for (int k = 1; k < argc; ++k) {
        if (!std::strcmp(argv[k], "--prior-comparison")) priors = true;
        else if (k + 1 >= argc) break;
        else if (!std::strcmp(argv[k], "--repeat")) repeat = std::atoi(argv[++k]);
        else if (!std::strcmp(argv[k], "--threads")) threads = std::atoi(argv[++k]);
        else if (!std::strcmp(argv[k], "--samples")) samples = std::atoi(argv[++k]);
    }
    if (priors) return priorComparison(repeat, threads, samples);
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
