#include "renderer/scene/texture.h"

#include "common/error.h"

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <string>

namespace OCIO = OCIO_NAMESPACE;

namespace skinlab::renderer {
namespace {

// The sRGB EOTF (IEC 61966-2-1) as an OpenColorIO built-in transform: an exponent of 2.4 with offset 0.055,
// whose linear segment OCIO derives so that value and slope are continuous (break point 0.0392857 encoded,
// slope 1 / 12.9232; IEC 61966-2-1 rounds these to 0.04045 and 1 / 12.92, a difference below 4e-7).
// The forward direction decodes (encoded → linear). Alpha gets gamma 1, offset 0 (identity): alpha is
// coverage, never colour-encoded.
OCIO::ConstCPUProcessorRcPtr makeSrgbProcessor(OCIO::TransformDirection direction) {
    auto transform = OCIO::ExponentWithLinearTransform::Create();
    const double gamma[4] = {2.4, 2.4, 2.4, 1.0};
    const double offset[4] = {0.055, 0.055, 0.055, 0.0};
    transform->setGamma(gamma);
    transform->setOffset(offset);
    transform->setDirection(direction);
    // A raw config: no file, no environment variable ($OCIO) can change what this processor does.
    OCIO::ConstConfigRcPtr config = OCIO::Config::CreateRaw();
    return config->getProcessor(transform)->getDefaultCPUProcessor();
}

const OCIO::ConstCPUProcessorRcPtr& decoder() {
    static const OCIO::ConstCPUProcessorRcPtr processor = makeSrgbProcessor(OCIO::TRANSFORM_DIR_FORWARD);
    return processor;
}

const OCIO::ConstCPUProcessorRcPtr& encoder() {
    static const OCIO::ConstCPUProcessorRcPtr processor = makeSrgbProcessor(OCIO::TRANSFORM_DIR_INVERSE);
    return processor;
}

void applyRgb(const OCIO::ConstCPUProcessorRcPtr& processor, float* rgb, std::size_t count, long channels) {
    if (count == 0) return;
    // One row of `count` pixels; PackedImageDesc takes long dimensions.
    OCIO::PackedImageDesc image(rgb, static_cast<long>(count), 1, channels);
    processor->apply(image);
}

[[noreturn]] void failTexture(const std::filesystem::path& path, const std::string& why) {
    std::string message = why;
    std::replace(message.begin(), message.end(), '\n', ' '); // keep the error on one line
    throw InputError(path.string() + ": cannot read texture (" + message + ")");
}

} // namespace

float srgbToLinear(float encoded) {
    float rgb[3] = {encoded, encoded, encoded};
    srgbToLinearRgb(rgb, 1);
    return rgb[0];
}

float linearToSrgb(float linear) {
    float rgb[3] = {linear, linear, linear};
    linearToSrgbRgb(rgb, 1);
    return rgb[0];
}

void srgbToLinearRgb(float* rgb, std::size_t count) { applyRgb(decoder(), rgb, count, 3); }
void linearToSrgbRgb(float* rgb, std::size_t count) { applyRgb(encoder(), rgb, count, 3); }

Image loadTexture(const std::filesystem::path& path, ColorEncoding encoding) {
    std::error_code code;
    if (!std::filesystem::is_regular_file(path, code)) failTexture(path, "no such file");
    auto input = OIIO::ImageInput::open(path.string());
    if (!input) failTexture(path, OIIO::geterror());
    const OIIO::ImageSpec& spec = input->spec();
    const int channels = spec.nchannels;
    if (spec.width <= 0 || spec.height <= 0 || channels <= 0) failTexture(path, "empty image");

    std::vector<float> raw(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) *
                           static_cast<std::size_t>(channels));
    // Integer formats are converted to float in [0, 1] by OpenImageIO; float formats are kept as stored.
    if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, raw.data())) {
        failTexture(path, input->geterror());
    }
    input->close();

    Image image;
    image.width = spec.width;
    image.height = spec.height;
    const std::size_t pixelCount = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height);
    image.pixels.resize(pixelCount * 4);
    // Alpha is the channel OpenImageIO names as alpha, else the 4th channel, else (grey + alpha) the 2nd.
    int alphaChannel = spec.alpha_channel;
    if (alphaChannel < 0 && channels >= 4) alphaChannel = 3;
    if (alphaChannel < 0 && channels == 2) alphaChannel = 1;
    const bool grey = channels < 3;
    for (std::size_t i = 0; i < pixelCount; ++i) {
        const float* source = &raw[i * static_cast<std::size_t>(channels)];
        float* target = &image.pixels[i * 4];
        target[0] = source[0];
        target[1] = grey ? source[0] : source[1];
        target[2] = grey ? source[0] : source[2];
        target[3] = alphaChannel >= 0 ? source[alphaChannel] : 1.0f;
    }
    if (encoding == ColorEncoding::sRGB) applyRgb(decoder(), image.pixels.data(), pixelCount, 4);
    return image;
}

} // namespace skinlab::renderer
