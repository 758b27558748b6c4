// SSS milliseconds per method against samples per pass and close/mid/far views (thesis Fig. 5.1 and Table 5.2;
// docs/benchmarks.md, "SSS methods").
//   bench_sss [--scene S] [--width W] [--height H] [--samples 5,11,21,51,101] [--views close,mid,far]
//             [--methods gaussian-sum,separable,artistic,pscbf] [--frames N] [--assets DIR] [--out DIR]
// For every view, method and sample count: one warm-up render (kernel construction, shader compilation), then N
// measured renders; the SSS stage's GPU time (GL_TIME_ELAPSED, cross-checked against glFinish wall time by the
// renderer) is reported as the median, and the minimum beside it (on a machine shared with other work the minimum
// is the figure least disturbed by it). Writes DIR/sss.csv and DIR/sss.png (atomically) and prints a table.
#include "bench/bench_stats.h"
#include "common/files.h"
#include "renderer/renderer.h"
#include "renderer/sss/sss_params.h"
#include "sss_plot.h"

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace {

using skinlab::bench::median;

std::vector<std::string> split(const std::string& text) { return skinlab::bench::splitCommas(text); }

// Share of pixels with skin mask > 0 in an EXR written by the renderer.
double skinShare(const std::filesystem::path& exr) {
    auto input = OIIO::ImageInput::open(exr.string());
    if (!input) return 0.0;
    const OIIO::ImageSpec& spec = input->spec();
    const int channel = spec.channelindex("mask.Y");
    if (channel < 0) return 0.0;
    std::vector<float> mask(size_t(spec.width) * spec.height);
    input->read_image(0, 0, channel, channel + 1, OIIO::TypeDesc::FLOAT, mask.data());
    return double(std::count_if(mask.begin(), mask.end(), [](float m) { return m > 0.0f; })) / double(mask.size());
}

// Whether `method` reads sss.samples (the screen-space methods do; "none", the copy, does not and refuses the key).
bool readsSamples(const std::string& method) {
    const auto* info = skinlab::renderer::sss::findMethod(method);
    return info && skinlab::renderer::sss::methodUsesKey(info->method, "samples");
}

int run(int argc, char** argv) {
    std::string scene = "builtin:head";
    int width = 640, height = 360, frames = 3;
    std::vector<int> samples{5, 11, 21, 51, 101};
    std::vector<std::string> views{"close", "mid", "far"};
    std::vector<std::string> methods = skinlab::renderer::sss::screenSpaceMethodNames();
    std::string assets, out = "bench-sss";
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i], value = argv[i + 1];
        if (key == "--scene") scene = value;
        else if (key == "--width") width = std::atoi(value.c_str());
        else if (key == "--height") height = std::atoi(value.c_str());
        else if (key == "--frames") frames = std::max(1, std::atoi(value.c_str()));
        else if (key == "--samples") {
            samples.clear();
            for (const auto& s : split(value)) samples.push_back(std::atoi(s.c_str()));
        } else if (key == "--views") views = split(value);
        else if (key == "--methods") methods = split(value);
        else if (key == "--assets") assets = value;
        else if (key == "--out") out = value;
        else {
            std::fprintf(stderr, "bench_sss: unknown option %s\n", key.c_str());
            return 2;
        }
    }
    skinlab::ensureDirectory(out);
    skinlab::renderer::Renderer renderer;
    const std::filesystem::path scratch = std::filesystem::temp_directory_path() / "skinlab-bench-sss";
    std::filesystem::create_directories(scratch);
    std::printf("GL_RENDERER: %s\nGL_VERSION: %s\nscene %s, %d×%d, median of %d frames after one warm-up\n\n",
                renderer.glRenderer().c_str(), renderer.glVersion().c_str(), scene.c_str(), width, height, frames);
    std::string csv = "scene,view,skin_share,method,samples,sss_gpu_ms_median,sss_wall_ms_median,frames,width,height,"
                      "gl_renderer,sss_gpu_ms_min\n";
    std::vector<std::pair<std::string, std::vector<skinlab::bench::SssSeries>>> panels;
    double gpuMinimum = 0.0; // of the last measure()
    auto measure = [&](const std::string& view, const std::string& method, int n, double& wallMs) {
        skinlab::renderer::RenderRequest request;
        request.scene = scene;
        request.method = method;
        request.overrides = {"camera.view=" + view};
        if (readsSamples(method)) request.overrides.push_back("sss.samples=" + std::to_string(n));
        request.width = width;
        request.height = height;
        request.assetsDir = assets;
        request.exrPath = scratch / "frame.exr";
        std::vector<double> gpu, wall;
        for (int frame = 0; frame <= frames; ++frame) {
            const auto result = renderer.render(request);
            if (frame == 0) continue;
            gpu.push_back(result.timingsMs["passes"]["sss"].get<double>());
            wall.push_back(result.timingsMs["passes_wall"]["sss"].get<double>());
        }
        wallMs = median(wall);
        gpuMinimum = *std::min_element(gpu.begin(), gpu.end());
        return median(gpu);
    };
    for (const auto& view : views) {
        double wall = 0.0;
        const double noneMs = measure(view, "none", samples.front(), wall);
        const double share = skinShare(scratch / "frame.exr");
        std::printf("view %s (skin %.1f %% of the pixels): none (copy) %.2f ms\n", view.c_str(), 100.0 * share, noneMs);
        std::printf("  %-13s", "samples");
        for (int n : samples) std::printf(" %9d", n);
        std::printf("\n");
        std::vector<skinlab::bench::SssSeries> series;
        for (const auto& method : methods) {
            skinlab::bench::SssSeries s{method, {}, {}};
            std::printf("  %-13s", method.c_str());
            std::vector<double> minima;
            for (int n : samples) {
                const double ms = measure(view, method, n, wall);
                s.samples.push_back(n);
                s.milliseconds.push_back(ms);
                minima.push_back(gpuMinimum);
                std::printf(" %9.2f", ms);
                std::fflush(stdout);
                char row[512];
                std::snprintf(row, sizeof row, "%s,%s,%.4f,%s,%d,%.3f,%.3f,%d,%d,%d,\"%s\",%.3f\n", scene.c_str(),
                              view.c_str(), share, method.c_str(), n, ms, wall, frames, width, height,
                              renderer.glRenderer().c_str(), gpuMinimum);
                csv += row;
            }
            std::printf("\n  %-13s", (method + " min").c_str());
            for (double minimum : minima) std::printf(" %9.2f", minimum);
            std::printf("\n");
            series.push_back(std::move(s));
        }
        panels.emplace_back(view, std::move(series));
        std::printf("\n");
    }
    std::filesystem::remove_all(scratch);
    skinlab::writeFileAtomic(std::filesystem::path(out) / "sss.csv", csv);
    const std::string title = "SSS stage, " + scene + " " + std::to_string(width) + "x" + std::to_string(height) +
                              ", " + renderer.glRenderer();
    skinlab::writeFileAtomic(std::filesystem::path(out) / "sss.png", skinlab::bench::plotSssTimings(panels, title));
    std::printf("wrote %s/sss.csv and %s/sss.png\n", out.c_str(), out.c_str());
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_sss: %s\n", e.what());
        return 1;
    }
}
