// `skinlab render`: one scene → linear EXR with AOVs (+ display PNG, + timings JSON). docs/rendering.md.
#include "cli/commands.h"
#include "cli/options.h"
#include "common/error.h"
#include "common/files.h"
#include "renderer/renderer.h"

#include <cstdio>
#include <memory>
#include <spdlog/spdlog.h>

namespace skinlab::cli {

namespace {

struct RenderOptions {
    std::string scene;
    std::string method;
    std::vector<std::string> overrides;
    int width = 0;
    int height = 0;
    std::string assets;
    std::string exr;
    std::string png;
    std::string timings;
};

void checkOutputPath(const std::string& path, const char* option) {
    const std::filesystem::path parent = std::filesystem::absolute(path).parent_path();
    std::error_code error;
    if (!std::filesystem::is_directory(parent, error))
        throw InputError(path + ": cannot write " + option + " output (folder " + parent.string() + " does not exist)");
}

void runRender(const RenderOptions& options) {
    renderer::RenderRequest request;
    request.scene = options.scene;
    request.overrides = options.overrides;
    if (!options.method.empty()) request.method = options.method;
    if (options.width > 0) request.width = options.width;
    if (options.height > 0) request.height = options.height;
    request.assetsDir = options.assets;
    request.exrPath = options.exr;
    request.pngPath = options.png;
    checkOutputPath(options.exr, "-o");
    if (!options.png.empty()) checkOutputPath(options.png, "--png");
    if (!options.timings.empty()) checkOutputPath(options.timings, "--timings");

    // Validate the spec (and its files) before creating the GL context: bad input fails fast, even without EGL.
    renderer::resolveScene(request);
    renderer::Renderer renderer;
    const renderer::RenderResult result = renderer.render(request);
    if (!options.timings.empty()) {
        nlohmann::json timings = result.timingsMs;
        timings["scene"] = options.scene;
        writeFileAtomic(options.timings, timings.dump(2) + "\n");
    }
    std::printf("%s\n", options.exr.c_str());
    if (!options.png.empty()) std::printf("%s\n", options.png.c_str());
}

} // namespace

void registerRender(CLI::App& app) {
    auto options = std::make_shared<RenderOptions>();
    CLI::App* render = app.add_subcommand(
        "render", "Render one scene to a linear EXR (beauty + AOVs, metadata) and optionally a display PNG");
    render->add_option("--scene", options->scene, "Scene spec (TOML file) or builtin:halo|bleed|ear|head")->required();
    render->add_option("--method", options->method, "SSS method (shorthand for --set sss.method=M)");
    addOverridesOption(*render, options->overrides, "spec value");
    render->add_option("--width", options->width, "Image width in pixels (shorthand for --set render.width=W)")
        ->check(CLI::Range(16, 8192));
    render->add_option("--height", options->height, "Image height in pixels (shorthand for --set render.height=H)")
        ->check(CLI::Range(16, 8192));
    addAssetsOption(*render, options->assets);
    render->add_option("-o,--output", options->exr, "Output EXR (float32, linear, AOV channels)")->required();
    render->add_option("--png", options->png, "Also write a display PNG (tone mapped, sRGB)");
    render->add_option("--timings", options->timings, "Write per-pass milliseconds (JSON)");
    render->callback([options] { runRender(*options); });
}

} // namespace skinlab::cli
