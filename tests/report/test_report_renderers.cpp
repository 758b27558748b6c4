// A block whose conditions come from different renderers (skinlab's rasterizer and EEVEE, each with its no-SSS
// baseline): `skinlab report` warns in one line and lists each SSS condition's JOD against its own renderer's
// baseline; a block of one renderer gets neither (docs/pathtraced.md, "EEVEE against the rasterizer").
#include "common/files.h"
#include "experiments/study_creation.h"
#include "experiments/study_store.h"
#include "stimulus_set_fixture.h"
#include "store_answer.h"
#include "tests/common/cli_run.h"

#include <gtest/gtest.h>

using namespace skinlab::experiments;
using namespace skinlab::experiments::test_support;
namespace fs = std::filesystem;

namespace {

const char* kDesign = R"(
title = "Renderer test"
seed = 3
repetitions = 2
)";

// Answers every trial by a fixed preference (the lower condition index wins).
void participate(StudyStore& store, const std::string& label) {
    const ParticipantRecord p = store.join(label);
    const std::int64_t session = store.startSession(p.id, "test", 1280, 800, 1.0);
    while (const std::optional<TrialRecord> trial = store.nextTrial(p.id)) {
        const PlannedTrial& plan = trial->plan;
        const bool chooseA =
            plan.kind == TrialKind::catchTrial ? plan.expected == 'A' : plan.conditionA < plan.conditionB;
        store.recordResponse(storeAnswer(p, session, *trial, chooseA == plan.aOnLeft ? "left" : "right"));
    }
}

std::string reportOf(const std::vector<std::string>& methods, const std::string& stem) {
    TempFolder folder(stem);
    StimulusSetSpec spec;
    spec.blocks = {"builtin:head/mid"};
    spec.methods = methods;
    spec.withReference = false;
    writeStimulusSet(folder.path() / "stimuli", spec);
    const fs::path database = folder.path() / "study.db";
    createStudy(folder.path() / "stimuli", writeText(folder.path(), "design.toml", kDesign), {}, database);
    {
        StudyStore store(database);
        for (const char* label : {"A1", "A2", "A3"}) participate(store, label);
    }
    const fs::path reportFolder = folder.path() / "report";
    const skinlab::test_support::CliRun reported = skinlab::test_support::runCli(
        "report " + database.string() + " -o " + reportFolder.string() + " --no-pdf --bootstrap 100");
    EXPECT_EQ(reported.exitCode, 0) << reported.output;
    return reported.exitCode == 0 ? skinlab::readFile(reportFolder / "index.html") : std::string();
}

} // namespace

TEST(ReportRenderers, SssEffectsWithinEachRendererAndOneWarningAcrossRenderers) {
    const std::string mixed = reportOf({"none", "separable", "eevee", "eevee-no-sss"}, "report-renderers-mixed");
    EXPECT_NE(mixed.find("Warning: builtin:head/mid: conditions of different renderers (skinlab, eevee) are compared "
                         "directly"),
              std::string::npos);
    EXPECT_NE(mixed.find("SSS effect within each renderer"), std::string::npos);
    // separable against none, eevee against eevee-no-sss: never eevee against skinlab's none.
    EXPECT_NE(mixed.find("<td class=\"l\">separable</td><td class=\"l\">skinlab</td><td class=\"l\">none</td>"),
              std::string::npos);
    EXPECT_NE(mixed.find("<td class=\"l\">eevee</td><td class=\"l\">eevee</td><td class=\"l\">eevee-no-sss</td>"),
              std::string::npos);

    const std::string single = reportOf({"none", "separable", "artistic"}, "report-renderers-single");
    EXPECT_FALSE(single.empty());
    EXPECT_EQ(single.find("conditions of different renderers"), std::string::npos);
    EXPECT_EQ(single.find("SSS effect within each renderer"), std::string::npos);
}
