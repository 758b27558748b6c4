#pragma once
// PSNR and SSIM through OpenCV's quality module (opencv_contrib), with its traps handled (docs/metrics.md):
// QualitySSIM hard-codes C1 = (0.01·255)² = 6.5025 and C2 = (0.03·255)² = 58.5225, so its inputs must be on a
// 0–255 scale; QualityPSNR's default peak is 255. Both functions here take CV_64F images in [0, 255].
#include <opencv2/core.hpp>

namespace skinlab::metrics {

// PSNR in dB over every sample of every channel (the MSE pooled over channels, peak 255), restricted to the
// pixels where `mask` (CV_8UC1) is non-zero, or everywhere when `mask` is empty. +inf when the images agree;
// NaN when the mask selects nothing.
double peakSignalToNoiseRatio(const cv::Mat& reference, const cv::Mat& test, const cv::Mat& mask = {});

// Per-pixel SSIM map (Wang et al. 2004; OpenCV's 11×11 Gaussian window, σ = 1.5), averaged over the channels:
// CV_64FC1.
cv::Mat structuralSimilarityMap(const cv::Mat& reference, const cv::Mat& test);

// Mean of the SSIM map over `mask` (everywhere when empty); NaN when the mask selects nothing.
double structuralSimilarity(const cv::Mat& ssimMap, const cv::Mat& mask = {});

} // namespace skinlab::metrics
