// Integration tests of the study server over real HTTP on an ephemeral loopback port: a full participant
// session, every malformed or hostile request (answered 4xx JSON with nothing changed), and 50 simulated
// participants at once.
#include "experiments/simulated_observers.h"
#include "experiments/study_export.h"
#include "study_server_fixture.h"

#include <gtest/gtest.h>
#include <sstream>

using namespace skinlab::experiments;
using namespace skinlab::experiments::test_support;
using nlohmann::json;

namespace {

const char* kDesign = R"(
title = "Server test"
question = "Which image looks more like real skin?"
seed = 42
repetitions = 2
break_every = 5
[reference]
show = true
[practice]
trials = 2
[catch]
blank = 2
)";

json screen() { return {{"viewport_width", 1600}, {"viewport_height", 900}, {"device_pixel_ratio", 1.0}}; }

struct Participant {
    std::string token;
    std::int64_t session = 0;
    json state;
};

Participant joinAndStart(HttpClient& client, const std::string& label = "") {
    Participant p;
    json body = json::object();
    if (!label.empty()) body["label"] = label;
    JsonAnswer joined = postJson(client, "/api/join", body);
    EXPECT_EQ(joined.status, 201) << joined.raw;
    p.token = joined.body.value("token", "");
    json start = screen();
    start["token"] = p.token;
    JsonAnswer session = postJson(client, "/api/session", start);
    EXPECT_EQ(session.status, 200) << session.raw;
    p.session = session.body.value("session", 0);
    p.state = session.body;
    return p;
}

json responseBody(const Participant& p, std::int64_t trial, const std::string& side) {
    json body = screen();
    body["token"] = p.token;
    body["trial"] = trial;
    body["side"] = side;
    body["session"] = p.session;
    body["response_ms"] = 812.5;
    body["client_time"] = "2026-11-23T14:00:00.000Z";
    return body;
}

// A rejected request: the expected 4xx status, a JSON {"error": ...} body, and no change to the data.
void expectRejected(RunningStudy& study, const std::string& what, int status, const std::function<JsonAnswer()>& send) {
    const std::string before = study.fingerprint();
    const JsonAnswer answer = send();
    EXPECT_EQ(answer.status, status) << what << ": " << answer.raw.substr(0, 200);
    EXPECT_EQ(answer.contentType, "application/json") << what;
    EXPECT_TRUE(answer.body.is_object() && answer.body.contains("error") && answer.body["error"].is_string())
        << what << ": " << answer.raw.substr(0, 200);
    EXPECT_EQ(study.fingerprint(), before) << what << ": the request changed stored data";
}

} // namespace

TEST(StudyServer, ParticipantCompletesASessionAndExportsFollowContract3) {
    RunningStudy study(kDesign);
    HttpClient client = study.client();
    JsonAnswer page = get(client, "/");
    EXPECT_EQ(page.status, 200);
    EXPECT_NE(page.raw.find("<script src=\"/app.js\"></script>"), std::string::npos);
    EXPECT_EQ(get(client, "/app.js").status, 200);
    EXPECT_EQ(get(client, "/style.css").status, 200);

    Participant p = joinAndStart(client, "alice");
    ASSERT_FALSE(p.state["completed"].get<bool>());
    EXPECT_EQ(p.state["practice_total"], 2);
    EXPECT_EQ(p.state["total"], 6 * 2 + 2);
    int answered = 0;
    std::set<std::int64_t> seen;
    while (!p.state["completed"].get<bool>()) {
        const json& trial = p.state["trial"];
        ASSERT_TRUE(trial.is_object());
        EXPECT_TRUE(seen.insert(trial["id"].get<std::int64_t>()).second);
        ASSERT_TRUE(trial["reference"].is_object()) << "reference.show = true";
        // Stimuli are served by number, with the study's image bytes.
        if (!trial["left"].contains("blank")) {
            JsonAnswer image = get(client, trial["left"]["url"].get<std::string>());
            EXPECT_EQ(image.status, 200);
            EXPECT_EQ(image.contentType, "image/png");
            EXPECT_EQ(image.raw.substr(1, 3), "PNG");
        }
        JsonAnswer ack =
            postJson(client, "/api/response", responseBody(p, trial["id"], answered % 3 ? "left" : "right"));
        ASSERT_EQ(ack.status, 200) << ack.raw;
        EXPECT_TRUE(ack.body["stored"].get<bool>());
        p.state = ack.body;
        ASSERT_LT(++answered, 100);
    }
    EXPECT_EQ(answered, 16);
    EXPECT_EQ(p.state["completion_code"].get<std::string>().size(), 8u);

    // Contract 3 CSV: exact header, one row per response, catch rows carry `correct`.
    std::istringstream csv(exportResponses(study.store(), "csv"));
    std::string line;
    std::getline(csv, line);
    // Contract 3's columns first; the online columns (empty here: a client that reports none) after them.
    EXPECT_EQ(
        line.rfind(
            "observer,scene,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,correct,response_ms,flagged,",
            0),
        0u)
        << line;
    int rows = 0, practice = 0, catches = 0;
    while (std::getline(csv, line)) {
        ++rows;
        EXPECT_EQ(line.rfind("alice,scene:", 0), 0u) << line;
        if (line.find(",practice,,") != std::string::npos) ++practice;
        if (line.find(",catch,1,") != std::string::npos || line.find(",catch,0,") != std::string::npos) ++catches;
        EXPECT_NE(line.find(",812.5"), std::string::npos) << line;
    }
    EXPECT_EQ(rows, 16);
    EXPECT_EQ(practice, 2);
    EXPECT_EQ(catches, 2);
    std::istringstream pwcmp(exportResponses(study.store(), "pwcmp"));
    std::getline(pwcmp, line);
    EXPECT_EQ(line.rfind("observer,scene,condition_A,condition_B,is_A_selected,flagged,", 0), 0u) << line;
    const auto columns = std::count(line.begin(), line.end(), ',');
    rows = 0;
    while (std::getline(pwcmp, line)) {
        ++rows;
        EXPECT_EQ(std::count(line.begin(), line.end(), ','), columns) << line;
        EXPECT_EQ(line.find("blank"), std::string::npos) << "catch trials are not in pwcmp";
    }
    EXPECT_EQ(rows, 12);
    const json exported = json::parse(exportResponses(study.store(), "json"));
    ASSERT_EQ(exported["responses"].size(), 16u);
    EXPECT_EQ(exported["responses"][0]["viewport_width"], 1600);
    EXPECT_EQ(exported["responses"][0]["user_agent"].get<std::string>().rfind("skinlab-client", 0), 0u);

    // Researcher endpoints with the token.
    JsonAnswer status =
        get(client, "/api/researcher/status", {{"Authorization", std::string("Bearer ") + kResearcherToken}});
    ASSERT_EQ(status.status, 200);
    EXPECT_EQ(status.body["participants"][0]["answered"], 16);
    EXPECT_EQ(status.body["participants"][0]["catch_answered"], 2);
    JsonAnswer exportAnswer = get(client, "/api/researcher/export?format=pwcmp",
                                  {{"Authorization", std::string("Bearer ") + kResearcherToken}});
    EXPECT_EQ(exportAnswer.status, 200);
    EXPECT_EQ(exportAnswer.raw, exportResponses(study.store(), "pwcmp"));

    // Resuming a finished participant shows the completion code again.
    json again = screen();
    again["token"] = p.token;
    JsonAnswer resumed = postJson(client, "/api/session", again);
    EXPECT_EQ(resumed.status, 200);
    EXPECT_TRUE(resumed.body["completed"].get<bool>());
}

TEST(StudyServer, ResumingContinuesAtTheFirstUnansweredTrial) {
    RunningStudy study(kDesign);
    HttpClient client = study.client();
    Participant p = joinAndStart(client);
    for (int i = 0; i < 5; ++i) {
        JsonAnswer ack = postJson(client, "/api/response", responseBody(p, p.state["trial"]["id"], "left"));
        ASSERT_EQ(ack.status, 200);
        p.state = ack.body;
    }
    const std::int64_t next = p.state["trial"]["id"];
    json again = screen();
    again["token"] = p.token;
    JsonAnswer resumed = postJson(client, "/api/session", again);
    ASSERT_EQ(resumed.status, 200);
    EXPECT_EQ(resumed.body["trial"]["id"], next);
    EXPECT_EQ(resumed.body["trial"]["position"], 5);
    EXPECT_GT(resumed.body["session"].get<std::int64_t>(), p.session);
}

TEST(StudyServer, HostileAndMalformedRequestsAreRejectedWithoutChangingData) {
    RunningStudy study(kDesign);
    HttpClient client = study.client();
    Participant alice = joinAndStart(client, "alice");
    Participant bob = joinAndStart(client, "bob");
    // Alice answers her first trial, so replays can be tested.
    const std::int64_t first = alice.state["trial"]["id"];
    JsonAnswer ack = postJson(client, "/api/response", responseBody(alice, first, "left"));
    ASSERT_EQ(ack.status, 200);
    const std::int64_t second = ack.body["trial"]["id"];
    const std::int64_t bobsTrial = bob.state["trial"]["id"];

    auto post = [&](const json& body) { return [&client, body] { return postJson(client, "/api/response", body); }; };
    auto with = [&](json body, const std::string& key, const json& value) {
        if (value.is_null()) body.erase(key);
        else body[key] = value;
        return body;
    };
    const json good = responseBody(alice, second, "right");

    expectRejected(study, "bad JSON", 400,
                   [&] { return postRaw(client, "/api/response", "{\"token\": ", "application/json"); });
    expectRejected(study, "JSON array", 400,
                   [&] { return postRaw(client, "/api/response", "[1,2]", "application/json"); });
    expectRejected(study, "not JSON content type", 415,
                   [&] { return postRaw(client, "/api/response", good.dump(), "text/plain"); });
    expectRejected(study, "form post", 415, [&] {
        return postRaw(client, "/api/response", "token=x&trial=1", "application/x-www-form-urlencoded");
    });
    expectRejected(study, "huge body", 413, [&] {
        json body = good;
        body["client_time"] = std::string(200000, 'x');
        return postJson(client, "/api/response", body);
    });
    expectRejected(study, "huge join body", 413, [&] {
        return postRaw(client, "/api/join", "{\"label\":\"" + std::string(1 << 20, 'a') + "\"}", "application/json");
    });
    expectRejected(study, "missing side", 400, post(with(good, "side", nullptr)));
    expectRejected(study, "side up", 400, post(with(good, "side", "up")));
    expectRejected(study, "trial as string", 400, post(with(good, "trial", std::to_string(second))));
    expectRejected(study, "negative trial", 400, post(with(good, "trial", -5)));
    expectRejected(study, "negative response time", 400, post(with(good, "response_ms", -1)));
    expectRejected(study, "zero pixel ratio", 400, post(with(good, "device_pixel_ratio", 0)));
    expectRejected(study, "long client time", 400, post(with(good, "client_time", std::string(100, '1'))));
    expectRejected(study, "token as number", 400, post(with(good, "token", 12345)));
    expectRejected(study, "unknown participant", 404, post(with(good, "token", std::string(32, 'f'))));
    expectRejected(study, "unknown trial", 404, post(with(good, "trial", 999999)));
    // Another participant's trial or session is as unknown as one that does not exist (no 403 tells whose it is).
    expectRejected(study, "someone else's trial", 404, post(with(good, "trial", bobsTrial)));
    expectRejected(study, "someone else's session", 404, post(with(good, "session", bob.session)));
    expectRejected(study, "unknown session", 404, post(with(good, "session", 99999)));
    expectRejected(study, "a trial row id without its tag", 404, post(with(good, "trial", second & 0xFFFFFFFF)));
    const auto aliceTrials = study.store().trials(study.store().participant(alice.token).id);
    expectRejected(study, "out of order (skipping ahead)", 409,
                   post(with(good, "trial", trialReference(alice.token, aliceTrials[4].id))));
    expectRejected(study, "replay with a different answer", 409, post(responseBody(alice, first, "right")));
    expectRejected(study, "bad label", 400, [&] { return postJson(client, "/api/join", {{"label", "../../etc"}}); });
    expectRejected(study, "taken label", 409, [&] { return postJson(client, "/api/join", {{"label", "alice"}}); });
    expectRejected(study, "session with unknown token", 404, [&] {
        json body = screen();
        body["token"] = "nobody";
        return postJson(client, "/api/session", body);
    });
    expectRejected(study, "state without token", 400, [&] { return get(client, "/api/state"); });

    // Researcher endpoints.
    expectRejected(study, "status without token", 401, [&] { return get(client, "/api/researcher/status"); });
    expectRejected(study, "status with wrong token", 403, [&] {
        return get(client, "/api/researcher/status", {{"Authorization", "Bearer wrong"}});
    });
    expectRejected(study, "export with wrong token", 403, [&] {
        return get(client, "/api/researcher/export", {{"Authorization", "Bearer abc"}});
    });
    expectRejected(study, "export with the token in the URL", 401,
                   [&] { return get(client, std::string("/api/researcher/export?token=") + kResearcherToken); });
    expectRejected(study, "export with bad format", 400, [&] {
        return get(client, "/api/researcher/export?format=xml",
                   {{"Authorization", std::string("Bearer ") + kResearcherToken}});
    });

    // Path traversal and files outside the study: nothing but the numbered stimuli is reachable.
    for (const std::string path :
         {"/stimuli/../manifest.json", "/stimuli/..%2f..%2fmanifest.json", "/stimuli/%2e%2e/%2e%2e/etc/passwd",
          "/../../../../etc/passwd", "/manifest.json", "/png/0-separable.png", "/stimuli/0-separable.png",
          "/stimuli/999.png", "/stimuli/-1.png", "/stimuli/1.png/..", "/stimuli/1.png%00.txt", "/design.toml",
          "/study.db", "/index.html/../../study.db", "/api/../study.db"}) {
        expectRejected(study, "GET " + path, 404, [&] { return get(client, path); });
    }
    expectRejected(study, "unknown API", 404, [&] { return postJson(client, "/api/drop_tables", json::object()); });

    // A replay of the stored answer is harmless: 200, marked duplicate, nothing changes.
    const std::string before = study.fingerprint();
    JsonAnswer replay = postJson(client, "/api/response", responseBody(alice, first, "left"));
    EXPECT_EQ(replay.status, 200);
    EXPECT_TRUE(replay.body["duplicate"].get<bool>());
    EXPECT_EQ(replay.body["trial"]["id"], second);
    EXPECT_EQ(study.fingerprint(), before);

    // After all that, the good request still works.
    EXPECT_EQ(postJson(client, "/api/response", good).status, 200);
    EXPECT_EQ(study.store().responseCount(), 2);
}

TEST(StudyServer, FiftySimulatedParticipantsAtOnce) {
    RunningStudy study(kDesign);
    SimulationOptions options;
    options.port = study.port();
    options.observers = 50;
    options.randomObservers = 5;
    options.invertedObservers = 5;
    options.seed = 7;
    options.labelPrefix = "sim";
    // Truth per condition (JOD): reference-like > separable > artistic by 1.5 JOD steps.
    options.truth.byCondition = {{"reference-like", 3.0}, {"separable", 1.5}, {"artistic", 0.0}};
    const SimulationReport report = simulateObservers(study.store(), options);
    for (const ObserverResult& o : report.observers) EXPECT_TRUE(o.failure.empty()) << o.label << ": " << o.failure;
    EXPECT_EQ(report.completed(), 50);
    EXPECT_EQ(report.rejected(), 0);
    EXPECT_EQ(report.acknowledged(), 50u * 16u);
    EXPECT_EQ(study.store().responseCount(), 50 * 16);

    // Every acknowledged response is stored exactly as acknowledged.
    const auto rows = study.store().responses();
    std::map<std::int64_t, bool> storedLeft;
    for (const ResponseRow& r : rows) storedLeft[r.trialId] = r.aSelected == r.aOnLeft;
    for (const ObserverResult& o : report.observers)
        for (const auto& [trial, side] : o.acknowledged) EXPECT_EQ(storedLeft.at(trial), side == "left") << o.label;

    // The answers carry the truth: attentive observers prefer the better condition, pass catch trials;
    // inverted observers fail them.
    int better = 0, comparisons = 0;
    std::map<std::string, std::pair<int, int>> catchByKind;
    const std::map<std::string, double> q = options.truth.byCondition;
    for (const ResponseRow& r : rows) {
        const std::string kind = r.observer.size() > 7 ? r.observer.substr(8) : "thurstone"; // "sim-001-random"
        if (r.kind == TrialKind::catchTrial) {
            auto& [correct, total] = catchByKind[kind];
            correct += *r.correct ? 1 : 0;
            ++total;
        } else if (kind == "thurstone" && (r.kind == TrialKind::test || r.kind == TrialKind::repeat)) {
            const bool aBetter = q.at(r.conditionA) > q.at(r.conditionB);
            better += aBetter == r.aSelected ? 1 : 0;
            ++comparisons;
        }
    }
    ASSERT_EQ(comparisons, 40 * 12);
    // Steps of 1.5 and 3 JOD: P(prefer better) = Φ(1.5/1.4826) ≈ 0.84 or Φ(3/1.4826) ≈ 0.98, mean ≈ 0.89.
    EXPECT_GT(better, comparisons * 80 / 100);
    EXPECT_LT(better, comparisons * 97 / 100);
    EXPECT_EQ(catchByKind["thurstone"].first, catchByKind["thurstone"].second);
    EXPECT_EQ(catchByKind["inverted"].first, 0);
    EXPECT_GT(catchByKind["inverted"].second, 0);
    EXPECT_LT(report.latencyPercentile(50), 1000.0);
}

TEST(StudyServer, SimulateRunAgainWithTheSamePrefixContinuesItsObservers) {
    RunningStudy study(kDesign);
    // An interrupted run: observer "resume-001" joined (with the simulator's join key) and answered 3 trials.
    HttpClient client = study.client();
    JsonAnswer joined =
        postJson(client, "/api/join", {{"label", "resume-001"}, {"join_key", simulatedJoinKey("resume-001")}});
    ASSERT_EQ(joined.status, 201) << joined.raw;
    Participant p;
    p.token = joined.body["token"];
    json start = screen();
    start["token"] = p.token;
    JsonAnswer session = postJson(client, "/api/session", start);
    p.session = session.body["session"];
    p.state = session.body;
    for (int i = 0; i < 3; ++i) {
        JsonAnswer ack = postJson(client, "/api/response", responseBody(p, p.state["trial"]["id"], "left"));
        ASSERT_EQ(ack.status, 200);
        p.state = ack.body;
    }
    SimulationOptions options;
    options.port = study.port();
    options.observers = 2;
    options.labelPrefix = "resume";
    const SimulationReport first = simulateObservers(study.store(), options);
    for (const ObserverResult& o : first.observers) EXPECT_TRUE(o.failure.empty()) << o.label << ": " << o.failure;
    EXPECT_EQ(first.completed(), 2);
    EXPECT_EQ(first.rejected(), 0);
    EXPECT_EQ(first.acknowledged(), 16u - 3u + 16u) << "resume-001 continued after its 3 answers";
    EXPECT_EQ(study.store().responseCount(), 32);
    // The same command again: both observers are found complete; nothing is stored twice, nothing refused (no 409).
    const SimulationReport again = simulateObservers(study.store(), options);
    for (const ObserverResult& o : again.observers) EXPECT_TRUE(o.failure.empty()) << o.label << ": " << o.failure;
    EXPECT_EQ(again.completed(), 2);
    EXPECT_EQ(again.rejected(), 0);
    EXPECT_EQ(again.acknowledged(), 0u);
    EXPECT_EQ(study.store().status().size(), 2u);
    EXPECT_EQ(study.store().responseCount(), 32);
}
