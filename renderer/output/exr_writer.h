#pragma once
// Writes a render as a float32 OpenEXR (docs/rendering.md, "EXR layout"): beauty R, G, B and AOV channels
// named "layer.channel", plus string and float metadata attributes. Deterministic: ZIP ("zips") compression, no
// timestamps or host names; the same channels and values give the same bytes. Atomic: written to a
// temporary sibling and renamed.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace skinlab::renderer {

struct ExrChannel {
    std::string name;          // "R", "diffuse.G", "depth.Z", ...
    std::vector<float> values; // width * height, top row first
};

struct ExrMetadata {
    std::map<std::string, std::string> strings;
    std::map<std::string, float> floats;
};

// Throws InputError "PATH: cannot write EXR (...)" when the file cannot be written.
void writeExr(const std::filesystem::path& path, int width, int height, const std::vector<ExrChannel>& channels,
              const ExrMetadata& metadata);

} // namespace skinlab::renderer
