#include "analysis/metrics/metric_render.h"

#include "common/error.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace skinlab::metrics {
namespace {

int channelIndex(const OIIO::ImageSpec& spec, const std::string& name) {
    for (int c = 0; c < spec.nchannels; ++c)
        if (spec.channelnames[static_cast<size_t>(c)] == name) return c;
    return -1;
}

int requireChannel(const OIIO::ImageSpec& spec, const std::string& file, const std::string& name) {
    int index = channelIndex(spec, name);
    if (index < 0) throwInput(file, name, "channel is missing");
    return index;
}

std::optional<double> floatAttribute(const OIIO::ImageSpec& spec, const std::string& file, const std::string& name,
                                     bool required) {
    const OIIO::ParamValue* value = spec.find_attribute(name);
    if (!value) {
        if (required) throwInput(file, name, "metadata attribute is missing");
        return std::nullopt;
    }
    if (value->type().basetype != OIIO::TypeDesc::FLOAT && value->type().basetype != OIIO::TypeDesc::DOUBLE)
        throwInput(file, name, "metadata attribute is not a number");
    double number = value->get_float();
    if (!std::isfinite(number) || number <= 0.0)
        throwInput(file, name, "metadata attribute must be a positive number, got " + std::to_string(number));
    return number;
}

// Copies one float channel of an interleaved buffer into a single-channel plane.
void extractChannel(const std::vector<float>& pixels, int channels, int index, cv::Mat& plane) {
    auto* out = plane.ptr<float>();
    size_t count = plane.total();
    for (size_t i = 0; i < count; ++i) out[i] = pixels[i * static_cast<size_t>(channels) + static_cast<size_t>(index)];
}

// The encoding a file states or implies (ImageEncoding::automatic's rule).
ImageEncoding impliedEncoding(const OIIO::ImageSpec& spec) {
    std::string colourSpace = spec.get_string_attribute("oiio:ColorSpace");
    std::string lower = colourSpace;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    if (lower.find("srgb") != std::string::npos) return ImageEncoding::srgb;
    if (lower.find("linear") != std::string::npos) return ImageEncoding::linear;
    bool floating = spec.format.basetype == OIIO::TypeDesc::FLOAT || spec.format.basetype == OIIO::TypeDesc::HALF ||
                    spec.format.basetype == OIIO::TypeDesc::DOUBLE;
    return floating ? ImageEncoding::linear : ImageEncoding::srgb;
}

// The sRGB EOTF (IEC 61966-2-1).
float decodeSrgb(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

} // namespace

ImageEncoding parseImageEncoding(const std::string& text) {
    if (text == "auto") return ImageEncoding::automatic;
    if (text == "srgb") return ImageEncoding::srgb;
    if (text == "linear") return ImageEncoding::linear;
    throwInput("--encoding", "", "\"" + text + "\" is not one of auto, srgb, linear");
}

const char* imageEncodingName(ImageEncoding encoding) {
    switch (encoding) {
    case ImageEncoding::automatic: return "auto";
    case ImageEncoding::srgb: return "srgb";
    case ImageEncoding::linear: return "linear";
    }
    return "?";
}

namespace {

struct OpenedRender {
    std::unique_ptr<OIIO::ImageInput> input;
    MetricRender render;
    int channels[5] = {-1, -1, -1, -1, -1}; // R, G, B, depth.Z, mask.Y
};

OpenedRender openMetricRender(const std::filesystem::path& path, RenderRole role, ImageEncoding encoding) {
    const std::string file = path.string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throwInput(file, "", "file not found");
    OpenedRender opened;
    opened.input = OIIO::ImageInput::open(file);
    if (!opened.input) {
        std::string reason = OIIO::geterror();
        if (auto newline = reason.find('\n'); newline != std::string::npos) reason.resize(newline);
        throwInput(file, "", "not a readable image (" + reason + ")");
    }
    const OIIO::ImageSpec& spec = opened.input->spec();
    if (spec.depth != 1) throwInput(file, "", "volume images are not supported");

    bool reference = role == RenderRole::reference;
    // A reference without any of skinlab's AOVs and metadata is a plain image (photograph, PNG, another
    // engine's render); one with some of them is a skinlab render with something missing, an error below.
    bool plain = channelIndex(spec, "depth.Z") < 0 && channelIndex(spec, "mask.Y") < 0 &&
                 !spec.find_attribute("skinlab:f_px") && !spec.find_attribute("skinlab:mm_per_unit");
    if (plain) reference = false;
    opened.channels[0] = requireChannel(spec, file, "R");
    opened.channels[1] = requireChannel(spec, file, "G");
    opened.channels[2] = requireChannel(spec, file, "B");
    if (reference) {
        opened.channels[3] = requireChannel(spec, file, "depth.Z");
        opened.channels[4] = requireChannel(spec, file, "mask.Y");
    }
    MetricRender& render = opened.render;
    render.path = path;
    render.plain = plain;
    render.encoding = encoding == ImageEncoding::automatic ? impliedEncoding(spec) : encoding;
    render.width = spec.width;
    render.height = spec.height;
    render.focalLengthPixels = floatAttribute(spec, file, "skinlab:f_px", reference);
    render.millimetresPerUnit = floatAttribute(spec, file, "skinlab:mm_per_unit", reference);
    // Not required here: `--sss-radius-mm` may stand in for it (prepareReference checks).
    // A test render's radius is never used (a render without SSS stores 0), so only a reference's is checked.
    if (reference) render.sssRadiusMillimetres = floatAttribute(spec, file, "skinlab:sss_radius_mm", false);
    return opened;
}

} // namespace

MetricRender inspectMetricRender(const std::filesystem::path& path, RenderRole role, ImageEncoding encoding) {
    return openMetricRender(path, role, encoding).render;
}

MetricRender loadMetricRender(const std::filesystem::path& path, RenderRole role, ImageEncoding encoding) {
    OpenedRender opened = openMetricRender(path, role, encoding);
    const std::string file = path.string();
    const OIIO::ImageSpec& spec = opened.input->spec();
    MetricRender render = std::move(opened.render);

    // Whole image, all channels, as float: the contract stores float32, and half files convert losslessly.
    std::vector<float> pixels(static_cast<size_t>(spec.width) * static_cast<size_t>(spec.height) *
                              static_cast<size_t>(spec.nchannels));
    if (!opened.input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data())) {
        std::string reason = opened.input->geterror();
        if (auto newline = reason.find('\n'); newline != std::string::npos) reason.resize(newline);
        throwInput(file, "", "cannot read pixels (" + reason + ")");
    }
    opened.input->close();

    cv::Mat planes[3];
    for (int c = 0; c < 3; ++c) {
        planes[c].create(spec.height, spec.width, CV_32FC1);
        extractChannel(pixels, spec.nchannels, opened.channels[c], planes[c]);
        if (render.encoding == ImageEncoding::srgb)
            for (auto it = planes[c].begin<float>(); it != planes[c].end<float>(); ++it) *it = decodeSrgb(*it);
    }
    cv::merge(planes, 3, render.beauty);
    if (opened.channels[3] >= 0) {
        render.depth.create(spec.height, spec.width, CV_32FC1);
        extractChannel(pixels, spec.nchannels, opened.channels[3], render.depth);
    }
    if (opened.channels[4] >= 0) {
        render.mask.create(spec.height, spec.width, CV_32FC1);
        extractChannel(pixels, spec.nchannels, opened.channels[4], render.mask);
    }
    return render;
}

} // namespace skinlab::metrics
