// Speed of the object-space reference as a render method (sss.method = "reference", renderer/gl/reference_method.h):
// whole renders through Renderer (EGL; llvmpipe on the CI machine) of builtin:halo and, when $SKINLAB_ASSETS holds
// it, the scanned head in its close view, at edge lengths 2 and 1 mm (or those given). Prints one Markdown table row
// per case: the render's wall time, the "sss" pass (bake + read back + convolution + draw), the tessellation (done
// once per model and edge length, then cached; measured here on the first render of each case), and the sample
// counts. Each case renders twice; the second row shows the cached tessellation.
//   bench_reference_render [width=1280] [height=720] [edges=2,1]   (edge lengths in mm, comma-separated)
#include "bench/bench_stats.h"
#include "renderer/renderer.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

using namespace skinlab::renderer;

int main(int argc, char** argv) {
    const int width = argc > 1 ? std::atoi(argv[1]) : 1280;
    const int height = argc > 2 ? std::atoi(argv[2]) : 720;
    const std::vector<std::string> edges = skinlab::bench::splitCommas(argc > 3 ? argv[3] : "2,1");
    const char* assets = std::getenv("SKINLAB_ASSETS");
    struct Case {
        std::string name, scene;
        std::vector<std::string> overrides;
    };
    std::vector<Case> cases = {{"builtin:halo-grey-backdrop (mid view)", "builtin:halo-grey-backdrop", {}}};
    if (assets && std::filesystem::exists(std::filesystem::path(assets) / "LeePerrySmith/LeePerrySmith.glb"))
        cases.push_back({"scanned head (close view)",
                         std::string(SKINLAB_SOURCE_DIR) + "/renderer/scenes/lee-perry-smith.toml",
                         {"camera.view=close"}});
    else std::fprintf(stderr, "SKINLAB_ASSETS does not hold LeePerrySmith/: the scanned head is left out\n");
    const auto output = std::filesystem::temp_directory_path() / "bench_reference_render.exr";
    Renderer renderer;
    std::printf(
        "| scene | edge (mm) | render | samples (skin) | sources per sample | tessellate (ms) | bake + read back "
        "(ms) | convolve (ms) | sss pass, wall (ms) | render, wall (ms) "
        "|\n|---|---|---|---|---|---|---|---|---|---|\n");
    for (const Case& c : cases)
        for (const std::string& edge : edges)
            for (int repeat = 0; repeat < 2; ++repeat) {
                RenderRequest request;
                request.scene = c.scene;
                request.overrides = c.overrides;
                request.overrides.push_back("sss.reference_edge_mm=" + edge);
                request.method = "reference";
                request.width = width;
                request.height = height;
                request.exrPath = output;
                if (assets) request.assetsDir = assets;
                const auto start = std::chrono::steady_clock::now();
                const RenderResult result = renderer.render(request);
                const double wallMs =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
                const auto& run = result.timingsMs.at("reference");
                std::printf("| %s | %s | %s | %d (%d) | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f |\n", c.name.c_str(),
                            edge.c_str(), repeat == 0 ? "first" : "cached", run.at("samples").get<int>(),
                            run.at("skin_samples").get<int>(), run.at("sources_per_sample").get<double>(),
                            run.at("tessellate_ms").get<double>(), run.at("bake_readback_ms").get<double>(),
                            run.at("convolve_ms").get<double>(),
                            result.timingsMs.at("passes_wall").at("sss").get<double>(), wallMs);
                std::fflush(stdout);
            }
    std::filesystem::remove(output);
    std::printf("\nGL_RENDERER: %s\n", renderer.glRenderer().c_str());
    return 0;
}
