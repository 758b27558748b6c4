#pragma once
// Figures of a scaled block, drawn with OpenCV primitives (8-bit BGR images, saved as PNG):
//  - scores: each condition's JOD score with its 95 % interval (error bar), conditions in input order;
//  - preference matrix: heat map of P(row chosen over column) = D_ij / (D_ij + D_ji), diverging
//    blue (0 %) – white (50 %) – red (100 %), grey where the pair was never compared, counts in each cell.
#include "analysis/scaling/scale_analysis.h"

#include <opencv2/core.hpp>

#include <string>

namespace skinlab::analysis::scaling {

cv::Mat plotScores(const BlockAnalysis& block);
cv::Mat plotPreferenceMatrix(const BlockAnalysis& block);
std::string encodePng(const cv::Mat& image); // PNG bytes

} // namespace skinlab::analysis::scaling
