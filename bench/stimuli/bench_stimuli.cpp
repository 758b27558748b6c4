// Stimulus-set throughput: builds a set spec (default stimuli/specs/demo.toml) into a fresh folder
// and reports stimuli per minute, then rebuilds it unchanged (nothing rendered: the cost of the resume check,
// which re-hashes every file), then the visibility against viewing distance of the built set (`stimuli
// visibility`, when it has references). Prints a table and writes bench_stimuli.csv (and bench_visibility.csv) into
// the output folder.
//   bench_stimuli [--spec SPEC] [--jobs N] [-o DIR] [--assets DIR] [--set key=value ...]
#include "common/files.h"
#include "renderer/renderer.h"
#include "stimuli/build.h"
#include "stimuli/visibility.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <spdlog/spdlog.h>
#include <string>
#include <thread>

namespace fs = std::filesystem;

int main(int argc, char** argv) {
    skinlab::stimuli::BuildOptions options;
    options.spec = fs::path(SKINLAB_SOURCE_DIR) / "stimuli/specs/demo.toml";
    fs::path out = fs::temp_directory_path() / "skinlab-bench-stimuli";
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "bench_stimuli: %s needs a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--spec") options.spec = next();
        else if (a == "--jobs") options.jobs = std::stoi(next());
        else if (a == "-o") out = next();
        else if (a == "--assets") options.assetsDir = next();
        else if (a == "--set") options.specOverrides.push_back(next());
        else {
            std::fprintf(stderr, "usage: bench_stimuli [--spec SPEC] [--jobs N] [-o DIR] [--assets DIR] [--set k=v]\n");
            return 2;
        }
    }
    spdlog::set_level(spdlog::level::warn);
    try {
        fs::path setDir = out / "set";
        fs::remove_all(setDir);
        options.outputDir = setDir;
        options.progress = skinlab::stimuli::BuildOptions::ProgressStyle::lines;
        std::string glRenderer;
        {
            skinlab::renderer::Renderer probe;
            glRenderer = probe.glRenderer();
        }
        skinlab::stimuli::BuildSummary cold = skinlab::stimuli::buildSet(options);
        skinlab::stimuli::BuildSummary warm = skinlab::stimuli::buildSet(options);
        double perMinute = 60.0 * static_cast<double>(cold.rendered) / cold.wallSeconds;
        std::printf("spec            %s\n", options.spec.string().c_str());
        std::printf("GL renderer     %s\n", glRenderer.c_str());
        std::printf("CPU threads     %u, jobs %d\n", std::thread::hardware_concurrency(), options.jobs);
        std::printf("stimuli         %zu\n", cold.stimuli);
        std::printf("cold build      %.1f s  (%.1f stimuli/min, %.2f s per stimulus; incl. spec check, EGL "
                    "start, contact sheet)\n",
                    cold.wallSeconds, perMinute, cold.wallSeconds / static_cast<double>(cold.rendered));
        std::printf("no-op rebuild   %.2f s  (%zu rendered)\n", warm.wallSeconds, warm.rendered);
        std::string csv = "spec,gl_renderer,cpu_threads,jobs,stimuli,cold_build_s,stimuli_per_minute,noop_rebuild_s\n";
        csv += "\"" + options.spec.filename().string() + "\",\"" + glRenderer + "\"," +
               std::to_string(std::thread::hardware_concurrency()) + "," + std::to_string(options.jobs) + "," +
               std::to_string(cold.stimuli) + "," + std::to_string(cold.wallSeconds) + "," + std::to_string(perMinute) +
               "," + std::to_string(warm.wallSeconds) + "\n";
        skinlab::writeFileAtomic(out / "bench_stimuli.csv", csv);
        std::printf("written         %s\n", (out / "bench_stimuli.csv").string().c_str());
        // Visibility against viewing distance (`stimuli visibility`): every condition at 6 pixels per degree.
        const std::optional<skinlab::stimuli::Manifest> manifest = skinlab::stimuli::readManifest(setDir);
        if (manifest && std::any_of(manifest->stimuli.begin(), manifest->stimuli.end(),
                                    [](const skinlab::formats::ManifestEntry& s) { return s.reference; })) {
            const skinlab::stimuli::VisibilityTable table =
                skinlab::stimuli::computeVisibility(setDir, *manifest, skinlab::stimuli::VisibilityOptions{});
            std::printf("visibility      %.1f s  (%zu conditions x %zu pixels per degree, 2 threads)\n", table.seconds,
                        table.rows.size(), table.pixelsPerDegree.size());
            skinlab::writeFileAtomic(out / "bench_visibility.csv",
                                     "spec,conditions,pixels_per_degree,threads,visibility_s\n\"" +
                                         options.spec.filename().string() + "\"," + std::to_string(table.rows.size()) +
                                         "," + std::to_string(table.pixelsPerDegree.size()) + ",2," +
                                         std::to_string(table.seconds) + "\n");
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_stimuli: %s\n", e.what());
        return 1;
    }
    return 0;
}
