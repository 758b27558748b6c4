#include "renderer/output/display_output.h"

#include "common/error.h"
#include "common/files.h"
#include "renderer/scene/texture.h"

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cmath>

namespace skinlab::renderer {

std::vector<std::uint8_t> encodeDisplaySrgb8(const std::vector<float>& linearRgb) {
    std::vector<float> encoded(linearRgb.size());
    for (std::size_t i = 0; i < linearRgb.size(); ++i) encoded[i] = std::clamp(linearRgb[i], 0.0f, 1.0f);
    linearToSrgbRgb(encoded.data(), encoded.size() / 3);
    std::vector<std::uint8_t> codes(encoded.size());
    for (std::size_t i = 0; i < encoded.size(); ++i)
        codes[i] = static_cast<std::uint8_t>(std::lround(std::clamp(encoded[i], 0.0f, 1.0f) * 255.0f));
    return codes;
}

void writePng(const std::filesystem::path& path, int width, int height, const std::vector<std::uint8_t>& rgb) {
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    spec.attribute("DateTime", ""); // no timestamp (OpenImageIO adds the current time to an absent DateTime)
    AtomicOutput output(path);
    auto writer = OIIO::ImageOutput::create("png");
    if (!writer) throw RuntimeError("OpenImageIO has no PNG writer: " + OIIO::geterror());
    if (!writer->open(output.tempPath().string(), spec))
        throw InputError(path.string() + ": cannot write PNG (" + writer->geterror() + ")");
    if (!writer->write_image(OIIO::TypeDesc::UINT8, rgb.data()))
        throw InputError(path.string() + ": cannot write PNG (" + writer->geterror() + ")");
    if (!writer->close()) throw InputError(path.string() + ": cannot write PNG (" + writer->geterror() + ")");
    output.commit();
}

} // namespace skinlab::renderer
