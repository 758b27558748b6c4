// Timing of `skinlab analyze metrics` on one 1280×720 pair (docs/benchmarks.md, "Metrics").
// Synthetic renders (disc scene, contract-1 EXR with beauty, depth.Z, mask.Y) so the benchmark needs no GL.
// Run: build/<dir>/tests/analysis/metrics/bench_metrics --benchmark_repetitions=5
#include "analysis/metrics/error_bands.h"
#include "analysis/metrics/flip.h"
#include "analysis/metrics/metrics_run.h"
#include "analysis/metrics/render_comparison.h"

#include "synthetic_render.h"
#include "tests/common/temp_folder.h"

#include <benchmark/benchmark.h>

#include <filesystem>

namespace {
namespace fs = std::filesystem;
using namespace skinlab::metrics;
// The synthetic renders' namespace, by a name apart from GoogleTest's ::testing (tests/common/temp_folder.h).
namespace synthetic = skinlab::metrics::testing;

constexpr int width = 1280;
constexpr int height = 720;

struct Fixture {
    // The folder lives as long as the fixture (the process) and is removed at exit.
    skinlab::test_support::TempFolder temp{"bench-metrics"};
    fs::path folder = temp.path();
    fs::path referencePath = folder / "reference.exr";
    fs::path testPath = folder / "test.exr";
    Fixture() {
        synthetic::DiscScene scene;
        scene.size = height;
        scene.width = width;
        scene.farPlaneIsSkin = true;
        scene.stripeHalfWidth = 0.02;
        synthetic::SyntheticRender reference = synthetic::renderDiscScene(scene);
        synthetic::SyntheticRender test = reference;
        test.beauty = cv::Mat(reference.beauty * 1.05); // every pixel differs: the full ΔE00 cost
        synthetic::writeSyntheticExr(referencePath, reference);
        synthetic::writeSyntheticExr(testPath, test);
    }
};

Fixture& fixture() {
    static Fixture instance;
    return instance;
}

// Reading both EXRs (all channels, float32).
void loadPair(benchmark::State& state) {
    for (auto _ : state) {
        MetricRender reference = loadMetricRender(fixture().referencePath, RenderRole::reference);
        MetricRender test = loadMetricRender(fixture().testPath, RenderRole::test);
        benchmark::DoNotOptimize(reference.beauty.data);
        benchmark::DoNotOptimize(test.beauty.data);
    }
}

// Edges, three exact distance transforms and the four bands.
void buildBands(benchmark::State& state) {
    MetricRender reference = loadMetricRender(fixture().referencePath, RenderRole::reference);
    BandGeometry geometry{*reference.sssRadiusMillimetres / *reference.millimetresPerUnit,
                          *reference.focalLengthPixels};
    for (auto _ : state) {
        ErrorBands bands = buildErrorBands(reference.depth, reference.mask, geometry);
        benchmark::DoNotOptimize(bands.masks[0].data);
    }
}

// The reference's bands and encodings (done once per reference).
void prepareTheReference(benchmark::State& state) {
    MetricRender reference = loadMetricRender(fixture().referencePath, RenderRole::reference);
    for (auto _ : state) {
        PreparedReference prepared = prepareReference(reference, {});
        benchmark::DoNotOptimize(prepared.lab.data);
    }
}

// One test against a prepared reference: per-pixel ΔE00, PSNR, SSIM, band scores.
void compareOneTest(benchmark::State& state) {
    PreparedReference prepared = prepareReference(loadMetricRender(fixture().referencePath, RenderRole::reference), {});
    MetricRender test = loadMetricRender(fixture().testPath, RenderRole::test);
    for (auto _ : state) {
        ComparisonResult result = compareWithReference(prepared, test, {});
        benchmark::DoNotOptimize(result.image.ssim);
    }
}

// LDR-FLIP alone on the 1280×720 pair (both images through the CSF and feature filters, the per-pixel map, the
// mean), at the paper's 67.02 pixels per degree.
void flipOnePair(benchmark::State& state) {
    MetricRender reference = loadMetricRender(fixture().referencePath, RenderRole::reference);
    MetricRender test = loadMetricRender(fixture().testPath, RenderRole::test);
    for (auto _ : state) {
        cv::Mat map = flipErrorMap(reference.beauty, test.beauty, flipDefaultPixelsPerDegree);
        benchmark::DoNotOptimize(flipMean(map));
    }
}

// The whole command for one pair: read, prepare, compare, heat map PNG, CSV and JSON.
void wholeCommand(benchmark::State& state) {
    ComparisonPlan plan = planFileComparisons(fixture().referencePath, {fixture().testPath});
    for (auto _ : state) runMetrics(plan, {}, fixture().folder / "out");
}

BENCHMARK(loadPair)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(buildBands)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(prepareTheReference)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(compareOneTest)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(flipOnePair)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(wholeCommand)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
