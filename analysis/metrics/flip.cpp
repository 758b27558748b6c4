#include "analysis/metrics/flip.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace skinlab::metrics {
namespace {

constexpr double pi = std::numbers::pi;

// Linear sRGB → XYZ (D65): the IEC 61966-2-1 matrix in exact rational form (from the primaries' chromaticities);
// its inverse is computed once.
constexpr double rgbToXyz[3][3] = {{10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0},
                                   {2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0},
                                   {1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0}};
// The D65 white of the matrix above (its image of RGB (1, 1, 1)).
constexpr double whiteX = 0.950428545, whiteY = 1.0, whiteZ = 1.088900371;

// Perceptual exponents and remapping constants of the paper (§4).
constexpr double colourExponent = 0.7;              // q_c
constexpr double featureExponent = 0.5;             // q_f
constexpr double remapBreak = 0.4;                  // p_c
constexpr double remapTarget = 0.95;                // p_t
constexpr double featureSigmaDegrees = 0.5 * 0.082; // σ of the feature detectors: half the 0.082° peak spacing

struct Vec3 {
    double v[3];
};

struct Matrix3 {
    double m[3][3];
};

Matrix3 invert(const double a[3][3]) {
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                 a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    Matrix3 r{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            // Cofactor of a[j][i] (the adjugate is the transposed cofactor matrix).
            int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
            r.m[i][j] = (a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]) / det;
        }
    return r;
}

const Matrix3& xyzToRgb() {
    static const Matrix3 inverse = invert(rgbToXyz);
    return inverse;
}

Vec3 multiply(const double m[3][3], const Vec3& x) {
    return {{m[0][0] * x.v[0] + m[0][1] * x.v[1] + m[0][2] * x.v[2],
             m[1][0] * x.v[0] + m[1][1] * x.v[1] + m[1][2] * x.v[2],
             m[2][0] * x.v[0] + m[2][1] * x.v[1] + m[2][2] * x.v[2]}};
}

double labCompand(double t) {
    constexpr double delta = 6.0 / 29.0;
    return t > delta * delta * delta ? std::cbrt(t) : t / (3.0 * delta * delta) + 4.0 / 29.0;
}

// Linear RGB (already clamped) → CIELAB (D65) → Hunt-adjusted (L, 0.01·L·a, 0.01·L·b).
Vec3 huntLab(const Vec3& rgb) {
    Vec3 xyz = multiply(rgbToXyz, rgb);
    double fx = labCompand(xyz.v[0] / whiteX), fy = labCompand(xyz.v[1] / whiteY), fz = labCompand(xyz.v[2] / whiteZ);
    double lightness = 116.0 * fy - 16.0;
    double a = 500.0 * (fx - fy), b = 200.0 * (fy - fz);
    return {{lightness, 0.01 * lightness * a, 0.01 * lightness * b}};
}

double hyab(const Vec3& first, const Vec3& second) {
    double da = first.v[1] - second.v[1], db = first.v[2] - second.v[2];
    return std::fabs(first.v[0] - second.v[0]) + std::sqrt(da * da + db * db);
}

double clampUnit(double value) {
    if (!std::isfinite(value)) return value > 0.0 ? 1.0 : 0.0;
    return std::clamp(value, 0.0, 1.0);
}

// Linear RGB × exposure, clamped → YCxCz planes (CV_64FC1 each): Y' = 116·Y/Yw − 16, Cx = 500(X/Xw − Y/Yw),
// Cz = 200(Y/Yw − Z/Zw).
std::array<cv::Mat, 3> toYCxCz(const cv::Mat& linear, double exposure) {
    cv::Mat input;
    linear.convertTo(input, CV_64FC3);
    std::array<cv::Mat, 3> planes;
    for (auto& plane : planes) plane.create(input.size(), CV_64FC1);
    for (int y = 0; y < input.rows; ++y) {
        const auto* in = input.ptr<cv::Vec3d>(y);
        double* out[3] = {planes[0].ptr<double>(y), planes[1].ptr<double>(y), planes[2].ptr<double>(y)};
        for (int x = 0; x < input.cols; ++x) {
            Vec3 rgb{{clampUnit(in[x][0] * exposure), clampUnit(in[x][1] * exposure), clampUnit(in[x][2] * exposure)}};
            Vec3 xyz = multiply(rgbToXyz, rgb);
            double nx = xyz.v[0] / whiteX, ny = xyz.v[1] / whiteY, nz = xyz.v[2] / whiteZ;
            out[0][x] = 116.0 * ny - 16.0;
            out[1][x] = 500.0 * (nx - ny);
            out[2][x] = 200.0 * (ny - nz);
        }
    }
    return planes;
}

// One Gaussian term a·√(π/b)·exp(−π²x²/b) of a contrast sensitivity function, sampled at x = i / PPD degrees.
struct CsfTerm {
    double a, b;
};

// The separable CSF filter of one channel: Σ_k w_k · (g_k ⊗ g_k) with each g_k normalised to unit sum and
// weights making the whole 2-D kernel sum to 1 (the same as normalising the 2-D kernel Σ_k a_k√(π/b_k)
// exp(−π²(x²+y²)/b_k)).
cv::Mat filterCsf(const cv::Mat& plane, const std::vector<CsfTerm>& terms, int radius, double ppd) {
    std::vector<cv::Mat> kernels;
    std::vector<double> weights;
    double total = 0.0;
    for (const CsfTerm& term : terms) {
        cv::Mat kernel(2 * radius + 1, 1, CV_64FC1);
        double sum = 0.0;
        for (int i = -radius; i <= radius; ++i) {
            double x = i / ppd;
            double value = std::exp(-pi * pi * x * x / term.b);
            kernel.at<double>(i + radius) = value;
            sum += value;
        }
        kernel /= sum;
        double weight = term.a * std::sqrt(pi / term.b) * sum * sum;
        kernels.push_back(kernel);
        weights.push_back(weight);
        total += weight;
    }
    cv::Mat result = cv::Mat::zeros(plane.size(), CV_64FC1);
    for (std::size_t k = 0; k < kernels.size(); ++k) {
        cv::Mat filtered;
        cv::sepFilter2D(plane, filtered, CV_64F, kernels[k], kernels[k], cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
        result += filtered * (weights[k] / total);
    }
    return result;
}

// Filtered YCxCz → linear RGB clamped to [0, 1] → Hunt-adjusted CIELAB (CV_64FC3).
cv::Mat filteredHuntLab(const std::array<cv::Mat, 3>& planes) {
    cv::Mat out(planes[0].size(), CV_64FC3);
    for (int y = 0; y < out.rows; ++y) {
        const double* in[3] = {planes[0].ptr<double>(y), planes[1].ptr<double>(y), planes[2].ptr<double>(y)};
        auto* row = out.ptr<cv::Vec3d>(y);
        for (int x = 0; x < out.cols; ++x) {
            double ny = (in[0][x] + 16.0) / 116.0;
            double nx = in[1][x] / 500.0 + ny;
            double nz = ny - in[2][x] / 200.0;
            Vec3 rgb = multiply(xyzToRgb().m, Vec3{{nx * whiteX, ny * whiteY, nz * whiteZ}});
            for (double& c : rgb.v) c = clampUnit(c);
            Vec3 lab = huntLab(rgb);
            row[x] = {lab.v[0], lab.v[1], lab.v[2]};
        }
    }
    return out;
}

// Edge (first derivative) and point (second derivative) detectors of the Gaussian with σ in pixels, each
// normalised so that its positive weights sum to +1 and its negative weights to −1, and the Gaussian itself
// (unit sum) for the other axis.
struct FeatureKernels {
    cv::Mat gaussian, edge, point;
};

FeatureKernels featureKernels(double sigma) {
    int radius = static_cast<int>(std::ceil(3.0 * sigma));
    FeatureKernels k;
    k.gaussian.create(2 * radius + 1, 1, CV_64FC1);
    k.edge.create(2 * radius + 1, 1, CV_64FC1);
    k.point.create(2 * radius + 1, 1, CV_64FC1);
    double gaussianSum = 0.0;
    double edgePositive = 0.0, edgeNegative = 0.0, pointPositive = 0.0, pointNegative = 0.0;
    for (int i = -radius; i <= radius; ++i) {
        double x = i;
        double g = std::exp(-x * x / (2.0 * sigma * sigma));
        double edge = -x * g;                               // ∝ dg/dx
        double point = (x * x / (sigma * sigma) - 1.0) * g; // ∝ d²g/dx²
        k.gaussian.at<double>(i + radius) = g;
        k.edge.at<double>(i + radius) = edge;
        k.point.at<double>(i + radius) = point;
        gaussianSum += g;
        (edge > 0 ? edgePositive : edgeNegative) += edge;
        (point > 0 ? pointPositive : pointNegative) += point;
    }
    k.gaussian /= gaussianSum;
    for (int i = 0; i < k.edge.rows; ++i) {
        double& e = k.edge.at<double>(i);
        e = e > 0 ? e / edgePositive : e / -edgeNegative;
        double& p = k.point.at<double>(i);
        p = p > 0 ? p / pointPositive : p / -pointNegative;
    }
    return k;
}

struct Features {
    cv::Mat edge, point; // magnitudes, CV_64FC1
};

Features detectFeatures(const cv::Mat& achromatic, const FeatureKernels& k) {
    auto magnitude = [&](const cv::Mat& derivative) {
        cv::Mat alongX, alongY;
        cv::sepFilter2D(achromatic, alongX, CV_64F, derivative, k.gaussian, cv::Point(-1, -1), 0.0,
                        cv::BORDER_REPLICATE);
        cv::sepFilter2D(achromatic, alongY, CV_64F, k.gaussian, derivative, cv::Point(-1, -1), 0.0,
                        cv::BORDER_REPLICATE);
        cv::Mat result;
        cv::magnitude(alongX, alongY, result);
        return result;
    };
    return {magnitude(k.edge), magnitude(k.point)};
}

double remapColourDifference(double difference, double maximum) {
    double knee = remapBreak * maximum;
    if (difference < knee) return difference * remapTarget / knee;
    return remapTarget + (difference - knee) / (maximum - knee) * (1.0 - remapTarget);
}

} // namespace

double pixelsPerDegree(double distance, double horizontalPixels, double monitorWidth) {
    return distance * (horizontalPixels / monitorWidth) * pi / 180.0;
}

double flipMaximumColourDifference() {
    return std::pow(hyab(huntLab({{0.0, 1.0, 0.0}}), huntLab({{0.0, 0.0, 1.0}})), colourExponent);
}

cv::Mat flipErrorMap(const cv::Mat& referenceLinear, const cv::Mat& testLinear, double ppd, double exposure) {
    CV_Assert(referenceLinear.size() == testLinear.size() && referenceLinear.channels() == 3 &&
              testLinear.channels() == 3);
    if (!(ppd > 0.0) || !std::isfinite(ppd))
        throw std::invalid_argument("flipErrorMap(): pixels per degree must be a positive number");

    // Contrast sensitivity functions (paper, Eq. 2 and Table 1), one radius for all three channels: three standard
    // deviations of the widest Gaussian (b = 0.04), in pixels.
    const int radius = static_cast<int>(std::ceil(3.0 * std::sqrt(0.04 / (2.0 * pi * pi)) * ppd));
    const std::vector<CsfTerm> achromatic{{1.0, 0.0047}};
    const std::vector<CsfTerm> redGreen{{1.0, 0.0053}};
    const std::vector<CsfTerm> blueYellow{{34.1, 0.04}, {13.5, 0.025}};
    const double maximum = flipMaximumColourDifference();
    const FeatureKernels kernels = featureKernels(featureSigmaDegrees * ppd);

    auto prepare = [&](const cv::Mat& linear, cv::Mat& lab, Features& features) {
        std::array<cv::Mat, 3> planes = toYCxCz(linear, exposure);
        cv::Mat luminance = (planes[0] + 16.0) / 116.0; // normalised achromatic y, unfiltered
        features = detectFeatures(luminance, kernels);
        std::array<cv::Mat, 3> filtered = {filterCsf(planes[0], achromatic, radius, ppd),
                                           filterCsf(planes[1], redGreen, radius, ppd),
                                           filterCsf(planes[2], blueYellow, radius, ppd)};
        lab = filteredHuntLab(filtered);
    };
    cv::Mat labReference, labTest;
    Features featuresReference, featuresTest;
    prepare(referenceLinear, labReference, featuresReference);
    prepare(testLinear, labTest, featuresTest);

    cv::Mat map(referenceLinear.size(), CV_64FC1);
    const double inverseSqrt2 = 1.0 / std::sqrt(2.0);
    for (int y = 0; y < map.rows; ++y) {
        const auto* r = labReference.ptr<cv::Vec3d>(y);
        const auto* t = labTest.ptr<cv::Vec3d>(y);
        const double* er = featuresReference.edge.ptr<double>(y);
        const double* et = featuresTest.edge.ptr<double>(y);
        const double* pr = featuresReference.point.ptr<double>(y);
        const double* pt = featuresTest.point.ptr<double>(y);
        double* out = map.ptr<double>(y);
        for (int x = 0; x < map.cols; ++x) {
            double colour =
                std::pow(hyab({{r[x][0], r[x][1], r[x][2]}}, {{t[x][0], t[x][1], t[x][2]}}), colourExponent);
            double colourError = remapColourDifference(colour, maximum);
            double featureDifference = std::max(std::fabs(er[x] - et[x]), std::fabs(pr[x] - pt[x]));
            double featureError = std::pow(inverseSqrt2 * featureDifference, featureExponent);
            out[x] = std::pow(colourError, 1.0 - featureError);
        }
    }
    return map;
}

double flipMean(const cv::Mat& flipMap, const cv::Mat& mask) {
    double sum = 0.0;
    std::size_t count = 0;
    for (int y = 0; y < flipMap.rows; ++y) {
        const double* row = flipMap.ptr<double>(y);
        const std::uint8_t* selected = mask.empty() ? nullptr : mask.ptr<std::uint8_t>(y);
        for (int x = 0; x < flipMap.cols; ++x)
            if (!selected || selected[x]) {
                sum += row[x];
                ++count;
            }
    }
    return count ? sum / static_cast<double>(count) : std::numeric_limits<double>::quiet_NaN();
}

} // namespace skinlab::metrics
