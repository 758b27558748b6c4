#include "stimuli/presentation.h"

#include "common/error.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <string>
#include <vector>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

CropRect effectiveCrop(const Presentation& presentation, int renderWidth, int renderHeight) {
    return presentation.crop ? *presentation.crop : CropRect{0, 0, renderWidth, renderHeight};
}

bool presents(const Presentation& presentation) { return presentation.crop || presentation.magnification != 1; }

std::vector<std::string> nativeRenderOverrides(const Presentation& presentation, int renderWidth, int renderHeight) {
    if (presentation.method != PresentationMethod::native || !presents(presentation)) return {};
    const CropRect c = effectiveCrop(presentation, renderWidth, renderHeight);
    const int m = presentation.magnification;
    return {"render.width=" + std::to_string(renderWidth * m), "render.height=" + std::to_string(renderHeight * m),
            "render.window={ x = " + std::to_string(c.x * m) + ", y = " + std::to_string(c.y * m) +
                ", width = " + std::to_string(c.width * m) + ", height = " + std::to_string(c.height * m) + " }"};
}

void checkPresentation(const Presentation& presentation, int renderWidth, int renderHeight, const std::string& specName,
                       const std::string& stimulusId) {
    const std::string stimulus = " (stimulus '" + stimulusId + "')";
    if (presentation.crop) {
        const CropRect& c = *presentation.crop;
        const std::string& key = presentation.cropWhere;
        if (c.x >= renderWidth)
            throwInput(specName, key + ".x",
                       std::to_string(c.x) + " lies outside the " + std::to_string(renderWidth) + " × " +
                           std::to_string(renderHeight) + " render" + stimulus);
        if (c.y >= renderHeight)
            throwInput(specName, key + ".y",
                       std::to_string(c.y) + " lies outside the " + std::to_string(renderWidth) + " × " +
                           std::to_string(renderHeight) + " render" + stimulus);
        if (c.x + c.width > renderWidth)
            throwInput(specName, key + ".width",
                       "x + width = " + std::to_string(c.x + c.width) + " exceeds the render width " +
                           std::to_string(renderWidth) + stimulus);
        if (c.y + c.height > renderHeight)
            throwInput(specName, key + ".height",
                       "y + height = " + std::to_string(c.y + c.height) + " exceeds the render height " +
                           std::to_string(renderHeight) + stimulus);
    }
    const CropRect c = effectiveCrop(presentation, renderWidth, renderHeight);
    const long long presentedWidth = static_cast<long long>(c.width) * presentation.magnification;
    const long long presentedHeight = static_cast<long long>(c.height) * presentation.magnification;
    if (presentedWidth > 16384 || presentedHeight > 16384)
        throwInput(specName, presentation.magnificationWhere,
                   std::to_string(presentation.magnification) + " makes the presented image " +
                       std::to_string(presentedWidth) + " × " + std::to_string(presentedHeight) +
                       " pixels (at most 16384 each way)" + stimulus);
    if (presentation.method == PresentationMethod::native && presents(presentation)) {
        // The renderer's limits (renderer/scene/scene_spec.cpp): the window at most 8192, the frame at most 65536.
        const long long frameWidth = static_cast<long long>(renderWidth) * presentation.magnification;
        const long long frameHeight = static_cast<long long>(renderHeight) * presentation.magnification;
        if (presentedWidth > 8192 || presentedHeight > 8192 || frameWidth > 65536 || frameHeight > 65536)
            throwInput(specName, presentation.magnificationWhere,
                       std::to_string(presentation.magnification) + " cannot be rendered natively: the presented " +
                           std::to_string(presentedWidth) + " × " + std::to_string(presentedHeight) +
                           " pixels (at most 8192 each way) of a " + std::to_string(frameWidth) + " × " +
                           std::to_string(frameHeight) +
                           " frame (at most 65536); lower it, or set presentation = "
                           "\"replicate\"" +
                           stimulus);
    }
}

nlohmann::json presentationJson(const Presentation& presentation, int renderWidth, int renderHeight) {
    const CropRect c = effectiveCrop(presentation, renderWidth, renderHeight);
    const int m = presentation.magnification;
    return {{"render", {{"width", renderWidth}, {"height", renderHeight}}},
            {"crop", {{"x", c.x}, {"y", c.y}, {"width", c.width}, {"height", c.height}}},
            {"magnification", m},
            {"presented", {{"width", c.width * m}, {"height", c.height * m}}},
            {"method", presentation.method == PresentationMethod::native ? "native" : "replicate"}};
}

namespace {

OIIO::ImageBuf readWhole(const fs::path& path) {
    OIIO::ImageBuf image(path.string());
    if (!image.read(0, 0, true))
        throw RuntimeError(path.string() + ": cannot read for cropping (" + image.geterror() + ")");
    return image;
}

// Writes `image` over `path` in the pixel formats of `original` (per channel where it has them).
void writeOver(OIIO::ImageBuf& image, const fs::path& path, const OIIO::ImageSpec& original) {
    if (!original.channelformats.empty()) image.set_write_format(original.channelformats);
    else image.set_write_format(original.format);
    // The spec read back has no DateTime (the renderer writes none), and ImageBuf::write would stamp the current time
    // into an EXR without one: an empty value keeps it out (same inputs ⇒ same bytes).
    image.specmod().attribute("DateTime", "");
    // Written beside the file, then renamed over it (the file itself is still a temporary of the build).
    fs::path temp = path.parent_path() / ("." + path.stem().string() + ".present" + path.extension().string());
    if (!image.write(temp.string())) {
        std::error_code ec;
        fs::remove(temp, ec);
        throw RuntimeError(path.string() + ": cannot write the cropped image (" + image.geterror() + ")");
    }
    fs::rename(temp, path);
}

std::string cropText(const CropRect& c) {
    return std::to_string(c.x) + " " + std::to_string(c.y) + " " + std::to_string(c.width) + " " +
           std::to_string(c.height);
}

} // namespace

void applyPresentation(const fs::path& exr, const fs::path& png, const Presentation& presentation) {
    if (presentation.method == PresentationMethod::native || !presents(presentation)) return;
    {
        OIIO::ImageBuf source = readWhole(exr);
        const OIIO::ImageSpec& spec = source.spec();
        const CropRect c = effectiveCrop(presentation, spec.width, spec.height);
        const OIIO::ImageSpec original = spec;
        OIIO::ImageSpec croppedSpec = spec;
        croppedSpec.set_format(OIIO::TypeDesc::FLOAT); // held as float; written back in the original formats
        croppedSpec.width = croppedSpec.full_width = c.width;
        croppedSpec.height = croppedSpec.full_height = c.height;
        croppedSpec.x = croppedSpec.y = croppedSpec.full_x = croppedSpec.full_y = 0;
        croppedSpec.tile_width = croppedSpec.tile_height = 0;
        croppedSpec.attribute("skinlab:crop", cropText(c));
        OIIO::ImageBuf cropped(croppedSpec);
        const OIIO::ROI roi(spec.x + c.x, spec.x + c.x + c.width, spec.y + c.y, spec.y + c.y + c.height, 0, 1, 0,
                            spec.nchannels);
        std::vector<float> pixels(static_cast<size_t>(c.width) * static_cast<size_t>(c.height) *
                                  static_cast<size_t>(spec.nchannels));
        if (!source.get_pixels(roi, OIIO::TypeDesc::FLOAT, pixels.data()) ||
            !cropped.set_pixels(OIIO::ROI(0, c.width, 0, c.height, 0, 1, 0, spec.nchannels), OIIO::TypeDesc::FLOAT,
                                pixels.data()))
            throw RuntimeError(exr.string() + ": cannot crop (" + source.geterror() + cropped.geterror() + ")");
        source.reset();
        writeOver(cropped, exr, original);
    }
    {
        OIIO::ImageBuf source = readWhole(png);
        const OIIO::ImageSpec& spec = source.spec();
        const CropRect c = effectiveCrop(presentation, spec.width, spec.height);
        const int m = presentation.magnification;
        const auto channels = static_cast<size_t>(spec.nchannels);
        std::vector<float> pixels(static_cast<size_t>(c.width) * static_cast<size_t>(c.height) * channels);
        const OIIO::ROI roi(spec.x + c.x, spec.x + c.x + c.width, spec.y + c.y, spec.y + c.y + c.height, 0, 1, 0,
                            spec.nchannels);
        if (!source.get_pixels(roi, OIIO::TypeDesc::FLOAT, pixels.data()))
            throw RuntimeError(png.string() + ": cannot crop (" + source.geterror() + ")");
        const int width = c.width * m, height = c.height * m;
        std::vector<float> presented(static_cast<size_t>(width) * static_cast<size_t>(height) * channels);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const size_t from =
                    (static_cast<size_t>(y / m) * static_cast<size_t>(c.width) + static_cast<size_t>(x / m)) * channels;
                const size_t to =
                    (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * channels;
                for (size_t k = 0; k < channels; ++k) presented[to + k] = pixels[from + k];
            }
        const OIIO::ImageSpec original = spec;
        OIIO::ImageSpec presentedSpec = spec;
        presentedSpec.set_format(OIIO::TypeDesc::FLOAT);
        presentedSpec.width = presentedSpec.full_width = width;
        presentedSpec.height = presentedSpec.full_height = height;
        presentedSpec.x = presentedSpec.y = presentedSpec.full_x = presentedSpec.full_y = 0;
        presentedSpec.attribute("skinlab:crop", cropText(c));
        presentedSpec.attribute("skinlab:magnification", m);
        OIIO::ImageBuf out(presentedSpec);
        if (!out.set_pixels(OIIO::ROI(0, width, 0, height, 0, 1, 0, spec.nchannels), OIIO::TypeDesc::FLOAT,
                            presented.data()))
            throw RuntimeError(png.string() + ": cannot magnify (" + out.geterror() + ")");
        source.reset();
        writeOver(out, png, original);
    }
}

} // namespace skinlab::stimuli
