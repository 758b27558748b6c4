#pragma once
// Presentation of a rendered stimulus (docs/stimuli.md, "Designing a set whose differences are visible"): the
// crop of the render a participant sees and its integer nearest-neighbour magnification. Applied after
// rendering, to the files of the stimulus:
//  - the EXR (all AOVs, linear) is cropped: image metrics run on the render pixels that are shown;
//  - the PNG is cropped and magnified: it is exactly what the study page shows at one image pixel per device
//    pixel, and what the predicted JOD (stimuli/prediction.h) is computed on at the display's pixels per degree.
// The manifest entry records it: "presentation": {"render": {width, height}, "crop": {x, y, width, height},
// "magnification": m, "presented": {width, height}}; the entry's width and height are the presented size.
#include "stimuli/set_spec.h"

#include <filesystem>
#include <nlohmann/json.hpp>

namespace skinlab::stimuli {

// The crop of a render of renderWidth × renderHeight (the whole frame when the presentation has none).
CropRect effectiveCrop(const Presentation& presentation, int renderWidth, int renderHeight);

// Throws InputError "SPEC: KEY: ..." when the crop does not lie inside the render (KEY: the crop's key,
// "fixed.crop.width" or "crop[1].crop.x", ...), or when the presented image would exceed 16384 pixels.
void checkPresentation(const Presentation& presentation, int renderWidth, int renderHeight, const std::string& specName,
                       const std::string& stimulusId);

// The manifest's "presentation" object.
nlohmann::json presentationJson(const Presentation& presentation, int renderWidth, int renderHeight);

// Crops `exr` in place (every channel and the metadata kept; "skinlab:crop" added) and crops and magnifies
// `png` in place (nearest neighbour: each pixel becomes a magnification × magnification square). Nothing
// happens for the whole frame at magnification 1. Throws RuntimeError when a file cannot be read or written.
void applyPresentation(const std::filesystem::path& exr, const std::filesystem::path& png,
                       const Presentation& presentation);

} // namespace skinlab::stimuli
