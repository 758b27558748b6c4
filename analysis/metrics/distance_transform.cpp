#include "analysis/metrics/distance_transform.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace skinlab::metrics {
namespace {

// Stands in for "no feature" in the squared-distance input: finite, so the envelope arithmetic never forms
// inf − inf, and far above any squared distance inside an image (< 2·65536²).
constexpr double noFeature = 1e20;

// 1-D squared distance transform of f (length n): out[q] = min_p (q − p)² + f[p], argOut[q] = the minimising p.
// `vertices` (n) and `boundaries` (n + 1) are scratch space.
void squaredDistance1d(const double* f, int n, double* out, int* argOut, std::vector<int>& vertices,
                       std::vector<double>& boundaries) {
    int k = 0;
    vertices[0] = 0;
    boundaries[0] = -std::numeric_limits<double>::infinity();
    boundaries[1] = std::numeric_limits<double>::infinity();
    for (int q = 1; q < n; ++q) {
        // Abscissa where the parabola rooted at q overtakes the one rooted at v; boundaries[0] = −inf ends the loop.
        auto crossing = [&](int v) { return ((f[q] + double(q) * q) - (f[v] + double(v) * v)) / (2.0 * q - 2.0 * v); };
        double s = crossing(vertices[static_cast<size_t>(k)]);
        while (s <= boundaries[static_cast<size_t>(k)]) {
            --k;
            s = crossing(vertices[static_cast<size_t>(k)]);
        }
        ++k;
        vertices[static_cast<size_t>(k)] = q;
        boundaries[static_cast<size_t>(k)] = s;
        boundaries[static_cast<size_t>(k) + 1] = std::numeric_limits<double>::infinity();
    }
    k = 0;
    for (int q = 0; q < n; ++q) {
        while (boundaries[static_cast<size_t>(k) + 1] < q) ++k;
        int v = vertices[static_cast<size_t>(k)];
        out[q] = double(q - v) * (q - v) + f[v];
        argOut[q] = v;
    }
}

} // namespace

DistanceField euclideanDistanceTransform(const cv::Mat& features) {
    CV_Assert(features.type() == CV_8UC1);
    const int width = features.cols;
    const int height = features.rows;
    const int longest = std::max(width, height);
    std::vector<int> vertices(static_cast<size_t>(longest));
    std::vector<double> boundaries(static_cast<size_t>(longest) + 1);
    std::vector<double> input(static_cast<size_t>(longest));
    std::vector<double> output(static_cast<size_t>(longest));
    std::vector<int> argument(static_cast<size_t>(longest));

    // Pass 1, columns: squared distance to the nearest feature in the same column, and that feature's row.
    std::vector<double> columnDistance(static_cast<size_t>(width) * static_cast<size_t>(height));
    std::vector<int> columnRow(columnDistance.size());
    for (int x = 0; x < width; ++x) {
        for (int y = 0; y < height; ++y) input[static_cast<size_t>(y)] = features.at<uint8_t>(y, x) ? 0.0 : noFeature;
        squaredDistance1d(input.data(), height, output.data(), argument.data(), vertices, boundaries);
        for (int y = 0; y < height; ++y) {
            size_t index = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
            columnDistance[index] = output[static_cast<size_t>(y)];
            columnRow[index] = argument[static_cast<size_t>(y)];
        }
    }

    // Pass 2, rows: combine the column results.
    DistanceField field;
    field.distance.create(height, width, CV_32FC1);
    field.nearest.create(height, width, CV_32SC1);
    for (int y = 0; y < height; ++y) {
        size_t row = static_cast<size_t>(y) * static_cast<size_t>(width);
        squaredDistance1d(columnDistance.data() + row, width, output.data(), argument.data(), vertices, boundaries);
        auto* distanceRow = field.distance.ptr<float>(y);
        auto* nearestRow = field.nearest.ptr<int>(y);
        for (int x = 0; x < width; ++x) {
            double squared = output[static_cast<size_t>(x)];
            if (squared >= 0.5 * noFeature) {
                distanceRow[x] = std::numeric_limits<float>::infinity();
                nearestRow[x] = -1;
            } else {
                int featureX = argument[static_cast<size_t>(x)];
                distanceRow[x] = static_cast<float>(std::sqrt(squared));
                nearestRow[x] = columnRow[row + static_cast<size_t>(featureX)] * width + featureX;
            }
        }
    }
    return field;
}

} // namespace skinlab::metrics
