// skinlab against pwcmp (Perez-Ortiz & Mantiuk 2017, https://github.com/mantiuk/pwcmp) on pwcmp's own real data:
// examples/ex3_tmo_cmp_data.csv (1,213 answers, 18 observers, 5 scenes × 7 tone-mapping operators; shipped in
// tests/data/pwcmp/ with pwcmp's MIT licence).
//
// The reference numbers below were obtained by running pwcmp (commit 07876b29) in GNU Octave 7.3 with the
// statistics package 1.5.3, with one change to pw_scale.m: `optimoptions('fminunc', 'SpecifyObjectiveGradient',
// true, 'Display', 'off')` replaced by `optimset('GradObj', 'on', 'Display', 'off')` (Octave has no optimoptions).
// The CSV was read into per-observer count matrices exactly as pw_scale_table does (conditions in the order of
// unique(), i.e. sorted), then per scene `pw_scale(M)` (defaults: 'gaussian' prior, 'mean0' regularisation),
// `pw_scale(M, {'prior', 'none'})` with fminunc's TolFun and TolX at 1e-14, and
// `[L, dist_L] = pw_outlier_analysis({MM_corridor, ..., MM_window})`; and examples/ex1_simple_scaling.m as it is.
#include "analysis/scaling/comparison_data.h"
#include "analysis/scaling/pairwise_model.h"
#include "analysis/scaling/responses.h"
#include "analysis/scaling/scale_analysis.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace skinlab::analysis::scaling;

const std::string kData = std::string(SKINLAB_SOURCE_DIR) + "/tests/data/pwcmp/ex3_tmo_cmp_data.csv";

// pwcmp's condition order (sorted).
const std::vector<std::string> kConditions = {"ferwerda96",  "hateren06", "irawan05",  "mantiuk08",
                                              "pattanaik00", "ronan12",   "tmo_camera"};

// pw_scale(M) per scene (JOD, mean 0), in kConditions order.
const std::map<std::string, std::vector<double>> kPwScaleDefault = {
    {"corridor", {0.014570, -1.515826, 0.535147, 0.791377, -0.946374, -0.281512, 1.402618}},
    {"exhibition", {-0.410124, -2.333515, 2.720643, 0.578473, -0.632531, -0.030569, 0.107623}},
    {"rivoli", {0.587874, -1.352813, 1.162747, 0.222544, -0.882205, 0.156884, 0.104969}},
    {"students", {-0.354554, -1.422776, 1.581292, 1.148735, -1.187561, 0.474357, -0.239492}},
    {"window", {-0.661357, -0.997592, 0.550104, 0.569595, 0.287648, -0.203632, 0.455235}},
};

// pw_scale(M, {'prior', 'none'}), optimised to convergence.
const std::map<std::string, std::vector<double>> kPwScaleNoPrior = {
    {"corridor", {0.015884, -1.590088, 0.551748, 0.822194, -0.978960, -0.290532, 1.469754}},
    {"exhibition", {-0.492948, -2.452168, 3.114946, 0.573610, -0.726006, -0.077187, 0.059752}},
    {"rivoli", {0.602636, -1.406312, 1.224491, 0.224622, -0.907097, 0.159166, 0.102493}},
    {"students", {-0.384987, -1.595550, 1.787474, 1.262040, -1.314603, 0.509601, -0.263974}},
    {"window", {-0.667827, -1.009606, 0.556554, 0.578819, 0.290255, -0.208421, 0.460227}},
};

// pw_outlier_analysis: per observer, log10 likelihood per compared pair L and dist_L.
const std::map<std::string, std::pair<double, double>> kOutliers = {
    {"F01", {-0.247047, 0.361470}}, {"F02", {-0.191290, 0.0}},      {"M01", {-0.211913, 0.0}},
    {"M02", {-0.326801, 3.452002}}, {"M03", {-0.207155, 0.0}},      {"M04", {-0.187972, 0.0}},
    {"M05", {-0.233002, 0.0}},      {"M06", {-0.260402, 0.878972}}, {"M07", {-0.217319, 0.0}},
    {"M08", {-0.199520, 0.0}},      {"M09", {-0.233047, 0.0}},      {"M10", {-0.225400, 0.0}},
    {"M11", {-0.212787, 0.0}},      {"M12", {-0.222862, 0.0}},      {"bab", {-0.353025, 4.468159}},
    {"hae", {-0.237719, 0.0}},      {"rfm", {-0.234406, 0.0}},      {"rwn", {-0.212723, 0.0}},
};

Dataset ex3() {
    const ResponseTable table = readResponses(kData);
    DatasetOptions options;
    options.conditionOrder = kConditions;
    return buildDataset(table, options);
}

TEST(PwcmpReference, ReadsPwcmpsOwnFileIgnoringExtraColumns) {
    const ResponseTable table = readResponses(kData);
    EXPECT_EQ(table.format, ResponseFormat::PwcmpCsv);
    EXPECT_EQ(table.responses.size(), 1213u);
    EXPECT_EQ(table.ignoredColumns, (std::vector<std::string>{"session_id", "criterion"}));
    const Dataset dataset = ex3();
    ASSERT_EQ(dataset.blocks.size(), 5u);
    for (const BlockData& block : dataset.blocks) EXPECT_EQ(block.observerCount(), 18) << block.name;
}

TEST(PwcmpReference, PwcmpPriorReproducesPwScale) {
    FitOptions pwcmp;
    pwcmp.prior = Prior::Pwcmp;
    FitOptions gaussian; // skinlab's default prior, for contrast: it differs from pw_scale by up to 0.38 JOD here
    double largestGaussianDifference = 0.0;
    for (const BlockData& block : ex3().blocks) {
        const std::vector<double>& expected = kPwScaleDefault.at(block.name);
        const FitResult fit = fitScores(block.totalCounts(), pwcmp);
        ASSERT_TRUE(fit.converged) << block.name;
        const FitResult skinlab = fitScores(block.totalCounts(), gaussian);
        for (size_t i = 0; i < expected.size(); ++i) {
            const auto k = static_cast<Eigen::Index>(i);
            // Measured: at most 1.5e-3 JOD apart (exhibition), about what fminunc's default stopping tolerances
            // leave (pw_scale run to TolFun = TolX = 1e-14 moves by up to 1.5e-3); the requirement is 0.01 JOD.
            EXPECT_NEAR(fit.scores[k], expected[i], 0.003) << block.name << " " << kConditions[i];
            largestGaussianDifference = std::max(largestGaussianDifference, std::abs(skinlab.scores[k] - expected[i]));
        }
    }
    EXPECT_GT(largestGaussianDifference, 0.3) << "the two priors should differ on this data";
}

TEST(PwcmpReference, PwcmpPriorReproducesExampleOne) {
    // examples/ex1_simple_scaling.m: D = [0 25 0; 75 0 25; 0 75 0]; pw_scale(D) gave -0.999998, 0, 0.999998.
    PairCounts counts;
    counts.conditions = 3;
    counts.pairs = {{0, 1}, {1, 2}};
    counts.first = Eigen::Vector2d(25, 25);
    counts.second = Eigen::Vector2d(75, 75);
    FitOptions options;
    options.prior = Prior::Pwcmp;
    const FitResult fit = fitScores(counts, options);
    EXPECT_NEAR(fit.scores[0], -0.999998, 1e-4);
    EXPECT_NEAR(fit.scores[1], 0.0, 1e-4);
    EXPECT_NEAR(fit.scores[2], 0.999998, 1e-4);
}

TEST(PwcmpReference, NegligibleGaussianPriorReproducesPwScaleWithoutPrior) {
    FitOptions options;
    options.priorPrecision = 1e-6;
    for (const BlockData& block : ex3().blocks) {
        const std::vector<double>& expected = kPwScaleNoPrior.at(block.name);
        const FitResult fit = fitScores(block.totalCounts(), options);
        for (size_t i = 0; i < expected.size(); ++i)
            EXPECT_NEAR(fit.scores[static_cast<Eigen::Index>(i)], expected[i], 1e-3)
                << block.name << " " << kConditions[i];
    }
}

TEST(PwcmpReference, OutlierAnalysisReproducesPwOutlierAnalysis) {
    AnalysisOptions options;
    options.pwcmpOutliers = true;
    options.bootstrap.samples = 100;
    options.intervals = IntervalMethod::profile; // intervals are not under test here
    const Analysis analysis = analyzeDataset(ex3(), options);
    ASSERT_EQ(analysis.observers.size(), kOutliers.size());
    std::vector<std::string> flagged;
    for (const ObserverSummary& observer : analysis.observers) {
        const auto& [likelihood, distance] = kOutliers.at(observer.observer);
        EXPECT_NEAR(observer.pwcmpLogLikelihood, likelihood, 5e-4) << observer.observer;
        // Measured: L within 2.1e-4, dist_L within 0.008 (the leave-one-out fits inherit fminunc's tolerance).
        EXPECT_NEAR(observer.pwcmpDistance, distance, 0.02) << observer.observer;
        if (observer.pwcmpOutlier) flagged.push_back(observer.observer);
    }
    EXPECT_EQ(flagged, (std::vector<std::string>{"M02", "bab"}));
}

} // namespace
