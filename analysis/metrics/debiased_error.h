#pragma once
// Scores against a noisy ground truth without its noise: several path-traced renders of the same scene with
// independent seeds r_1 … r_S (S ≥ 2) stand for the noise-free image r̄. For a test render a and a region B,
//
//     MSE(a) = mean over pairs i < j of  (1/|B|) Σ_{p∈B} (a_p − r_i,p) · (a_p − r_j,p)
//
// is an unbiased estimate of (1/|B|) Σ (a_p − r̄_p)²: the cross terms of two independent noises vanish in
// expectation, where the plain MSE against one noisy image adds the noise variance to every condition. The
// uncertainty comes from a leave-one-seed-out jackknife (S ≥ 3; S ≥ 4 recommended), and a paired difference
// D = MSE(a) − MSE(b) uses the same seeds on both sides, so the noise they share cancels (docs/metrics.md,
// "Scoring against a path-traced truth"). Values are linear luminance Y (Rec. 709) × exposure, as the leak energy.
#include "analysis/metrics/error_bands.h"
#include "analysis/metrics/metric_render.h"

#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace skinlab::metrics {

// The regions scored: the four bands of docs/metrics.md, the skin and the whole image.
inline constexpr std::size_t debiasedRegionCount = 6;
std::string_view debiasedRegionName(std::size_t region); // halo, bleed, spill, interior, skin, image

// An estimate with its leave-one-seed-out jackknife standard error (NaN with two seeds).
struct JackknifeEstimate {
    double value = 0.0;
    double standardError = 0.0;
    std::vector<double> leaveOneOut; // the estimate without seed k, k = 0 … S−1 (empty with two seeds)
};

// The S seeded renders of one scene, with the regions (from the first seed's depth and mask: the geometry is
// the same in every seed) and each seed's luminance.
struct SeededTruth {
    std::vector<std::filesystem::path> paths;
    ErrorBands bands;
    std::array<cv::Mat, debiasedRegionCount> regions; // CV_8UC1 255 inside
    std::vector<cv::Mat> luminance;                   // CV_64FC1 per seed
    double meanSkinLuminance = 0.0;                   // over seeds and skin pixels (0 without skin)
    double exposure = 1.0;
};

// Reads and checks the seeds: at least two, equal sizes, the first with skinlab's depth, mask and metadata (a
// reference role). `sssRadiusMillimetres` overrides the first seed's skinlab:sss_radius_mm when positive.
// InputError names the file at fault.
SeededTruth loadSeededTruth(const std::vector<std::filesystem::path>& seeds, double exposure,
                            double sssRadiusMillimetres);

// Linear luminance × exposure of a render's beauty (CV_64FC1; non-finite values become 0).
cv::Mat renderLuminance(const MetricRender& render, double exposure);

struct DebiasedScores {
    std::filesystem::path test;
    std::array<std::size_t, debiasedRegionCount> pixels{};
    std::array<JackknifeEstimate, debiasedRegionCount> mse; // unbiased squared error against r̄ (Y², may be < 0)
    // Plain MSE against the first seed alone (what one noisy reference gives), for comparison.
    std::array<double, debiasedRegionCount> plainMse{};
};

// Scores one test luminance image (same size as the truth) in every region.
DebiasedScores scoreDebiased(const SeededTruth& truth, const cv::Mat& testLuminance,
                             const std::filesystem::path& testPath);

// D = MSE(a) − MSE(b) with the jackknife over the seeds both share.
JackknifeEstimate debiasedDifference(const DebiasedScores& a, const DebiasedScores& b, std::size_t region);

// Kendall's τ_b between two score vectors of equal length (ties in either count as in τ_b; NaN if undefined).
double kendallTauB(const std::vector<double>& x, const std::vector<double>& y);

// How a ranking of the tests by another score (e.g. the MSE against the object-space reference) agrees with the
// ranking by the debiased MSE against the path-traced truth, in one region.
struct RankingAgreement {
    std::size_t conditions = 0;
    JackknifeEstimate tau;          // τ_b over all pairs; jackknife over the seeds
    std::size_t separatedPairs = 0; // pairs whose debiased difference is > 1.96 standard errors from 0
    std::size_t concordantSeparated = 0;
    double tauSeparated = 0.0; // (concordant − discordant) / separated over the separated pairs; NaN if none
};

RankingAgreement rankingAgreement(const std::vector<DebiasedScores>& scores, const std::vector<double>& otherScore,
                                  std::size_t region);

// `skinlab analyze metrics --reference-seeds`: every test scored against the seeded truth; with a compared
// reference (the object-space `reference` render of the same scene) also each test's paired difference from it
// and the agreement of the rankings under the two truths. Checks every input before writing
// OUTPUT/debiased.csv and OUTPUT/debiased.json (last), atomically.
struct DebiasedRunOptions {
    double exposure = 1.0;
    double sssRadiusMillimetres = 0.0;      // > 0 overrides the first seed's skinlab:sss_radius_mm
    std::filesystem::path compareReference; // empty: none
};

struct DebiasedRun {
    SeededTruth truth;
    std::vector<DebiasedScores> tests;
    std::optional<DebiasedScores> compared;                           // the compared reference's own scores
    std::vector<std::array<double, debiasedRegionCount>> comparedMse; // per test: plain MSE against it
    std::array<RankingAgreement, debiasedRegionCount> agreement{};
};

DebiasedRun runDebiasedMetrics(const std::vector<std::filesystem::path>& seeds,
                               const std::vector<std::filesystem::path>& tests, const DebiasedRunOptions& options,
                               const std::filesystem::path& outputFolder);

} // namespace skinlab::metrics
