// Speed of the object-space reference (renderer/reference): (adaptive) tessellation to a target edge length and the CPU
// convolution of every skin sample, on builtin:halo's sphere and builtin:head, at 2 threads (the CI machine's
// cores). Prints one Markdown table row per case: wall-clock and process CPU milliseconds (all threads), each the
// median of `repeats` runs. CPU time is the figure to compare on a shared, loaded machine: wall-clock time grows
// with the load of other processes, CPU time does not.
//   bench_reference [repeats=3]
//   bench_reference --smoke   (ctest's smoke run: one repeat of the 2 mm cases)
#include "bench/bench_stats.h"
#include "renderer/sss/radial_profile.h"
#include "renderer/reference/surface_convolution.h"
#include "renderer/reference/tessellation.h"
#include "renderer/scene/builtin_geometry.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

using namespace skinlab::renderer;
using namespace skinlab::renderer::reference;

namespace {

using skinlab::bench::median;

void run(const char* name, const Model& model, float edgeMm, int repeats) {
    std::vector<double> tessellateMs, convolveMs, convolveCpuMs;
    ConvolutionReport report;
    std::size_t skinSamples = 0;
    const auto profile = sss::makeRadialProfile(sss::SssParams{});
    for (int r = 0; r < repeats; ++r) {
        auto start = std::chrono::steady_clock::now();
        const Model fine = tessellateSkin(model, edgeMm, 1.0f);
        const SurfaceSamples samples = gatherSurfaceSamples(fine, 1.0f);
        tessellateMs.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        std::vector<glm::vec3> irradiance(samples.size());
        const glm::vec3 light = glm::normalize(glm::vec3(0.45f, 0.45f, 0.77f));
        for (std::size_t i = 0; i < samples.size(); ++i)
            irradiance[i] = glm::vec3(std::max(0.0f, glm::dot(samples.normal[i], light)));
        ConvolutionSettings settings;
        settings.threads = 2;
        start = std::chrono::steady_clock::now();
        const std::clock_t cpuStart = std::clock();
        const auto out = convolveSurface(samples, irradiance, *profile, settings, nullptr, &report);
        convolveMs.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        convolveCpuMs.push_back(1000.0 * double(std::clock() - cpuStart) / CLOCKS_PER_SEC);
        skinSamples = report.receivers;
        if (out.empty()) std::abort();
    }
    std::printf("| %s | %.2f | %zu | %.0f | %.0f | %.0f | %.0f |\n", name, edgeMm, skinSamples, report.meanSources,
                median(tessellateMs), median(convolveMs), median(convolveCpuMs));
    std::fflush(stdout);
}
} // namespace

int main(int argc, char** argv) {
    const bool smoke = argc > 1 && std::string(argv[1]) == "--smoke";
    const int repeats = smoke ? 1 : argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
    const std::vector<float> haloEdges = smoke ? std::vector<float>{2.0f} : std::vector<float>{2.0f, 1.0f, 0.5f};
    const std::vector<float> headEdges = smoke ? std::vector<float>{2.0f} : std::vector<float>{2.0f, 1.0f};
    std::printf(
        "| model | edge (mm) | skin samples | sources per sample | tessellate + gather, wall (ms) | convolve, wall "
        "(ms) | convolve, CPU (ms) |\n");
    std::printf("|---|---|---|---|---|---|---|\n");
    const Model halo = makeHaloScene(200.0f);
    for (const float edge : haloEdges) run("builtin:halo sphere", halo, edge, repeats);
    const Model head = makeHeadScene(false);
    // Adaptive tessellation: 2 mm gives 0.17 M samples (the former uniform rounds: 1.6 M), so 1 mm is timed too.
    for (const float edge : headEdges) run("builtin:head", head, edge, repeats);
    return 0;
}
