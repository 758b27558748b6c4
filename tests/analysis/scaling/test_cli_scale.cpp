// `skinlab analyze scale` end to end: a CSV export of simulated observers → every output file, well formed;
// a bad file → exit 2 and one line naming it; an existing output folder is never left half-written.
#include "analysis/scaling/screening.h"
#include "analysis/scaling/simulation.h"

#include "tests/common/cli_run.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

fs::path scratch() {
    const fs::path folder = fs::path(SKINLAB_BINARY_DIR) / "test-scratch" / "scaling-cli";
    fs::create_directories(folder);
    return folder;
}

using skinlab::test_support::CliRun;
CliRun run(const std::string& arguments) { return skinlab::test_support::runCli(arguments); }

// Contract-3 CSV from simulated observers, two blocks, with sides, a catch trial per observer.
std::string simulatedCsv() {
    using namespace skinlab::analysis::scaling;
    std::ostringstream csv;
    csv << "observer,scene,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,correct,response_ms\n";
    const char* names[] = {"none", "gaussian-sum", "separable", "artistic"};
    for (int b = 0; b < 2; ++b) {
        SimulationDesign design;
        design.trueScores = {0.0, 0.8, 1.2, 1.6};
        design.observers = 12;
        design.trialsPerPair = 4;
        design.randomObservers = b == 0 ? 1 : 0;
        const SimulatedBlock simulated = simulateBlock(design, 100 + b);
        const std::string scene = b == 0 ? "builtin:head/mid" : "builtin:head/close";
        for (int k = 0; k < design.observers; ++k) {
            for (size_t p = 0; p < simulated.block.pairs.size(); ++p) {
                const auto [i, j] = simulated.block.pairs[p];
                const auto pi = static_cast<Eigen::Index>(p);
                for (int w = 0; w < simulated.block.winsFirst(k, pi); ++w)
                    csv << "p" << k << "," << scene << "," << names[i] << "," << names[j] << ",1," << (w % 2)
                        << ",test,,900\n";
                for (int w = 0; w < simulated.block.winsSecond(k, pi); ++w)
                    csv << "p" << k << "," << scene << "," << names[j] << "," << names[i] << ",1," << (w % 2)
                        << ",test,,900\n";
            }
            csv << "p" << k << "," << scene << ",none,artistic,0,1,catch," << (k == 3 ? 0 : 1) << ",400\n";
        }
    }
    return csv.str();
}

TEST(CliScale, WritesEveryOutput) {
    const fs::path input = scratch() / "responses.csv";
    std::ofstream(input) << simulatedCsv();
    const fs::path output = scratch() / "out";
    fs::remove_all(output);
    const CliRun result = run("analyze scale " + input.string() + " -o " + output.string() + " --bootstrap 300");
    ASSERT_EQ(result.exitCode, 0) << result.output;
    for (const char* file : {"scale.json", "scores.csv", "pairs.csv", "observers.csv", "consistency.csv", "counts.csv",
                             "report_section.html"})
        EXPECT_TRUE(fs::exists(output / file)) << file;
    std::ifstream stream(output / "scale.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    ASSERT_EQ(json["blocks"].size(), 2u);
    const auto& mid = json["blocks"][0];
    EXPECT_EQ(mid["name"], "builtin:head/mid");
    EXPECT_EQ(mid["interval_method"], "studentized-bootstrap");
    EXPECT_EQ(json["settings"]["prior"], "gaussian");
    // True order none < gaussian-sum < separable < artistic; the extremes are 1.6 JOD apart.
    EXPECT_LT(mid["scores"][0]["jod"].get<double>(), mid["scores"][3]["jod"].get<double>());
    EXPECT_TRUE(mid["side_bias"]["available"].get<bool>());
    for (const char* plot : {"scores", "matrix"})
        EXPECT_TRUE(fs::exists(output / mid["plots"][plot].get<std::string>()));
    // Observer p3 failed both catch trials: the protocol's rule (the one the dashboard and the report apply) leaves
    // p3 out of the scale; p11 answered at random in block 1 and stays in (screening flags, it does not exclude).
    ASSERT_EQ(json["excluded_observers"].size(), 1u);
    EXPECT_EQ(json["excluded_observers"][0]["observer"], "p3");
    EXPECT_EQ(json["excluded_observers"][0]["reason"], "failed 2 of 2 catch trials");
    EXPECT_EQ(mid["observers"], 11);
    for (const auto& observer : json["observers"]) EXPECT_NE(observer["observer"], "p3");
    EXPECT_NE(result.output.find("excluded observer p3: failed 2 of 2 catch trials"), std::string::npos)
        << result.output;
    const std::string html = (std::ostringstream() << std::ifstream(output / "report_section.html").rdbuf()).str();
    EXPECT_EQ(html.rfind("<section class=\"skinlab-scaling\">", 0), 0u);
    EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
    EXPECT_NE(result.output.find("builtin:head/close"), std::string::npos);
    // Each block's count of significant pairs, as scale.json records them.
    for (const auto& block : json["blocks"]) {
        int significant = 0;
        for (const auto& pair : block["pairs"]) significant += pair["significant"].get<bool>() ? 1 : 0;
        const std::string line = "  significant pairs: " + std::to_string(significant) + " of " +
                                 std::to_string(block["pairs"].size()) + " (correction over the block's pairs: holm)\n";
        EXPECT_NE(result.output.find(line), std::string::npos) << line << result.output;
    }
}

// --no-exclusion scales every observer, p3 with its two failed catch trials among them.
TEST(CliScale, NoExclusionKeepsCatchTrialFailures) {
    const fs::path input = scratch() / "responses-all.csv";
    std::ofstream(input) << simulatedCsv();
    const fs::path output = scratch() / "out-all";
    fs::remove_all(output);
    const CliRun result =
        run("analyze scale " + input.string() + " -o " + output.string() + " --bootstrap 100 --no-exclusion");
    ASSERT_EQ(result.exitCode, 0) << result.output;
    std::ifstream stream(output / "scale.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    EXPECT_TRUE(json["excluded_observers"].empty());
    EXPECT_EQ(json["blocks"][0]["observers"], 12);
    bool sawCatch = false;
    for (const auto& observer : json["observers"])
        if (observer["observer"] == "p3") sawCatch = observer["catch_failures"] == 2;
    EXPECT_TRUE(sawCatch);
}

TEST(ExclusionRule, NoAnswersOrMoreThanOneFailedCatchTrialInFour) {
    using skinlab::analysis::scaling::exclusionReason;
    EXPECT_EQ(exclusionReason(0, 0, 0).value_or(""), "no answers");
    EXPECT_FALSE(exclusionReason(10, 0, 0));
    EXPECT_FALSE(exclusionReason(10, 4, 1)); // one in four: kept
    EXPECT_EQ(exclusionReason(10, 4, 2).value_or(""), "failed 2 of 4 catch trials");
    EXPECT_EQ(exclusionReason(10, 2, 1).value_or(""), "failed 1 of 2 catch trials");
    EXPECT_FALSE(exclusionReason(10, 8, 2));
}

TEST(CliScale, BadInputExitsTwoWithOneLine) {
    const fs::path input = scratch() / "negative.csv";
    std::ofstream(input) << "condition,a,b\na,0,-1\nb,3,0\n";
    const fs::path output = scratch() / "bad-out";
    fs::remove_all(output);
    const CliRun result = run("analyze scale " + input.string() + " -o " + output.string());
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_EQ(result.output, "skinlab: error: " + input.string() + ": line 2: column b: negative count -1\n");
    EXPECT_FALSE(fs::exists(output / "scale.json"));
}

TEST(CliScale, CountMatrixOracle) {
    const fs::path input = scratch() / "oracle.csv";
    std::ofstream(input) << "condition,A,B,C\nA,0,25,0\nB,75,0,25\nC,0,75,0\n";
    const fs::path output = scratch() / "oracle-out";
    const CliRun result = run("analyze scale " + input.string() + " -o " + output.string());
    ASSERT_EQ(result.exitCode, 0) << result.output;
    std::ifstream stream(output / "scale.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    const auto& scores = json["blocks"][0]["scores"];
    EXPECT_NEAR(scores[0]["jod"].get<double>(), -1.0, 1e-3);
    EXPECT_NEAR(scores[2]["jod"].get<double>(), 1.0, 1e-3);
    EXPECT_EQ(json["blocks"][0]["interval_method"], "profile-likelihood");
}

TEST(CliScale, AConditionNeverComparedIsNotMeasuredInEveryOutput) {
    // D has no comparison at all: it has no score (the prior alone puts it at 0) and no interval (the profile search
    // stopped at ±200 JOD), so no output may print a number for it.
    const fs::path input = scratch() / "unmeasured.csv";
    std::ofstream(input) << "condition,A,B,C,D\nA,0,25,0,0\nB,75,0,25,0\nC,0,75,0,0\nD,0,0,0,0\n";
    const fs::path output = scratch() / "unmeasured-out";
    const CliRun result = run("analyze scale " + input.string() + " -o " + output.string());
    ASSERT_EQ(result.exitCode, 0) << result.output;
    EXPECT_NE(result.output.find("D                        not measured"), std::string::npos) << result.output;
    std::ifstream stream(output / "scale.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    const auto& d = json["blocks"][0]["scores"][3];
    EXPECT_EQ(d["condition"], "D");
    EXPECT_EQ(d["measured"], false);
    EXPECT_TRUE(d["jod"].is_null()) << d.dump();
    EXPECT_TRUE(d["ci_low"].is_null() && d["ci_high"].is_null()) << d.dump();
    EXPECT_EQ(d["bound"], "not-measured");
    EXPECT_EQ(json["blocks"][0]["scores"][0]["measured"], true);
    for (const auto& pair : json["blocks"][0]["pairs"])
        if (pair["condition_B"] == "D") {
            EXPECT_TRUE(pair["difference_jod"].is_null()) << pair.dump();
            EXPECT_EQ(pair["bound"], "not-measured");
        }
    std::ifstream csvStream(output / "scores.csv");
    std::string line, dLine;
    while (std::getline(csvStream, line))
        if (line.rfind("matrix,D,", 0) == 0 || line.find(",D,") != std::string::npos) dLine = line;
    ASSERT_FALSE(dLine.empty());
    EXPECT_NE(dLine.find(",D,,,,,"), std::string::npos) << dLine; // jod, ci_low, ci_high, standard_error empty
    EXPECT_NE(dLine.find("not-measured"), std::string::npos) << dLine;
    std::ifstream htmlStream(output / "report_section.html");
    const std::string html((std::istreambuf_iterator<char>(htmlStream)), std::istreambuf_iterator<char>());
    EXPECT_NE(html.find("<td>D</td><td colspan=\"4\">not measured"), std::string::npos);
}

TEST(CliScale, PwcmpsOwnExampleFileWithItsPriorAndOutlierAnalysis) {
    // pwcmp's examples/ex3_tmo_cmp_data.csv as it is (extra columns session_id and criterion).
    const std::string input = std::string(SKINLAB_SOURCE_DIR) + "/tests/data/pwcmp/ex3_tmo_cmp_data.csv";
    const fs::path output = scratch() / "ex3-out";
    fs::remove_all(output);
    const CliRun result = run("analyze scale " + input + " -o " + output.string() +
                              " --prior pwcmp --pwcmp-outliers --intervals percentile --bootstrap 200");
    ASSERT_EQ(result.exitCode, 0) << result.output;
    EXPECT_NE(result.output.find("ignored column(s) session_id, criterion"), std::string::npos) << result.output;
    std::ifstream stream(output / "scale.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    EXPECT_EQ(json["settings"]["prior"], "pwcmp");
    EXPECT_TRUE(json["settings"]["prior_precision"].is_null());
    EXPECT_EQ(json["settings"]["intervals"], "percentile");
    ASSERT_EQ(json["blocks"].size(), 5u);
    for (const auto& block : json["blocks"]) EXPECT_EQ(block["interval_method"], "percentile-bootstrap");
    // pwcmp's example flags M02 and bab (dist_L > 1.5).
    std::vector<std::string> flagged;
    for (const auto& observer : json["observers"])
        if (observer["pwcmp_outlier"] == true) flagged.push_back(observer["observer"]);
    EXPECT_EQ(flagged, (std::vector<std::string>{"M02", "bab"}));
    const std::string scores = (std::ostringstream() << std::ifstream(output / "scores.csv").rdbuf()).str();
    EXPECT_NE(scores.find(",bound,prior,prior_driven\n"), std::string::npos);
    EXPECT_NE(scores.find(",two-sided,pwcmp,0\n"), std::string::npos);
    const std::string html = (std::ostringstream() << std::ifstream(output / "report_section.html").rdbuf()).str();
    EXPECT_NE(html.find("pwcmp's prior"), std::string::npos);
}

TEST(CliValidate, SmallRunMeetsTheScreeningTargets) {
    const fs::path output = scratch() / "validate";
    const CliRun result = run(
        "analyze validate --experiments 20 --observers 20 --bootstrap 200 --scenarios screening -o " + output.string());
    ASSERT_EQ(result.exitCode, 0) << result.output;
    std::ifstream stream(output / "validation.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    ASSERT_EQ(json["rows"].size(), 1u);
    EXPECT_EQ(json["rows"][0]["inverted_hit_rate"].get<double>(), 1.0);
    EXPECT_GE(json["rows"][0]["random_hit_rate"].get<double>(), 0.9);
    EXPECT_LE(json["rows"][0]["false_alarm_rate"].get<double>(), 0.02);
}

TEST(CliValidate, DegenerateScenariosGiveFiniteIntervals) {
    const fs::path output = scratch() / "validate-degenerate";
    const CliRun result = run("analyze validate --experiments 6 --observers 10 --bootstrap 200 --trials-per-pair 2 "
                              "--scenarios sparse,disconnected,near-unanimous -o " +
                              output.string());
    ASSERT_EQ(result.exitCode, 0) << result.output;
    std::ifstream stream(output / "validation.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    ASSERT_EQ(json["rows"].size(), 3u);
    for (const auto& row : json["rows"]) {
        EXPECT_TRUE(row["coverage"].is_number()) << row.dump();
        EXPECT_LT(row["maximum_half_width"].get<double>(), 250.0) << row.dump();
        EXPECT_GT(row["mean_width"].get<double>(), 0.0) << row.dump();
    }
    EXPECT_EQ(json["rows"][1]["fallback_share"].get<double>(), 1.0) << "disconnected designs always fall back";
    const CliRun bad = run("analyze validate --scenarios sparse,unknown");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.output.find("'unknown' is not one of"), std::string::npos) << bad.output;
}

TEST(CliValidate, NearUnanimousDesignsCoverScoresPairsAndOneSidedBounds) {
    // 5 conditions 1.5 JOD apart, 10 observers, 1 trial per pair: most pairs unanimous. The reported intervals
    // (open ends open, the finite end of a one-sided interval at the exact one-sided bound) must hold the truth
    // ≥ 94.5 % of the time for scores and pairs, and so must the finite ends of the one-sided intervals. With the
    // χ²₁ bound as the finite end, those one-sided intervals covered 0.75–0.85 (scores) and 0.54–0.93 (pairs).
    const fs::path output = scratch() / "validate-near-unanimous";
    const CliRun result = run("analyze validate --scores 0,1.5,3,4.5,6 --trials-per-pair 1 --observers 10 "
                              "--experiments 150 --bootstrap 200 --scenarios thurstone --seed 3 -o " +
                              output.string());
    ASSERT_EQ(result.exitCode, 0) << result.output;
    std::ifstream stream(output / "validation.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    const auto& row = json["rows"].at(0);
    EXPECT_GE(row["coverage"].get<double>(), 0.945) << row.dump();
    EXPECT_GE(row["pair_coverage"].get<double>(), 0.945) << row.dump();
    EXPECT_GT(row["one_sided_share"].get<double>(), 0.2) << "the design is near-unanimous: " << row.dump();
    EXPECT_GE(row["one_sided_coverage"].get<double>(), 0.945) << row.dump();
    EXPECT_GE(row["pair_one_sided_coverage"].get<double>(), 0.945) << row.dump();
}

TEST(CliValidate, ActiveScenarioRunsWithProfileIntervals) {
    // Small numbers: the point is that the scenario runs through the study server's planner and reports the
    // likelihood intervals next to the bootstrap's (analyze scale's choice for active studies) and the union's
    // coverage; the figures themselves are in docs/analysis.md.
    const fs::path output = scratch() / "validate-active";
    const CliRun result = run("analyze validate --experiments 4 --observers 6 --bootstrap 100 --scores 0,0.5,1,2,3 "
                              "--active-trials 8 --scenarios active -o " +
                              output.string());
    ASSERT_EQ(result.exitCode, 0) << result.output;
    std::ifstream stream(output / "validation.json");
    const nlohmann::json json = nlohmann::json::parse(stream);
    ASSERT_EQ(json["rows"].size(), 1u);
    const auto& row = json["rows"][0];
    EXPECT_EQ(row["scenario"], "active");
    EXPECT_EQ(row["experiments"], 4);
    EXPECT_GT(row["coverage"].get<double>(), 0.5) << row.dump();
    EXPECT_LE(row["coverage"].get<double>(), 1.0) << row.dump();
    EXPECT_TRUE(row["bootstrap_coverage"].is_number()) << row.dump();
    // The union of the two intervals holds every truth either holds.
    EXPECT_GE(row["union_coverage"].get<double>(), row["coverage"].get<double>()) << row.dump();
    EXPECT_GE(row["union_coverage"].get<double>(), row["bootstrap_coverage"].get<double>()) << row.dump();
    EXPECT_LE(row["union_coverage"].get<double>(), 1.0) << row.dump();
    EXPECT_GT(row["mean_width"].get<double>(), 0.0) << row.dump();
    EXPECT_LT(row["maximum_half_width"].get<double>(), 250.0) << row.dump();
    EXPECT_EQ(json["options"]["active_trials"], 8);
    EXPECT_NE(result.output.find("| active | 6 |"), std::string::npos) << result.output;
}

} // namespace
