#pragma once
// LDR-FLIP, own implementation of P. Andersson, J. Nilsson, T. Akenine-Möller, M. Oskarsson, K. Åström,
// M. D. Fairchild, "FLIP: A Difference Evaluator for Alternating Images", Proc. ACM Comput. Graph. Interact. Tech.
// 3(2), article 15, 2020 (docs/metrics.md, "FLIP"). Per pixel: a colour difference of the two images after
// spatial filtering with contrast sensitivity functions in YCxCz (HyAB distance of Hunt-adjusted CIELAB, remapped
// to [0, 1]), raised to the power 1 − ΔE_f, where ΔE_f compares edges and points of the unfiltered achromatic
// channels. 0 for identical images, at most 1.
#include <opencv2/core.hpp>

namespace skinlab::metrics {

// The paper's viewing set-up: 0.7 m from a 0.7 m wide monitor with 3840 pixels across,
// PPD = 0.7 · (3840 / 0.7) · π / 180.
inline constexpr double flipDefaultPixelsPerDegree = 67.02064327658226;

// Pixels per degree of a viewing set-up: distance · (horizontal resolution / monitor width) · π / 180 (both
// lengths in the same unit).
double pixelsPerDegree(double distance, double horizontalPixels, double monitorWidth);

// Per-pixel FLIP (CV_64FC1) of two linear Rec.709 RGB images (CV_32FC3 or CV_64FC3, channels R, G, B, same size).
// Each channel is multiplied by `exposure` and clamped to [0, 1] first (non-finite values: +inf → 1, others → 0).
// Filters use clamp-to-edge borders. Throws std::invalid_argument for a non-positive `pixelsPerDegree`.
cv::Mat flipErrorMap(const cv::Mat& referenceLinear, const cv::Mat& testLinear, double pixelsPerDegree,
                     double exposure = 1.0);

// Mean of a FLIP map over `mask` (CV_8UC1, non-zero selects; everywhere when empty), summed in double; NaN when
// the mask selects nothing.
double flipMean(const cv::Mat& flipMap, const cv::Mat& mask = {});

// c_max = HyAB(Hunt(Lab(green)), Hunt(Lab(blue)))^0.7, the largest colour difference the remapping assumes
// (≈ 41.2761).
double flipMaximumColourDifference();

} // namespace skinlab::metrics
