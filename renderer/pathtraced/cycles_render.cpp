#include "renderer/pathtraced/cycles_render.h"

#include "common/error.h"
#include "common/files.h"
#include "renderer/pathtraced/blender_process.h"

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdlib>
#include <limits>
#include <unistd.h>

namespace skinlab::renderer::pathtraced {

std::filesystem::path makeWorkFolder(const std::string& prefix) {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    if (!::mkdtemp(pattern.data()))
        throw InputError(pattern + ": cannot create a temporary folder (" + std::strerror(errno) + ")");
    return pattern;
}

std::map<std::string, std::vector<float>> readExrChannels(const std::filesystem::path& path, int& width, int& height) {
    auto input = OIIO::ImageInput::open(path.string());
    if (!input) throw InputError(path.string() + ": cannot read Blender's EXR (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = input->spec();
    width = spec.width;
    height = spec.height;
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    const int channelCount = spec.nchannels;
    std::vector<float> all(pixels * static_cast<std::size_t>(channelCount));
    if (!input->read_image(0, 0, 0, channelCount, OIIO::TypeDesc::FLOAT, all.data()))
        throw InputError(path.string() + ": cannot read Blender's EXR (" + input->geterror() + ")");
    input->close();
    std::map<std::string, std::vector<float>> channels;
    for (int c = 0; c < channelCount; ++c) {
        std::vector<float> values(pixels);
        for (std::size_t p = 0; p < pixels; ++p)
            values[p] = all[p * static_cast<std::size_t>(channelCount) + static_cast<std::size_t>(c)];
        channels[spec.channel_name(c)] = std::move(values);
    }
    return channels;
}

const std::vector<float>& channelEndingWith(const std::map<std::string, std::vector<float>>& channels,
                                            const std::string& suffix, const std::filesystem::path& file) {
    for (const auto& [name, values] : channels)
        if (name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0 &&
            (name.size() == suffix.size() || name[name.size() - suffix.size() - 1] == '.'))
            return values;
    std::string names;
    for (const auto& entry : channels) names += (names.empty() ? "" : ", ") + entry.first;
    throw InputError(file.string() + ": no channel '" + suffix + "' in Blender's EXR (it has: " + names + ")");
}

nlohmann::json readRecord(const std::filesystem::path& path) {
    try {
        return nlohmann::json::parse(readFile(path));
    } catch (const nlohmann::json::exception& e) {
        throw InputError(path.string() + ": not JSON (" + e.what() + ")");
    }
}

namespace {
CyclesImage renderWithBlender(const BlenderSceneInputs& inputs, float exposure) {
    const bool eevee = inputs.engine == "eevee";
    const auto start = std::chrono::steady_clock::now();
    const std::filesystem::path folder = makeWorkFolder(eevee ? "skinlab-eevee" : "skinlab-pathtraced");
    writeBlenderScene(folder, inputs);
    runBlender(inputs.params.blender, folder / "cycles_scene.py", {"render", (folder / "scene.json").string()}, folder,
               folder / "blender.log", eevee ? "eevee.blender" : "pathtraced.blender");

    CyclesImage image;
    const std::filesystem::path exr = folder / "cycles.exr";
    auto channels = readExrChannels(exr, image.width, image.height);
    if (rendersEnvironmentSeparately(inputs)) {
        // The unshadowed environment's pass: light adds (Combined and the direct / indirect passes); colours,
        // depth and indices are the same in both passes.
        const std::filesystem::path second = folder / kEnvironmentOutput;
        int width = 0, height = 0;
        const auto environment = readExrChannels(second, width, height);
        if (width != image.width || height != image.height)
            throw InputError(second.string() + ": " + std::to_string(width) + "x" + std::to_string(height) +
                             ", the first pass is " + std::to_string(image.width) + "x" + std::to_string(image.height));
        for (auto& [name, values] : channels) {
            const bool light = name.find("Combined.") != std::string::npos || name.find("Dir.") != std::string::npos ||
                               name.find("Ind.") != std::string::npos;
            if (!light || name.ends_with(".A")) continue;
            const auto found = environment.find(name);
            if (found == environment.end())
                throw InputError(second.string() + ": no channel '" + name + "' in the environment pass");
            for (std::size_t p = 0; p < values.size(); ++p) values[p] += found->second[p];
        }
    }
    if (image.width != inputs.spec->width || image.height != inputs.spec->height)
        throw InputError(exr.string() + ": Blender wrote " + std::to_string(image.width) + "x" +
                         std::to_string(image.height) + ", expected " + std::to_string(inputs.spec->width) + "x" +
                         std::to_string(inputs.spec->height));
    const std::size_t pixels = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
    const char* rgb[] = {"R", "G", "B"};
    image.beauty.resize(pixels * 3);
    image.diffuse.resize(pixels * 3);
    image.specular.resize(pixels * 3);
    for (int c = 0; c < 3; ++c) {
        const std::string ch = rgb[c];
        // EEVEE has no indirect passes (its world light is part of the direct ones): zeros stand in for them.
        const std::vector<float> none(eevee ? pixels : 0, 0.0f);
        const auto& combined = channelEndingWith(channels, "Combined." + ch, exr);
        const auto& diffuseDirect = channelEndingWith(channels, "DiffDir." + ch, exr);
        const auto& diffuseIndirect = eevee ? none : channelEndingWith(channels, "DiffInd." + ch, exr);
        const auto& diffuseColor = channelEndingWith(channels, "DiffCol." + ch, exr);
        const auto& glossyDirect = channelEndingWith(channels, "GlossDir." + ch, exr);
        const auto& glossyIndirect = eevee ? none : channelEndingWith(channels, "GlossInd." + ch, exr);
        const auto& glossyColor = channelEndingWith(channels, "GlossCol." + ch, exr);
        for (std::size_t p = 0; p < pixels; ++p) {
            image.beauty[p * 3 + c] = exposure * combined[p];
            image.diffuse[p * 3 + c] = exposure * (diffuseDirect[p] + diffuseIndirect[p]) * diffuseColor[p];
            image.specular[p * 3 + c] = exposure * (glossyDirect[p] + glossyIndirect[p]) * glossyColor[p];
        }
    }
    const auto& depth = channelEndingWith(channels, "Depth.Z", exr);
    const auto& skin = channelEndingWith(channels, eevee ? "skinlab_skin.X" : "IndexMA.X", exr);
    // Where a camera ray leaves the scene Cycles writes 1e10, EEVEE (a half-float depth pass) 65504, half's largest.
    const float background = eevee ? 65504.0f : 1e9f;
    image.depth.resize(pixels);
    image.mask.resize(pixels);
    for (std::size_t p = 0; p < pixels; ++p) {
        image.depth[p] = depth[p] >= background ? std::numeric_limits<float>::infinity() : depth[p];
        image.mask[p] = skin[p] >= 0.5f ? 1.0f : 0.0f;
        if (std::isinf(image.depth[p])) {
            // Where no surface is seen the rasterizer's diffuse layer holds the background (its background pass
            // writes there) and its specular 0: the same here, so that every layer means the same in both.
            for (std::size_t c = 0; c < 3; ++c) {
                image.diffuse[p * 3 + c] = image.beauty[p * 3 + c];
                image.specular[p * 3 + c] = 0.0f;
            }
        }
    }
    const nlohmann::json record = readRecord(folder / "cycles.json");
    image.blenderVersion = record.value("blender_version", "");
    image.renderSeconds = record.value("render_seconds", 0.0);
    image.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
    return image;
}
} // namespace

CyclesImage renderWithCycles(const BlenderSceneInputs& inputs, float exposure) {
    BlenderSceneInputs cycles = inputs;
    cycles.engine = "cycles";
    return renderWithBlender(cycles, exposure);
}

CyclesImage renderWithEevee(const BlenderSceneInputs& inputs, float exposure) {
    BlenderSceneInputs eevee = inputs;
    eevee.engine = "eevee";
    eevee.params.environmentShadow = true; // one pass
    return renderWithBlender(eevee, exposure);
}

} // namespace skinlab::renderer::pathtraced
