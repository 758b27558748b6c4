// Cost of anti-aliasing per SSS method (docs/benchmarks.md, "Anti-aliasing").
//   bench_antialiasing [--scene S] [--size N] [--methods none,gaussian-sum,...] [--factors none,2,3,4]
//                      [--frames N] [--csv FILE]
// For every method and supersampling factor ("none": render.antialiasing = "none"), one warm-up render (shader
// compilation, kernel construction, model loading), then N measured renders of an N × N image with its PNG; reports
// the median of the GPU total of the passes and of the whole render() call (passes, read-back, EXR and PNG writes),
// and the ratio to "none". Default scene: renderer/scenes/evaluation/halo-skin-backdrop.toml at 256², the demo's
// silhouette stimulus.
#include "bench/bench_stats.h"
#include "common/files.h"
#include "renderer/renderer.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

int main(int argc, char** argv) {
    std::string scene =
        (std::filesystem::path(SKINLAB_SOURCE_DIR) / "renderer/scenes/evaluation/halo-skin-backdrop.toml").string();
    int size = 256;
    int frames = 3;
    std::vector<std::string> methods = {"none", "gaussian-sum", "separable", "artistic", "pscbf"};
    std::vector<std::string> factors = {"none", "2", "3", "4"};
    std::string csvPath;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i];
        const std::string value = argv[i + 1];
        if (key == "--scene") scene = value;
        else if (key == "--size") size = std::atoi(value.c_str());
        else if (key == "--frames") frames = std::max(1, std::atoi(value.c_str()));
        else if (key == "--methods") methods = skinlab::bench::splitCommas(value);
        else if (key == "--factors") factors = skinlab::bench::splitCommas(value);
        else if (key == "--csv") csvPath = value;
        else {
            std::fprintf(stderr, "bench_antialiasing: unknown option %s\n", key.c_str());
            return 2;
        }
    }

    skinlab::renderer::Renderer renderer;
    const std::filesystem::path scratch = std::filesystem::temp_directory_path() / "skinlab-bench-antialiasing";
    std::filesystem::create_directories(scratch);
    std::printf("GL_RENDERER: %s\n%s, %d×%d, median of %d renders after one warm-up\n\n", renderer.glRenderer().c_str(),
                scene.c_str(), size, size, frames);
    std::printf("%-14s %-7s %12s %12s %10s\n", "method", "factor", "passes ms", "render ms", "× none");
    std::string csv = "method,factor,gpu_total_ms_median,render_ms_median,ratio_to_none,frames,size,gl_renderer\n";
    for (const std::string& method : methods) {
        double noneMs = 0.0;
        for (const std::string& factor : factors) {
            skinlab::renderer::RenderRequest request;
            request.scene = scene;
            request.method = method;
            request.width = size;
            request.height = size;
            request.overrides = {factor == "none" ? "render.antialiasing=none" : "render.ssaa_factor=" + factor};
            request.exrPath = scratch / "frame.exr";
            request.pngPath = scratch / "frame.png";
            std::vector<double> passes, calls;
            for (int frame = 0; frame <= frames; ++frame) {
                const auto start = std::chrono::steady_clock::now();
                const auto result = renderer.render(request);
                const double ms =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
                if (frame == 0) continue; // warm-up
                passes.push_back(result.timingsMs["gpu_total"].get<double>());
                calls.push_back(ms);
            }
            const double renderMs = skinlab::bench::median(calls);
            if (factor == "none") noneMs = renderMs;
            const double ratio = noneMs > 0.0 ? renderMs / noneMs : 0.0;
            std::printf("%-14s %-7s %12.1f %12.1f %10.2f\n", method.c_str(), factor.c_str(),
                        skinlab::bench::median(passes), renderMs, ratio);
            csv += method + "," + factor + "," + std::to_string(skinlab::bench::median(passes)) + "," +
                   std::to_string(renderMs) + "," + std::to_string(ratio) + "," + std::to_string(frames) + "," +
                   std::to_string(size) + ",\"" + renderer.glRenderer() + "\"\n";
        }
    }
    std::filesystem::remove_all(scratch);
    if (!csvPath.empty()) skinlab::writeFileAtomic(csvPath, csv);
    return 0;
}
