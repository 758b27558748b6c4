#pragma once
// Synthetic renders for the metrics tests, written as EXR files in the layout of contract 1 (beauty R,G,B,
// depth.Z, mask.Y, skinlab:* metadata) with OpenImageIO, so the tests read them through the same code path as
// real renders. Scenes are analytic and point-sampled at pixel centres, so any resolution rasterises the same
// physical scene.
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace skinlab::metrics::testing {

struct SyntheticRender {
    int width = 0;
    int height = 0;
    cv::Mat beauty; // CV_32FC3 R, G, B
    cv::Mat depth;  // CV_32FC1, +inf on background
    cv::Mat mask;   // CV_32FC1
    float focalLengthPixels = 0.0f;
    float millimetresPerUnit = 1000.0f; // world units are metres
    float sssRadiusMillimetres = 8.0f;
};

// Which parts to leave out of the written file, to provoke errors.
struct WriteOptions {
    std::vector<std::string> omitChannels;               // e.g. {"depth.Z"}
    std::vector<std::string> omitAttributes;             // e.g. {"skinlab:f_px"}
    std::map<std::string, std::string> stringAttributes; // added or replacing the defaults, e.g. skinlab:resolved
};

void writeSyntheticExr(const std::filesystem::path& path, const SyntheticRender& render,
                       const WriteOptions& options = {});

// A pinhole camera looking down −Z with vertical field of view `fovYDegrees`: f_px = (H/2)/tan(fovY/2).
double focalLengthPixels(int height, double fovYDegrees);

// "Disc in front of a far plane": a skin disc of world radius `discRadius` at depth `nearDepth`, centred on the
// view axis, in front of a plane at `farDepth` (skin or not). Optionally a non-skin stripe |Y| < stripeHalfWidth
// across the disc (a material edge at continuous depth). Colours: skin (0.6, 0.4, 0.3), stripe (0.2, 0.1, 0.1),
// far plane (0.3, 0.3, 0.35).
struct DiscScene {
    int size = 512; // image height in pixels (and width, unless `width` is set)
    int width = 0;  // image width in pixels; 0 = square
    double fovYDegrees = 30.0;
    double discRadius = 0.1; // metres
    double nearDepth = 1.0;  // metres
    double farDepth = 1.5;   // metres; +inf leaves the background empty
    bool farPlaneIsSkin = false;
    double stripeHalfWidth = 0.0; // metres; 0 = no stripe
};

// Per-pixel facts the generator knows, for checks: world-space distances to the silhouette and to the stripe.
struct DiscPixel {
    bool onDisc = false;
    bool onStripe = false;
    double screenRadius = 0.0; // pixels from the image centre
    double worldX = 0.0;       // on the surface hit
    double worldY = 0.0;
    double depth = 0.0;
};

SyntheticRender renderDiscScene(const DiscScene& scene);
DiscPixel discPixel(const DiscScene& scene, int x, int y);

} // namespace skinlab::metrics::testing
