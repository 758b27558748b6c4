// Cost of transmittance and of the surface-AOV pass (docs/benchmarks.md, "Transmittance and surface AOVs").
//   bench_surface_passes [--rounds N] [--width W] [--height H] [--assets DIR]
// Renders builtin:head and, when the assets folder is known (--assets or $SKINLAB_ASSETS), the scanned head at
// 1280×720 in one process, alternating frames with transmittance off and on (one warm-up frame of each first):
// on a shared machine the load drifts, and paired frames taken seconds apart cancel most of that drift. Prints the
// minimum and median per pass for each setting (the minimum is the figure least disturbed by other processes) and
// the median of the paired differences of the main pass (on − off), the cost of transmittance inside the main
// pass. GPU ms from the renderer's timer queries.
#include "bench/bench_stats.h"
#include "renderer/renderer.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace {

using skinlab::bench::median;

double minimum(const std::vector<double>& values) {
    return values.empty() ? 0.0 : *std::min_element(values.begin(), values.end());
}

} // namespace

int main(int argc, char** argv) {
    int rounds = 7;
    int width = 1280;
    int height = 720;
    std::string assets;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i];
        const std::string value = argv[i + 1];
        if (key == "--rounds") rounds = std::max(1, std::atoi(value.c_str()));
        else if (key == "--width") width = std::atoi(value.c_str());
        else if (key == "--height") height = std::atoi(value.c_str());
        else if (key == "--assets") assets = value;
        else {
            std::fprintf(stderr, "bench_surface_passes: unknown option %s\n", key.c_str());
            return 2;
        }
    }
    if (assets.empty())
        if (const char* environment = std::getenv("SKINLAB_ASSETS")) assets = environment;
    std::vector<std::string> scenes = {"builtin:head"};
    const std::filesystem::path scanned =
        std::filesystem::path(SKINLAB_SOURCE_DIR) / "renderer/scenes/lee-perry-smith.toml";
    if (!assets.empty()) scenes.push_back(scanned.string());

    skinlab::renderer::Renderer renderer;
    const std::filesystem::path scratch = std::filesystem::temp_directory_path() / "skinlab-bench-surface-passes";
    std::filesystem::create_directories(scratch);
    std::printf("GL_RENDERER: %s\n%d×%d, %d rounds of (off, on) after one warm-up frame of each\n\n",
                renderer.glRenderer().c_str(), width, height, rounds);
    const std::vector<std::string> passes = {"main", "surface_aovs", "transmittance", "sss"};
    for (const std::string& scene : scenes) {
        skinlab::renderer::RenderRequest request;
        request.scene = scene;
        request.width = width;
        request.height = height;
        request.assetsDir = assets;
        request.exrPath = scratch / "frame.exr";
        std::map<std::string, std::vector<double>> off, on;
        std::vector<double> mainDifference;
        for (int round = 0; round <= rounds; ++round) {
            request.overrides = {};
            const auto withoutTransmittance = renderer.render(request);
            request.overrides = {"transmittance.enabled=true"};
            const auto withTransmittance = renderer.render(request);
            if (round == 0) continue; // warm-up: shader compilation, file loading
            for (const auto& pass : passes) {
                off[pass].push_back(withoutTransmittance.timingsMs["passes"][pass].get<double>());
                on[pass].push_back(withTransmittance.timingsMs["passes"][pass].get<double>());
            }
            mainDifference.push_back(withTransmittance.timingsMs["passes"]["main"].get<double>() -
                                     withoutTransmittance.timingsMs["passes"]["main"].get<double>());
        }
        const std::string label = scene == scanned.string() ? "lee-perry-smith" : scene;
        std::printf("%s\n  %-14s %10s %10s %10s %10s\n", label.c_str(), "pass (GPU ms)", "off min", "off median",
                    "on min", "on median");
        for (const auto& pass : passes)
            std::printf("  %-14s %10.2f %10.2f %10.2f %10.2f\n", pass.c_str(), minimum(off[pass]), median(off[pass]),
                        minimum(on[pass]), median(on[pass]));
        std::printf("  main on − off (median of the paired differences): %.2f\n\n", median(mainDifference));
    }
    std::filesystem::remove_all(scratch);
    return 0;
}
