// The SSS stage alone on frozen frames, methods interleaved (docs/benchmarks.md, "Mikkelsen's pscbf").
//   bench_sss_stage [--scene S] [--width W] [--height H] [--views close,mid,far] [--methods separable,pscbf]
//                   [--samples 13,21] [--repeats N] [--assets DIR] [--out DIR]
// Why beside bench_sss: bench_sss measures each method in a run of whole renders, so on a machine shared with other
// work a burst of load lands on one method and not the other. Here every view is rendered once (method none), its
// AOVs read back from the EXR and uploaded, and then each repeat runs every method × sample count once in turn on
// the same textures, timed by glFinish wall clock around SssStage::run (llvmpipe: the GPU is the CPU). The first
// repeat (shader compilation, kernel construction) is discarded; the minimum and the median of the rest are
// reported. Writes DIR/sss_stage.csv atomically and prints a table.
#include "bench/bench_stats.h"
#include "common/files.h"
#include "renderer/gl/gl_resources.h"
#include "renderer/gl/shader_library.h"
#include "renderer/gl/sss_stage.h"
#include "renderer/renderer.h"
#include "renderer/sss/sss_params.h"

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

using skinlab::bench::median;

using namespace skinlab::renderer;

std::vector<std::string> split(const std::string& text) { return skinlab::bench::splitCommas(text); }

// The AOVs of one rendered frame as GL textures (rows flipped: the EXR is top row first, GL bottom row first).
struct FrozenFrame {
    gl::Texture diffuse, depth, albedo, mask, geometricNormal;
    gl::SssStageInputs inputs;
    double skinShare = 0.0;
};

FrozenFrame freeze(const std::filesystem::path& exr) {
    auto file = OIIO::ImageInput::open(exr.string());
    if (!file) throw std::runtime_error("cannot open " + exr.string());
    const OIIO::ImageSpec& spec = file->spec();
    const int w = spec.width, h = spec.height, channels = spec.nchannels;
    std::vector<float> all(size_t(w) * h * channels);
    file->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, all.data());
    auto gather = [&](std::vector<std::string> names, float fill) {
        std::vector<float> out(size_t(w) * h * 4, fill);
        for (int c = 0; c < int(names.size()); ++c) {
            const int index = spec.channelindex(names[c]);
            if (index < 0) throw std::runtime_error(exr.string() + ": no channel " + names[c]);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    out[(size_t(h - 1 - y) * w + x) * 4 + c] = all[(size_t(y) * w + x) * channels + index];
        }
        return out;
    };
    auto upload = [&](const std::vector<float>& rgba) {
        gl::Texture texture = gl::createTexture2D(GL_RGBA32F, w, h);
        glTextureSubImage2D(texture.get(), 0, 0, 0, w, h, GL_RGBA, GL_FLOAT, rgba.data());
        return texture;
    };
    FrozenFrame frame;
    const auto diffuse = gather({"diffuse.R", "diffuse.G", "diffuse.B", "mask.Y"}, 0.0f);
    frame.diffuse = upload(diffuse);
    frame.depth = upload(gather({"depth.Z"}, 0.0f)); // the passes read .r
    frame.albedo = upload(gather({"albedo.R", "albedo.G", "albedo.B", "mask.Y"}, 0.0f));
    frame.mask = upload(gather({"mask.Y"}, 0.0f));
    frame.geometricNormal = upload(gather({"geonormal.X", "geonormal.Y", "geonormal.Z"}, 0.0f));
    size_t skin = 0;
    for (size_t i = 0; i < size_t(w) * h; ++i) skin += diffuse[i * 4 + 3] > 0.0f;
    frame.skinShare = double(skin) / double(size_t(w) * h);
    gl::SssStageInputs& inputs = frame.inputs;
    inputs.diffuse = frame.diffuse.get();
    inputs.linearDepth = frame.depth.get();
    inputs.albedo = frame.albedo.get();
    inputs.skinMask = frame.mask.get();
    inputs.normal = frame.geometricNormal.get();
    inputs.geometricNormal = frame.geometricNormal.get();
    inputs.width = w;
    inputs.height = h;
    inputs.focalLengthPixels = spec.get_float_attribute("skinlab:f_px");
    inputs.mmPerUnit = spec.get_float_attribute("skinlab:mm_per_unit", 1.0f);
    const auto camera = nlohmann::json::parse(spec.get_string_attribute("skinlab:camera"));
    for (int i = 0; i < 16; ++i) inputs.view[i / 4][i % 4] = camera.at("view").at(i).get<float>();
    gl::checkGl("bench_sss_stage upload");
    return frame;
}

} // namespace

int main(int argc, char** argv) {
    std::string scene = "builtin:head", assets, out = "bench-sss-stage";
    int width = 1280, height = 720, repeats = 15;
    std::vector<std::string> views{"close", "mid", "far"}, methods{"separable", "pscbf"};
    std::vector<int> samples{13, 21};
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i], value = argv[i + 1];
        if (key == "--scene") scene = value;
        else if (key == "--width") width = std::atoi(value.c_str());
        else if (key == "--height") height = std::atoi(value.c_str());
        else if (key == "--repeats") repeats = std::max(2, std::atoi(value.c_str()));
        else if (key == "--views") views = split(value);
        else if (key == "--methods") methods = split(value);
        else if (key == "--samples") {
            samples.clear();
            for (const auto& s : split(value)) samples.push_back(std::atoi(s.c_str()));
        } else if (key == "--assets") assets = value;
        else if (key == "--out") out = value;
        else {
            std::fprintf(stderr, "bench_sss_stage: unknown option %s\n", key.c_str());
            return 2;
        }
    }
    skinlab::ensureDirectory(out);
    Renderer renderer; // owns the EGL context, current on this thread from here on
    const std::filesystem::path scratch = std::filesystem::temp_directory_path() / "skinlab-bench-sss-stage";
    std::filesystem::create_directories(scratch);
    gl::ShaderLibrary shaders;
    gl::SssStage stage(shaders);
    std::printf("GL_RENDERER: %s\nscene %s, %d×%d; SSS stage alone, methods interleaved; min and median of %d repeats "
                "after one warm-up, ms\n\n",
                renderer.glRenderer().c_str(), scene.c_str(), width, height, repeats - 1);
    std::string csv =
        "scene,view,skin_share,method,samples,sss_ms_min,sss_ms_median,repeats,width,height,gl_renderer\n";
    for (const auto& view : views) {
        RenderRequest request;
        request.scene = scene;
        request.method = "none";
        request.overrides = {"camera.view=" + view};
        request.width = width;
        request.height = height;
        request.assetsDir = assets;
        request.exrPath = scratch / "frame.exr";
        renderer.render(request);
        const FrozenFrame frame = freeze(request.exrPath);
        const gl::Texture output = gl::createTexture2D(GL_RGBA32F, width, height);
        struct Config {
            std::string method;
            int samples;
            gl::SssStageSettings settings;
            std::vector<double> milliseconds;
        };
        std::vector<Config> configs;
        for (const auto& method : methods)
            for (int n : samples) {
                sss::SssParams params = sss::sssParamsFromJson({{"method", method}, {"samples", n}}, "bench");
                configs.push_back({method, n, {params, {}}, {}});
            }
        for (int repeat = 0; repeat < repeats; ++repeat)
            for (auto& config : configs) {
                glFinish();
                const auto start = std::chrono::steady_clock::now();
                stage.run(frame.inputs, config.settings, output.get());
                glFinish();
                const double ms =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
                if (repeat > 0) config.milliseconds.push_back(ms);
            }
        std::printf("view %s (skin %.1f %% of the pixels)\n  %-10s %7s %9s %9s\n", view.c_str(),
                    100.0 * frame.skinShare, "method", "samples", "min", "median");
        for (const auto& config : configs) {
            const double minimum = *std::min_element(config.milliseconds.begin(), config.milliseconds.end());
            const double middle = median(config.milliseconds);
            std::printf("  %-10s %7d %9.2f %9.2f\n", config.method.c_str(), config.samples, minimum, middle);
            char row[512];
            std::snprintf(row, sizeof row, "%s,%s,%.4f,%s,%d,%.3f,%.3f,%d,%d,%d,\"%s\"\n", scene.c_str(), view.c_str(),
                          frame.skinShare, config.method.c_str(), config.samples, minimum, middle, repeats - 1, width,
                          height, renderer.glRenderer().c_str());
            csv += row;
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    std::filesystem::remove_all(scratch);
    skinlab::writeFileAtomic(std::filesystem::path(out) / "sss_stage.csv", csv);
    std::printf("wrote %s/sss_stage.csv\n", out.c_str());
    return 0;
}
