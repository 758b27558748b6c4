// skinlab tune: milliseconds from a control change to the updated image (docs/benchmarks.md, "Live tuning").
//   bench_tune [--scene S] [--width W] [--height H] [--frames N] [--assets DIR] [--skinlab PATH]
// An in-process TuneServer on loopback and the project's HTTP client in the role of the page: for each
// screen-space method, one warm-up request, then N requests that each move one slider of the method (sss.width_mm
// up and down: the SSS stage and tone map re-run), N that orbit the camera (camera.yaw_deg: the main passes re-run,
// the shadow maps stay) and N that move a light's intensity (shadow maps and main passes re-run). Each figure is the whole round trip the page waits for: request, render, read-back, sRGB encoding, PNG,
// base64 and answer. Prints p50 and p95 per method and kind of change.
#include "bench/bench_stats.h"
#include "net/http_client.h"
#include "renderer/sss/sss_params.h"
#include "tune/tune_server.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

namespace {

using skinlab::bench::percentile;

} // namespace

int main(int argc, char** argv) {
    std::string scene = "builtin:head";
    int width = 640, height = 360, frames = 20;
    std::string assets, skinlab = "skinlab";
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i], value = argv[i + 1];
        if (key == "--scene") scene = value;
        else if (key == "--width") width = std::atoi(value.c_str());
        else if (key == "--height") height = std::atoi(value.c_str());
        else if (key == "--frames") frames = std::max(2, std::atoi(value.c_str()));
        else if (key == "--assets") assets = value;
        else if (key == "--skinlab") skinlab = value;
        else {
            std::fprintf(stderr, "bench_tune: unknown option %s\n", key.c_str());
            return 2;
        }
    }
    const auto work = std::filesystem::temp_directory_path() / ("skinlab-bench-tune-" + std::to_string(::getpid()));
    skinlab::tune::TuneOptions options;
    options.scenes = {scene};
    options.assetsDir = assets;
    options.executable = skinlab;
    options.workDir = work;
    options.exportDir = work / "exports";
    int status = 0;
    {
        skinlab::tune::TuneServer server(options);
        const int port = server.bind();
        std::thread serving([&] { server.run(); });
        skinlab::net::HttpClient client("127.0.0.1", port);
        client.setTimeout(std::chrono::seconds(300));
        // This start's token, from the page (as the page's script sends it with every POST).
        const std::string page = client.get("/").body;
        const std::string marker = "<meta name=\"skinlab-token\" content=\"";
        const std::size_t at = page.find(marker);
        if (at == std::string::npos) {
            std::fprintf(stderr, "bench_tune: the page holds no token\n");
            std::exit(1);
        }
        const skinlab::net::HttpHeaders token{{"X-Skinlab-Token", page.substr(at + marker.size(), 64)}};
        const std::string size = "render.width=" + std::to_string(width);
        const std::string sizeH = "render.height=" + std::to_string(height);
        std::printf("scene %s at %dx%d, %d changes per kind; milliseconds from request to image (HTTP round trip)\n",
                    scene.c_str(), width, height, frames);
        std::printf("%-14s %-8s %8s %8s %8s\n", "method", "change", "p50", "p95", "max");
        for (const std::string& method : skinlab::renderer::sss::screenSpaceMethodNames()) {
            auto request = [&](double widthMm, double intensity, double yaw) {
                const nlohmann::json body = {
                    {"client", "bench"},
                    {"scene", scene},
                    {"overrides",
                     {size, sizeH, "sss.method=\"" + method + "\"", "sss.width_mm=" + std::to_string(widthMm),
                      "lights[0].intensity=" + std::to_string(intensity), "camera.yaw_deg=" + std::to_string(yaw)}}};
                const auto start = std::chrono::steady_clock::now();
                const auto answer = client.send("POST", "/api/render", body.dump(), token);
                const double ms =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
                if (answer.status != 200) {
                    std::fprintf(stderr, "bench_tune: %s: %d %s\n", method.c_str(), answer.status, answer.body.c_str());
                    std::exit(1);
                }
                return ms;
            };
            request(3.0, 1.0, 20.0); // warm-up: upload, shaders, lighting
            std::vector<double> sss, camera, lighting;
            for (int f = 0; f < frames; ++f) sss.push_back(request(f % 2 ? 3.0 : 2.0, 1.0, 20.0));
            for (int f = 0; f < frames; ++f) camera.push_back(request(3.0, 1.0, f % 2 ? 20.0 : 25.0));
            for (int f = 0; f < frames; ++f) lighting.push_back(request(3.0, f % 2 ? 1.0 : 1.2, 20.0));
            using Kind = std::pair<const char*, std::vector<double>&>;
            for (const auto& [kind, values] : {Kind{"sss", sss}, Kind{"camera", camera}, Kind{"light", lighting}})
                std::printf("%-14s %-8s %8.1f %8.1f %8.1f\n", method.c_str(), kind, percentile(values, 0.5),
                            percentile(values, 0.95), *std::max_element(values.begin(), values.end()));
            std::fflush(stdout);
        }
        server.stop();
        serving.join();
    }
    std::filesystem::remove_all(work);
    return status;
}
