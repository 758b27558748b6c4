// Coverage of the study report's "Predicted and measured" intervals (report/prediction_section.h): simulated
// studies of one block (Thurstone observers, every pair, the sides alternating), scaled as `analyze scale` does,
// then slope and RMSE of the measured scores against the prediction with their bootstrap intervals, as the report
// computes them. The true slope and RMSE are those of the true scores against the prediction (least squares with an
// intercept; RMS of truth − prediction about its mean, n − 1 degrees of freedom). Per scenario: how often each
// interval holds the true value (± its Monte Carlo standard error), the mean width, how often the RMSE's interval
// lies above the true RMSE (a miss on that side) and how often it starts at 0. Scenarios: 5 conditions (bootstrap
// over observers) and 8 (over observers and conditions), each with truth = prediction (true slope 1, RMSE 0: the
// circular `study simulate --truth predicted` case) and with a truth that departs from the prediction.
// Usage: bench_prediction_coverage [--studies N] [--samples B] [--observers K] [--trials-per-pair T] [--seed S]
#include "report/prediction_section.h"

#include "analysis/scaling/bootstrap.h"
#include "analysis/scaling/simulation.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace scaling = skinlab::analysis::scaling;

namespace {

struct Scenario {
    const char* name;
    std::vector<double> predicted, truth;
};

struct Truth {
    double slope = 0.0, rmse = 0.0;
};

Truth trueAgreement(const std::vector<double>& predicted, const std::vector<double>& truth) {
    const auto n = static_cast<double>(predicted.size());
    double mx = 0.0, my = 0.0, md = 0.0;
    for (std::size_t i = 0; i < predicted.size(); ++i)
        mx += predicted[i] / n, my += truth[i] / n, md += (truth[i] - predicted[i]) / n;
    double xy = 0.0, xx = 0.0, squares = 0.0;
    for (std::size_t i = 0; i < predicted.size(); ++i) {
        xy += (predicted[i] - mx) * (truth[i] - my);
        xx += (predicted[i] - mx) * (predicted[i] - mx);
        squares += std::pow(truth[i] - predicted[i] - md, 2);
    }
    return {xy / xx, std::sqrt(squares / (n - 1.0))};
}

struct Options {
    int studies = 300, samples = 200, observers = 10, trialsPerPair = 2;
    std::uint64_t seed = 77;
};

void run(const Scenario& scenario, const Options& options) {
    const Truth truth = trueAgreement(scenario.predicted, scenario.truth);
    int slopeCovered = 0, rmseCovered = 0, rmseAbove = 0, rmseAtZero = 0, counted = 0;
    double slopeWidth = 0.0, rmseWidth = 0.0, slopeMean = 0.0, rmseMean = 0.0;
    for (int study = 0; study < options.studies; ++study) {
        const std::uint64_t seed = scaling::mixSeed(options.seed, static_cast<std::uint64_t>(study));
        scaling::SimulationDesign design;
        design.trueScores = scenario.truth;
        design.observers = options.observers;
        design.trialsPerPair = options.trialsPerPair;
        const scaling::SimulatedBlock simulated = scaling::simulateBlock(design, seed);
        scaling::AnalysisOptions analysis;
        analysis.bootstrap.samples = options.samples;
        analysis.bootstrap.threads = 1;
        const scaling::BlockAnalysis block = scaling::analyzeBlock(simulated.block, analysis);
        skinlab::report::PredictionOptions agreement;
        agreement.samples = options.samples;
        agreement.seed = seed;
        const auto a =
            skinlab::report::blockPredictionAgreement(block, scenario.predicted, &simulated.block, agreement);
        if (!a || !std::isfinite(a->slopeLow) || !std::isfinite(a->rmseLow)) continue;
        ++counted;
        slopeCovered += a->slopeLow <= truth.slope && truth.slope <= a->slopeHigh;
        rmseCovered += a->rmseLow <= truth.rmse + 1e-12 && truth.rmse <= a->rmseHigh;
        rmseAbove += a->rmseLow > truth.rmse + 1e-12;
        rmseAtZero += a->rmseLow == 0.0;
        slopeWidth += (a->slopeHigh - a->slopeLow);
        rmseWidth += (a->rmseHigh - a->rmseLow);
        slopeMean += a->slope;
        rmseMean += a->rmse;
    }
    const double n = counted > 0 ? counted : 1.0;
    auto share = [&](int k) { return counted > 0 ? double(k) / counted : 0.0; };
    auto error = [&](int k) { return counted > 0 ? std::sqrt(share(k) * (1.0 - share(k)) / counted) : 0.0; };
    std::printf(
        "| %s | %zu | %d | %.2f | %.2f | %.3f ± %.3f | %.2f | %.2f | %.2f | %.3f ± %.3f | %.3f | %.2f | %.3f |\n",
        scenario.name, scenario.truth.size(), counted, truth.slope, slopeMean / n, share(slopeCovered),
        error(slopeCovered), slopeWidth / n, truth.rmse, rmseMean / n, share(rmseCovered), error(rmseCovered),
        share(rmseAbove), rmseWidth / n, share(rmseAtZero));
    std::fflush(stdout);
}

int integerOption(const char* name, const char* value) {
    char* end = nullptr;
    const long v = std::strtol(value, &end, 10);
    if (*end != '\0' || v < 1) {
        std::fprintf(stderr, "bench_prediction_coverage: %s: \"%s\" is not a positive integer\n", name, value);
        std::exit(2);
    }
    return static_cast<int>(v);
}

} // namespace

int main(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (i + 1 >= argc) {
            std::fprintf(stderr, "bench_prediction_coverage: %s needs a value\n", arg.c_str());
            return 2;
        }
        const char* value = argv[++i];
        if (arg == "--studies") options.studies = integerOption("--studies", value);
        else if (arg == "--samples") options.samples = integerOption("--samples", value);
        else if (arg == "--observers") options.observers = integerOption("--observers", value);
        else if (arg == "--trials-per-pair") options.trialsPerPair = integerOption("--trials-per-pair", value);
        else if (arg == "--seed") options.seed = static_cast<std::uint64_t>(integerOption("--seed", value));
        else {
            std::fprintf(stderr, "bench_prediction_coverage: unknown option %s\n", arg.c_str());
            return 2;
        }
    }
    // Predicted JOD differences 0.6 apart (the demo's range); the departing truth compresses the differences (true
    // slope below 1) and moves two conditions off the line.
    const std::vector<double> predicted5 = {0.0, 0.6, 1.2, 1.8, 2.4};
    const std::vector<double> truth5 = {0.0, 0.7, 0.6, 1.5, 1.7};
    const std::vector<double> predicted8 = {0.0, 0.35, 0.7, 1.05, 1.4, 1.75, 2.1, 2.45};
    const std::vector<double> truth8 = {0.0, 0.45, 0.4, 0.9, 1.0, 1.5, 1.4, 1.9};
    const std::vector<Scenario> scenarios = {{"truth = prediction", predicted5, predicted5},
                                             {"truth departs", predicted5, truth5},
                                             {"truth = prediction", predicted8, predicted8},
                                             {"truth departs", predicted8, truth8}};
    std::printf("%d studies per row, %d observers, %d trials per pair, %d bootstrap resamples, seed %llu\n\n",
                options.studies, options.observers, options.trialsPerPair, options.samples,
                static_cast<unsigned long long>(options.seed));
    std::printf(
        "| scenario | conditions | studies | true slope | mean slope | slope coverage | mean width | true RMSE | "
        "mean RMSE | RMSE coverage | interval above the truth | mean width | RMSE interval from 0 |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const Scenario& s : scenarios) run(s, options);
    return 0;
}
