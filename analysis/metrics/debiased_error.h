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
// "Scoring against a path-traced truth"). Values are linear luminance Y (Rec. 709) × exposure, as the leak energy,
// and beside it each linear channel R, G, B × exposure and CIELAB (the display encoding of ΔE00, so that the squared
// error is ΔE*ab²; the cross terms of CIELAB's noise vanish only to first order, since CIELAB is not linear).
#include "analysis/metrics/error_bands.h"
#include "analysis/metrics/metric_render.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace skinlab::metrics {

// The regions scored: the four bands of docs/metrics.md, the skin and the whole image.
inline constexpr std::size_t debiasedRegionCount = 6;
std::string_view debiasedRegionName(std::size_t region); // halo, bleed, spill, interior, skin, image

// The quantities scored: Y (the default), R, G, B (linear × exposure) and CIELAB (ΔE*ab², the display encoding
// of docs/metrics.md).
inline constexpr std::size_t debiasedQuantityCount = 5;
std::string_view debiasedQuantityName(std::size_t quantity); // Y, R, G, B, Lab

// One image per quantity: CV_64FC1 for Y, R, G, B; CV_64FC3 for CIELAB. An empty Mat: the quantity is not scored.
using DebiasedImages = std::array<cv::Mat, debiasedQuantityCount>;

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
    std::vector<DebiasedImages> images;               // per seed, every quantity (images[k][0] is luminance[k])
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

// Every quantity of a render's beauty (non-finite values become 0).
DebiasedImages renderQuantities(const MetricRender& render, double exposure);

struct DebiasedScores {
    std::filesystem::path test;
    std::array<std::size_t, debiasedRegionCount> pixels{};
    std::array<JackknifeEstimate, debiasedRegionCount> mse; // unbiased squared error against r̄ (Y², may be < 0)
    // Plain MSE against the first seed alone (what one noisy reference gives), for comparison.
    std::array<double, debiasedRegionCount> plainMse{};
    std::size_t seeds = 0;
    // Per quantity and region: the pair terms P_ij = (1/|B|) Σ_{p∈B} (a_p − r_i,p)·(a_p − r_j,p) over the pairs
    // i < j in the order (0,1), (0,2) … (S−2,S−1) (empty where the quantity was not scored), and the estimate
    // from them, the mean of P; quantity 0 (Y) equals `mse` and `plainMse`.
    std::array<std::array<std::vector<double>, debiasedRegionCount>, debiasedQuantityCount> pairTerms;
    std::array<std::array<JackknifeEstimate, debiasedRegionCount>, debiasedQuantityCount> quantityMse;
    std::array<std::array<double, debiasedRegionCount>, debiasedQuantityCount> quantityPlainMse{};
};

// Scores one test luminance image (same size as the truth) in every region: Y only.
DebiasedScores scoreDebiased(const SeededTruth& truth, const cv::Mat& testLuminance,
                             const std::filesystem::path& testPath);
// Scores every quantity the test and the truth both have.
DebiasedScores scoreDebiased(const SeededTruth& truth, const DebiasedImages& test,
                             const std::filesystem::path& testPath);

// The estimate from pair terms over a draw of seeds (indices < seeds, repeats allowed): the mean of P_ij over the
// pairs of draws a < b whose seeds differ (a resampled U-statistic; NaN if no two draws differ). The draw 0 … S−1
// gives the estimate itself; all seeds but k its leave-one-out value.
double pairTermMean(const std::vector<double>& pairTerms, std::size_t seeds, const std::vector<std::size_t>& draw);

// The precision of the seeds' mean as a truth (`skinlab analyze seed-mean`): its squared error against the noise-free
// image in one quantity and region, σ̄²/S, with σ̄² the per-pixel noise variance of one seed estimated from the
// pairs, the mean over i < j of ½ (1/|B|) Σ_{p∈B} (r_i,p − r_j,p)² (unbiased: independent seeds differ by twice the
// variance); the jackknife leaves one seed out of σ̄². NaN where the quantity or the region is empty.
JackknifeEstimate seedMeanMse(const SeededTruth& truth, std::size_t quantity, std::size_t region);

// A truth is precise enough for the differences it ranks when its squared error against the noise-free image is at
// most this share of the best condition's.
inline constexpr double truthPrecisionRatio = 0.5;

// D = MSE(a) − MSE(b) with the jackknife over the seeds both share.
JackknifeEstimate debiasedDifference(const DebiasedScores& a, const DebiasedScores& b, std::size_t region);

// Kendall's τ_b between two score vectors of equal length (ties in either count as in τ_b; NaN if undefined).
double kendallTauB(const std::vector<double>& x, const std::vector<double>& y);

// What the path-traced truth ranks the tests by: the debiased squared error of one quantity in one region, or the
// excess of a band over the interior, √MSE(band) − √MSE(interior) (negative MSEs count as 0), the counterpart of
// the ΔE00 excess (band mean − interior mean) of docs/metrics.md.
enum class TruthKind { mse, rmsExcess };
struct TruthScore {
    std::size_t region = 4;
    std::size_t quantity = 0;
    TruthKind kind = TruthKind::mse;
};

// The truth score of one test from the seeds in `draw` (all seeds when null).
double truthScore(const DebiasedScores& scores, const TruthScore& truth, const std::vector<std::size_t>* draw);

struct AgreementOptions {
    double level = 0.95; // of every interval
    std::size_t bootstrapReplicates = 2000;
    std::uint64_t bootstrapSeed = 41;  // the bootstrap's draws are reproducible
    std::size_t competitiveCount = 16; // the competitive conditions: this many closest to the truth
};

// How a ranking of the tests by another score (e.g. the MSE against the object-space reference) agrees with the
// ranking by the truth score against the path-traced truth, over a subset of the tests.
struct RankingAgreement {
    std::size_t conditions = 0;                // in the subset
    std::vector<std::size_t> members;          // the subset's indices into the tests
    JackknifeEstimate tau;                     // τ_b over all pairs of the subset; leave-one-seed-out jackknife
    double tQuantile = 0.0;                    // t_{(1+level)/2} with S − 1 degrees of freedom (NaN with two seeds)
    std::array<double, 2> jackknifeInterval{}; // τ_b ± t·SE, clipped to [−1, 1]
    // Percentile interval of τ_b over bootstrap replicates that resample the subset's conditions and the seeds
    // (each with replacement; NaN with fewer than three conditions).
    std::array<double, 2> bootstrapInterval{};
    std::size_t separatedPairs = 0; // pairs whose truth-score difference is > t standard errors from 0
    std::size_t concordantSeparated = 0;
    double tauSeparated = 0.0; // (concordant − discordant) / separated over the separated pairs; NaN if none
};

// Over all tests, Y's debiased MSE in `region`, with the default options.
RankingAgreement rankingAgreement(const std::vector<DebiasedScores>& scores, const std::vector<double>& otherScore,
                                  std::size_t region);
RankingAgreement rankingAgreement(const std::vector<DebiasedScores>& scores, const std::vector<double>& otherScore,
                                  const TruthScore& truth, const std::vector<std::size_t>& members,
                                  const AgreementOptions& options);

// The agreement over all tests, over the competitive ones (the `competitiveCount` smallest truth scores) and over
// all but the clearly worse (truth score above Tukey's upper fence Q3 + 1.5·IQR of all the tests' truth scores).
struct AgreementSubsets {
    RankingAgreement all;
    RankingAgreement competitive;
    RankingAgreement withoutClearlyWorse;
    double clearlyWorseFence = 0.0;
};
AgreementSubsets agreementSubsets(const std::vector<DebiasedScores>& scores, const std::vector<double>& otherScore,
                                  const TruthScore& truth, const AgreementOptions& options);

// A score of the evaluation table (`skinlab analyze metrics --reference`, metrics.json) and the truth score it is
// checked against: the band's debiased squared error of Y for leak energies, of CIELAB for ΔE00 means, and the
// CIELAB rms excess for ΔE00 excesses.
struct TableScore {
    std::string name;   // e.g. halo_leak_energy
    std::string region; // metrics.json: "skin" or a band
    std::string key;    // metrics.json: leak_energy, excess, delta_e00_mean
    TruthScore truth;
};
const std::vector<TableScore>& tableScores();

// `skinlab analyze metrics --reference-seeds`: every test scored against the seeded truth; with a compared
// reference (the object-space `reference` render of the same scene) also each test's paired difference from it
// and the agreement of the rankings under the two truths. Checks every input before writing
// OUTPUT/debiased.csv, OUTPUT/agreement.csv (with a compared reference) and OUTPUT/debiased.json (last),
// atomically.
struct DebiasedRunOptions {
    double exposure = 1.0;
    double sssRadiusMillimetres = 0.0;      // > 0 overrides the first seed's skinlab:sss_radius_mm
    std::filesystem::path compareReference; // empty: none
    // metrics.json of `analyze metrics --reference R` on the same tests (empty: none): the agreement of each table
    // score with the truth's ranking.
    std::filesystem::path compareMetrics;
    AgreementOptions agreement;
};

struct DebiasedRun {
    SeededTruth truth;
    std::vector<DebiasedScores> tests;
    std::optional<DebiasedScores> compared; // the compared reference's own scores
    // Per test, quantity and region: the plain MSE against the compared reference.
    std::vector<std::array<std::array<double, debiasedRegionCount>, debiasedQuantityCount>> comparedMse;
    std::array<std::array<AgreementSubsets, debiasedRegionCount>, debiasedQuantityCount> agreement{};
    std::vector<std::pair<TableScore, AgreementSubsets>> tableAgreement; // with compareMetrics
};

DebiasedRun runDebiasedMetrics(const std::vector<std::filesystem::path>& seeds,
                               const std::vector<std::filesystem::path>& tests, const DebiasedRunOptions& options,
                               const std::filesystem::path& outputFolder);

} // namespace skinlab::metrics
