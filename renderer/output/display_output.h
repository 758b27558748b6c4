#pragma once
// The display image: tone-mapped linear values in [0, 1] → sRGB-encoded 8-bit PNG. The encoding is the sRGB
// inverse EOTF through OpenColorIO (renderer/scene/texture.h, linearToSrgbRgb: a processor built from OCIO's
// built-in transforms, no config file), then rounded to the nearest 8-bit code.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace skinlab::renderer {

// Encodes RGB triples (linear display-referred, clamped to [0, 1]) to 8-bit sRGB codes.
std::vector<std::uint8_t> encodeDisplaySrgb8(const std::vector<float>& linearRgb);

// Writes an 8-bit RGB PNG atomically (no timestamp chunks). Throws InputError "PATH: cannot write PNG (...)".
void writePng(const std::filesystem::path& path, int width, int height, const std::vector<std::uint8_t>& rgb);

} // namespace skinlab::renderer
