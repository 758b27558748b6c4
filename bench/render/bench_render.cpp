// Per-pass milliseconds of the renderer without SSS (docs/benchmarks.md, "Renderer").
//   bench_render [--frames N] [--width W] [--height H] [--assets DIR] [--csv FILE] [--set key=value ...]
// Renders builtin:head and, when the assets folder is known (--assets or $SKINLAB_ASSETS), the scanned head
// (renderer/scenes/lee-perry-smith.toml) at 1280×720: one warm-up frame (shader compilation, file loading),
// then N measured frames; prints the median per pass (GPU timer queries, cross-checked with glFinish wall
// clock) and the wall-clock total of the passes, and writes one CSV row per scene and pass. --set overrides a
// scene key for every scene (repeatable), e.g. --set transmittance.enabled=true.
#include "bench/bench_stats.h"
#include "common/files.h"
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

} // namespace

int main(int argc, char** argv) {
    int frames = 5;
    int width = 1280;
    int height = 720;
    std::string assets;
    std::string csvPath;
    std::vector<std::string> overrides;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i];
        const std::string value = argv[i + 1];
        if (key == "--frames") frames = std::max(1, std::atoi(value.c_str()));
        else if (key == "--width") width = std::atoi(value.c_str());
        else if (key == "--height") height = std::atoi(value.c_str());
        else if (key == "--assets") assets = value;
        else if (key == "--csv") csvPath = value;
        else if (key == "--set") overrides.push_back(value);
        else {
            std::fprintf(stderr, "bench_render: unknown option %s\n", key.c_str());
            return 2;
        }
    }
    if (assets.empty())
        if (const char* environment = std::getenv("SKINLAB_ASSETS")) assets = environment;

    std::vector<std::string> scenes = {"builtin:head"};
    const std::filesystem::path scanned =
        std::filesystem::path(SKINLAB_SOURCE_DIR) / "renderer/scenes/lee-perry-smith.toml";
    if (!assets.empty()) scenes.push_back(scanned.string());
    else std::fprintf(stderr, "bench_render: no assets folder (--assets or SKINLAB_ASSETS): scanned head skipped\n");

    skinlab::renderer::Renderer renderer;
    const std::filesystem::path scratch = std::filesystem::temp_directory_path() / "skinlab-bench-render";
    std::filesystem::create_directories(scratch);
    std::string csv = "scene,pass,gpu_ms_median,wall_ms_median,frames,width,height,gl_renderer\n";
    std::printf("GL_RENDERER: %s\nGL_VERSION: %s\n%d×%d, median of %d frames after one warm-up\n\n",
                renderer.glRenderer().c_str(), renderer.glVersion().c_str(), width, height, frames);
    const std::vector<std::string> passes = {"shadow",        "main", "background",   "surface_aovs",
                                             "transmittance", "sss",  "add_specular", "tone_map"};
    for (const std::string& scene : scenes) {
        skinlab::renderer::RenderRequest request;
        request.scene = scene;
        request.overrides = overrides;
        request.width = width;
        request.height = height;
        request.assetsDir = assets;
        request.exrPath = scratch / "frame.exr";
        std::map<std::string, std::vector<double>> gpu, wall;
        std::vector<double> totals, totalsWall, readback;
        for (int frame = 0; frame <= frames; ++frame) {
            const auto result = renderer.render(request);
            if (frame == 0) continue; // warm-up: shader compilation, model/texture loading
            for (const auto& pass : passes) {
                gpu[pass].push_back(result.timingsMs["passes"][pass].get<double>());
                wall[pass].push_back(result.timingsMs["passes_wall"][pass].get<double>());
            }
            totals.push_back(result.timingsMs["gpu_total"].get<double>());
            totalsWall.push_back(result.timingsMs["wall_total"].get<double>());
            readback.push_back(result.timingsMs["cpu"]["readback"].get<double>());
        }
        const std::string label = scene == scanned.string() ? "lee-perry-smith" : scene;
        std::printf("%s\n  %-14s %10s %10s\n", label.c_str(), "pass", "GPU ms", "wall ms");
        for (const auto& pass : passes) {
            std::printf("  %-14s %10.2f %10.2f\n", pass.c_str(), median(gpu[pass]), median(wall[pass]));
            csv += label + "," + pass + "," + std::to_string(median(gpu[pass])) + "," +
                   std::to_string(median(wall[pass])) + "," + std::to_string(frames) + "," + std::to_string(width) +
                   "," + std::to_string(height) + ",\"" + renderer.glRenderer() + "\"\n";
        }
        std::printf("  %-14s %10.2f %10.2f\n", "frame total", median(totals), median(totalsWall));
        std::printf("  %-14s %10s %10.2f\n\n", "AOV readback", "", median(readback));
        csv += label + ",total," + std::to_string(median(totals)) + "," + std::to_string(median(totalsWall)) + "," +
               std::to_string(frames) + "," + std::to_string(width) + "," + std::to_string(height) + ",\"" +
               renderer.glRenderer() + "\"\n";
        csv += label + ",readback,," + std::to_string(median(readback)) + "," + std::to_string(frames) + "," +
               std::to_string(width) + "," + std::to_string(height) + ",\"" + renderer.glRenderer() + "\"\n";
    }
    std::filesystem::remove_all(scratch);
    if (!csvPath.empty()) skinlab::writeFileAtomic(csvPath, csv);
    return 0;
}
