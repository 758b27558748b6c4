#pragma once
// Contact sheet of a stimulus set, to inspect it at a glance: contact.html (every display PNG, labelled by its
// factor levels, grouped by block, references marked) and contact.png (a grid of thumbnails, one row per block,
// each captioned with the levels that vary inside the block).
#include "stimuli/manifest.h"

#include <filesystem>
#include <string>
#include <vector>

namespace skinlab::stimuli {

struct ContactSheetFiles {
    std::filesystem::path html;
    std::filesystem::path png;
};

// The captions of contact.png's thumbnails (before wrapping), block by block in manifest order: the levels that
// vary inside the block, by label ("bleed separable cbf=true"), "(ref)" on the reference, and the predicted JOD
// against the reference when the build recorded it ("... - predicted 8.17 JOD").
std::vector<std::string> contactSheetCaptions(const Manifest& manifest);

// Writes DIR/contact.html and DIR/contact.png atomically from the manifest and the PNGs it lists.
ContactSheetFiles writeContactSheet(const std::filesystem::path& dir, const Manifest& manifest,
                                    int thumbnailWidth = 256);

} // namespace skinlab::stimuli
