#include "synthetic_render.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace skinlab::metrics::testing {

double focalLengthPixels(int height, double fovYDegrees) {
    return (height / 2.0) / std::tan(0.5 * fovYDegrees * std::numbers::pi / 180.0);
}

void writeSyntheticExr(const std::filesystem::path& path, const SyntheticRender& render, const WriteOptions& options) {
    auto omitted = [](const std::vector<std::string>& list, const std::string& name) {
        return std::find(list.begin(), list.end(), name) != list.end();
    };
    std::vector<std::string> names;
    std::vector<std::function<float(int, int)>> sources;
    const std::pair<const char*, int> beautyChannels[3] = {{"R", 0}, {"G", 1}, {"B", 2}};
    for (auto [name, channel] : beautyChannels)
        if (!omitted(options.omitChannels, name)) {
            names.emplace_back(name);
            sources.emplace_back([&render, c = channel](int x, int y) { return render.beauty.at<cv::Vec3f>(y, x)[c]; });
        }
    if (!omitted(options.omitChannels, "depth.Z")) {
        names.emplace_back("depth.Z");
        sources.emplace_back([&render](int x, int y) { return render.depth.at<float>(y, x); });
    }
    if (!omitted(options.omitChannels, "mask.Y")) {
        names.emplace_back("mask.Y");
        sources.emplace_back([&render](int x, int y) { return render.mask.at<float>(y, x); });
    }
    OIIO::ImageSpec spec(render.width, render.height, static_cast<int>(names.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = names;
    spec.alpha_channel = -1;
    if (!omitted(options.omitAttributes, "skinlab:f_px")) spec.attribute("skinlab:f_px", render.focalLengthPixels);
    if (!omitted(options.omitAttributes, "skinlab:mm_per_unit"))
        spec.attribute("skinlab:mm_per_unit", render.millimetresPerUnit);
    if (!omitted(options.omitAttributes, "skinlab:sss_radius_mm"))
        spec.attribute("skinlab:sss_radius_mm", render.sssRadiusMillimetres);
    spec.attribute("skinlab:version", "test");
    spec.attribute("skinlab:resolved", "{}");
    for (const auto& [key, value] : options.stringAttributes) spec.attribute(key, value);

    std::vector<float> pixels(static_cast<size_t>(render.width) * static_cast<size_t>(render.height) * names.size());
    size_t i = 0;
    for (int y = 0; y < render.height; ++y)
        for (int x = 0; x < render.width; ++x)
            for (const auto& source : sources) pixels[i++] = source(x, y);
    auto output = OIIO::ImageOutput::create(path.string());
    if (!output || !output->open(path.string(), spec) || !output->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) ||
        !output->close())
        throw std::runtime_error("cannot write test EXR " + path.string() + ": " + OIIO::geterror());
}

DiscPixel discPixel(const DiscScene& scene, int x, int y) {
    const double f = focalLengthPixels(scene.size, scene.fovYDegrees);
    // Pixel centre relative to the principal point; +Y up.
    const int width = scene.width > 0 ? scene.width : scene.size;
    double u = x + 0.5 - width / 2.0;
    double v = scene.size / 2.0 - (y + 0.5);
    DiscPixel pixel;
    pixel.screenRadius = std::hypot(u, v);
    double discX = u * scene.nearDepth / f;
    double discY = v * scene.nearDepth / f;
    if (std::hypot(discX, discY) <= scene.discRadius) {
        pixel.onDisc = true;
        pixel.worldX = discX;
        pixel.worldY = discY;
        pixel.depth = scene.nearDepth;
        pixel.onStripe = std::fabs(discY) < scene.stripeHalfWidth;
    } else {
        pixel.depth = scene.farDepth;
        pixel.worldX = u * scene.farDepth / f;
        pixel.worldY = v * scene.farDepth / f;
    }
    return pixel;
}

SyntheticRender renderDiscScene(const DiscScene& scene) {
    SyntheticRender render;
    render.width = scene.width > 0 ? scene.width : scene.size;
    render.height = scene.size;
    render.focalLengthPixels = static_cast<float>(focalLengthPixels(scene.size, scene.fovYDegrees));
    render.beauty.create(render.height, render.width, CV_32FC3);
    render.depth.create(render.height, render.width, CV_32FC1);
    render.mask.create(render.height, render.width, CV_32FC1);
    for (int y = 0; y < render.height; ++y)
        for (int x = 0; x < render.width; ++x) {
            DiscPixel pixel = discPixel(scene, x, y);
            cv::Vec3f colour;
            float skin = 0.0f;
            if (pixel.onDisc && !pixel.onStripe) {
                colour = {0.6f, 0.4f, 0.3f};
                skin = 1.0f;
            } else if (pixel.onDisc) {
                colour = {0.2f, 0.1f, 0.1f};
            } else if (std::isfinite(scene.farDepth)) {
                colour = {0.3f, 0.3f, 0.35f};
                skin = scene.farPlaneIsSkin ? 1.0f : 0.0f;
            } else {
                colour = {0.0f, 0.0f, 0.0f};
            }
            render.beauty.at<cv::Vec3f>(y, x) = colour;
            render.depth.at<float>(y, x) = static_cast<float>(pixel.depth);
            render.mask.at<float>(y, x) = skin;
        }
    return render;
}

} // namespace skinlab::metrics::testing
