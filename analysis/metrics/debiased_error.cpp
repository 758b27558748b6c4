#include "analysis/metrics/debiased_error.h"

#include "analysis/metrics/colour_space.h"
#include "analysis/metrics/rank_statistics.h"
#include "analysis/metrics/render_comparison.h"
#include "common/csv.h"
#include "common/error.h"
#include "common/files.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>

#include <nlohmann/json.hpp>

namespace skinlab::metrics {
namespace {

constexpr double notANumber = std::numeric_limits<double>::quiet_NaN();

// The plain squared error between two images of one quantity over a region (dot product for CIELAB).
double meanSquaredDifference(const cv::Mat& a, const cv::Mat& b, const cv::Mat& inside) {
    if (a.empty() || b.empty()) return notANumber;
    double sum = 0.0;
    std::size_t pixels = 0;
    const int channels = a.channels();
    for (int y = 0; y < inside.rows; ++y) {
        const auto* in = inside.ptr<unsigned char>(y);
        const auto* left = a.ptr<double>(y);
        const auto* right = b.ptr<double>(y);
        for (int x = 0; x < inside.cols; ++x)
            if (in[x]) {
                for (int c = 0; c < channels; ++c) {
                    const double d = left[x * channels + c] - right[x * channels + c];
                    sum += d * d;
                }
                ++pixels;
            }
    }
    return pixels > 0 ? sum / static_cast<double>(pixels) : notANumber;
}

// The jackknife's standard error of the leave-one-out estimates θ_(k): √((S−1)/S · Σ (θ_(k) − θ̄)²).
double jackknifeStandardError(const std::vector<double>& leaveOneOut) {
    const std::size_t seeds = leaveOneOut.size();
    if (seeds < 2) return notANumber;
    double mean = 0.0;
    for (double value : leaveOneOut) mean += value;
    mean /= static_cast<double>(seeds);
    double sum = 0.0;
    for (double value : leaveOneOut) sum += (value - mean) * (value - mean);
    return std::sqrt(static_cast<double>(seeds - 1) / static_cast<double>(seeds) * sum);
}

} // namespace

std::string_view debiasedRegionName(std::size_t region) {
    static constexpr std::array<std::string_view, debiasedRegionCount> names{"halo",     "bleed", "spill",
                                                                             "interior", "skin",  "image"};
    return region < names.size() ? names[region] : std::string_view{"?"};
}

std::string_view debiasedQuantityName(std::size_t quantity) {
    static constexpr std::array<std::string_view, debiasedQuantityCount> names{"Y", "R", "G", "B", "Lab"};
    return quantity < names.size() ? names[quantity] : std::string_view{"?"};
}

DebiasedImages renderQuantities(const MetricRender& render, double exposure) {
    DebiasedImages images;
    images[0] = renderLuminance(render, exposure);
    for (std::size_t channel = 0; channel < 3; ++channel) images[1 + channel] = cv::Mat(render.beauty.size(), CV_64FC1);
    images[4] = cv::Mat(render.beauty.size(), CV_64FC3);
    for (int y = 0; y < render.beauty.rows; ++y) {
        const auto* rgb = render.beauty.ptr<cv::Vec3f>(y);
        auto* lab = images[4].ptr<cv::Vec3d>(y);
        for (int x = 0; x < render.beauty.cols; ++x) {
            for (int channel = 0; channel < 3; ++channel) {
                const double value = static_cast<double>(rgb[x][channel]) * exposure;
                images[1 + static_cast<std::size_t>(channel)].ptr<double>(y)[x] = std::isfinite(value) ? value : 0.0;
            }
            const Lab colour = displayLab(rgb[x][0], rgb[x][1], rgb[x][2], exposure);
            lab[x] = cv::Vec3d(colour.lightness, colour.a, colour.b);
        }
    }
    return images;
}

cv::Mat renderLuminance(const MetricRender& render, double exposure) {
    cv::Mat luminance(render.beauty.size(), CV_64FC1);
    for (int y = 0; y < render.beauty.rows; ++y) {
        const auto* rgb = render.beauty.ptr<cv::Vec3f>(y);
        auto* out = luminance.ptr<double>(y);
        for (int x = 0; x < render.beauty.cols; ++x) {
            const double value = luminanceRec709(rgb[x][0], rgb[x][1], rgb[x][2]) * exposure;
            out[x] = std::isfinite(value) ? value : 0.0;
        }
    }
    return luminance;
}

SeededTruth loadSeededTruth(const std::vector<std::filesystem::path>& seeds, double exposure,
                            double sssRadiusMillimetres) {
    if (seeds.size() < 2)
        throwInput("--reference-seeds", "",
                   "needs at least two path-traced renders of the same scene with different seeds (four or more "
                   "for standard errors), got " +
                       std::to_string(seeds.size()));
    SeededTruth truth;
    truth.paths = seeds;
    truth.exposure = exposure;
    MetricOptions options;
    options.exposure = exposure;
    if (sssRadiusMillimetres > 0.0) options.sssRadiusMillimetres = sssRadiusMillimetres;
    MetricRender first = loadMetricRender(seeds.front(), RenderRole::reference);
    if (first.plain)
        throwInput(seeds.front().string(), "",
                   "a seeded truth needs skinlab's depth.Z, mask.Y and camera metadata (a skinlab render)");
    const int width = first.width;
    const int height = first.height;
    truth.images.push_back(renderQuantities(first, exposure));
    truth.luminance.push_back(truth.images.back()[0]);
    PreparedReference prepared = prepareReference(std::move(first), options);
    truth.bands = prepared.bands;
    for (std::size_t band = 0; band < allBands.size(); ++band) truth.regions[band] = truth.bands.masks[band];
    truth.regions[4] = truth.bands.skin;
    truth.regions[5] = cv::Mat(height, width, CV_8UC1, cv::Scalar(255));
    for (std::size_t seed = 1; seed < seeds.size(); ++seed) {
        for (std::size_t other = 0; other < seed; ++other)
            if (std::filesystem::weakly_canonical(seeds[other]) == std::filesystem::weakly_canonical(seeds[seed]))
                throwInput(seeds[seed].string(), "",
                           "given twice in --reference-seeds: the estimate needs independent seeds");
        const MetricRender render = loadMetricRender(seeds[seed], RenderRole::test);
        if (render.width != width || render.height != height)
            throwInput(seeds[seed].string(), "",
                       std::to_string(render.width) + "x" + std::to_string(render.height) + " differs from " +
                           seeds.front().string() + " (" + std::to_string(width) + "x" + std::to_string(height) + ")");
        truth.images.push_back(renderQuantities(render, exposure));
        truth.luminance.push_back(truth.images.back()[0]);
    }
    double skinSum = 0.0;
    std::size_t skinPixels = 0;
    for (const cv::Mat& luminance : truth.luminance)
        for (int y = 0; y < height; ++y) {
            const auto* inside = truth.regions[4].ptr<unsigned char>(y);
            const auto* value = luminance.ptr<double>(y);
            for (int x = 0; x < width; ++x)
                if (inside[x]) {
                    skinSum += value[x];
                    ++skinPixels;
                }
        }
    truth.meanSkinLuminance = skinPixels > 0 ? skinSum / static_cast<double>(skinPixels) : 0.0;
    return truth;
}

DebiasedScores scoreDebiased(const SeededTruth& truth, const cv::Mat& testLuminance,
                             const std::filesystem::path& testPath) {
    DebiasedImages images;
    images[0] = testLuminance;
    return scoreDebiased(truth, images, testPath);
}

namespace {

// The index of the pair i < j among S seeds, in the order (0,1), (0,2) … (S−2,S−1).
std::size_t pairIndex(std::size_t i, std::size_t j, std::size_t seeds) {
    return i * (2 * seeds - i - 1) / 2 + (j - i - 1);
}

// The pair terms of one quantity in one region, and the plain squared error against the first seed.
template <int Channels>
void accumulatePairs(const SeededTruth& truth, std::size_t quantity, const cv::Mat& test, const cv::Mat& inside,
                     std::vector<double>& pairSums, double& plainSum, std::size_t& pixels) {
    using Pixel = cv::Vec<double, Channels>;
    const std::size_t seeds = truth.images.size();
    std::vector<Pixel> residual(seeds);
    for (int y = 0; y < inside.rows; ++y) {
        const auto* in = inside.ptr<unsigned char>(y);
        const auto* value = test.ptr<Pixel>(y);
        for (int x = 0; x < inside.cols; ++x) {
            if (!in[x]) continue;
            ++pixels;
            for (std::size_t k = 0; k < seeds; ++k) residual[k] = value[x] - truth.images[k][quantity].ptr<Pixel>(y)[x];
            plainSum += residual[0].dot(residual[0]);
            std::size_t pair = 0;
            for (std::size_t i = 0; i < seeds; ++i)
                for (std::size_t j = i + 1; j < seeds; ++j) pairSums[pair++] += residual[i].dot(residual[j]);
        }
    }
}

} // namespace

DebiasedScores scoreDebiased(const SeededTruth& truth, const DebiasedImages& test,
                             const std::filesystem::path& testPath) {
    const std::size_t seeds = truth.images.size();
    if (test[0].empty() || test[0].size() != truth.luminance.front().size())
        throwInput(testPath.string(), "",
                   std::to_string(test[0].cols) + "x" + std::to_string(test[0].rows) +
                       " differs from the path-traced truth " + truth.paths.front().string() + " (" +
                       std::to_string(truth.luminance.front().cols) + "x" +
                       std::to_string(truth.luminance.front().rows) + ")");
    DebiasedScores scores;
    scores.test = testPath;
    scores.seeds = seeds;
    std::vector<std::size_t> allSeeds(seeds);
    for (std::size_t k = 0; k < seeds; ++k) allSeeds[k] = k;
    for (std::size_t quantity = 0; quantity < debiasedQuantityCount; ++quantity) {
        const bool scored =
            !test[quantity].empty() && std::all_of(truth.images.begin(), truth.images.end(),
                                                   [&](const DebiasedImages& seed) { return !seed[quantity].empty(); });
        for (std::size_t region = 0; region < debiasedRegionCount; ++region) {
            JackknifeEstimate& estimate = scores.quantityMse[quantity][region];
            estimate.value = estimate.standardError = notANumber;
            scores.quantityPlainMse[quantity][region] = notANumber;
            if (!scored) continue;
            std::vector<double> pairSums(seeds * (seeds - 1) / 2, 0.0);
            double plainSum = 0.0;
            std::size_t pixels = 0;
            if (test[quantity].channels() == 3)
                accumulatePairs<3>(truth, quantity, test[quantity], truth.regions[region], pairSums, plainSum, pixels);
            else accumulatePairs<1>(truth, quantity, test[quantity], truth.regions[region], pairSums, plainSum, pixels);
            if (quantity == 0) scores.pixels[region] = pixels;
            if (pixels == 0) continue;
            const double n = static_cast<double>(pixels);
            for (double& sum : pairSums) sum /= n;
            scores.pairTerms[quantity][region] = pairSums;
            scores.quantityPlainMse[quantity][region] = plainSum / n;
            estimate.value = pairTermMean(pairSums, seeds, allSeeds);
            if (seeds >= 3) {
                for (std::size_t k = 0; k < seeds; ++k) {
                    std::vector<std::size_t> without;
                    for (std::size_t other = 0; other < seeds; ++other)
                        if (other != k) without.push_back(other);
                    estimate.leaveOneOut.push_back(pairTermMean(pairSums, seeds, without));
                }
                estimate.standardError = jackknifeStandardError(estimate.leaveOneOut);
            }
        }
    }
    scores.mse = scores.quantityMse[0];
    scores.plainMse = scores.quantityPlainMse[0];
    return scores;
}

double pairTermMean(const std::vector<double>& pairTerms, std::size_t seeds, const std::vector<std::size_t>& draw) {
    if (pairTerms.size() != seeds * (seeds - 1) / 2) return notANumber;
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t a = 0; a < draw.size(); ++a)
        for (std::size_t b = a + 1; b < draw.size(); ++b) {
            if (draw[a] == draw[b] || draw[a] >= seeds || draw[b] >= seeds) continue;
            sum += pairTerms[pairIndex(std::min(draw[a], draw[b]), std::max(draw[a], draw[b]), seeds)];
            ++count;
        }
    return count > 0 ? sum / static_cast<double>(count) : notANumber;
}

JackknifeEstimate seedMeanMse(const SeededTruth& truth, std::size_t quantity, std::size_t region) {
    const std::size_t seeds = truth.images.size();
    JackknifeEstimate estimate;
    estimate.value = estimate.standardError = notANumber;
    if (seeds < 2 || quantity >= debiasedQuantityCount || region >= debiasedRegionCount) return estimate;
    const cv::Mat& inside = truth.regions[region];
    std::vector<double> pairTerms;
    for (std::size_t i = 0; i < seeds; ++i)
        for (std::size_t j = i + 1; j < seeds; ++j) {
            const double mean = meanSquaredDifference(truth.images[i][quantity], truth.images[j][quantity], inside);
            if (std::isnan(mean)) return estimate;
            pairTerms.push_back(0.5 * mean);
        }
    const double count = static_cast<double>(seeds);
    std::vector<std::size_t> all(seeds);
    for (std::size_t k = 0; k < seeds; ++k) all[k] = k;
    estimate.value = pairTermMean(pairTerms, seeds, all) / count;
    if (seeds >= 3) {
        for (std::size_t k = 0; k < seeds; ++k) {
            std::vector<std::size_t> without;
            for (std::size_t other = 0; other < seeds; ++other)
                if (other != k) without.push_back(other);
            estimate.leaveOneOut.push_back(pairTermMean(pairTerms, seeds, without) / count);
        }
        estimate.standardError = jackknifeStandardError(estimate.leaveOneOut);
    }
    return estimate;
}

JackknifeEstimate debiasedDifference(const DebiasedScores& a, const DebiasedScores& b, std::size_t region) {
    JackknifeEstimate difference;
    difference.value = a.mse[region].value - b.mse[region].value;
    const auto& left = a.mse[region].leaveOneOut;
    const auto& right = b.mse[region].leaveOneOut;
    if (left.size() != right.size() || left.empty()) {
        difference.standardError = notANumber;
        return difference;
    }
    for (std::size_t k = 0; k < left.size(); ++k) difference.leaveOneOut.push_back(left[k] - right[k]);
    difference.standardError = jackknifeStandardError(difference.leaveOneOut);
    return difference;
}

double kendallTauB(const std::vector<double>& x, const std::vector<double>& y) {
    if (x.size() != y.size() || x.size() < 2) return notANumber;
    double concordant = 0.0;
    double discordant = 0.0;
    double tiesX = 0.0; // pairs tied in x only
    double tiesY = 0.0; // pairs tied in y only
    for (std::size_t i = 0; i < x.size(); ++i)
        for (std::size_t j = i + 1; j < x.size(); ++j) {
            const double dx = x[i] - x[j];
            const double dy = y[i] - y[j];
            if (!std::isfinite(dx) || !std::isfinite(dy)) return notANumber;
            if (dx == 0.0 && dy == 0.0) continue;
            if (dx == 0.0) tiesX += 1.0;
            else if (dy == 0.0) tiesY += 1.0;
            else if ((dx > 0.0) == (dy > 0.0)) concordant += 1.0;
            else discordant += 1.0;
        }
    const double denominator = std::sqrt((concordant + discordant + tiesX) * (concordant + discordant + tiesY));
    return denominator > 0.0 ? (concordant - discordant) / denominator : notANumber;
}

double truthScore(const DebiasedScores& scores, const TruthScore& truth, const std::vector<std::size_t>* draw) {
    if (truth.quantity >= debiasedQuantityCount || truth.region >= debiasedRegionCount) return notANumber;
    std::vector<std::size_t> all;
    if (!draw) {
        for (std::size_t k = 0; k < scores.seeds; ++k) all.push_back(k);
        draw = &all;
    }
    const auto mse = [&](std::size_t region) {
        const auto& terms = scores.pairTerms[truth.quantity][region];
        return terms.empty() ? notANumber : pairTermMean(terms, scores.seeds, *draw);
    };
    if (truth.kind == TruthKind::mse) return mse(truth.region);
    constexpr std::size_t interior = 3;
    return std::sqrt(std::max(mse(truth.region), 0.0)) - std::sqrt(std::max(mse(interior), 0.0));
}

namespace {

// The truth score of a test with its leave-one-seed-out values.
JackknifeEstimate truthEstimate(const DebiasedScores& scores, const TruthScore& truth) {
    JackknifeEstimate estimate;
    estimate.value = truthScore(scores, truth, nullptr);
    if (scores.seeds >= 3) {
        for (std::size_t k = 0; k < scores.seeds; ++k) {
            std::vector<std::size_t> without;
            for (std::size_t other = 0; other < scores.seeds; ++other)
                if (other != k) without.push_back(other);
            estimate.leaveOneOut.push_back(truthScore(scores, truth, &without));
        }
        estimate.standardError = jackknifeStandardError(estimate.leaveOneOut);
    } else {
        estimate.standardError = notANumber;
    }
    return estimate;
}

} // namespace

RankingAgreement rankingAgreement(const std::vector<DebiasedScores>& scores, const std::vector<double>& otherScore,
                                  std::size_t region) {
    std::vector<std::size_t> all(scores.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    return rankingAgreement(scores, otherScore, TruthScore{region, 0, TruthKind::mse}, all, AgreementOptions{});
}

RankingAgreement rankingAgreement(const std::vector<DebiasedScores>& scores, const std::vector<double>& otherScore,
                                  const TruthScore& truth, const std::vector<std::size_t>& members,
                                  const AgreementOptions& options) {
    RankingAgreement agreement;
    agreement.members = members;
    agreement.conditions = members.size();
    agreement.jackknifeInterval = agreement.bootstrapInterval = {notANumber, notANumber};
    const std::size_t seeds = scores.empty() ? 0 : scores.front().seeds;
    agreement.tQuantile =
        seeds >= 3 ? studentTQuantile(0.5 * (1.0 + options.level), static_cast<double>(seeds - 1)) : notANumber;
    std::vector<JackknifeEstimate> estimates;
    std::vector<double> other;
    for (std::size_t member : members) {
        estimates.push_back(truthEstimate(scores.at(member), truth));
        other.push_back(otherScore.at(member));
    }
    std::vector<double> values;
    for (const JackknifeEstimate& estimate : estimates) values.push_back(estimate.value);
    agreement.tau.value = kendallTauB(other, values);
    const std::size_t leaveOut = estimates.empty() ? 0 : estimates.front().leaveOneOut.size();
    for (std::size_t k = 0; k < leaveOut; ++k) {
        std::vector<double> without;
        for (const JackknifeEstimate& estimate : estimates) without.push_back(estimate.leaveOneOut[k]);
        agreement.tau.leaveOneOut.push_back(kendallTauB(other, without));
    }
    agreement.tau.standardError = jackknifeStandardError(agreement.tau.leaveOneOut);
    if (std::isfinite(agreement.tau.standardError) && std::isfinite(agreement.tQuantile))
        agreement.jackknifeInterval = {
            std::max(-1.0, agreement.tau.value - agreement.tQuantile * agreement.tau.standardError),
            std::min(1.0, agreement.tau.value + agreement.tQuantile * agreement.tau.standardError)};

    // Pairs the truth separates: |difference| > t·SE with the jackknife over the seeds both share.
    double concordant = 0.0;
    double discordant = 0.0;
    for (std::size_t i = 0; i < estimates.size(); ++i)
        for (std::size_t j = i + 1; j < estimates.size(); ++j) {
            const double difference = estimates[i].value - estimates[j].value;
            std::vector<double> differences;
            for (std::size_t k = 0; k < leaveOut; ++k)
                differences.push_back(estimates[i].leaveOneOut[k] - estimates[j].leaveOneOut[k]);
            const double error = jackknifeStandardError(differences);
            if (!(std::abs(difference) > agreement.tQuantile * error)) continue;
            ++agreement.separatedPairs;
            const double otherDifference = other[i] - other[j];
            if (otherDifference != 0.0 && (otherDifference > 0.0) == (difference > 0.0)) {
                concordant += 1.0;
                ++agreement.concordantSeparated;
            } else if (otherDifference != 0.0) {
                discordant += 1.0;
            }
        }
    agreement.tauSeparated = agreement.separatedPairs > 0
                                 ? (concordant - discordant) / static_cast<double>(agreement.separatedPairs)
                                 : notANumber;

    // Bootstrap: each replicate draws the subset's conditions and the seeds with replacement (a draw of seeds
    // with fewer than two distinct seeds is drawn again) and ranks the drawn conditions by their truth scores from
    // the drawn seeds.
    const std::size_t count = members.size();
    if (count >= 3 && options.bootstrapReplicates > 0 && seeds >= 2) {
        std::mt19937_64 random(options.bootstrapSeed);
        std::uniform_int_distribution<std::size_t> pickCondition(0, count - 1);
        std::uniform_int_distribution<std::size_t> pickSeed(0, seeds - 1);
        std::vector<double> replicates;
        replicates.reserve(options.bootstrapReplicates);
        std::vector<std::size_t> conditionDraw(count);
        std::vector<std::size_t> seedDraw(seeds);
        std::vector<double> x(count);
        std::vector<double> y(count);
        std::vector<double> cache(count);
        std::vector<char> cached(count);
        for (std::size_t replicate = 0; replicate < options.bootstrapReplicates; ++replicate) {
            for (std::size_t& c : conditionDraw) c = pickCondition(random);
            do {
                for (std::size_t& k : seedDraw) k = pickSeed(random);
            } while (std::all_of(seedDraw.begin(), seedDraw.end(), [&](std::size_t k) { return k == seedDraw[0]; }));
            std::fill(cached.begin(), cached.end(), 0);
            for (std::size_t i = 0; i < count; ++i) {
                const std::size_t c = conditionDraw[i];
                if (!cached[c]) {
                    cache[c] = truthScore(scores[members[c]], truth, &seedDraw);
                    cached[c] = 1;
                }
                x[i] = other[c];
                y[i] = cache[c];
            }
            replicates.push_back(kendallTauB(x, y));
        }
        agreement.bootstrapInterval = percentileInterval(std::move(replicates), options.level);
    }
    return agreement;
}

AgreementSubsets agreementSubsets(const std::vector<DebiasedScores>& scores, const std::vector<double>& otherScore,
                                  const TruthScore& truth, const AgreementOptions& options) {
    AgreementSubsets subsets;
    std::vector<double> values;
    std::vector<std::size_t> all;
    for (std::size_t i = 0; i < scores.size(); ++i) {
        values.push_back(truthScore(scores[i], truth, nullptr));
        all.push_back(i);
    }
    subsets.all = rankingAgreement(scores, otherScore, truth, all, options);
    subsets.competitive =
        rankingAgreement(scores, otherScore, truth, smallestIndices(values, options.competitiveCount), options);
    subsets.clearlyWorseFence = upperTukeyFence(values);
    std::vector<std::size_t> kept;
    for (std::size_t i = 0; i < values.size(); ++i)
        if (!(values[i] > subsets.clearlyWorseFence)) kept.push_back(i); // a NaN fence keeps all
    subsets.withoutClearlyWorse = rankingAgreement(scores, otherScore, truth, kept, options);
    return subsets;
}

const std::vector<TableScore>& tableScores() {
    static const std::vector<TableScore> scores{
        {"halo_leak_energy", "halo", "leak_energy", {0, 0, TruthKind::mse}},
        {"bleed_leak_energy", "bleed", "leak_energy", {1, 0, TruthKind::mse}},
        {"spill_leak_energy", "spill", "leak_energy", {2, 0, TruthKind::mse}},
        {"halo_delta_e00_mean", "halo", "delta_e00_mean", {0, 4, TruthKind::mse}},
        {"bleed_delta_e00_mean", "bleed", "delta_e00_mean", {1, 4, TruthKind::mse}},
        {"halo_excess", "halo", "excess", {0, 4, TruthKind::rmsExcess}},
        {"bleed_excess", "bleed", "excess", {1, 4, TruthKind::rmsExcess}},
        {"skin_delta_e00_mean", "skin", "delta_e00_mean", {4, 4, TruthKind::mse}},
    };
    return scores;
}

} // namespace skinlab::metrics

namespace skinlab::metrics {
namespace {

DebiasedImages loadTestImages(const std::filesystem::path& path, const SeededTruth& truth) {
    const MetricRender render = loadMetricRender(path, RenderRole::test);
    return renderQuantities(render, truth.exposure);
}

nlohmann::json finiteOrNull(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

nlohmann::json estimateJson(const JackknifeEstimate& estimate) {
    return {{"value", estimate.value},
            {"standard_error", estimate.standardError},
            {"leave_one_seed_out", estimate.leaveOneOut}};
}

nlohmann::json intervalJson(const std::array<double, 2>& interval) {
    return std::isfinite(interval[0]) && std::isfinite(interval[1]) ? nlohmann::json{interval[0], interval[1]}
                                                                    : nlohmann::json();
}

// One subset's agreement; `tau_b_interval_95` is the jackknife interval with the t quantile.
nlohmann::json agreementJson(const RankingAgreement& a) {
    return {{"conditions", a.conditions},
            {"members", a.members},
            {"tau_b", estimateJson(a.tau)},
            {"jackknife_t_quantile", finiteOrNull(a.tQuantile)},
            {"tau_b_interval_95", intervalJson(a.jackknifeInterval)},
            {"tau_b_bootstrap_interval_95", intervalJson(a.bootstrapInterval)},
            {"separated_pairs", a.separatedPairs},
            {"concordant_separated_pairs", a.concordantSeparated},
            {"tau_separated", a.tauSeparated}};
}

// The whole subset (its keys at the top, as before) with the competitive subsets beside it.
nlohmann::json subsetsJson(const AgreementSubsets& subsets, const TruthScore& truth) {
    nlohmann::json json = agreementJson(subsets.all);
    json["truth"] = {{"region", std::string(debiasedRegionName(truth.region))},
                     {"quantity", std::string(debiasedQuantityName(truth.quantity))},
                     {"kind", truth.kind == TruthKind::mse ? "mse" : "rms_excess"}};
    json["competitive"] = agreementJson(subsets.competitive);
    json["without_clearly_worse"] = agreementJson(subsets.withoutClearlyWorse);
    json["without_clearly_worse"]["fence"] = finiteOrNull(subsets.clearlyWorseFence);
    return json;
}

std::string number(double value) {
    if (!std::isfinite(value)) return "";
    char text[64];
    std::snprintf(text, sizeof text, "%.9g", value);
    return text;
}

// Rows of agreement.csv: one per subset.
std::string agreementRows(const std::string& score, const TruthScore& truth, const AgreementSubsets& subsets) {
    std::string rows;
    const std::string head = csvField(score) + "," + std::string(debiasedRegionName(truth.region)) + "," +
                             std::string(debiasedQuantityName(truth.quantity)) + "," +
                             (truth.kind == TruthKind::mse ? "mse" : "rms_excess");
    for (const auto& [name, a] : {std::pair<const char*, const RankingAgreement*>{"all", &subsets.all},
                                  {"competitive", &subsets.competitive},
                                  {"without_clearly_worse", &subsets.withoutClearlyWorse}})
        rows += head + "," + name + "," + std::to_string(a->conditions) + "," + number(a->tau.value) + "," +
                number(a->tau.standardError) + "," + number(a->tQuantile) + "," + number(a->jackknifeInterval[0]) +
                "," + number(a->jackknifeInterval[1]) + "," + number(a->bootstrapInterval[0]) + "," +
                number(a->bootstrapInterval[1]) + "," + std::to_string(a->separatedPairs) + "," +
                std::to_string(a->concordantSeparated) + "," +
                (a == &subsets.withoutClearlyWorse ? number(subsets.clearlyWorseFence) : std::string()) + "\n";
    return rows;
}

// A table score per test from metrics.json of `analyze metrics --reference`, matched by the test's path.
std::vector<double> tableScoreValues(const nlohmann::json& metrics, const std::filesystem::path& file,
                                     const std::vector<DebiasedScores>& tests, const TableScore& score) {
    std::map<std::filesystem::path, const nlohmann::json*> byPath;
    for (const auto& comparison : metrics.at("comparisons"))
        byPath[std::filesystem::weakly_canonical(comparison.at("test").at("path").get<std::string>())] = &comparison;
    std::vector<double> values;
    for (const DebiasedScores& test : tests) {
        const auto found = byPath.find(std::filesystem::weakly_canonical(test.test));
        if (found == byPath.end())
            throwInput(file.string(), "",
                       "has no comparison of " + test.test.string() +
                           " (score the same test renders with analyze metrics --reference)");
        const nlohmann::json& comparison = *found->second;
        const nlohmann::json* entry = nullptr;
        if (score.region == "skin") {
            if (comparison.contains("skin") && comparison["skin"].is_object()) entry = &comparison["skin"];
        } else if (comparison.contains("bands") && comparison["bands"].is_object() &&
                   comparison["bands"].contains(score.region)) {
            entry = &comparison["bands"][score.region];
        }
        const bool present = entry && entry->contains(score.key) && (*entry)[score.key].is_number();
        values.push_back(present ? (*entry)[score.key].get<double>() : notANumber);
    }
    return values;
}

} // namespace

namespace {

// The table scores of --compare-metrics (a metrics.json of `analyze metrics`), or null without it.
nlohmann::json readTableMetrics(const DebiasedRunOptions& options) {
    nlohmann::json tableMetrics;
    if (!options.compareMetrics.empty()) {
        try {
            tableMetrics = nlohmann::json::parse(readFile(options.compareMetrics));
            if (!tableMetrics.contains("comparisons") || !tableMetrics["comparisons"].is_array())
                throwInput(options.compareMetrics.string(), "comparisons",
                           "missing: not a metrics.json of skinlab analyze metrics");
        } catch (const nlohmann::json::exception& e) {
            throwInput(options.compareMetrics.string(), "", std::string("not valid JSON: ") + e.what());
        }
    }
    return tableMetrics;
}

// --compare-reference: every test against the compared reference, and how the two truths rank the tests.
void compareWithReference(DebiasedRun& run, const std::vector<DebiasedImages>& images,
                          const DebiasedRunOptions& options, const nlohmann::json& tableMetrics) {
    const DebiasedImages compared = loadTestImages(options.compareReference, run.truth);
    run.compared = scoreDebiased(run.truth, compared, options.compareReference);
    for (const DebiasedImages& image : images) {
        std::array<std::array<double, debiasedRegionCount>, debiasedQuantityCount> mse{};
        for (std::size_t quantity = 0; quantity < debiasedQuantityCount; ++quantity)
            for (std::size_t region = 0; region < debiasedRegionCount; ++region)
                mse[quantity][region] =
                    meanSquaredDifference(image[quantity], compared[quantity], run.truth.regions[region]);
        run.comparedMse.push_back(mse);
    }
    for (std::size_t quantity = 0; quantity < debiasedQuantityCount; ++quantity)
        for (std::size_t region = 0; region < debiasedRegionCount; ++region) {
            std::vector<double> other;
            for (const auto& mse : run.comparedMse) other.push_back(mse[quantity][region]);
            run.agreement[quantity][region] =
                agreementSubsets(run.tests, other, TruthScore{region, quantity, TruthKind::mse}, options.agreement);
        }
    if (!options.compareMetrics.empty())
        for (const TableScore& score : tableScores()) {
            const std::vector<double> values = tableScoreValues(tableMetrics, options.compareMetrics, run.tests, score);
            run.tableAgreement.emplace_back(score, agreementSubsets(run.tests, values, score.truth, options.agreement));
        }
}

// Per region and quantity: the best (smallest) debiased MSE among the tests, and how close the two truths come to
// the noise-free image against it: the seeds' mean (σ̄²/S) and the compared reference (its debiased MSE).
nlohmann::json truthPrecisionJson(const DebiasedRun& run) {
    nlohmann::json regions = nlohmann::json::object();
    for (std::size_t region = 0; region < debiasedRegionCount; ++region) {
        nlohmann::json quantities = nlohmann::json::object();
        for (std::size_t quantity = 0; quantity < debiasedQuantityCount; ++quantity) {
            double best = notANumber;
            for (const DebiasedScores& test : run.tests) {
                const double value = test.quantityMse[quantity][region].value;
                if (std::isfinite(value) && !(value >= best)) best = value;
            }
            const auto entry = [&](const JackknifeEstimate& mse) {
                const double ratio = std::isfinite(mse.value) && best > 0.0 ? mse.value / best : notANumber;
                return nlohmann::json{{"mse", estimateJson(mse)},
                                      {"ratio_to_best_condition", finiteOrNull(ratio)},
                                      {"precise_enough", std::isfinite(ratio) && ratio <= truthPrecisionRatio}};
            };
            nlohmann::json item{{"best_condition_mse", finiteOrNull(best)},
                                {"seed_mean", entry(seedMeanMse(run.truth, quantity, region))}};
            if (run.compared) item["compared_reference"] = entry(run.compared->quantityMse[quantity][region]);
            quantities[std::string(debiasedQuantityName(quantity))] = item;
        }
        regions[std::string(debiasedRegionName(region))] = quantities;
    }
    return {{"criterion", "a truth's debiased MSE against the noise-free image <= " + number(truthPrecisionRatio) +
                              " x the best condition's"},
            {"seeds", run.truth.images.size()},
            {"regions", regions}};
}

// debiased.csv, debiased.json and, with a compared reference, agreement.csv.
void writeDebiasedOutputs(const DebiasedRun& run, const std::vector<std::filesystem::path>& seeds,
                          const DebiasedRunOptions& options, const std::filesystem::path& outputFolder) {
    const double skin = run.truth.meanSkinLuminance;
    std::string csv = "test,region,pixels,mse,mse_se,relative_rmse,plain_mse_one_seed,mse_against_compared,"
                      "difference_from_compared,difference_se";
    for (std::size_t quantity = 1; quantity < debiasedQuantityCount; ++quantity) {
        const std::string name(debiasedQuantityName(quantity));
        csv += ",mse_" + name + ",mse_" + name + "_se,mse_" + name + "_against_compared";
    }
    csv += "\n";
    nlohmann::json testsJson = nlohmann::json::array();
    const auto addRows = [&](const DebiasedScores& scores, const auto* comparedMse) {
        nlohmann::json regions = nlohmann::json::object();
        for (std::size_t region = 0; region < debiasedRegionCount; ++region) {
            const JackknifeEstimate& mse = scores.mse[region];
            const double relative =
                skin > 0.0 && std::isfinite(mse.value) ? std::sqrt(std::max(mse.value, 0.0)) / skin : notANumber;
            JackknifeEstimate difference;
            difference.value = difference.standardError = notANumber;
            if (run.compared && comparedMse) difference = debiasedDifference(scores, *run.compared, region);
            const double against = comparedMse ? (*comparedMse)[0][region] : notANumber;
            csv += csvField(scores.test.string()) + "," + std::string(debiasedRegionName(region)) + "," +
                   std::to_string(scores.pixels[region]) + "," + number(mse.value) + "," + number(mse.standardError) +
                   "," + number(relative) + "," + number(scores.plainMse[region]) + "," + number(against) + "," +
                   number(difference.value) + "," + number(difference.standardError);
            nlohmann::json entry{{"pixels", scores.pixels[region]},
                                 {"mse", estimateJson(mse)},
                                 {"relative_rmse", relative},
                                 {"plain_mse_one_seed", scores.plainMse[region]}};
            nlohmann::json colour = nlohmann::json::object();
            for (std::size_t quantity = 1; quantity < debiasedQuantityCount; ++quantity) {
                const JackknifeEstimate& q = scores.quantityMse[quantity][region];
                const double qAgainst = comparedMse ? (*comparedMse)[quantity][region] : notANumber;
                csv += "," + number(q.value) + "," + number(q.standardError) + "," + number(qAgainst);
                nlohmann::json item{{"mse", estimateJson(q)},
                                    {"plain_mse_one_seed", scores.quantityPlainMse[quantity][region]}};
                if (comparedMse) item["mse_against_compared"] = qAgainst;
                colour[std::string(debiasedQuantityName(quantity))] = item;
            }
            csv += "\n";
            entry["by_quantity"] = colour;
            if (comparedMse) {
                entry["mse_against_compared"] = against;
                entry["difference_from_compared"] = estimateJson(difference);
            }
            regions[std::string(debiasedRegionName(region))] = entry;
        }
        return nlohmann::json{{"test", scores.test.string()}, {"regions", regions}};
    };
    using ComparedMse = std::array<std::array<double, debiasedRegionCount>, debiasedQuantityCount>;
    for (std::size_t i = 0; i < run.tests.size(); ++i)
        testsJson.push_back(addRows(run.tests[i], run.compared ? &run.comparedMse[i] : nullptr));
    nlohmann::json json{{"format", "skinlab-debiased-metrics"},
                        {"seeds", nlohmann::json::array()},
                        {"exposure", options.exposure},
                        {"mean_skin_luminance", skin},
                        {"quantity", "linear luminance Y (Rec. 709) x exposure"},
                        {"quantities",
                         "Y, R, G, B: linear x exposure; Lab: CIELAB of the display encoding (squared error = "
                         "dE*ab^2, debiased to first order)"},
                        {"tests", testsJson}};
    for (const auto& seed : seeds) json["seeds"].push_back(seed.string());
    json["truth_precision"] = truthPrecisionJson(run);
    std::string agreementCsv;
    if (run.compared) {
        json["compared_reference"] = addRows(*run.compared, static_cast<const ComparedMse*>(nullptr));
        json["agreement_settings"] = {{"level", options.agreement.level},
                                      {"bootstrap_replicates", options.agreement.bootstrapReplicates},
                                      {"bootstrap_seed", options.agreement.bootstrapSeed},
                                      {"competitive_count", options.agreement.competitiveCount},
                                      {"clearly_worse", "truth score above Q3 + 1.5 IQR of all conditions'"}};
        agreementCsv = "score,region,quantity,truth,subset,conditions,tau_b,tau_b_se,t_quantile,jackknife_low,"
                       "jackknife_high,bootstrap_low,bootstrap_high,separated_pairs,concordant_separated_pairs,"
                       "clearly_worse_fence\n";
        nlohmann::json agreement = nlohmann::json::object();
        nlohmann::json byQuantity = nlohmann::json::object();
        for (std::size_t quantity = 0; quantity < debiasedQuantityCount; ++quantity) {
            nlohmann::json regions = nlohmann::json::object();
            for (std::size_t region = 0; region < debiasedRegionCount; ++region) {
                const TruthScore truth{region, quantity, TruthKind::mse};
                regions[std::string(debiasedRegionName(region))] = subsetsJson(run.agreement[quantity][region], truth);
                agreementCsv += agreementRows("mse_against_compared", truth, run.agreement[quantity][region]);
            }
            if (quantity == 0) agreement = regions;
            byQuantity[std::string(debiasedQuantityName(quantity))] = regions;
        }
        json["ranking_agreement"] = agreement;
        json["ranking_agreement_by_quantity"] = byQuantity;
        if (!run.tableAgreement.empty()) {
            nlohmann::json table = nlohmann::json::object();
            for (const auto& [score, subsets] : run.tableAgreement) {
                table[score.name] = subsetsJson(subsets, score.truth);
                agreementCsv += agreementRows(score.name, score.truth, subsets);
            }
            json["table_score_agreement"] = table;
        }
    }
    ensureDirectory(outputFolder);
    writeFileAtomic(outputFolder / "debiased.csv", csv);
    if (!agreementCsv.empty()) writeFileAtomic(outputFolder / "agreement.csv", agreementCsv);
    writeFileAtomic(outputFolder / "debiased.json", json.dump(2) + "\n");
}

} // namespace

DebiasedRun runDebiasedMetrics(const std::vector<std::filesystem::path>& seeds,
                               const std::vector<std::filesystem::path>& tests, const DebiasedRunOptions& options,
                               const std::filesystem::path& outputFolder) {
    if (tests.empty()) throwInput("TEST.exr", "", "required: at least one render to score against the seeds");
    if (!(options.exposure > 0.0) || !std::isfinite(options.exposure))
        throwInput("--exposure", "", number(options.exposure) + " must be a positive number");
    if (!options.compareMetrics.empty() && options.compareReference.empty())
        throwInput("--compare-metrics", options.compareMetrics.string(), "only with --compare-reference");
    const nlohmann::json tableMetrics = readTableMetrics(options);
    DebiasedRun run;
    run.truth = loadSeededTruth(seeds, options.exposure, options.sssRadiusMillimetres);
    std::vector<DebiasedImages> images;
    for (const auto& test : tests) {
        images.push_back(loadTestImages(test, run.truth));
        run.tests.push_back(scoreDebiased(run.truth, images.back(), test));
    }
    if (!options.compareReference.empty()) compareWithReference(run, images, options, tableMetrics);
    writeDebiasedOutputs(run, seeds, options, outputFolder);
    return run;
}

} // namespace skinlab::metrics
