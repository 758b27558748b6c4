// Cost of the artifact extensions (docs/benchmarks.md, "Artifact extensions"): SSS-stage
// milliseconds of every screen-space method with each extension set, at one scene, view and size.
//   bench_extensions [--scene S] [--view close|mid|far] [--width W] [--height H] [--frames N] [--assets DIR]
//                    [--methods gaussian-sum,separable,artistic,pscbf]
// For every method and extension set: one warm-up render (kernel construction, shader compilation), then N measured
// renders; the SSS stage's GPU time (GL_TIME_ELAPSED) is reported as the median and the minimum (on a machine
// shared with other work the minimum is the figure least disturbed by it). Prints a Markdown table.
#include "bench/bench_stats.h"
#include "renderer/renderer.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

using skinlab::bench::median;

std::vector<std::string> split(const std::string& text) { return skinlab::bench::splitCommas(text); }

struct ExtensionSet {
    const char* name;
    std::vector<std::string> overrides; // β is set per method below
    bool lab;
};

} // namespace

int main(int argc, char** argv) {
    std::string scene = "builtin:head", view = "close", assets;
    int width = 1280, height = 720, frames = 3;
    std::vector<std::string> methods = skinlab::renderer::sss::screenSpaceMethodNames();
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i], value = argv[i + 1];
        if (key == "--scene") scene = value;
        else if (key == "--view") view = value;
        else if (key == "--width") width = std::stoi(value);
        else if (key == "--height") height = std::stoi(value);
        else if (key == "--frames") frames = std::max(1, std::stoi(value));
        else if (key == "--assets") assets = value;
        else if (key == "--methods") methods = split(value);
        else {
            std::fprintf(stderr, "bench_extensions: unknown option %s\n", key.c_str());
            return 2;
        }
    }
    const std::vector<ExtensionSet> sets{{"follow-surface", {}, false},
                                         {"+cbf", {"sss.cbf=true"}, false},
                                         {"+lab_weight", {}, true},
                                         {"+curvature", {"sss.curvature=\"reduce-floor\""}, false},
                                         {"all", {"sss.cbf=true", "sss.curvature=\"reduce-floor\""}, true}};
    const std::filesystem::path scratch =
        std::filesystem::temp_directory_path() / ("skinlab-bench-extensions-" + std::to_string(::getpid()));
    std::filesystem::create_directories(scratch);
    skinlab::renderer::Renderer renderer;
    std::printf("GL_RENDERER: %s\nGL_VERSION: %s\n%s, %s view, %d×%d, SSS stage GPU ms: median (minimum) of %d "
                "frames after one warm-up\n\n| method |",
                renderer.glRenderer().c_str(), renderer.glVersion().c_str(), scene.c_str(), view.c_str(), width, height,
                frames);
    for (const auto& set : sets) std::printf(" %s |", set.name);
    std::printf("\n|---|");
    for (std::size_t i = 0; i < sets.size(); ++i) std::printf("---|");
    std::printf("\n");
    for (const auto& method : methods) {
        std::printf("| %s |", method.c_str());
        for (const auto& set : sets) {
            skinlab::renderer::RenderRequest request;
            request.scene = scene;
            request.method = method;
            request.overrides = {"camera.view=\"" + view + "\""};
            request.overrides.insert(request.overrides.end(), set.overrides.begin(), set.overrides.end());
            // The thesis' β: 0.5 for the sum of Gaussians, 0.09 for the others.
            if (set.lab)
                request.overrides.push_back(method == "gaussian-sum" ? "sss.lab_weight=0.5" : "sss.lab_weight=0.09");
            request.width = width;
            request.height = height;
            request.assetsDir = assets;
            request.exrPath = scratch / "frame.exr";
            std::vector<double> gpu;
            for (int frame = 0; frame <= frames; ++frame) {
                const auto result = renderer.render(request);
                if (frame > 0) gpu.push_back(result.timingsMs["passes"]["sss"].get<double>());
            }
            std::printf(" %.0f (%.0f) |", median(gpu), *std::min_element(gpu.begin(), gpu.end()));
            std::fflush(stdout);
        }
        std::printf("\n");
    }
    std::filesystem::remove_all(scratch);
    return 0;
}
