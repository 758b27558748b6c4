// `skinlab analyze scale` and `skinlab report` leave out the same observers: on one study file with an observer who
// fails the catch trials, one who answered only the practice trial and one who never answered, the two scale.json
// files list the same excluded observers and scale the same ones (the protocol's rule, scaling::excludeObservers).
#include "experiments/study_creation.h"
#include "experiments/study_store.h"
#include "common/files.h"
#include "stimulus_set_fixture.h"
#include "store_answer.h"
#include "tests/common/cli_run.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <set>

using namespace skinlab::experiments;
using namespace skinlab::experiments::test_support;
namespace fs = std::filesystem;

namespace {

const char* kDesign = R"(
title = "Exclusion test"
seed = 5
repetitions = 2
[practice]
trials = 1
[catch]
blank = 2
)";

enum class Attention { attentive, failsCatchTrials, practiceOnly, joinsOnly };

// Answers the observer's trials: catch trials right (attentive) or wrong, the others by a fixed preference.
void participate(StudyStore& store, const std::string& label, Attention attention) {
    const ParticipantRecord p = store.join(label);
    if (attention == Attention::joinsOnly) return;
    const std::int64_t session = store.startSession(p.id, "test", 1280, 800, 1.0);
    while (const std::optional<TrialRecord> trial = store.nextTrial(p.id)) {
        const PlannedTrial& plan = trial->plan;
        if (attention == Attention::practiceOnly && plan.kind != TrialKind::practice) break;
        bool chooseA = plan.conditionA < plan.conditionB; // a consistent preference
        if (plan.kind == TrialKind::catchTrial)
            chooseA = (plan.expected == 'A') == (attention != Attention::failsCatchTrials);
        store.recordResponse(storeAnswer(p, session, *trial, chooseA == plan.aOnLeft ? "left" : "right"));
    }
}

nlohmann::json readJson(const fs::path& path) { return nlohmann::json::parse(skinlab::readFile(path)); }

std::set<std::string> excludedIn(const nlohmann::json& scale) {
    std::set<std::string> names;
    for (const nlohmann::json& e : scale.at("excluded_observers")) names.insert(e.at("observer").get<std::string>());
    return names;
}

std::set<std::string> scaledIn(const nlohmann::json& scale) {
    std::set<std::string> names;
    for (const nlohmann::json& o : scale.at("observers")) names.insert(o.at("observer").get<std::string>());
    return names;
}

} // namespace

TEST(ReportExclusion, ReportAndAnalyzeScaleLeaveOutTheSameObservers) {
    TempFolder folder("report-exclusion");
    StimulusSetSpec spec;
    spec.blocks = {"scene:a/mid"};
    spec.withReference = false; // no image metrics: the test is about the observers
    writeStimulusSet(folder.path() / "stimuli", spec);
    const fs::path database = folder.path() / "study.db";
    createStudy(folder.path() / "stimuli", writeText(folder.path(), "design.toml", kDesign), {}, database);
    {
        StudyStore store(database);
        for (const char* label : {"A1", "A2", "A3"}) participate(store, label, Attention::attentive);
        participate(store, "careless", Attention::failsCatchTrials);
        participate(store, "practice-only", Attention::practiceOnly);
        participate(store, "absent", Attention::joinsOnly);
    }

    const fs::path scaleFolder = folder.path() / "scale";
    const skinlab::test_support::CliRun scaled = skinlab::test_support::runCli(
        "analyze scale " + database.string() + " -o " + scaleFolder.string() + " --bootstrap 100");
    ASSERT_EQ(scaled.exitCode, 0) << scaled.output;
    const fs::path reportFolder = folder.path() / "report";
    const skinlab::test_support::CliRun reported = skinlab::test_support::runCli(
        "report " + database.string() + " -o " + reportFolder.string() + " --no-pdf --bootstrap 100");
    ASSERT_EQ(reported.exitCode, 0) << reported.output;

    const nlohmann::json fromAnalyze = readJson(scaleFolder / "scale.json");
    const nlohmann::json fromReport = readJson(reportFolder / "scale.json");
    const std::set<std::string> excluded{"careless", "practice-only"};
    EXPECT_EQ(excludedIn(fromAnalyze), excluded) << fromAnalyze.at("excluded_observers").dump();
    EXPECT_EQ(excludedIn(fromReport), excluded) << fromReport.at("excluded_observers").dump();
    EXPECT_EQ(scaledIn(fromAnalyze), (std::set<std::string>{"A1", "A2", "A3"}));
    EXPECT_EQ(scaledIn(fromReport), scaledIn(fromAnalyze));
    // The page counts them the same way: 3 analysed; the never-answering participant is excluded there too.
    EXPECT_NE(skinlab::readFile(reportFolder / "index.html").find("6 joined, 3 analysed, 3 excluded"),
              std::string::npos);
}
