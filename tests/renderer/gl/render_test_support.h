#pragma once
// Shared helpers of the GL tests: one Renderer per test process (EGL context creation costs ~100 ms), skipping
// with the EGL failure message when no platform works; EXR reading; temporary folders.
#include "common/error.h"
#include "renderer/renderer.h"
#include "tests/common/temp_folder.h"

#include <OpenImageIO/imageio.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <gtest/gtest.h>
#include <map>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

namespace skinlab::renderer::test {

inline std::string& rendererFailure() {
    static std::string failure;
    return failure;
}

// The process-wide renderer, or nullptr (rendererFailure() says why) when no EGL platform works.
inline Renderer* sharedRenderer() {
    static std::unique_ptr<Renderer> renderer;
    static bool tried = false;
    if (!tried) {
        tried = true;
        try {
            renderer = std::make_unique<Renderer>();
        } catch (const std::exception& e) {
            rendererFailure() = e.what();
        }
    }
    return renderer.get();
}

#define SKINLAB_REQUIRE_RENDERER(name)                                                                                 \
    ::skinlab::renderer::Renderer* name = ::skinlab::renderer::test::sharedRenderer();                                 \
    if (!name) GTEST_SKIP() << "no EGL/OpenGL 4.5 context: " << ::skinlab::renderer::test::rendererFailure()

struct ExrImage {
    int width = 0;
    int height = 0;
    std::map<std::string, std::vector<float>> channels; // planar, top row first
    std::map<std::string, std::string> strings;
    std::map<std::string, float> floats;
    std::vector<std::string> channelOrder;

    float at(const std::string& channel, int x, int y) const {
        return channels.at(
            channel)[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)];
    }
};

inline ExrImage readExr(const std::filesystem::path& path) {
    auto input = OIIO::ImageInput::open(path.string());
    if (!input) throw std::runtime_error("cannot open " + path.string() + ": " + OIIO::geterror());
    const OIIO::ImageSpec& spec = input->spec();
    ExrImage image;
    image.width = spec.width;
    image.height = spec.height;
    std::vector<float> interleaved(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) *
                                   static_cast<std::size_t>(spec.nchannels));
    if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, interleaved.data()))
        throw std::runtime_error("cannot read " + path.string() + ": " + input->geterror());
    const std::size_t pixels = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height);
    for (int c = 0; c < spec.nchannels; ++c) {
        std::vector<float> plane(pixels);
        for (std::size_t p = 0; p < pixels; ++p)
            plane[p] = interleaved[p * static_cast<std::size_t>(spec.nchannels) + static_cast<std::size_t>(c)];
        image.channels[spec.channelnames[static_cast<std::size_t>(c)]] = std::move(plane);
        image.channelOrder.push_back(spec.channelnames[static_cast<std::size_t>(c)]);
    }
    for (const auto& attribute : spec.extra_attribs) {
        if (attribute.type() == OIIO::TypeDesc::STRING)
            image.strings[attribute.name().string()] = attribute.get_string();
        else if (attribute.type() == OIIO::TypeDesc::FLOAT)
            image.floats[attribute.name().string()] = attribute.get_float();
    }
    return image;
}

inline std::vector<unsigned char> readPng(const std::filesystem::path& path, int& width, int& height) {
    auto input = OIIO::ImageInput::open(path.string());
    if (!input) throw std::runtime_error("cannot open " + path.string());
    width = input->spec().width;
    height = input->spec().height;
    std::vector<unsigned char> rgb(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
    input->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, rgb.data());
    return rgb;
}

using skinlab::test_support::TempFolder;

// Renders `scene` with `method` (and the `overrides`, as --set) at width × height into `exrPath`; the assets come
// from $SKINLAB_ASSETS (the renderer's default). Without anti-aliasing unless the overrides turn it on
// ("render.antialiasing=ssaa"): the tests through here check per-pixel mechanics (kernels against their CPU
// mirrors, Blender against the rasterizer pixel by pixel) on pixel-centre samples; anti-aliasing has its own
// tests (test_antialiasing.cpp).
inline RenderResult renderToExr(Renderer& renderer, const std::string& scene, const std::string& method,
                                std::vector<std::string> overrides, int width, int height,
                                const std::filesystem::path& exrPath) {
    RenderRequest request;
    request.scene = scene;
    request.method = method;
    request.overrides = {"render.antialiasing=none"};
    for (std::string& override : overrides) request.overrides.push_back(std::move(override));
    request.width = width;
    request.height = height;
    request.exrPath = exrPath;
    return renderer.render(request);
}

// Rec. 709 luminance of the diffuse AOV (after SSS) at a pixel.
inline double diffuseLuminance(const ExrImage& image, int x, int y) {
    return 0.2126 * image.at("diffuse.R", x, y) + 0.7152 * image.at("diffuse.G", x, y) +
           0.0722 * image.at("diffuse.B", x, y);
}

inline std::string readText(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

} // namespace skinlab::renderer::test
