#include "analysis/metrics/error_bands.h"

#include "analysis/metrics/distance_transform.h"

#include <cmath>

namespace skinlab::metrics {

std::string_view bandName(Band band) {
    switch (band) {
    case Band::halo: return "halo";
    case Band::bleed: return "bleed";
    case Band::spill: return "spill";
    case Band::interior: return "interior";
    }
    return "?";
}

namespace {

// Half a pixel: the boundary between the two pixels of an edge pair lies half a pixel from either centre.
constexpr float halfPixel = 0.5f;

bool validDepth(float depth) { return std::isfinite(depth) && depth > 0.0f; }

} // namespace

ErrorBands buildErrorBands(const cv::Mat& depth, const cv::Mat& skinMask, const BandGeometry& geometry) {
    CV_Assert(depth.type() == CV_32FC1 && skinMask.type() == CV_32FC1 && depth.size() == skinMask.size());
    const int width = depth.cols;
    const int height = depth.rows;
    const auto radiusWorld = static_cast<float>(geometry.supportRadiusWorld);

    ErrorBands bands;
    // 0.5 splits an anti-aliased mask at half coverage, so a pixel counts as skin when skin covers most of it.
    bands.skin = skinMask >= 0.5f;
    bands.projectedRadius = cv::Mat::zeros(height, width, CV_32FC1);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            float d = depth.at<float>(y, x);
            if (validDepth(d))
                bands.projectedRadius.at<float>(y, x) =
                    static_cast<float>(geometry.supportRadiusWorld * geometry.focalLengthPixels / d);
        }

    // Edges between 4-neighbours p and q. A jump to or from the background (depth +inf) is a depth edge.
    bands.depthEdges = cv::Mat::zeros(height, width, CV_8UC1);
    bands.materialEdges = cv::Mat::zeros(height, width, CV_8UC1);
    auto classifyPair = [&](int y0, int x0, int y1, int x1) {
        float d0 = depth.at<float>(y0, x0);
        float d1 = depth.at<float>(y1, x1);
        bool valid0 = validDepth(d0);
        bool valid1 = validDepth(d1);
        if (!valid0 && !valid1) return; // background next to background
        bool jump = valid0 != valid1 || std::fabs(d0 - d1) > radiusWorld;
        if (jump) {
            bands.depthEdges.at<uint8_t>(y0, x0) = 255;
            bands.depthEdges.at<uint8_t>(y1, x1) = 255;
        } else if (bands.skin.at<uint8_t>(y0, x0) != bands.skin.at<uint8_t>(y1, x1)) {
            bands.materialEdges.at<uint8_t>(y0, x0) = 255;
            bands.materialEdges.at<uint8_t>(y1, x1) = 255;
        }
    };
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            if (x + 1 < width) classifyPair(y, x, y, x + 1);
            if (y + 1 < height) classifyPair(y, x, y + 1, x);
        }

    DistanceField toDepthEdge = euclideanDistanceTransform(bands.depthEdges);
    DistanceField toMaterialEdge = euclideanDistanceTransform(bands.materialEdges);
    DistanceField toSkin = euclideanDistanceTransform(bands.skin);

    for (auto& m : bands.masks) m = cv::Mat::zeros(height, width, CV_8UC1);
    const auto* radius = bands.projectedRadius.ptr<float>();
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            float rho = bands.projectedRadius.at<float>(y, x);
            if (bands.skin.at<uint8_t>(y, x)) {
                float depthEdgeDistance = toDepthEdge.distance.at<float>(y, x) + halfPixel;
                float materialEdgeDistance = toMaterialEdge.distance.at<float>(y, x) + halfPixel;
                if (depthEdgeDistance <= rho) bands.masks[size_t(Band::halo)].at<uint8_t>(y, x) = 255;
                else if (materialEdgeDistance <= rho) bands.masks[size_t(Band::bleed)].at<uint8_t>(y, x) = 255;
                else if (depthEdgeDistance > 2.0f * rho && materialEdgeDistance > 2.0f * rho)
                    bands.masks[size_t(Band::interior)].at<uint8_t>(y, x) = 255;
            } else {
                // Spill: the non-skin pixel's own depth may be the background's +inf, so ρ is taken at the
                // nearest skin pixel, the one whose kernel could reach it.
                int nearestSkin = toSkin.nearest.at<int>(y, x);
                if (nearestSkin < 0) continue;
                float skinDistance = toSkin.distance.at<float>(y, x) - halfPixel;
                if (skinDistance <= radius[nearestSkin]) bands.masks[size_t(Band::spill)].at<uint8_t>(y, x) = 255;
            }
        }
    return bands;
}

} // namespace skinlab::metrics
