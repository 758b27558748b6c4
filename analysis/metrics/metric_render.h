#pragma once
// A render as the metrics read it: the beauty image and, for a reference, the depth and skin-mask AOVs and the
// camera/SSS metadata that the halo and bleed bands need. Layout: contract 1 (docs/metrics.md, "Inputs").
#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace skinlab::metrics {

// How a file's R, G, B values map to linear light. `automatic`: EXR, HDR and other floating-point files are
// linear; 8/16-bit integer files (PNG, JPEG, TIFF, ...) are sRGB unless the file states a linear colour space
// (OpenImageIO's oiio:ColorSpace "linear"/"Linear"/"scene_linear").
enum class ImageEncoding { automatic, srgb, linear };
ImageEncoding parseImageEncoding(const std::string& text); // "auto", "srgb", "linear"; InputError otherwise
const char* imageEncodingName(ImageEncoding encoding);     // "auto", "srgb", "linear"

struct MetricRender {
    std::filesystem::path path;
    // A plain image: none of skinlab's AOVs and metadata (no depth.Z, mask.Y, skinlab:f_px, skinlab:mm_per_unit).
    // As a reference it gets the image-wide metrics only.
    bool plain = false;
    ImageEncoding encoding = ImageEncoding::linear; // the decoding applied (never automatic once loaded)
    int width = 0;
    int height = 0;
    cv::Mat beauty; // CV_32FC3, channels R, G, B in this order: linear Rec.709, exposure applied, not tone mapped
                    // (an sRGB file is decoded with the sRGB EOTF)
    cv::Mat depth;  // CV_32FC1 linear view-space depth in world units; +inf on background (empty if not loaded)
    cv::Mat mask;   // CV_32FC1 skin mask 0..1 (empty if not loaded)
    std::optional<double> focalLengthPixels;    // skinlab:f_px, (H/2)/tan(fovY/2)
    std::optional<double> millimetresPerUnit;   // skinlab:mm_per_unit
    std::optional<double> sssRadiusMillimetres; // skinlab:sss_radius_mm
};

// What a caller needs from a file. A test render needs only its beauty (R, G, B); the reference also needs
// depth.Z, mask.Y, skinlab:f_px and skinlab:mm_per_unit (skinlab:sss_radius_mm too, unless the command line
// gives the radius) — unless it has none of them, which makes it a plain image (MetricRender::plain).
enum class RenderRole { test, reference };

// Reads an EXR following contract 1. Throws InputError "FILE: message" when the file is missing or unreadable
// and "FILE: CHANNEL: channel is missing" / "FILE: ATTRIBUTE: metadata attribute is missing" when the role needs
// something that is not there.
MetricRender loadMetricRender(const std::filesystem::path& path, RenderRole role,
                              ImageEncoding encoding = ImageEncoding::automatic);

// The same checks as loadMetricRender on the file's header only (no pixels are read): lets a command reject bad
// input before it writes anything. Returns the render with empty images.
MetricRender inspectMetricRender(const std::filesystem::path& path, RenderRole role,
                                 ImageEncoding encoding = ImageEncoding::automatic);

} // namespace skinlab::metrics
