#pragma once
// Presentation of a rendered stimulus (docs/stimuli.md, "Designing a set whose differences are visible"): the
// crop of the render a participant sees and its integer magnification, made one of two ways (`presentation`):
//  - native (the default): the renderer renders the crop's part of the camera's frustum at the presented size, a
//    render.window of the frame at magnification × the render size (nativeRenderOverrides); the EXR (all AOVs)
//    and the PNG are that render, nothing is resampled;
//  - replicate: the render is cropped after rendering (the EXR, all AOVs) and the PNG cropped and magnified by
//    nearest neighbour (each pixel a magnification × magnification square); the build warns about it.
// The PNG is exactly what the study page shows at one image pixel per device pixel, and what the predicted JOD
// (stimuli/prediction.h) is computed on at the display's pixels per degree.
// The manifest entry records it: "presentation": {"render": {width, height}, "crop": {x, y, width, height},
// "magnification": m, "presented": {width, height}, "method": "native"|"replicate"}; "render" is the render size
// the crop is given in (the set's), the entry's width and height are the presented size.
#include "stimuli/set_spec.h"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::stimuli {

// The crop of a render of renderWidth × renderHeight (the whole frame when the presentation has none).
CropRect effectiveCrop(const Presentation& presentation, int renderWidth, int renderHeight);

// Throws InputError "SPEC: KEY: ..." when the crop does not lie inside the render (KEY: the crop's key,
// "fixed.crop.width" or "crop[1].crop.x", ...), when the presented image would exceed 16384 pixels, or when a
// native presentation cannot be rendered (presented image over 8192 pixels, frame over 65536, a scene that sets
// its own render.window).
void checkPresentation(const Presentation& presentation, int renderWidth, int renderHeight, const std::string& specName,
                       const std::string& stimulusId);

// Whether the presentation changes the render at all (a crop, or a magnification above 1).
bool presents(const Presentation& presentation);

// The scene overrides that render a native presentation of a render.width × render.height frame: render.width and
// render.height × magnification and render.window = the crop × magnification. Empty for a replicated presentation
// or the whole frame at magnification 1.
std::vector<std::string> nativeRenderOverrides(const Presentation& presentation, int renderWidth, int renderHeight);

// The manifest's "presentation" object.
nlohmann::json presentationJson(const Presentation& presentation, int renderWidth, int renderHeight);

// A replicated presentation: crops `exr` in place (every channel and the metadata kept; "skinlab:crop" added) and
// crops and magnifies `png` in place (nearest neighbour: each pixel becomes a magnification × magnification
// square). Nothing happens for a native presentation (the render is already the presented image) or the whole
// frame at magnification 1. Throws RuntimeError when a file cannot be read or written.
void applyPresentation(const std::filesystem::path& exr, const std::filesystem::path& png,
                       const Presentation& presentation);

} // namespace skinlab::stimuli
