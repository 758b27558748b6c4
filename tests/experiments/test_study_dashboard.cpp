// The researcher dashboard (GET /researcher, GET /api/researcher/dashboard), the client address behind a trusted
// proxy (X-Forwarded-For believed from it only), and `study backup` while answers are being written. Real HTTP on
// an ephemeral loopback port, real SQLite.
#include "common/error.h"
#include "experiments/nginx_config.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_backup.h"
#include "study_server_fixture.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <map>
#include <set>

using namespace skinlab::experiments;
using namespace skinlab::experiments::test_support;
using nlohmann::json;

namespace {

const char* kDesign = R"(
title = "Dashboard test"
question = "Which image looks more like real skin?"
seed = 7
repetitions = 1
[practice]
trials = 1
[catch]
blank = 1
)";

json screen() { return {{"viewport_width", 1600}, {"viewport_height", 900}, {"device_pixel_ratio", 1.0}}; }

struct Participant {
    std::string token;
    std::int64_t session = 0;
};

Participant joinAndStart(HttpClient& client, const HttpHeaders& headers = {}) {
    Participant p;
    const HttpAnswer joined = client.send("POST", "/api/join", "{}", headers);
    EXPECT_EQ(joined.status, 201) << joined.body;
    p.token = json::parse(joined.body).value("token", "");
    json start = screen();
    start["token"] = p.token;
    JsonAnswer session = postJson(client, "/api/session", start);
    EXPECT_EQ(session.status, 200) << session.raw;
    p.session = session.body.value("session", 0);
    return p;
}

// Answers up to `count` trials (all when -1), always "left"; returns how many were answered.
int answer(HttpClient& client, const Participant& p, int count = -1) {
    int answered = 0;
    while (count < 0 || answered < count) {
        JsonAnswer state = get(client, "/api/state", {{"X-Skinlab-Token", p.token}});
        if (state.body["trial"].is_null()) break;
        json body = screen();
        body["token"] = p.token;
        body["trial"] = state.body["trial"]["id"];
        // An attentive observer: the image, never the blank panel of a catch trial (so nobody is excluded).
        body["side"] = state.body["trial"]["left"].contains("blank") ? "right" : "left";
        body["session"] = p.session;
        body["response_ms"] = 600.0 + 100.0 * answered;
        body["client_time"] = "2026-11-23T14:00:00.000Z";
        JsonAnswer stored = postJson(client, "/api/response", body);
        EXPECT_EQ(stored.status, 200) << stored.raw;
        ++answered;
    }
    return answered;
}

JsonAnswer dashboard(HttpClient& client, const std::string& token = kResearcherToken) {
    return get(client, "/api/researcher/dashboard", {{"Authorization", "Bearer " + token}});
}

const json* participantNamed(const json& board, const std::string& observer) {
    for (const json& p : board["participants"])
        if (p["observer"] == observer) return &p;
    return nullptr;
}

} // namespace

TEST(StudyDashboard, TokenOnlyInTheAuthorizationHeader) {
    RunningStudy study(kDesign);
    HttpClient client = study.client();
    EXPECT_EQ(get(client, "/api/researcher/dashboard").status, 401);
    const JsonAnswer inUrl = get(client, std::string("/api/researcher/dashboard?token=") + kResearcherToken);
    EXPECT_EQ(inUrl.status, 401);
    EXPECT_NE(inUrl.raw.find("never in the URL"), std::string::npos) << inUrl.raw;
    EXPECT_EQ(dashboard(client, "wrong-token").status, 403);
    EXPECT_EQ(
        get(client, "/api/researcher/dashboard", {{"Authorization", std::string("Basic ") + kResearcherToken}}).status,
        401);
    const JsonAnswer ok = dashboard(client);
    ASSERT_EQ(ok.status, 200) << ok.raw;
    EXPECT_EQ(ok.contentType, "application/json");

    // The page itself holds no data: served to anyone, it asks the API with the token it is given.
    const HttpAnswer page = client.get("/researcher");
    EXPECT_EQ(page.status, 200);
    EXPECT_NE(page.body.find("/researcher.js"), std::string::npos);
    EXPECT_EQ(page.header("Referrer-Policy"), "no-referrer");
    EXPECT_EQ(client.get("/researcher.js").status, 200);
    EXPECT_EQ(client.get("/researcher.css").status, 200);
}

TEST(StudyDashboard, ShowsProgressCatchTrialsResponseTimesAndTheLiveScale) {
    RunningStudy study(kDesign, {}, [](ServerOptions& o) { o.dashboardInterval = std::chrono::milliseconds(0); });
    HttpClient client = study.client();
    JsonAnswer empty = dashboard(client);
    ASSERT_EQ(empty.status, 200) << empty.raw;
    EXPECT_EQ(empty.body["totals"]["participants"], 0);
    EXPECT_EQ(empty.body["scale"]["state"], "none");
    EXPECT_EQ(empty.body["viewing_conditions"]["note"], "not recorded");
    EXPECT_EQ(empty.body["flagged_trials"]["note"], "not recorded");

    const Participant first = joinAndStart(client), second = joinAndStart(client);
    const int total = answer(client, first);
    answer(client, second, 3);
    JsonAnswer board = dashboard(client);
    ASSERT_EQ(board.status, 200) << board.raw;
    EXPECT_EQ(board.body["totals"]["participants"], 2);
    EXPECT_EQ(board.body["totals"]["completed"], 1);
    EXPECT_EQ(board.body["totals"]["responses"], total + 3);
    const json* p1 = participantNamed(board.body, "P001");
    ASSERT_NE(p1, nullptr) << board.raw;
    EXPECT_EQ((*p1)["answered"], total);
    EXPECT_EQ((*p1)["total"], total);
    EXPECT_EQ((*p1)["completed"], true);
    EXPECT_EQ((*p1)["client_address"], "127.0.0.1");
    EXPECT_EQ((*p1)["address_source"], "peer");
    // Blank catch trials, all answered with the image.
    const int catchAnswered = (*p1)["catch_answered"], catchCorrect = (*p1)["catch_correct"];
    EXPECT_GE(catchAnswered, 1);
    EXPECT_EQ(catchCorrect, catchAnswered);
    EXPECT_GE(board.body["totals"]["catch_answered"].get<int>(), catchAnswered);
    // Response times: every non-practice answer in exactly one bin.
    int binned = 0;
    for (const json& bin : board.body["response_times"]["bins"]) binned += bin["count"].get<int>();
    EXPECT_EQ(binned, board.body["response_times"]["count"].get<int>());
    EXPECT_EQ(binned, total + 3 - 2); // one practice trial each
    // The scale: every block, every condition, an interval around the score. An end only the prior would set (a
    // condition that won or lost every comparison) is open: null, never a number the data do not support.
    const json& scale = board.body["scale"];
    ASSERT_EQ(scale["state"], "ok") << scale.dump();
    ASSERT_EQ(scale["blocks"].size(), 2u);
    for (const json& block : scale["blocks"]) {
        EXPECT_GE(block["conditions"].size(), 3u) << block.dump(); // three methods (and the reference)
        for (const json& c : block["conditions"]) {
            ASSERT_TRUE(c["jod"].is_number()) << c.dump();
            if (c["low"].is_number()) {
                EXPECT_LE(c["low"].get<double>(), c["jod"].get<double>() + 1e-9);
            }
            if (c["high"].is_number()) {
                EXPECT_GE(c["high"].get<double>(), c["jod"].get<double>() - 1e-9);
            }
            if (!c["low"].is_number() || !c["high"].is_number()) {
                EXPECT_TRUE(c["interval_fallback"].get<bool>());
            }
        }
    }
    const int scaled = scale["responses"];
    // More answers: the next dashboard shows them and a scale recomputed from them.
    answer(client, second);
    JsonAnswer later = dashboard(client);
    EXPECT_EQ(later.body["totals"]["completed"], 2);
    EXPECT_GT(later.body["scale"]["responses"].get<int>(), scaled);
}

TEST(StudyDashboard, ScaleIsRecomputedAtMostOncePerInterval) {
    RunningStudy study(kDesign, {}, [](ServerOptions& o) { o.dashboardInterval = std::chrono::hours(1); });
    HttpClient client = study.client();
    const int total = answer(client, joinAndStart(client));
    const JsonAnswer first = dashboard(client);
    ASSERT_EQ(first.body["scale"]["state"], "ok") << first.raw;
    answer(client, joinAndStart(client), 3);
    const JsonAnswer second = dashboard(client);
    // The counts are current; the scale is the cached one until the interval has passed.
    EXPECT_EQ(second.body["totals"]["responses"], total + 3);
    EXPECT_EQ(second.body["scale"]["computed_at"], first.body["scale"]["computed_at"]);
    EXPECT_EQ(second.body["scale"]["responses"], first.body["scale"]["responses"]);
}

TEST(StudyServerProxy, ForwardedAddressIsBelievedOnlyFromATrustedProxy) {
    RunningStudy study(kDesign, {}, [](ServerOptions& o) {
        o.trustedProxies = {"127.0.0.2"};
        o.joinsPerMinute = 1;
        o.joinBurst = 2;
    });
    HttpClient proxy = study.client();
    proxy.setSourceAddress("127.0.0.2");
    HttpClient other = study.client();
    other.setSourceAddress("127.0.0.3");
    HttpClient researcher = study.client();

    // Through the proxy: the forwarded address (the rightmost entry, the one the proxy added) is the client's.
    joinAndStart(proxy, {{"X-Forwarded-For", "198.51.100.7"}});
    joinAndStart(proxy, {{"X-Forwarded-For", "203.0.113.99, 198.51.100.8"}});
    // From any other peer the header is ignored: the peer's address is stored.
    joinAndStart(other, {{"X-Forwarded-For", "198.51.100.9"}});
    const JsonAnswer board = dashboard(researcher);
    ASSERT_EQ(board.status, 200);
    std::map<std::string, std::string> addresses;
    for (const json& p : board.body["participants"])
        addresses[p["observer"]] =
            p["client_address"].get<std::string>() + "/" + p["address_source"].get<std::string>();
    EXPECT_EQ(addresses["P001"], "198.51.100.7/forwarded");
    EXPECT_EQ(addresses["P002"], "198.51.100.8/forwarded");
    EXPECT_EQ(addresses["P003"], "127.0.0.3/peer");

    // The join rate limit counts the forwarded address: 198.51.100.7 has used its burst of 2, others have not.
    EXPECT_EQ(proxy.send("POST", "/api/join", "{}", {{"X-Forwarded-For", "198.51.100.7"}}).status, 201);
    EXPECT_EQ(proxy.send("POST", "/api/join", "{}", {{"X-Forwarded-For", "198.51.100.7"}}).status, 429);
    EXPECT_EQ(proxy.send("POST", "/api/join", "{}", {{"X-Forwarded-For", "198.51.100.10"}}).status, 201);
    // A spoofing peer cannot escape its own limit by naming other addresses: 127.0.0.3 has one join left.
    EXPECT_EQ(other.send("POST", "/api/join", "{}", {{"X-Forwarded-For", "192.0.2.1"}}).status, 201);
    EXPECT_EQ(other.send("POST", "/api/join", "{}", {{"X-Forwarded-For", "192.0.2.2"}}).status, 429);
    // A header from the proxy that is not an address: refused, nothing stored.
    const std::string before = study.fingerprint();
    EXPECT_EQ(proxy.send("POST", "/api/join", "{}", {{"X-Forwarded-For", "not-an-address"}}).status, 400);
    EXPECT_EQ(study.fingerprint(), before);
}

TEST(StudyServerProxy, PublicHostTrustsLoopbackProxies) {
    RunningStudy study(kDesign, {}, [](ServerOptions& o) { o.publicHost = "study.example.org"; });
    HttpClient client = study.client();
    joinAndStart(client, {{"X-Forwarded-For", "198.51.100.20"}});
    const JsonAnswer board = dashboard(client);
    ASSERT_EQ(board.body["participants"].size(), 1u);
    EXPECT_EQ(board.body["participants"][0]["client_address"], "198.51.100.20");
}

TEST(StudyBackup, CopyWhileAnswersAreWrittenHoldsAConsistentPrefix) {
    RunningStudy study(kDesign);
    HttpClient client = study.client();
    std::vector<Participant> participants;
    for (int i = 0; i < 4; ++i) participants.push_back(joinAndStart(client));
    // The writer answers every trial of every participant, one committed response at a time, in a known order.
    std::atomic<bool> done{false};
    std::thread writer([&] {
        HttpClient own = study.client();
        for (const Participant& p : participants) answer(own, p);
        done = true;
    });
    const std::filesystem::path folder = study.folder() / "backups";
    std::filesystem::create_directories(folder);
    std::vector<std::int64_t> seen;
    int copies = 0;
    std::int64_t previous = -1;
    while (true) {
        const bool last = done.load();
        const auto out = folder / ("copy-" + std::to_string(copies++) + ".db");
        const BackupSummary summary = backupStudy(study.databasePath(), out, false);
        EXPECT_FALSE(std::filesystem::exists(out.string() + "-wal")) << "the copy is one self-contained file";
        SqliteDatabase copy(out.string(), false);
        SqliteStatement check = copy.prepare("PRAGMA integrity_check");
        ASSERT_TRUE(check.step());
        EXPECT_EQ(check.text(0), "ok");
        // A consistent prefix: participants answered in order, each one's trials in order, so the copy holds
        // every answer of the participants before some point, a leading run of positions of the one at that
        // point, and nothing after it.
        SqliteStatement rows =
            copy.prepare("SELECT t.participant_id, t.position FROM responses r JOIN trials t ON t.id = r.trial_id"
                         " ORDER BY t.participant_id, t.position");
        std::vector<std::pair<std::int64_t, int>> stored;
        while (rows.step()) stored.emplace_back(rows.integer(0), static_cast<int>(rows.integer(1)));
        EXPECT_EQ(static_cast<std::int64_t>(stored.size()), summary.responses);
        SqliteStatement planned =
            copy.prepare("SELECT participant_id, COUNT(*) FROM trials GROUP BY participant_id ORDER BY participant_id");
        std::map<std::int64_t, int> perParticipant;
        while (planned.step()) perParticipant[planned.integer(0)] = static_cast<int>(planned.integer(1));
        std::size_t k = 0;
        for (const auto& [participant, count] : perParticipant) {
            int position = 0;
            while (k < stored.size() && stored[k].first == participant) {
                EXPECT_EQ(stored[k].second, position) << "a gap in participant " << participant << "'s answers";
                ++position;
                ++k;
            }
            if (k < stored.size()) {
                EXPECT_EQ(position, count) << "a later participant's answer before this one finished";
            }
        }
        EXPECT_GE(summary.responses, previous) << "a later copy holds fewer answers";
        previous = summary.responses;
        seen.push_back(summary.responses);
        if (last) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    writer.join();
    EXPECT_GE(copies, 2);
    EXPECT_EQ(previous, study.store().responseCount()) << "the copy after the last answer holds every answer";
    // An existing copy is not replaced unless asked; the study itself never.
    const auto existing = folder / "copy-0.db";
    EXPECT_THROW(backupStudy(study.databasePath(), existing, false), skinlab::InputError);
    EXPECT_NO_THROW(backupStudy(study.databasePath(), existing, true));
    EXPECT_THROW(backupStudy(study.databasePath(), study.databasePath(), true), skinlab::InputError);
    std::set<std::int64_t> distinct(seen.begin(), seen.end());
    std::printf("%d copies taken while answering, %zu distinct answer counts\n", copies, distinct.size());
}

TEST(NginxSiteConfig, FillsTheTemplateAndRefusesValuesNginxWouldMisread) {
    TempFolder folder("nginx-config");
    const auto cert =
        writeText(folder.path(), "cert.pem", "-----BEGIN CERTIFICATE-----\nMIIB\n-----END CERTIFICATE-----\n");
    const auto key =
        writeText(folder.path(), "key.pem", "-----BEGIN PRIVATE KEY-----\nMIIB\n-----END PRIVATE KEY-----\n");
    NginxSiteOptions o;
    o.serverName = "study.example.org";
    o.upstream = "127.0.0.1:8080";
    o.certificate = cert.string();
    o.key = key.string();
    o.redirectPort = 80;
    const std::string text = nginxSiteConfig(o);
    EXPECT_EQ(text.find('@'), std::string::npos) << "a placeholder left unfilled";
    for (const std::string& expected :
         {std::string("server 127.0.0.1:8080;"), std::string("server_name study.example.org;"),
          "ssl_certificate     " + cert.string() + ";", "ssl_certificate_key " + key.string() + ";",
          std::string("listen 443 ssl http2;"), std::string("listen [::]:443 ssl http2;"),
          std::string("proxy_set_header X-Forwarded-For $remote_addr;"), std::string("client_max_body_size 16k;"),
          std::string("return 301 https://study.example.org$request_uri;"),
          std::string("--public-host study.example.org"),
          std::string("map $remote_addr $skinlab_study_example_org_client"),
          std::string("limit_req_zone $skinlab_study_example_org_client zone="),
          std::string("limit_conn_zone $skinlab_study_example_org_client zone="),
          std::string(
              "log_format skinlab_study_example_org_private '$remote_addr [$time_local] \"$request_method $uri "),
          std::string("access_log /var/log/nginx/access.log skinlab_study_example_org_private;")}) {
        EXPECT_NE(text.find(expected), std::string::npos) << expected;
    }
    // The redirect goes to the configured name, never the client's Host; no log line holds a query string.
    EXPECT_EQ(text.find("$host$request_uri"), std::string::npos);
    EXPECT_EQ(text.find("$request "), std::string::npos);
    EXPECT_EQ(text.find("$request_uri\""), std::string::npos);
    EXPECT_EQ(text.find("$http_referer"), std::string::npos);

    // Only the addresses asked for, for HTTPS and the redirect alike.
    {
        NginxSiteOptions only = o;
        only.listen = {"192.0.2.10:8443", "[2001:DB8::1]:8443"};
        only.accessLog = "off";
        const std::string site = nginxSiteConfig(only);
        std::vector<std::string> listens;
        for (std::size_t at = site.find("    listen "); at != std::string::npos; at = site.find("    listen ", at + 1))
            listens.push_back(site.substr(at + 11, site.find(';', at) - at - 11));
        EXPECT_EQ(listens, (std::vector<std::string>{"192.0.2.10:80", "[2001:db8::1]:80", "192.0.2.10:8443 ssl http2",
                                                     "[2001:db8::1]:8443 ssl http2"}));
        EXPECT_NE(site.find("return 301 https://study.example.org:8443$request_uri;"), std::string::npos);
        EXPECT_NE(site.find("access_log off;"), std::string::npos);
    }

    auto refused = [&](const std::function<void(NginxSiteOptions&)>& change, const std::string& option) {
        NginxSiteOptions bad = o;
        change(bad);
        try {
            nginxSiteConfig(bad);
            ADD_FAILURE() << option << ": accepted";
        } catch (const skinlab::InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(option, 0), 0u) << e.what();
        }
    };
    refused([](NginxSiteOptions& b) { b.serverName = "study.example.org; include /etc/passwd"; }, "--server-name");
    refused([](NginxSiteOptions& b) { b.serverName = ""; }, "--server-name");
    refused([](NginxSiteOptions& b) { b.upstream = "localhost:8080"; }, "--upstream");
    refused([](NginxSiteOptions& b) { b.upstream = "127.0.0.1:99999"; }, "--upstream");
    refused([](NginxSiteOptions& b) { b.certificate = "cert.pem"; }, "--cert");
    refused([](NginxSiteOptions& b) { b.certificate = b.certificate + " ssl_verify"; }, "--cert");
    refused([&](NginxSiteOptions& b) { b.key = (folder.path() / "missing.pem").string(); }, "--key");
    refused([&](NginxSiteOptions& b) { b.key = writeText(folder.path(), "plain.txt", "not a key\n").string(); },
            "--key");
    refused([](NginxSiteOptions& b) { b.listen = {"443x"}; }, "--listen");
    refused([](NginxSiteOptions& b) { b.listen = {"[2001:db8::zz]:443"}; }, "--listen");
    refused([](NginxSiteOptions& b) { b.listen = {"2001:db8::1:443"}; }, "--listen");
    refused([](NginxSiteOptions& b) { b.accessLog = "logs/access.log"; }, "--access-log");
    refused([](NginxSiteOptions& b) { b.accessLog = "/var/log/a.log; include /etc/passwd"; }, "--access-log");
}
