// Integration tests of active designs (pairs = "active"): the plan is stored batch by batch from the posterior of
// the stored answers, so reopening the study (a restart) changes nothing; a study runs end to end through the real
// `skinlab study` executable with simulated observers over HTTP while the server is killed with SIGKILL, every
// stored trial stays as it was, and `skinlab analyze scale` scales the export.
#include "child_process.h"
#include "common/files.h"
#include "experiments/simulated_observers.h"
#include "experiments/study_creation.h"
#include "experiments/study_store.h"
#include "stimulus_set_fixture.h"

#include <csignal>
#include <gtest/gtest.h>
#include <map>
#include <regex>
#include <thread>

using namespace skinlab::experiments;
using namespace skinlab::experiments::test_support;
namespace fs = std::filesystem;

namespace {

const char* kDesign = R"(
title = "Active test"
seed = 9
pairs = "active"
trials_per_participant = 12
[practice]
trials = 1
[catch]
blank = 2
)";

// 2 blocks × 5 conditions (4 methods + the reference): batches of 4 pairs.
StimulusSetSpec fiveConditions() {
    StimulusSetSpec spec;
    spec.methods = {"reference-like", "separable", "artistic", "flat"};
    return spec;
}

const std::map<std::string, double> kTruth = {
    {"reference", 2.0}, {"reference-like", 1.2}, {"separable", 1.0}, {"artistic", 0.0}, {"flat", -1.5}};

struct StudyFiles {
    TempFolder folder{"active"};
    fs::path stimuli = folder.path() / "stimuli";
    fs::path design;
    fs::path database = folder.path() / "study.db";
    StudyFiles() {
        writeStimulusSet(stimuli, fiveConditions());
        design = writeText(folder.path(), "design.toml", kDesign);
    }
};

CommandResult runSkinlab(std::vector<std::string> arguments) {
    arguments.insert(arguments.begin(), SKINLAB_CLI);
    return runCommand(arguments);
}

int startServer(std::unique_ptr<ChildProcess>& child, const fs::path& database, int port) {
    child = std::make_unique<ChildProcess>(std::vector<std::string>{SKINLAB_CLI, "study", "serve", database.string(),
                                                                    "--port", std::to_string(port), "--token",
                                                                    "researcher-token-0123456789", "--threads", "16"});
    static const std::regex serving(R"(serving .* on http://127\.0\.0\.1:(\d+)/)");
    for (int i = 0; i < 10; ++i) {
        bool ok = false;
        const std::string line = child->readLine(std::chrono::seconds(20), ok);
        if (!ok) break;
        std::smatch m;
        if (std::regex_search(line, m, serving)) return std::stoi(m[1].str());
    }
    return -1;
}

std::string describe(const TrialRecord& t) {
    return std::to_string(t.id) + "@" + std::to_string(t.position) + ":" + trialKindName(t.plan.kind) + ":" +
           t.plan.block + ":" + t.plan.conditionA + "/" + t.plan.conditionB + (t.plan.aOnLeft ? ":L" : ":R");
}

// Every stored trial of every participant.
std::map<std::int64_t, std::string> storedPlan(StudyStore& store) {
    std::map<std::int64_t, std::string> out;
    for (const ParticipantStatus& p : store.status())
        for (const TrialRecord& t : store.trials(p.participant.id)) out[t.id] = describe(t);
    return out;
}

// Answers every trial of a participant in-process (no HTTP): the better condition by kTruth always wins.
std::vector<std::string> answerAll(const fs::path& database, const std::string& label, bool reopenBetweenBatches) {
    auto store = std::make_unique<StudyStore>(database);
    const ParticipantRecord p = store->join(label);
    const std::int64_t session = store->startSession(p.id, "test", 800, 600, 1.0);
    std::vector<std::string> shown;
    for (int guard = 0; guard < 100; ++guard) {
        if (reopenBetweenBatches) store = std::make_unique<StudyStore>(database); // a restart before every trial
        const std::optional<TrialRecord> next = store->nextTrial(p.id);
        if (!next) break;
        shown.push_back(describe(*next));
        const PlannedTrial& t = next->plan;
        bool chooseA = true;
        if (t.kind == TrialKind::catchTrial) chooseA = t.expected == 'A';
        else if (t.stimulusB != kBlankStimulus) chooseA = kTruth.at(t.conditionA) > kTruth.at(t.conditionB);
        ResponseInput in;
        in.token = p.token;
        in.trialId = trialReference(p.token, next->id);
        in.side = chooseA == t.aOnLeft ? "left" : "right";
        in.sessionId = session;
        in.clientTime = "2026-01-01T00:00:00.000Z";
        store->recordResponse(in);
    }
    return shown;
}

} // namespace

TEST(ActiveStudy, PlansFromStoredAnswersSoARestartChangesNothing) {
    // Two copies of the same study; three participants in turn. In one copy the store is reopened before every
    // trial (each batch is planned by a fresh process state from the database alone), in the other never.
    std::vector<std::vector<std::string>> plans[2];
    for (int copy = 0; copy < 2; ++copy) {
        StudyFiles files;
        const CreatedStudy created = createStudy(files.stimuli, files.design, {}, files.database);
        EXPECT_EQ(created.trialsPerParticipant, 15); // 1 practice + 12 test + 2 catch
        for (const char* label : {"A", "B", "C"}) plans[copy].push_back(answerAll(files.database, label, copy == 1));
        StudyStore store(files.database);
        for (const ParticipantStatus& s : store.status()) {
            EXPECT_EQ(s.progress.total, 15);
            EXPECT_EQ(s.progress.answered, 15);
            EXPECT_EQ(s.testAnswered, 12);
            EXPECT_EQ(s.catchCorrect, 2);
        }
    }
    ASSERT_EQ(plans[0].size(), 3u);
    for (std::size_t p = 0; p < 3; ++p) {
        ASSERT_EQ(plans[0][p].size(), 15u);
        EXPECT_EQ(plans[0][p], plans[1][p]) << "participant " << p;
    }
    // Later participants' batches follow the answers: the posterior separates the conditions, so their plans differ
    // from the first participant's (planned from the prior).
    EXPECT_NE(plans[0][0], plans[0][2]);
}

TEST(ActiveStudy, ConcurrentRequestsOfOneParticipantStoreOneBatch) {
    // A batch is planned outside the store's lock and stored after a re-check: requests of the same participant
    // racing for the next batch must store it once, and all of them see the same next trial.
    StudyFiles files;
    createStudy(files.stimuli, files.design, {}, files.database);
    StudyStore store(files.database);
    const ParticipantRecord p = store.join("racer");
    const std::int64_t session = store.startSession(p.id, "test", 800, 600, 1.0);
    for (int guard = 0; guard < 100; ++guard) {
        std::vector<std::optional<TrialRecord>> seen(8);
        std::vector<std::thread> threads;
        for (std::size_t k = 0; k < seen.size(); ++k) threads.emplace_back([&, k] { seen[k] = store.nextTrial(p.id); });
        for (std::thread& t : threads) t.join();
        for (const auto& s : seen) {
            ASSERT_EQ(s.has_value(), seen[0].has_value());
            if (s) {
                EXPECT_EQ(s->id, seen[0]->id);
            }
        }
        if (!seen[0]) break;
        const PlannedTrial& t = seen[0]->plan;
        bool chooseA = true;
        if (t.kind == TrialKind::catchTrial) chooseA = t.expected == 'A';
        else if (t.stimulusB != kBlankStimulus) chooseA = kTruth.at(t.conditionA) > kTruth.at(t.conditionB);
        ResponseInput in;
        in.token = p.token;
        in.trialId = trialReference(p.token, seen[0]->id);
        in.side = chooseA == t.aOnLeft ? "left" : "right";
        in.sessionId = session;
        in.clientTime = "2026-01-01T00:00:00.000Z";
        store.recordResponse(in);
    }
    const std::vector<TrialRecord> trials = store.trials(p.id);
    ASSERT_EQ(trials.size(), 15u);
    for (std::size_t k = 0; k < trials.size(); ++k) EXPECT_EQ(trials[k].position, static_cast<int>(k));
    EXPECT_EQ(store.responseCount(), 15);
}

TEST(ActiveStudy, RunsEndToEndOverHttpAndItsPlanSurvivesKillNine) {
    StudyFiles files;
    const CommandResult created = runSkinlab({"study", "create", "--stimuli", files.stimuli.string(), "--design",
                                              files.design.string(), "-o", files.database.string()});
    ASSERT_EQ(created.exitCode, 0) << created.err;
    EXPECT_NE(created.out.find("per participant 15 trials (1 practice, 12 test, 0 repeat, 2 catch)"), std::string::npos)
        << created.out;

    std::unique_ptr<ChildProcess> server;
    const int port = startServer(server, files.database, 0);
    ASSERT_GT(port, 0);
    StudyStore store(files.database);
    SimulationOptions options;
    options.port = port;
    options.observers = 10;
    options.seed = 4;
    options.labelPrefix = "active";
    options.thinkMinMs = 5; // keeps the session going while the server is killed
    options.thinkMaxMs = 15;
    options.truth.byCondition = kTruth;
    SimulationReport report;
    std::thread simulation([&] { report = simulateObservers(store, options); });

    const std::int64_t total = 10 * 15;
    std::map<std::int64_t, std::string> beforeKill;
    int kills = 0;
    for (std::int64_t threshold : {total / 4, total / 2}) {
        for (int i = 0; i < 3000 && store.responseCount() < threshold; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        ASSERT_LT(store.responseCount(), total) << "the session ended before the kill; make it longer";
        server->kill(SIGKILL);
        EXPECT_EQ(server->wait(), 128 + SIGKILL);
        ++kills;
        // Every trial stored so far (shown or about to be) must come back unchanged.
        for (const auto& [id, text] : storedPlan(store)) beforeKill.emplace(id, text);
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        ASSERT_EQ(startServer(server, files.database, port), port);
    }
    simulation.join();
    EXPECT_EQ(kills, 2);
    for (const ObserverResult& o : report.observers) EXPECT_TRUE(o.failure.empty()) << o.label << ": " << o.failure;
    EXPECT_EQ(report.completed(), 10);
    EXPECT_EQ(store.responseCount(), total);

    const std::map<std::int64_t, std::string> after = storedPlan(store);
    EXPECT_EQ(after.size(), static_cast<std::size_t>(total));
    ASSERT_FALSE(beforeKill.empty());
    for (const auto& [id, text] : beforeKill) {
        ASSERT_TRUE(after.count(id)) << "trial " << id << " vanished";
        EXPECT_EQ(after.at(id), text) << "a stored trial was re-planned";
    }
    // Each plan: positions 0..14, practice first, 12 test trials, 2 catch trials; every response acknowledged once.
    std::size_t acknowledged = 0;
    for (const ObserverResult& o : report.observers) acknowledged += o.acknowledged.size();
    EXPECT_EQ(acknowledged, static_cast<std::size_t>(total));
    for (const ParticipantStatus& p : store.status()) {
        const std::vector<TrialRecord> trials = store.trials(p.participant.id);
        ASSERT_EQ(trials.size(), 15u) << p.participant.label;
        EXPECT_EQ(trials.front().plan.kind, TrialKind::practice);
        std::map<TrialKind, int> kinds;
        for (std::size_t k = 0; k < trials.size(); ++k) {
            EXPECT_EQ(trials[k].position, static_cast<int>(k));
            ++kinds[trials[k].plan.kind];
        }
        EXPECT_EQ(kinds[TrialKind::test], 12);
        EXPECT_EQ(kinds[TrialKind::catchTrial], 2);
        EXPECT_EQ(p.catchCorrect, 2);
    }

    // The CLI's own simulate runs further observers through the restarted server.
    const CommandResult simulated =
        runSkinlab({"study", "simulate", files.database.string(), "--observer-count", "2", "--url",
                    "http://127.0.0.1:" + std::to_string(port), "--truth-factor", "quality", "--label-prefix", "cli"});
    EXPECT_EQ(simulated.exitCode, 0) << simulated.out << simulated.err;
    EXPECT_NE(simulated.out.find("2/2 observers completed, 30 responses acknowledged, 0 rejected"), std::string::npos)
        << simulated.out;
    const CommandResult status = runSkinlab({"study", "status", files.database.string()});
    EXPECT_NE(status.out.find("12 participants, 12 completed, 180 responses"), std::string::npos) << status.out;

    // The analysis is unchanged: the export scales like any other.
    const fs::path exported = files.folder.path() / "responses.csv";
    ASSERT_EQ(
        runSkinlab({"study", "export", files.database.string(), "--format", "csv", "-o", exported.string()}).exitCode,
        0);
    const fs::path analysis = files.folder.path() / "scale";
    const CommandResult scaled =
        runSkinlab({"analyze", "scale", exported.string(), "-o", analysis.string(), "--bootstrap", "200"});
    ASSERT_EQ(scaled.exitCode, 0) << scaled.out << scaled.err;
    const nlohmann::json scale = nlohmann::json::parse(skinlab::readFile(analysis / "scale.json"));
    ASSERT_EQ(scale.at("blocks").size(), 2u) << scale.dump();
    for (const auto& block : scale.at("blocks")) {
        ASSERT_EQ(block.at("conditions").size(), 5u) << block.dump();
    }
    EXPECT_EQ(scale.at("settings").at("intervals"), "bootstrap"); // a CSV export does not say how pairs were chosen
    // Scaled from study.db, the design is known and said in the output; its intervals are the union of the
    // studentized bootstrap and the profile likelihood (neither alone covers 95 % at every number of observers in
    // active designs), each on request.
    const fs::path fromDatabase = files.folder.path() / "scale-db";
    const CommandResult scaledDb =
        runSkinlab({"analyze", "scale", files.database.string(), "-o", fromDatabase.string(), "--bootstrap", "200"});
    ASSERT_EQ(scaledDb.exitCode, 0) << scaledDb.out << scaledDb.err;
    EXPECT_NE(scaledDb.out.find("active design (pairs chosen from earlier answers): the union of the studentized "
                                "bootstrap and profile-likelihood intervals"),
              std::string::npos)
        << scaledDb.out;
    const nlohmann::json scaleDb = nlohmann::json::parse(skinlab::readFile(fromDatabase / "scale.json"));
    EXPECT_EQ(scaleDb.at("settings").at("intervals"), "bootstrap+profile");
    EXPECT_EQ(scaleDb.at("settings").at("intervals_reason"), "active design");
    for (const auto& block : scaleDb.at("blocks"))
        EXPECT_EQ(block.at("interval_method"), "studentized-bootstrap+profile-likelihood") << block.dump();
    auto scaleWith = [&](const std::string& intervals) {
        const fs::path out = files.folder.path() / ("scale-" + intervals);
        const CommandResult run = runSkinlab({"analyze", "scale", files.database.string(), "-o", out.string(),
                                              "--bootstrap", "200", "--intervals", intervals});
        EXPECT_EQ(run.exitCode, 0) << run.out << run.err;
        EXPECT_EQ(nlohmann::json::parse(skinlab::readFile(out / "scale.json")).at("settings").at("intervals_reason"),
                  "--intervals " + intervals);
        return nlohmann::json::parse(skinlab::readFile(out / "scale.json"));
    };
    const nlohmann::json bootstrap = scaleWith("bootstrap");
    const nlohmann::json profile = scaleWith("profile");
    // The union holds both intervals of every score: each end is the outer of the two (open ends are null).
    int compared = 0;
    for (std::size_t b = 0; b < scaleDb.at("blocks").size(); ++b)
        for (std::size_t i = 0; i < scaleDb.at("blocks")[b].at("scores").size(); ++i) {
            const auto& u = scaleDb.at("blocks")[b].at("scores")[i];
            const auto& s = bootstrap.at("blocks")[b].at("scores")[i];
            const auto& p = profile.at("blocks")[b].at("scores")[i];
            if (u.at("ci_low").is_null() || u.at("ci_high").is_null()) continue;
            EXPECT_DOUBLE_EQ(u.at("ci_low").get<double>(),
                             std::min(s.at("ci_low").get<double>(), p.at("ci_low").get<double>()))
                << u.dump();
            EXPECT_DOUBLE_EQ(u.at("ci_high").get<double>(),
                             std::max(s.at("ci_high").get<double>(), p.at("ci_high").get<double>()))
                << u.dump();
            ++compared;
        }
    EXPECT_GT(compared, 0);

    server->kill(SIGTERM);
    EXPECT_EQ(server->wait(), 0);
}

TEST(ActiveStudy, ThePlannersPriorComesFromTheDesign) {
    // The same study with the default prior (sd 1 JOD) and with active_prior_sd = 4: the first batch is planned
    // before any answer, so both plans begin alike; once answers are stored the planner's posterior depends on its
    // prior, and the plans part.
    std::vector<std::vector<std::string>> plans[2];
    for (int copy = 0; copy < 2; ++copy) {
        StudyFiles files;
        if (copy == 1) {
            std::string wide = kDesign;
            wide.insert(wide.find("[practice]"), "active_prior_sd = 4.0\n"); // a top-level key, before the tables
            files.design = writeText(files.folder.path(), "wide.toml", wide);
        }
        createStudy(files.stimuli, files.design, {}, files.database);
        EXPECT_EQ(StudyStore(files.database).definition().design.activePriorSd, copy == 0 ? 1.0 : 4.0);
        for (const char* label : {"A", "B", "C"}) plans[copy].push_back(answerAll(files.database, label, false));
    }
    ASSERT_EQ(plans[0][0].size(), plans[1][0].size());
    // The first participant's first batch (practice, three test trials, a catch trial) comes from the prior alone.
    for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(plans[0][0][k], plans[1][0][k]) << k;
    EXPECT_NE(plans[0][0], plans[1][0]) << "the answers weigh differently against a wider prior";
    EXPECT_NE(plans[0][2], plans[1][2]);
}
