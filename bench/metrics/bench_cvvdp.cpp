// Wall-clock time of ColorVideoVDP (analysis/metrics/cvvdp.h) on one image pair per resolution, with and without
// the per-pixel map, the time of each stage (colour, pyramid, CSF, masking, pooling, map) as counters in seconds
// per call, and the CPU time of the whole process (all threads) per call. The pair: a textured image and its
// Gaussian blur (σ = 2 px), so every band has differences; the time does not depend on the content. Display:
// standard_fhd (ppd 37.8: 7 Laplacian bands and the baseband).
// Run: build/release/bench/metrics/bench_cvvdp --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include "analysis/metrics/cvvdp.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <ctime>
#include <map>
#include <random>
#include <utility>

#include <opencv2/imgproc.hpp>

namespace {
using namespace skinlab::metrics;

struct Pair {
    cv::Mat reference;
    cv::Mat test;
};

const Pair& pair(int width, int height) {
    static std::map<std::pair<int, int>, Pair> cache;
    auto found = cache.find({width, height});
    if (found != cache.end()) return found->second;
    Pair p;
    p.reference.create(height, width, CV_32FC3);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> noise(0.0f, 0.1f);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const float u = float(x) / 97.0f, v = float(y) / 61.0f;
            const float base = 0.3f + 0.2f * std::sin(u) * std::cos(v);
            p.reference.at<cv::Vec3f>(y, x) = {base + noise(rng), base * 0.8f + noise(rng), base * 0.6f + noise(rng)};
        }
    cv::GaussianBlur(p.reference, p.test, {0, 0}, 2.0, 2.0, cv::BORDER_REFLECT);
    return cache.emplace(std::make_pair(width, height), std::move(p)).first->second;
}

void run(benchmark::State& state, bool withMap) {
    const int width = static_cast<int>(state.range(0)), height = static_cast<int>(state.range(1));
    const Pair& p = pair(width, height);
    const CvvdpDisplay display = cvvdpDisplay("standard_fhd");
    CvvdpStageTimes total;
    double jod = 0.0;
    const std::clock_t cpuStart = std::clock();
    for (auto _ : state) {
        CvvdpStageTimes times;
        const CvvdpResult result = cvvdp(p.reference, p.test, display, withMap, &times);
        benchmark::DoNotOptimize(result.jod);
        jod = result.jod;
        total.colour += times.colour;
        total.pyramid += times.pyramid;
        total.csf += times.csf;
        total.masking += times.masking;
        total.pooling += times.pooling;
        total.heatmap += times.heatmap;
    }
    const double n = static_cast<double>(state.iterations());
    // CPU time of the whole process (both worker threads), less sensitive than wall time to other jobs.
    state.counters["process_cpu_s"] = static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC / n;
    state.counters["colour_s"] = total.colour / n;
    state.counters["pyramid_s"] = total.pyramid / n;
    state.counters["csf_s"] = total.csf / n;
    state.counters["masking_s"] = total.masking / n;
    state.counters["pooling_s"] = total.pooling / n;
    state.counters["map_s"] = total.heatmap / n;
    state.counters["megapixels"] = width * height / 1e6;
    state.counters["jod"] = jod;
}

void jodOnly(benchmark::State& state) { run(state, false); }
void jodAndMap(benchmark::State& state) { run(state, true); }

void resolutions(benchmark::internal::Benchmark* b) {
    b->Args({320, 180})->Args({640, 360})->Args({1280, 720})->Args({1920, 1080})->Args({3840, 2160});
    b->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(jodOnly)->Apply(resolutions);
BENCHMARK(jodAndMap)->Apply(resolutions);

} // namespace

BENCHMARK_MAIN();
