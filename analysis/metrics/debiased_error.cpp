#include "analysis/metrics/debiased_error.h"

#include "analysis/metrics/colour_space.h"
#include "analysis/metrics/render_comparison.h"
#include "common/csv.h"
#include "common/error.h"
#include "common/files.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <nlohmann/json.hpp>

namespace skinlab::metrics {
namespace {

constexpr double notANumber = std::numeric_limits<double>::quiet_NaN();

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
    truth.luminance.push_back(renderLuminance(first, exposure));
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
        truth.luminance.push_back(renderLuminance(render, exposure));
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
    const std::size_t seeds = truth.luminance.size();
    if (testLuminance.size() != truth.luminance.front().size())
        throwInput(testPath.string(), "",
                   std::to_string(testLuminance.cols) + "x" + std::to_string(testLuminance.rows) +
                       " differs from the path-traced truth " + truth.paths.front().string() + " (" +
                       std::to_string(truth.luminance.front().cols) + "x" +
                       std::to_string(truth.luminance.front().rows) + ")");
    DebiasedScores scores;
    scores.test = testPath;
    const double pairs = static_cast<double>(seeds * (seeds - 1)) / 2.0;
    const double pairsWithoutOne = static_cast<double>((seeds - 1) * (seeds - 2)) / 2.0;
    std::vector<double> residual(seeds);
    for (std::size_t region = 0; region < debiasedRegionCount; ++region) {
        const cv::Mat& inside = truth.regions[region];
        std::size_t pixels = 0;
        double pairSum = 0.0;
        double plainSum = 0.0;
        std::vector<double> withoutSeed(seeds, 0.0);
        for (int y = 0; y < inside.rows; ++y) {
            const auto* in = inside.ptr<unsigned char>(y);
            const auto* test = testLuminance.ptr<double>(y);
            for (int x = 0; x < inside.cols; ++x) {
                if (!in[x]) continue;
                ++pixels;
                double total = 0.0;
                double squares = 0.0;
                for (std::size_t k = 0; k < seeds; ++k) {
                    residual[k] = test[x] - truth.luminance[k].ptr<double>(y)[x];
                    total += residual[k];
                    squares += residual[k] * residual[k];
                }
                plainSum += residual[0] * residual[0];
                // Σ_{i<j} e_i e_j = ((Σ e)² − Σ e²) / 2, and the same without seed k.
                pairSum += 0.5 * (total * total - squares);
                for (std::size_t k = 0; k < seeds; ++k) {
                    const double t = total - residual[k];
                    withoutSeed[k] += 0.5 * (t * t - (squares - residual[k] * residual[k]));
                }
            }
        }
        scores.pixels[region] = pixels;
        JackknifeEstimate& estimate = scores.mse[region];
        if (pixels == 0) {
            estimate.value = estimate.standardError = notANumber;
            scores.plainMse[region] = notANumber;
            continue;
        }
        const double n = static_cast<double>(pixels);
        estimate.value = pairSum / (n * pairs);
        scores.plainMse[region] = plainSum / n;
        if (seeds >= 3) {
            for (std::size_t k = 0; k < seeds; ++k)
                estimate.leaveOneOut.push_back(withoutSeed[k] / (n * pairsWithoutOne));
            estimate.standardError = jackknifeStandardError(estimate.leaveOneOut);
        } else {
            estimate.standardError = notANumber;
        }
    }
    return scores;
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

RankingAgreement rankingAgreement(const std::vector<DebiasedScores>& scores, const std::vector<double>& otherScore,
                                  std::size_t region) {
    RankingAgreement agreement;
    agreement.conditions = scores.size();
    std::vector<double> debiased;
    for (const DebiasedScores& score : scores) debiased.push_back(score.mse[region].value);
    agreement.tau.value = kendallTauB(otherScore, debiased);
    const std::size_t seeds = scores.empty() ? 0 : scores.front().mse[region].leaveOneOut.size();
    for (std::size_t k = 0; k < seeds; ++k) {
        std::vector<double> without;
        for (const DebiasedScores& score : scores) without.push_back(score.mse[region].leaveOneOut[k]);
        agreement.tau.leaveOneOut.push_back(kendallTauB(otherScore, without));
    }
    agreement.tau.standardError = jackknifeStandardError(agreement.tau.leaveOneOut);
    double concordant = 0.0;
    double discordant = 0.0;
    for (std::size_t i = 0; i < scores.size(); ++i)
        for (std::size_t j = i + 1; j < scores.size(); ++j) {
            const JackknifeEstimate difference = debiasedDifference(scores[i], scores[j], region);
            if (!(std::abs(difference.value) > 1.96 * difference.standardError)) continue;
            ++agreement.separatedPairs;
            const double other = otherScore[i] - otherScore[j];
            if (other != 0.0 && (other > 0.0) == (difference.value > 0.0)) {
                concordant += 1.0;
                ++agreement.concordantSeparated;
            } else if (other != 0.0) {
                discordant += 1.0;
            }
        }
    agreement.tauSeparated = agreement.separatedPairs > 0
                                 ? (concordant - discordant) / static_cast<double>(agreement.separatedPairs)
                                 : notANumber;
    return agreement;
}

} // namespace skinlab::metrics

namespace skinlab::metrics {
namespace {

double meanSquaredDifference(const cv::Mat& a, const cv::Mat& b, const cv::Mat& inside) {
    double sum = 0.0;
    std::size_t pixels = 0;
    for (int y = 0; y < inside.rows; ++y) {
        const auto* in = inside.ptr<unsigned char>(y);
        const auto* left = a.ptr<double>(y);
        const auto* right = b.ptr<double>(y);
        for (int x = 0; x < inside.cols; ++x)
            if (in[x]) {
                sum += (left[x] - right[x]) * (left[x] - right[x]);
                ++pixels;
            }
    }
    return pixels > 0 ? sum / static_cast<double>(pixels) : notANumber;
}

cv::Mat loadTestLuminance(const std::filesystem::path& path, const SeededTruth& truth) {
    const MetricRender render = loadMetricRender(path, RenderRole::test);
    return renderLuminance(render, truth.exposure);
}

nlohmann::json estimateJson(const JackknifeEstimate& estimate) {
    return {{"value", estimate.value},
            {"standard_error", estimate.standardError},
            {"leave_one_seed_out", estimate.leaveOneOut}};
}

std::string number(double value) {
    if (!std::isfinite(value)) return "";
    char text[64];
    std::snprintf(text, sizeof text, "%.9g", value);
    return text;
}

} // namespace

DebiasedRun runDebiasedMetrics(const std::vector<std::filesystem::path>& seeds,
                               const std::vector<std::filesystem::path>& tests, const DebiasedRunOptions& options,
                               const std::filesystem::path& outputFolder) {
    if (tests.empty()) throwInput("TEST.exr", "", "required: at least one render to score against the seeds");
    if (!(options.exposure > 0.0) || !std::isfinite(options.exposure))
        throwInput("--exposure", "", number(options.exposure) + " must be a positive number");
    DebiasedRun run;
    run.truth = loadSeededTruth(seeds, options.exposure, options.sssRadiusMillimetres);
    std::vector<cv::Mat> luminances;
    for (const auto& test : tests) {
        luminances.push_back(loadTestLuminance(test, run.truth));
        run.tests.push_back(scoreDebiased(run.truth, luminances.back(), test));
    }
    if (!options.compareReference.empty()) {
        const cv::Mat compared = loadTestLuminance(options.compareReference, run.truth);
        run.compared = scoreDebiased(run.truth, compared, options.compareReference);
        for (const cv::Mat& luminance : luminances) {
            std::array<double, debiasedRegionCount> mse{};
            for (std::size_t region = 0; region < debiasedRegionCount; ++region)
                mse[region] = meanSquaredDifference(luminance, compared, run.truth.regions[region]);
            run.comparedMse.push_back(mse);
        }
        for (std::size_t region = 0; region < debiasedRegionCount; ++region) {
            std::vector<double> other;
            for (const auto& mse : run.comparedMse) other.push_back(mse[region]);
            run.agreement[region] = rankingAgreement(run.tests, other, region);
        }
    }

    const double skin = run.truth.meanSkinLuminance;
    std::string csv = "test,region,pixels,mse,mse_se,relative_rmse,plain_mse_one_seed,mse_against_compared,"
                      "difference_from_compared,difference_se\n";
    nlohmann::json testsJson = nlohmann::json::array();
    const auto addRows = [&](const DebiasedScores& scores, const std::array<double, debiasedRegionCount>* comparedMse) {
        nlohmann::json regions = nlohmann::json::object();
        for (std::size_t region = 0; region < debiasedRegionCount; ++region) {
            const JackknifeEstimate& mse = scores.mse[region];
            const double relative =
                skin > 0.0 && std::isfinite(mse.value) ? std::sqrt(std::max(mse.value, 0.0)) / skin : notANumber;
            JackknifeEstimate difference;
            difference.value = difference.standardError = notANumber;
            if (run.compared && comparedMse) difference = debiasedDifference(scores, *run.compared, region);
            const double against = comparedMse ? (*comparedMse)[region] : notANumber;
            csv += csvField(scores.test.string()) + "," + std::string(debiasedRegionName(region)) + "," +
                   std::to_string(scores.pixels[region]) + "," + number(mse.value) + "," + number(mse.standardError) +
                   "," + number(relative) + "," + number(scores.plainMse[region]) + "," + number(against) + "," +
                   number(difference.value) + "," + number(difference.standardError) + "\n";
            nlohmann::json entry{{"pixels", scores.pixels[region]},
                                 {"mse", estimateJson(mse)},
                                 {"relative_rmse", relative},
                                 {"plain_mse_one_seed", scores.plainMse[region]}};
            if (comparedMse) {
                entry["mse_against_compared"] = against;
                entry["difference_from_compared"] = estimateJson(difference);
            }
            regions[std::string(debiasedRegionName(region))] = entry;
        }
        return nlohmann::json{{"test", scores.test.string()}, {"regions", regions}};
    };
    for (std::size_t i = 0; i < run.tests.size(); ++i)
        testsJson.push_back(addRows(run.tests[i], run.compared ? &run.comparedMse[i] : nullptr));
    nlohmann::json json{{"format", "skinlab-debiased-metrics"},
                        {"seeds", nlohmann::json::array()},
                        {"exposure", options.exposure},
                        {"mean_skin_luminance", skin},
                        {"quantity", "linear luminance Y (Rec. 709) x exposure"},
                        {"tests", testsJson}};
    for (const auto& seed : seeds) json["seeds"].push_back(seed.string());
    if (run.compared) {
        json["compared_reference"] = addRows(*run.compared, nullptr);
        nlohmann::json agreement = nlohmann::json::object();
        for (std::size_t region = 0; region < debiasedRegionCount; ++region) {
            const RankingAgreement& a = run.agreement[region];
            const double low = std::max(-1.0, a.tau.value - 1.96 * a.tau.standardError);
            const double high = std::min(1.0, a.tau.value + 1.96 * a.tau.standardError);
            agreement[std::string(debiasedRegionName(region))] = {
                {"conditions", a.conditions},
                {"tau_b", estimateJson(a.tau)},
                {"tau_b_interval_95",
                 std::isfinite(a.tau.standardError) ? nlohmann::json{low, high} : nlohmann::json()},
                {"separated_pairs", a.separatedPairs},
                {"concordant_separated_pairs", a.concordantSeparated},
                {"tau_separated", a.tauSeparated}};
        }
        json["ranking_agreement"] = agreement;
    }
    ensureDirectory(outputFolder);
    writeFileAtomic(outputFolder / "debiased.csv", csv);
    writeFileAtomic(outputFolder / "debiased.json", json.dump(2) + "\n");
    return run;
}

} // namespace skinlab::metrics
