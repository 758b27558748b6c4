#pragma once
// Textures from files through OpenImageIO, decoded to linear float RGBA; sRGB decoding through OpenColorIO.
#include <filesystem>
#include <glm/glm.hpp>
#include <vector>

namespace skinlab::renderer {

// How a texture file's values are to be read.
enum class ColorEncoding {
    sRGB, // colour (albedo): sRGB-encoded in the file, decoded to linear Rec.709 (the sRGB EOTF, IEC 61966-2-1)
    Data, // numbers (normal, specular, AO maps): values untouched, only scaled to [0, 1] for integer files
};

// A float RGBA image, rows stored top row first (the file's first row), pixels row-major, 4 floats each.
// With Model UVs (v = 0 at the top) texel (x, y) covers u in [x/W, (x+1)/W], v in [y/H, (y+1)/H]; upload
// to GL rows in storage order (GL's t = 0 is then the image top, matching v).
struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> pixels; // width * height * 4 floats: R, G, B, A

    glm::vec4 texel(int x, int y) const {
        const float* p =
            &pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4];
        return {p[0], p[1], p[2], p[3]};
    }
};

// Reads any OpenImageIO format (JPEG, PNG, TIFF, EXR, HDR, ...). Integer files are scaled to [0, 1], float
// files kept. Channels: grey → RGB = grey; grey+alpha; RGB (alpha = 1); RGBA; more channels: the first four.
// sRGB: R, G, B are decoded through the OpenColorIO sRGB → linear processor (alpha is never decoded).
// Errors: missing, unreadable or corrupt file → InputError "PATH: cannot read texture (MESSAGE)".
Image loadTexture(const std::filesystem::path& path, ColorEncoding encoding);

// The sRGB transfer function through the same OpenColorIO processors loadTexture uses: above the break point
// ((v + 0.055) / 1.055)^2.4 (IEC 61966-2-1), below it a linear segment. OpenColorIO's ExponentWithLinear-
// Transform makes the curve C1-continuous, so its break point is 0.0392857 encoded (offset / (gamma - 1)) with
// slope 1 / 12.9232, where the IEC text rounds to 0.04045 and 1 / 12.92: the two differ by < 4e-7 in linear
// value. Known values: srgbToLinear(0.5) = 0.214041, srgbToLinear(0.04045) = 0.0031308; linearToSrgb is
// the inverse.
float srgbToLinear(float encoded);
float linearToSrgb(float linear);

// Decodes / encodes a buffer of RGB triples in place (count = number of triples) through OpenColorIO.
void srgbToLinearRgb(float* rgb, std::size_t count);
void linearToSrgbRgb(float* rgb, std::size_t count);

} // namespace skinlab::renderer
