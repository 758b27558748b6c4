// Integration tests of online studies over real HTTP (in-process server on an ephemeral loopback port, real
// SQLite): recruitment platform ids (validation, round trip into every export format, a repeat visit resuming the
// same participant, MTurk's preview), the completion redirect and code, viewing conditions and the card
// calibration, requirements refusing a session before its first trial, per-trial page-hidden / focus flags and
// `analyze scale --drop-flagged`, and a study file written before these tables existed.
#include "analysis/scaling/responses.h"
#include "child_process.h"
#include "common/error.h"
#include "common/files.h"
#include "experiments/simulated_observers.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_creation.h"
#include "experiments/study_design.h"
#include "experiments/study_export.h"
#include "study_server_fixture.h"

#include <cmath>
#include <gtest/gtest.h>
#include <map>
#include <sstream>

using namespace skinlab::experiments;
using namespace skinlab::experiments::test_support;
using nlohmann::json;
namespace fs = std::filesystem;
namespace scaling = skinlab::analysis::scaling;

namespace {

const std::string kPid = "5f8a1b2c3d4e5f6a7b8c9d0e";
const std::string kStudyId = "60aa1b2c3d4e5f6a7b8c9d11";
const std::string kSessionId = "60bb1b2c3d4e5f6a7b8c9d22";

// 2 blocks x 3 pairs + 1 practice + 1 blank catch = 8 trials.
std::string design(const std::string& extra) {
    return R"(
title = "Online test"
seed = 5
repetitions = 1
break_every = 0
conditions = ["reference-like", "separable", "artistic"]
[practice]
trials = 1
[catch]
blank = 1
)" + extra;
}

const char* kProlific = R"(
[recruitment]
platform = "prolific"
completion_url = "https://app.prolific.com/submissions/complete?cc={code}"
completion_code = "C1ABCDEF"
)";

json prolificIds() { return {{"PROLIFIC_PID", kPid}, {"STUDY_ID", kStudyId}, {"SESSION_ID", kSessionId}}; }

// What the page reports when a session starts.
json viewing(int screenWidth = 1920, int screenHeight = 1080, double dpr = 1.0, bool fullscreen = true,
             bool pointerFine = true) {
    return {{"viewport_width", 1600},      {"viewport_height", 900},        {"device_pixel_ratio", dpr},
            {"screen_width", screenWidth}, {"screen_height", screenHeight}, {"colour_depth", 24},
            {"fullscreen", fullscreen},    {"pointer_fine", pointerFine},   {"touch_points", 0}};
}

json withToken(json body, const std::string& token) {
    body["token"] = token;
    return body;
}

json answer(const std::string& token, std::int64_t session, const json& state, bool hidden = false,
            bool blurred = false) {
    return {{"token", token},         {"trial", state["trial"]["id"]}, {"side", "left"},
            {"session", session},     {"response_ms", 640.0},          {"client_time", "2026-12-01T20:00:00.000Z"},
            {"viewport_width", 1600}, {"viewport_height", 900},        {"device_pixel_ratio", 1.0},
            {"page_hidden", hidden},  {"focus_lost", blurred},         {"fullscreen", true}};
}

// A rejected request: the status, an error naming `mentions`, and nothing stored.
void expectRejected(RunningStudy& study, int status, const std::string& mentions,
                    const std::function<JsonAnswer()>& send) {
    const std::string before = study.fingerprint();
    const JsonAnswer a = send();
    EXPECT_EQ(a.status, status) << a.raw;
    ASSERT_TRUE(a.body.is_object() && a.body.contains("error")) << a.raw;
    EXPECT_NE(a.body["error"].get<std::string>().find(mentions), std::string::npos) << a.raw;
    EXPECT_EQ(study.fingerprint(), before) << "a rejected request changed stored data: " << a.raw;
}

std::vector<std::string> csvLines(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

// The index of `name` in a CSV header line.
std::size_t columnOf(const std::string& header, const std::string& name) {
    std::istringstream in(header);
    std::size_t k = 0;
    for (std::string field; std::getline(in, field, ','); ++k)
        if (field == name) return k;
    ADD_FAILURE() << "no column " << name << " in " << header;
    return 0;
}

std::string fieldOf(const std::string& line, std::size_t column) {
    std::istringstream in(line);
    std::string field;
    for (std::size_t k = 0; k <= column; ++k) std::getline(in, field, ',');
    return field;
}

} // namespace

TEST(OnlineStudy, ProlificIdsRoundTripResumeAndRedirect) {
    RunningStudy study(design(kProlific));
    HttpClient client = study.client();
    std::string participantAnswers; // every participant-API answer, to check that no platform id is ever shown

    const JsonAnswer info = get(client, "/api/study");
    EXPECT_EQ(info.body["recruitment"]["platform"], "prolific");
    EXPECT_EQ(info.body["recruitment"]["parameters"], json({"PROLIFIC_PID", "STUDY_ID", "SESSION_ID"}));

    const JsonAnswer joined =
        postJson(client, "/api/join", {{"join_key", "first-visit"}, {"recruitment", prolificIds()}});
    ASSERT_EQ(joined.status, 201) << joined.raw;
    EXPECT_FALSE(joined.body["resumed"].get<bool>());
    const std::string token = joined.body["token"];
    participantAnswers += joined.raw;
    JsonAnswer session = postJson(client, "/api/session", withToken(viewing(), token));
    ASSERT_EQ(session.status, 200) << session.raw;
    participantAnswers += session.raw;
    json state = session.body;
    // Three answers: the second given while the page was hidden, the third after the window lost the focus.
    for (int i = 0; i < 3; ++i) {
        const JsonAnswer ack =
            postJson(client, "/api/response", answer(token, session.body["session"], state, i == 1, i == 2));
        ASSERT_EQ(ack.status, 200) << ack.raw;
        participantAnswers += ack.raw;
        state = ack.body;
    }
    const std::int64_t nextTrial = state["trial"]["id"];

    // A repeat visit from the same Prolific link in a new browser (another join key, the same SESSION_ID) is the
    // same participant; the PROLIFIC_PID without the SESSION_ID or the first browser's join key is refused.
    json withoutSession = prolificIds();
    withoutSession.erase("SESSION_ID");
    const JsonAnswer stranger =
        postJson(client, "/api/join", {{"join_key", "third-visit"}, {"recruitment", withoutSession}});
    EXPECT_EQ(stranger.status, 409) << stranger.raw;
    EXPECT_FALSE(stranger.body.contains("token"));
    const JsonAnswer again =
        postJson(client, "/api/join", {{"join_key", "second-visit"}, {"recruitment", prolificIds()}});
    ASSERT_EQ(again.status, 200) << again.raw;
    EXPECT_TRUE(again.body["resumed"].get<bool>());
    EXPECT_EQ(again.body["token"], token);
    EXPECT_EQ(again.body["observer"], joined.body["observer"]);
    participantAnswers += again.raw;
    session = postJson(client, "/api/session", withToken(viewing(2560, 1440, 1.0), token));
    ASSERT_EQ(session.status, 200) << session.raw;
    EXPECT_EQ(session.body["trial"]["id"], nextTrial) << "the repeat visit starts over instead of resuming";
    state = session.body;
    for (int i = 0; i < 20 && !state["completed"].get<bool>(); ++i) {
        const JsonAnswer ack = postJson(client, "/api/response", answer(token, session.body["session"], state));
        ASSERT_EQ(ack.status, 200) << ack.raw;
        participantAnswers += ack.raw;
        state = ack.body;
    }
    ASSERT_TRUE(state["completed"].get<bool>());
    EXPECT_EQ(state["completion_code"], "C1ABCDEF");
    EXPECT_EQ(state["completion_url"], "https://app.prolific.com/submissions/complete?cc=C1ABCDEF");
    EXPECT_EQ(study.store().status().size(), 1u) << "a second participation was created";
    for (const std::string& id : {kPid, kStudyId, kSessionId})
        EXPECT_EQ(participantAnswers.find(id), std::string::npos) << "the participant API shows a platform id";

    // Every export format carries the ids, the viewing conditions and the flags — but the platform's session id (it
    // resumes the participation) only when asked for.
    for (const std::string format : {"csv", "pwcmp", "json"}) {
        const std::string text = exportResponses(study.store(), format);
        EXPECT_EQ(text.find(kSessionId), std::string::npos) << format << ": the session id is exported by default";
        EXPECT_EQ(text.find("external_session_id"), std::string::npos) << format;
        EXPECT_NE(text.find(kPid), std::string::npos) << format;
    }
    // The researcher's export over HTTP likewise: the session ids only with include_session_ids=1.
    const HttpHeaders researcher{{"Authorization", "Bearer " + std::string(kResearcherToken)}};
    for (const std::string format : {"csv", "pwcmp", "json"}) {
        const JsonAnswer plain = get(client, "/api/researcher/export?format=" + format, researcher);
        EXPECT_EQ(plain.status, 200) << plain.raw;
        EXPECT_EQ(plain.raw.find(kSessionId), std::string::npos) << format << ": " << plain.raw;
        EXPECT_NE(plain.raw.find(kPid), std::string::npos) << format;
        const JsonAnswer asked =
            get(client, "/api/researcher/export?format=" + format + "&include_session_ids=1", researcher);
        EXPECT_EQ(asked.raw, exportResponses(study.store(), format, {.includeSessionIds = true})) << format;
        EXPECT_NE(asked.raw.find(kSessionId), std::string::npos) << format;
    }
    const std::vector<std::string> csv = csvLines(exportResponses(study.store(), "csv", {.includeSessionIds = true}));
    ASSERT_EQ(csv.size(), 9u);
    EXPECT_EQ(csv[0].rfind(
                  "observer,scene,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,correct,response_ms,", 0),
              0u);
    int flagged = 0;
    for (std::size_t k = 1; k < csv.size(); ++k) {
        EXPECT_EQ(fieldOf(csv[k], columnOf(csv[0], "external_id")), kPid) << csv[k];
        EXPECT_EQ(fieldOf(csv[k], columnOf(csv[0], "external_study_id")), kStudyId) << csv[k];
        EXPECT_EQ(fieldOf(csv[k], columnOf(csv[0], "external_session_id")), kSessionId) << csv[k];
        EXPECT_EQ(fieldOf(csv[k], columnOf(csv[0], "platform")), "prolific") << csv[k];
        EXPECT_EQ(fieldOf(csv[k], columnOf(csv[0], "screen_width")), k <= 3 ? "1920" : "2560") << csv[k];
        EXPECT_EQ(fieldOf(csv[k], columnOf(csv[0], "colour_depth")), "24") << csv[k];
        flagged += fieldOf(csv[k], columnOf(csv[0], "flagged")) == "1";
    }
    EXPECT_EQ(flagged, 2);
    EXPECT_EQ(fieldOf(csv[2], columnOf(csv[0], "page_hidden")), "1");
    EXPECT_EQ(fieldOf(csv[3], columnOf(csv[0], "focus_lost")), "1");
    const std::vector<std::string> pwcmp = csvLines(exportResponses(study.store(), "pwcmp"));
    ASSERT_GE(pwcmp.size(), 2u);
    EXPECT_EQ(pwcmp[0].rfind("observer,scene,condition_A,condition_B,is_A_selected,flagged,", 0), 0u);
    EXPECT_EQ(fieldOf(pwcmp[1], columnOf(pwcmp[0], "external_id")), kPid);
    const json exported = json::parse(exportResponses(study.store(), "json", {.includeSessionIds = true}));
    EXPECT_EQ(exported["participants"][0]["recruitment"]["external_id"], kPid);
    EXPECT_EQ(exported["participants"][0]["recruitment"]["external_session_id"], kSessionId);
    ASSERT_EQ(exported["sessions"].size(), 2u);
    EXPECT_EQ(exported["sessions"][0]["viewing"]["screen_width_px"], 1920);
    EXPECT_EQ(exported["sessions"][1]["viewing"]["screen_height"], 1440);
    EXPECT_EQ(exported["responses"][1]["flagged"], 1);
    EXPECT_EQ(exported["responses"][1]["page_hidden"], true);
    EXPECT_EQ(exported["responses"][0]["flagged"], 0);
    EXPECT_EQ(exported["responses"][0]["recruitment"]["external_study_id"], kStudyId);

    // The store's overview for the researcher: both sessions' conditions, and the two flagged trials.
    EXPECT_EQ(study.store().viewingConditions().size(), 2u);
    EXPECT_EQ(study.store().flaggedTrials().size(), 2u);
}

TEST(OnlineStudy, MalformedOrMissingPlatformIdsAreOne400NamingTheParameter) {
    RunningStudy study(design(kProlific));
    HttpClient client = study.client();
    auto join = [&](json ids) {
        return [&client, ids] { return postJson(client, "/api/join", {{"recruitment", ids}}); };
    };
    json shortPid = prolificIds();
    shortPid["PROLIFIC_PID"] = "5f8a1b2c";
    expectRejected(study, 400, "PROLIFIC_PID", join(shortPid));
    json template_ = prolificIds();
    template_["PROLIFIC_PID"] = "{{%PROLIFIC_PID%}}";
    expectRejected(study, 400, "PROLIFIC_PID", join(template_));
    json badStudy = prolificIds();
    badStudy["STUDY_ID"] = "60aa1b2c3d4e5f6a7b8c9d1'";
    expectRejected(study, 400, "STUDY_ID", join(badStudy));
    json missing = prolificIds();
    missing.erase("PROLIFIC_PID");
    expectRejected(study, 400, "PROLIFIC_PID: missing", join(missing));
    expectRejected(study, 400, "PROLIFIC_PID", [&] { return postJson(client, "/api/join", json::object()); });
    expectRejected(study, 400, "recruitment", join(json::array({kPid})));
    json notText = prolificIds();
    notText["SESSION_ID"] = 5;
    expectRejected(study, 400, "SESSION_ID", join(notText));
}

TEST(OnlineStudy, MturkPreviewShowsNoJoinAndTheWorkerIdResumes) {
    RunningStudy study(design("[recruitment]\nplatform = \"mturk\"\n"));
    HttpClient client = study.client();
    const JsonAnswer info = get(client, "/api/study");
    EXPECT_EQ(info.body["recruitment"]["parameters"], json({"workerId", "hitId", "assignmentId"}));
    const json preview = {{"workerId", "A1B2C3D4E5F6G7"},
                          {"assignmentId", "ASSIGNMENT_ID_NOT_AVAILABLE"},
                          {"hitId", "3ABCDEFGHIJKLMNOPQRSTUVWXYZ012"}};
    expectRejected(study, 403, "preview", [&] { return postJson(client, "/api/join", {{"recruitment", preview}}); });
    json badWorker = preview;
    badWorker["assignmentId"] = "3ABCDEFGHIJKLMNOPQRSTUVWXYZ999";
    badWorker["workerId"] = "A1B2-C3D4";
    expectRejected(study, 400, "workerId", [&] { return postJson(client, "/api/join", {{"recruitment", badWorker}}); });
    badWorker["workerId"] = std::string(65, 'A');
    expectRejected(study, 400, "workerId", [&] { return postJson(client, "/api/join", {{"recruitment", badWorker}}); });

    json accepted = preview;
    accepted["assignmentId"] = "3ABCDEFGHIJKLMNOPQRSTUVWXYZ999";
    const JsonAnswer joined =
        postJson(client, "/api/join", {{"join_key", "worker-browser"}, {"recruitment", accepted}});
    ASSERT_EQ(joined.status, 201) << joined.raw;
    // The same worker with another assignment (a second HIT of the same study) is still one participant: refused
    // from another browser, resumed from the first one (its join key).
    accepted["assignmentId"] = "3ZZZDEFGHIJKLMNOPQRSTUVWXYZ999";
    EXPECT_EQ(postJson(client, "/api/join", {{"recruitment", accepted}}).status, 409);
    const JsonAnswer again = postJson(client, "/api/join", {{"join_key", "worker-browser"}, {"recruitment", accepted}});
    ASSERT_EQ(again.status, 200) << again.raw;
    EXPECT_EQ(again.body["token"], joined.body["token"]);
    const std::vector<ParticipantStatus> status = study.store().status();
    ASSERT_EQ(status.size(), 1u);
    ASSERT_TRUE(status[0].external.has_value());
    EXPECT_EQ(status[0].external->id, "A1B2C3D4E5F6G7");
    EXPECT_EQ(status[0].external->session, "3ABCDEFGHIJKLMNOPQRSTUVWXYZ999");
    EXPECT_EQ(status[0].external->study, "3ABCDEFGHIJKLMNOPQRSTUVWXYZ012");

    // No completion URL: the participant's own code is shown at the end, no redirect.
    const std::string token = joined.body["token"];
    JsonAnswer session = postJson(client, "/api/session", withToken(viewing(), token));
    json state = session.body;
    for (int i = 0; i < 20 && !state["completed"].get<bool>(); ++i)
        state = postJson(client, "/api/response", answer(token, session.body["session"], state)).body;
    ASSERT_TRUE(state["completed"].get<bool>());
    EXPECT_EQ(state["completion_code"], status[0].participant.completionCode);
    EXPECT_FALSE(state.contains("completion_url"));
}

TEST(OnlineStudy, GenericPlatformUsesTheNamedParameter) {
    RunningStudy study(design("[recruitment]\nplatform = \"generic\"\nid_parameter = \"survey_code\"\n"
                              "completion_code = \"THANKS-2026\"\n"));
    HttpClient client = study.client();
    EXPECT_EQ(get(client, "/api/study").body["recruitment"]["parameters"], json({"survey_code"}));
    expectRejected(study, 400, "survey_code", [&] {
        return postJson(client, "/api/join", {{"recruitment", {{"survey_code", "12 34"}}}});
    });
    // Parameters of other platforms are not ids here.
    expectRejected(study, 400, "survey_code: missing", [&] {
        return postJson(client, "/api/join", {{"recruitment", {{"PROLIFIC_PID", kPid}}}});
    });
    const JsonAnswer joined =
        postJson(client, "/api/join", {{"join_key", "k1"}, {"recruitment", {{"survey_code", "48213"}}}});
    ASSERT_EQ(joined.status, 201) << joined.raw;
    EXPECT_EQ(
        postJson(client, "/api/join", {{"join_key", "k1"}, {"recruitment", {{"survey_code", "48213"}}}}).body["token"],
        joined.body["token"]);
    EXPECT_EQ(postJson(client, "/api/join", {{"recruitment", {{"survey_code", "48213"}}}}).status, 409);
    EXPECT_EQ(postJson(client, "/api/join", {{"recruitment", {{"survey_code", "48214"}}}}).status, 201);
    EXPECT_EQ(study.store().status().size(), 2u);
}

TEST(OnlineStudy, DesignKeysAreCheckedStrictly) {
    auto error = [](const std::string& extra) {
        try {
            parseStudyDesign(design(extra), "D.toml");
        } catch (const skinlab::InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_NE(error("[recruitment]\nplatform = \"sona\"\n").find("recruitment.id_parameter"), std::string::npos);
    EXPECT_NE(error("[recruitment]\nplatform = \"prolific\"\nid_parameter = \"x\"\n").find("recruitment.id_parameter"),
              std::string::npos);
    EXPECT_NE(error("[recruitment]\nplatform = \"qualtrics\"\n").find("recruitment.platform"), std::string::npos);
    EXPECT_NE(error("[recruitment]\nplatform = \"generic\"\nid_parameter = \"p\"\n").find("id_parameter"),
              std::string::npos);
    EXPECT_NE(error("[recruitment]\ncompletion_url = \"javascript:alert(1)\"\n").find("recruitment.completion_url"),
              std::string::npos);
    EXPECT_NE(error("[recruitment]\ncompletion_code = \"a b\"\n").find("recruitment.completion_code"),
              std::string::npos);
    EXPECT_NE(error("[display]\ncalibrate = true\n").find("display.viewing_distance_mm"), std::string::npos);
    EXPECT_NE(error("[requirements]\nfull_screen = true\n").find("requirements.full_screen"), std::string::npos);
    EXPECT_EQ(error("[recruitment]\nplatform = \"sona\"\nid_parameter = \"id\"\n[display]\ncalibrate = true\n"
                    "viewing_distance_mm = 600\n[requirements]\nmin_screen_width = 1280\nno_zoom = true\n"),
              "accepted");
    // The design survives the study file's JSON.
    const StudyDesign d = parseStudyDesign(design(kProlific), "D.toml");
    const StudyDesign back = StudyDesign::fromJson(d.toJson());
    EXPECT_EQ(back.recruitment.platform, "prolific");
    EXPECT_EQ(back.recruitment.completionUrl, d.recruitment.completionUrl);
    EXPECT_EQ(back.recruitment.completionCode, "C1ABCDEF");
}

TEST(OnlineStudy, RequirementsRefuseTheSessionBeforeTheFirstTrial) {
    RunningStudy study(design("[requirements]\nmin_screen_width = 1280\nmin_screen_height = 720\nno_zoom = true\n"
                              "fullscreen = true\ndesktop = true\n"));
    HttpClient client = study.client();
    const JsonAnswer joined = postJson(client, "/api/join", json::object());
    ASSERT_EQ(joined.status, 201);
    const std::string token = joined.body["token"];
    auto start = [&](json conditions) {
        return [&client, token, conditions] { return postJson(client, "/api/session", withToken(conditions, token)); };
    };
    expectRejected(study, 403, "at least 1280 x 720", start(viewing(1024, 768)));
    expectRejected(study, 403, "zoom", start(viewing(1920, 1080, 1.25)));
    expectRejected(study, 403, "full screen", start(viewing(1920, 1080, 1.0, false)));
    expectRejected(study, 403, "mouse or trackpad", start(viewing(1920, 1080, 1.0, true, false)));
    json bare = viewing();
    for (const char* key :
         {"screen_width", "screen_height", "colour_depth", "fullscreen", "pointer_fine", "touch_points"})
        bare.erase(key);
    expectRejected(study, 403, "did not report the screen", start(bare));
    const JsonAnswer refused = postJson(client, "/api/session", withToken(viewing(800, 600, 1.5, false, false), token));
    EXPECT_EQ(refused.body["unmet"].size(), 4u) << refused.raw;
    const JsonAnswer ok = postJson(client, "/api/session", withToken(viewing(1920, 1080, 2.0), token));
    ASSERT_EQ(ok.status, 200) << ok.raw;
    EXPECT_TRUE(ok.body["trial"].is_object());
    const std::vector<SessionViewing> sessions = study.store().viewingConditions();
    ASSERT_EQ(sessions.size(), 1u);
    ASSERT_TRUE(sessions[0].viewing.has_value());
    EXPECT_EQ(sessions[0].viewing->screenWidthPx, 3840);
    EXPECT_EQ(sessions[0].viewing->screenHeightPx, 2160);
}

TEST(OnlineStudy, CardCalibrationGivesPixelsPerDegree) {
    RunningStudy study(design("[display]\ncalibrate = true\nviewing_distance_mm = 600\n"));
    HttpClient client = study.client();
    const JsonAnswer joined = postJson(client, "/api/join", json::object());
    const std::string token = joined.body["token"];
    expectRejected(study, 400, "card_width",
                   [&] { return postJson(client, "/api/session", withToken(viewing(), token)); });
    json calibrated = viewing(1440, 900, 2.0);
    calibrated["card_width"] = 323.5;
    const JsonAnswer session = postJson(client, "/api/session", withToken(calibrated, token));
    ASSERT_EQ(session.status, 200) << session.raw;
    const std::vector<SessionViewing> sessions = study.store().viewingConditions();
    ASSERT_EQ(sessions.size(), 1u);
    const ViewingConditions& v = *sessions[0].viewing;
    const double pixelsPerMm = 323.5 * 2.0 / 85.60; // device pixels per mm of the ID-1 card's width
    EXPECT_NEAR(*v.pixelsPerMm, pixelsPerMm, 1e-9);
    EXPECT_EQ(*v.viewingDistanceMm, 600.0);
    // One degree at 600 mm spans 2 * 600 * tan(0.5 deg) = 10.47224 mm.
    EXPECT_NEAR(*v.pixelsPerDegree, 10.47224 * pixelsPerMm, 1e-3);
    const json exported = json::parse(exportResponses(study.store(), "json"));
    EXPECT_NEAR(exported["sessions"][0]["viewing"]["pixels_per_degree"].get<double>(), 10.47224 * pixelsPerMm, 1e-3);
}

TEST(OnlineStudy, AnalyzeScaleDropsFlaggedTrialsFromEveryFormat) {
    RunningStudy study(design(""));
    HttpClient client = study.client();
    // Two observers; four of their test answers flagged (page hidden or focus lost).
    for (int observer = 0; observer < 2; ++observer) {
        const JsonAnswer joined = postJson(client, "/api/join", json::object());
        const std::string token = joined.body["token"];
        const JsonAnswer session = postJson(client, "/api/session", withToken(viewing(), token));
        json state = session.body;
        // The participant API hides which trials are tests (catch trials look alike): the store knows.
        std::map<std::int64_t, TrialKind> kinds;
        for (const TrialRecord& t : study.store().trials(study.store().participant(token).id))
            kinds[t.id] = t.plan.kind;
        int tests = 0;
        while (!state["completed"].get<bool>()) {
            const TrialKind kind = kinds.at(state["trial"]["id"].get<std::int64_t>() & 0xFFFFFFFFll);
            const int n = kind == TrialKind::test ? ++tests : 0;
            state =
                postJson(client, "/api/response", answer(token, session.body["session"], state, n == 1, n == 3)).body;
        }
    }
    ASSERT_EQ(study.store().flaggedTrials().size(), 4u);
    for (const std::string format : {"csv", "json", "pwcmp"}) {
        const fs::path file = study.folder() / ("responses." + format);
        skinlab::writeFileAtomic(file, exportResponses(study.store(), format));
        scaling::ResponseTable table = scaling::readResponses(file);
        const std::size_t before = table.responses.size();
        const scaling::DroppedFlagged dropped = scaling::dropFlagged(table);
        EXPECT_TRUE(dropped.recorded) << format;
        EXPECT_EQ(dropped.dropped, 4u) << format;
        EXPECT_EQ(table.responses.size(), before - 4) << format;
    }
    // The study file itself, through the CLI.
    const CommandResult run = runCommand({SKINLAB_CLI, "analyze", "scale", study.databasePath().string(), "-o",
                                          (study.folder() / "scale").string(), "--bootstrap", "100", "--drop-flagged"});
    EXPECT_EQ(run.exitCode, 0) << run.err;
    EXPECT_NE(run.out.find("dropped 4 flagged trials"), std::string::npos) << run.out;
}

TEST(OnlineStudy, AStudyFileFromBeforeOnlineStudiesOpensAndGainsTheirTables) {
    TempFolder folder("online-old");
    writeStimulusSet(folder.path() / "stimuli");
    const fs::path database = folder.path() / "study.db";
    createStudy(folder.path() / "stimuli", writeText(folder.path(), "design.toml", design("")), {}, database);
    {
        // Back to the schema without the online tables, and the design JSON without the online keys.
        SqliteDatabase db(database.string(), false);
        db.execute("DROP VIEW responses_long; DROP TABLE trial_conditions; DROP TABLE viewing_conditions;"
                   " DROP TABLE recruitment;");
        db.execute(R"SQL(CREATE VIEW responses_long AS
  SELECT p.label AS observer, t.block AS scene, t.condition_a AS condition_A, t.condition_b AS condition_B,
         CASE r.chosen WHEN 'A' THEN 1 ELSE 0 END AS is_A_selected, t.a_on_left AS A_on_left,
         t.kind AS trial_kind,
         CASE WHEN t.kind = 'catch' THEN (CASE WHEN r.chosen = t.expected THEN 1 ELSE 0 END) ELSE NULL END AS correct,
         r.response_ms AS response_ms
  FROM responses r JOIN trials t ON t.id = r.trial_id JOIN participants p ON p.id = t.participant_id
  ORDER BY p.id, t.position)SQL");
        SqliteStatement read = db.prepare("SELECT value FROM meta WHERE key = 'definition'");
        read.step();
        json definition = json::parse(read.text(0));
        for (const char* key : {"recruitment", "display", "requirements"}) definition["design"].erase(key);
        SqliteStatement write = db.prepare("UPDATE meta SET value = ? WHERE key = 'definition'");
        write.bind(1, definition.dump());
        write.run();
    }
    // Opening it adds the online tables (and the view's `flagged`); everything works as in a new file.
    StudyStore store(database);
    EXPECT_EQ(store.definition().design.recruitment.platform, "none");
    const ParticipantRecord p = store.join("");
    const std::int64_t session = store.startSession(p.id, "test", 1280, 800, 1.0);
    const std::optional<TrialRecord> trial = store.nextTrial(p.id);
    ASSERT_TRUE(trial.has_value());
    ResponseInput in;
    in.token = p.token;
    in.trialId = trialReference(p.token, trial->id);
    in.side = "left";
    in.sessionId = session;
    in.responseMs = 500;
    in.clientTime = "2026-12-01T20:00:00.000Z";
    in.conditions = TrialConditions{true, false, false};
    EXPECT_EQ(store.recordResponse(in), ResponseOutcome::stored);
    EXPECT_EQ(store.flaggedTrials().size(), 1u);
    const std::vector<std::string> csv = csvLines(exportResponses(store, "csv"));
    ASSERT_EQ(csv.size(), 2u);
    EXPECT_EQ(fieldOf(csv[1], columnOf(csv[0], "flagged")), "1");
    const scaling::ResponseTable table = scaling::readResponses(database);
    ASSERT_EQ(table.responses.size(), 1u);
    EXPECT_EQ(table.responses[0].flagged, std::optional<bool>(true));
}

TEST(OnlineStudy, SimulatedObserversTakeAPlatformStudyWithRequirementsAndCalibration) {
    RunningStudy study(design(std::string(kProlific) + "[display]\ncalibrate = true\nviewing_distance_mm = 600\n"
                                                       "[requirements]\nmin_screen_width = 1280\ndesktop = true\n"));
    SimulationOptions options;
    options.port = study.port();
    options.observers = 2;
    options.labelPrefix = "online";
    const SimulationReport first = simulateObservers(study.store(), options);
    for (const ObserverResult& o : first.observers) EXPECT_TRUE(o.failure.empty()) << o.label << ": " << o.failure;
    EXPECT_EQ(first.completed(), 2);
    // Run again: the same platform ids return the same two participants.
    const SimulationReport again = simulateObservers(study.store(), options);
    EXPECT_EQ(again.completed(), 2);
    const std::vector<ParticipantStatus> status = study.store().status();
    ASSERT_EQ(status.size(), 2u);
    for (const ParticipantStatus& p : status) {
        ASSERT_TRUE(p.external.has_value());
        EXPECT_EQ(p.external->id.size(), 24u);
    }
    for (const SessionViewing& s : study.store().viewingConditions()) {
        ASSERT_TRUE(s.viewing && s.viewing->pixelsPerDegree);
        EXPECT_GT(*s.viewing->pixelsPerDegree, 0.0);
    }
}
