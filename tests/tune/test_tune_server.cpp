// skinlab tune over real HTTP on loopback (an in-process TuneServer on an ephemeral port, the project's Beast
// client), real EGL rendering, and the real `skinlab` executable for the CLI's errors and the export round trip.
#include "common/error.h"
#include "common/process.h"
#include "net/http_client.h"
#include "renderer/renderer.h"
#include "renderer/scene/builtin_scenes.h"
#include "renderer/sss/sss_params.h"
#include "tests/common/cli_run.h"
#include "tests/common/temp_folder.h"
#include "tune/tune_server.h"

#include <atomic>
#include <csignal>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <pthread.h>
#include <sstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace skinlab::tune {
namespace {

using net::HttpAnswer;
using net::HttpClient;
using json = nlohmann::json;

std::string& eglFailure() {
    static std::string failure;
    return failure;
}

bool eglAvailable() {
    static const bool available = [] {
        try {
            renderer::Renderer probe;
            return true;
        } catch (const std::exception& e) {
            eglFailure() = e.what();
            return false;
        }
    }();
    return available;
}

#define REQUIRE_EGL()                                                                                                  \
    if (!eglAvailable()) GTEST_SKIP() << "no EGL/OpenGL 4.5 context: " << eglFailure()

std::vector<unsigned char> decodeBase64(const std::string& text) {
    std::vector<unsigned char> out;
    int value = 0, bits = -8;
    for (const char c : text) {
        int digit;
        if (c >= 'A' && c <= 'Z') digit = c - 'A';
        else if (c >= 'a' && c <= 'z') digit = c - 'a' + 26;
        else if (c >= '0' && c <= '9') digit = c - '0' + 52;
        else if (c == '+') digit = 62;
        else if (c == '/') digit = 63;
        else break;
        value = (value << 6) + digit;
        bits += 6;
        if (bits >= 0) {
            out.push_back(static_cast<unsigned char>((value >> bits) & 0xFF));
            bits -= 8;
        }
    }
    return out;
}

// The image of a render answer (a PNG data URL), decoded to BGR 8-bit.
cv::Mat imageOf(const json& answer) {
    const std::string url = answer.at("image").get<std::string>();
    const std::string prefix = "data:image/png;base64,";
    EXPECT_EQ(url.rfind(prefix, 0), 0u);
    const std::vector<unsigned char> png = decodeBase64(url.substr(prefix.size()));
    return cv::imdecode(png, cv::IMREAD_COLOR);
}

bool identical(const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

std::string readAll(const std::filesystem::path& file) {
    std::ifstream in(file);
    return {std::istreambuf_iterator<char>(in), {}};
}

// The live (not zombie) processes whose parent is `parent`, from /proc.
std::vector<pid_t> childProcesses(pid_t parent) {
    std::vector<pid_t> out;
    for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
        const std::string name = entry.path().filename().string();
        if (name.find_first_not_of("0123456789") != std::string::npos) continue;
        const std::string stat = readAll(entry.path() / "stat");
        const std::size_t close = stat.rfind(')');
        if (close == std::string::npos || close + 4 >= stat.size()) continue;
        std::istringstream fields(stat.substr(close + 2));
        char state = 0;
        pid_t ppid = 0;
        fields >> state >> ppid;
        if (ppid == parent && state != 'Z') out.push_back(std::stoi(name));
    }
    return out;
}

// Waits up to `limit` until `parent` has no live child; whether it has none.
bool childrenEnd(pid_t parent, std::chrono::milliseconds limit) {
    const auto until = std::chrono::steady_clock::now() + limit;
    while (!childProcesses(parent).empty()) {
        if (std::chrono::steady_clock::now() > until) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return true;
}

class TuneServerTest : public ::testing::Test {
protected:
    void SetUp() override {
        REQUIRE_EGL();
        TuneOptions options;
        options.scenes = {"builtin:head", "builtin:halo"};
        options.exportDir = work_ / "exports";
        options.executable = SKINLAB_CLI;
        options.workDir = work_ / "work";
        options.token = token_;
        configure(options);
        server_ = std::make_unique<TuneServer>(options);
        port_ = server_->bind();
        thread_ = std::thread([this] { server_->run(); });
    }
    void TearDown() override {
        if (server_) server_->stop();
        if (thread_.joinable()) thread_.join();
        server_.reset();
    }
    virtual void configure(TuneOptions&) {}

    HttpClient client() const {
        HttpClient c("127.0.0.1", port_);
        c.setTimeout(std::chrono::seconds(120));
        return c;
    }
    // This start's token, read from the page the server serves (as the page's script reads it).
    std::string pageToken() {
        if (pageToken_.empty()) {
            HttpClient c = client();
            const std::string page = c.get("/").body;
            const std::string marker = "<meta name=\"skinlab-token\" content=\"";
            const std::size_t at = page.find(marker);
            EXPECT_NE(at, std::string::npos) << page.substr(0, 400);
            if (at != std::string::npos)
                pageToken_ = page.substr(at + marker.size(), page.find('"', at + marker.size()) - at - marker.size());
        }
        return pageToken_;
    }
    // The headers of the page's own POSTs.
    net::HttpHeaders pageHeaders() {
        net::HttpHeaders headers{{"X-Skinlab-Token", pageToken()}};
        if (!token_.empty()) headers.emplace_back("Authorization", "Bearer " + token_);
        return headers;
    }
    HttpAnswer post(HttpClient& c, const std::string& path, const json& body) {
        return c.send("POST", path, body.dump(), pageHeaders());
    }
    json render(HttpClient& c, const std::vector<std::string>& overrides, const std::string& clientId = "test",
                const std::string& scene = "builtin:head") {
        const HttpAnswer answer =
            post(c, "/api/render", {{"client", clientId}, {"scene", scene}, {"overrides", overrides}});
        EXPECT_EQ(answer.status, 200) << answer.body;
        return json::parse(answer.body);
    }

    test_support::TempFolder folder_;
    const std::filesystem::path work_ = folder_.path();
    std::string token_;
    std::string pageToken_;
    std::unique_ptr<TuneServer> server_;
    std::thread thread_;
    int port_ = 0;
};

const std::vector<std::string> kSmall{"render.width=160", "render.height=90", "shadow.resolution=512"};

// A manifest entry (contract 2, formats/stimulus_manifest.h): the keys every entry carries, and the test's own.
json manifestEntry(const std::string& id, const json& fields) {
    json entry = {{"id", id},
                  {"files", {{"exr", "exr/" + id + ".exr"}, {"png", "png/" + id + ".png"}}},
                  {"sha256", {{"exr", std::string(64, '0')}, {"png", std::string(64, '0')}}},
                  {"block", "test"},
                  {"width", 160},
                  {"height", 90}};
    entry.update(fields);
    return entry;
}

std::vector<std::string> with(std::vector<std::string> base, const std::vector<std::string>& more) {
    base.insert(base.end(), more.begin(), more.end());
    return base;
}

TEST_F(TuneServerTest, SchemaCarriesTheReadersDeclarations) {
    HttpClient c = client();
    const HttpAnswer answer = c.get("/api/schema");
    ASSERT_EQ(answer.status, 200) << answer.body;
    const json schema = json::parse(answer.body);
    ASSERT_EQ(schema["methods"].size(), renderer::sss::methodTable().size());
    for (const json& method : schema["methods"]) {
        const auto* info = renderer::sss::findMethod(method["name"].get<std::string>());
        ASSERT_NE(info, nullptr);
        for (const json& p : method["parameters"]) {
            const std::string name = p["name"];
            EXPECT_TRUE(renderer::sss::methodUsesKey(info->method, name)) << name;
            const auto& declared = renderer::sss::sssKey(name);
            if (p.contains("min")) {
                EXPECT_EQ(p["min"].get<double>(), declared.min);
                EXPECT_EQ(p["max"].get<double>(), declared.max);
            }
        }
    }
    // pscbf's samples default is its own (13), the others' 21.
    for (const json& method : schema["methods"])
        for (const json& p : method["parameters"])
            if (p["name"] == "samples") {
                EXPECT_EQ(p["default"].get<int>(), method["name"] == "pscbf" ? 13 : 21);
            }
    EXPECT_EQ(schema["scenes"][0], "builtin:head");
}

TEST_F(TuneServerTest, SliderChangesRerunOnlyWhatTheyTouch) {
    HttpClient c = client();
    const json first = render(c, with(kSmall, {"sss.method=\"separable\"", "sss.width_mm=2"}));
    EXPECT_EQ(first["reran"], json({"upload", "shadows", "lighting", "sss"}));
    const json wider = render(c, with(kSmall, {"sss.method=\"separable\"", "sss.width_mm=6"}));
    EXPECT_EQ(wider["reran"], json({"sss"})); // an [sss] key: the SSS stage and tone map only
    EXPECT_EQ(wider["resolved"]["sss"]["width_mm"], 6.0);
    EXPECT_FALSE(identical(imageOf(first), imageOf(wider)));
    const json brighter =
        render(c, with(kSmall, {"sss.method=\"separable\"", "sss.width_mm=6", "lights[0].intensity=2.5"}));
    EXPECT_EQ(brighter["reran"], json({"shadows", "lighting", "sss"})); // a light: the scene stays resident
    const json orbited = render(c, with(kSmall, {"sss.method=\"separable\"", "sss.width_mm=6",
                                                 "lights[0].intensity=2.5", "camera.yaw_deg=40"}));
    EXPECT_EQ(orbited["reran"], json({"lighting", "sss"})); // the camera: the shadow maps stay
    const json otherScene = render(c, kSmall, "test", "builtin:halo");
    EXPECT_EQ(otherScene["reran"], json({"upload", "shadows", "lighting", "sss"}));
}

TEST_F(TuneServerTest, IncrementalImagesEqualFullRenders) {
    // After a sequence of partial re-runs, the image equals `skinlab render`'s PNG of the same values, pixel for
    // pixel: the resident state carries nothing over.
    HttpClient c = client();
    const std::vector<std::string> steps[] = {
        with(kSmall, {"sss.method=\"artistic\""}),
        with(kSmall, {"sss.method=\"artistic\"", "sss.artistic_strength=[0.9, 0.2, 0.1]"}),
        with(kSmall, {"sss.method=\"gaussian-sum\"", "transmittance.enabled=true", "sss.width_mm=4"}),
        with(kSmall, {"sss.method=\"gaussian-sum\"", "transmittance.enabled=true", "sss.width_mm=1.5"}),
        with(kSmall, {"sss.method=\"pscbf\"", "camera.yaw_deg=-30", "render.exposure_ev=0.5"}),
        with(kSmall, {"sss.method=\"pscbf\"", "camera.yaw_deg=10", "camera.pitch_deg=15", "render.exposure_ev=0.5"}),
    };
    int step = 0;
    for (const auto& overrides : steps) {
        const cv::Mat live = imageOf(render(c, overrides));
        std::string command = "render --scene builtin:head";
        for (const auto& o : overrides) command += " --set '" + o + "'";
        const auto png = work_ / ("full-" + std::to_string(step) + ".png");
        command += " -o " + (work_ / "full.exr").string() + " --png " + png.string();
        const auto run = test_support::runCli(command);
        ASSERT_EQ(run.exitCode, 0) << run.output;
        EXPECT_TRUE(identical(live, cv::imread(png.string(), cv::IMREAD_COLOR))) << "step " << step;
        ++step;
    }
}

TEST_F(TuneServerTest, BadValueGetsTheCliError) {
    HttpClient c = client();
    for (const std::string bad : {"sss.width_mm=500", "sss.samples=20", "sss.artistic_falloff=[1, 1, 1]",
                                  "sss.method=\"blur\"", "camera.fvo=3"}) {
        const HttpAnswer answer =
            post(c, "/api/render",
                 {{"scene", "builtin:head"}, {"overrides", with(kSmall, {"sss.method=\"separable\"", bad})}});
        EXPECT_EQ(answer.status, 400) << bad;
        const std::string error = json::parse(answer.body)["error"];
        const auto cli = test_support::runCli("render --scene builtin:head --set sss.method='\"separable\"' --set '" +
                                              bad + "' -o " + (work_ / "x.exr").string());
        EXPECT_EQ(cli.exitCode, 2) << cli.output;
        EXPECT_EQ("skinlab: error: " + error + "\n", cli.output) << bad;
    }
}

TEST_F(TuneServerTest, BadInputNeverCrashesTheServer) {
    HttpClient c = client();
    const std::vector<std::pair<std::string, std::string>> requests{
        {"/api/render", "not json"},
        {"/api/render", "[]"},
        {"/api/render", R"({"scene": 3})"},
        {"/api/render", R"({"scene": "/etc/passwd"})"},
        {"/api/render", R"({"scene": "builtin:head", "overrides": "sss.width_mm=2"})"},
        {"/api/render", R"({"scene": "builtin:head", "overrides": [1, 2]})"},
        {"/api/render", R"({"scene": "builtin:head", "overrides": ["=", "a[99999999999].b=1", "[[x"]})"},
        {"/api/render", R"({"scene": "builtin:head", "overrides": ["render.width=100000"]})"},
        {"/api/render", R"({"scene": "builtin:head", "client": ""})"},
        {"/api/render",
         R"({"scene": "builtin:head", "overrides": ["render.width=64", "render.height=64"], "compare": {"reference": "job999"}})"},
        {"/api/kernel",
         R"({"scene": "builtin:head", "overrides": ["sss.method=\"separable\"", "sss.profile=\"file:/nonexistent\""]})"},
        {"/api/export", R"({"scene": "builtin:head", "name": "../../escape"})"},
        {"/api/export", R"({"scene": "builtin:head"})"},
        {"/api/job/cancel", R"({"id": 5})"},
        {"/api/reference", R"({"scene": "builtin:nothing"})"},
    };
    for (const auto& [path, body] : requests) {
        const HttpAnswer answer = c.send("POST", path, body, pageHeaders());
        EXPECT_GE(answer.status, 400) << path << " " << body << ": " << answer.body;
        EXPECT_LT(answer.status, 500) << path << " " << body << ": " << answer.body;
        EXPECT_TRUE(json::parse(answer.body).contains("error"));
    }
    EXPECT_EQ(c.get("/api/job?id=nothing").status, 404);
    EXPECT_EQ(c.get("/api/open?id=x").status, 404); // no stimulus set given
    EXPECT_EQ(c.get("/nothing").status, 404);
    EXPECT_EQ(c.get("/api/job").status, 400);
    // Another site's name in Host (DNS rebinding) is refused.
    EXPECT_EQ(c.get("/api/schema", {{"Host", "evil.example:" + std::to_string(port_)}}).status, 421);
    // Still serving.
    const json ok = render(c, kSmall);
    EXPECT_EQ(ok["width"], 160);
}

TEST_F(TuneServerTest, TwoClientsAtOnce) {
    std::atomic<int> failures{0};
    auto page = [&](const std::string& id, double width) {
        HttpClient c = client();
        for (int i = 0; i < 4; ++i) {
            const double w = width + 0.25 * i;
            const std::string value = std::to_string(w);
            const HttpAnswer answer =
                post(c, "/api/render",
                     {{"client", id},
                      {"scene", "builtin:head"},
                      {"overrides", with(kSmall, {"sss.method=\"separable\"", "sss.width_mm=" + value})}});
            if (answer.status != 200) {
                ++failures;
                continue;
            }
            const json body = json::parse(answer.body);
            // Each client gets its own values back (one request at a time per client: none is superseded).
            if (body.contains("superseded") || std::abs(body["resolved"]["sss"]["width_mm"].get<double>() - w) > 1e-9)
                ++failures;
        }
    };
    std::thread a(page, "tab-a", 1.0), b(page, "tab-b", 5.0);
    a.join();
    b.join();
    EXPECT_EQ(failures.load(), 0);
}

TEST_F(TuneServerTest, LatestRequestOfAClientWins) {
    // Three requests of one client sent at once, numbered as the page numbers them: at most the newest waits,
    // replaced ones (and older ones that arrive after it: the threads may start in any order) are answered
    // "superseded", and the newest request's answer has its values.
    std::vector<std::thread> threads;
    std::vector<json> answers(3);
    for (int i = 0; i < 3; ++i) {
        threads.emplace_back([&, i] {
            std::this_thread::sleep_for(std::chrono::milliseconds(40 * i));
            HttpClient c = client();
            answers[static_cast<std::size_t>(i)] = json::parse(
                post(c, "/api/render",
                     {{"client", "same"},
                      {"seq", i},
                      {"scene", "builtin:head"},
                      {"overrides",
                       with(kSmall, {"sss.method=\"separable\"", "sss.width_mm=" + std::to_string(2 + i)})}})
                    .body);
        });
    }
    for (auto& t : threads) t.join();
    ASSERT_TRUE(answers[2].contains("resolved")) << answers[2].dump();
    EXPECT_EQ(answers[2]["resolved"]["sss"]["width_mm"], 4.0);
    for (const json& a : answers) EXPECT_TRUE(a.contains("superseded") || a.contains("image"));
}

TEST_F(TuneServerTest, OlderRequestArrivingLateIsSuperseded) {
    HttpClient c = client();
    const auto body = [&](int seq, const char* width) {
        return json{{"client", "late"},
                    {"seq", seq},
                    {"scene", "builtin:head"},
                    {"overrides", with(kSmall, {"sss.method=\"separable\"", std::string("sss.width_mm=") + width})}};
    };
    const json newer = json::parse(post(c, "/api/render", body(7, "3")).body);
    ASSERT_TRUE(newer.contains("image")) << newer.dump();
    const json older = json::parse(post(c, "/api/render", body(6, "2")).body);
    EXPECT_EQ(older, json({{"superseded", true}}));
    const json again = json::parse(post(c, "/api/render", body(7, "3")).body); // the same number is not older
    EXPECT_TRUE(again.contains("image")) << again.dump();
    const HttpAnswer bad = post(c, "/api/render", json{{"client", "late"}, {"seq", -1}, {"scene", "builtin:head"}});
    EXPECT_EQ(bad.status, 400);
    EXPECT_NE(bad.body.find("seq: expected a non-negative integer, got -1"), std::string::npos) << bad.body;
}

TEST_F(TuneServerTest, ExportRendersPixelExactWithSkinlabRender) {
    HttpClient c = client();
    const std::vector<std::string> overrides =
        with(kSmall, {"sss.method=\"separable\"", "sss.width_mm=2.35", "sss.profile=\"burley\"",
                      "lights[0].intensity=1.3", "camera.yaw_deg=35.5", "render.exposure_ev=0.25",
                      "transmittance.enabled=true", "transmittance.translucency=0.7"});
    const cv::Mat live = imageOf(render(c, overrides));
    const HttpAnswer exported =
        post(c, "/api/export", {{"scene", "builtin:head"}, {"overrides", overrides}, {"name", "tuned-1"}});
    ASSERT_EQ(exported.status, 200) << exported.body;
    const json files = json::parse(exported.body);
    const std::filesystem::path scene = files["scene_file"].get<std::string>();
    ASSERT_TRUE(std::filesystem::exists(scene));
    EXPECT_NE(files["include_text"].get<std::string>().find("method = \"separable\""), std::string::npos);
    EXPECT_NE(files["include_text"].get<std::string>().find("sss.width_mm = 2.35"), std::string::npos);
    const auto png = work_ / "exported.png";
    const auto run = test_support::runCli("render --scene " + scene.string() + " -o " + (work_ / "e.exr").string() +
                                          " --png " + png.string());
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_TRUE(identical(live, cv::imread(png.string(), cv::IMREAD_COLOR)));
}

TEST_F(TuneServerTest, KernelCurvesFollowTheMethod) {
    HttpClient c = client();
    const HttpAnswer answer = post(
        c, "/api/kernel",
        {{"scene", "builtin:head"}, {"overrides", {"sss.method=\"separable\"", "sss.samples=11", "sss.width_mm=1.5"}}});
    ASSERT_EQ(answer.status, 200) << answer.body;
    const json k = json::parse(answer.body);
    ASSERT_EQ(k["deon"].size(), 3u);
    ASSERT_EQ(k["burley"].size(), 3u);
    ASSERT_EQ(k["method_curve"].size(), 3u);
    EXPECT_EQ(k["stages"][0]["taps"].size(), 6u); // the centre and five on one side of 11
    EXPECT_EQ(k["params"]["width_mm"], 1.5);
    // The d'Eon curve at the method's width: red reaches further than blue.
    const auto& radius = k["radius_mm"];
    const std::size_t far = radius.size() * 3 / 4;
    EXPECT_GT(k["deon"][0][far].get<double>(), k["deon"][2][far].get<double>());
    const HttpAnswer bad = post(c, "/api/kernel", {{"scene", "builtin:head"}, {"overrides", {"sss.samples=4"}}});
    EXPECT_EQ(bad.status, 400);
}

TEST_F(TuneServerTest, SlowMethodRunsInTheBackgroundAndCancels) {
    HttpClient c = client();
    const json started = render(c, with(kSmall, {"sss.method=\"reference\""}));
    ASSERT_TRUE(started.contains("job")) << started.dump();
    const std::string id = started["job"]["id"];
    const json status = json::parse(c.get("/api/job?id=" + id).body);
    EXPECT_EQ(status["method"], "reference");
    const HttpAnswer cancelled = post(c, "/api/job/cancel", {{"id", id}});
    EXPECT_EQ(json::parse(cancelled.body)["cancelled"], true);
    const json after = json::parse(c.get("/api/job?id=" + id).body);
    EXPECT_EQ(after["state"], "cancelled");
    EXPECT_GE(after["elapsed_s"].get<double>(), 0.0) << after.dump(); // read before the process is reaped too
    EXPECT_EQ(c.get("/api/job/image?id=" + id).status, 409);
    // Every method that is not interactive runs so, EEVEE too (it needs Blender; the live path has none).
    const json eevee = render(c, with(kSmall, {"sss.method=\"eevee\""}));
    ASSERT_TRUE(eevee.contains("job")) << eevee.dump();
    EXPECT_EQ(eevee["job"]["method"], "eevee");
    EXPECT_EQ(json::parse(post(c, "/api/job/cancel", {{"id", eevee["job"]["id"]}}).body)["cancelled"], true);
}

TEST_F(TuneServerTest, DifferenceAgainstTheReference) {
    HttpClient c = client();
    const std::vector<std::string> view{"render.width=96", "render.height=64", "shadow.resolution=256"};
    const HttpAnswer started = post(c, "/api/reference", {{"scene", "builtin:halo"}, {"overrides", view}});
    ASSERT_EQ(started.status, 200) << started.body;
    const std::string id = json::parse(started.body)["job"]["id"];
    json status;
    for (int i = 0; i < 600; ++i) {
        status = json::parse(c.get("/api/job?id=" + id).body);
        if (status["state"] != "running") break;
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    ASSERT_EQ(status["state"], "done") << status.dump();
    for (const std::string metric : {"deltaE00", "flip", "cvvdp"}) {
        const HttpAnswer answer = post(c, "/api/render",
                                       {{"scene", "builtin:halo"},
                                        {"overrides", with(view, {"sss.method=\"separable\""})},
                                        {"compare", {{"reference", id}, {"metric", metric}}}});
        ASSERT_EQ(answer.status, 200) << answer.body;
        const json compare = json::parse(answer.body)["compare"];
        EXPECT_EQ(compare["metric"], metric);
        EXPECT_TRUE(compare["jod"].is_number());
        for (const char* band : {"halo", "bleed", "spill", "interior"}) EXPECT_TRUE(compare["bands"].contains(band));
        EXPECT_FALSE(imageOf(compare).empty());
    }
}

class TuneServerTokenTest : public TuneServerTest {
protected:
    void SetUp() override {
        token_ = "s3cret-token";
        TuneServerTest::SetUp();
    }
};

TEST_F(TuneServerTokenTest, ApiNeedsTheToken) {
    HttpClient c = client();
    EXPECT_EQ(c.get("/api/schema").status, 401);
    EXPECT_EQ(c.get("/api/schema", {{"Authorization", "Bearer wrong"}}).status, 403);
    EXPECT_EQ(c.get("/api/schema", {{"Authorization", "Bearer s3cret-token"}}).status, 200);
    EXPECT_EQ(c.get("/").status, 200); // the page itself holds nothing
}

TEST_F(TuneServerTest, ScannedHeadOfferedWithTheAssets) {
    // $SKINLAB_ASSETS (or --assets) holding the scan: the page offers its scene, and it renders.
    const char* assets = std::getenv("SKINLAB_ASSETS");
    if (!assets || !std::filesystem::exists(std::filesystem::path(assets) / "LeePerrySmith/LeePerrySmith.glb"))
        GTEST_SKIP() << "SKINLAB_ASSETS does not hold LeePerrySmith/LeePerrySmith.glb";
    HttpClient c = client();
    const json schema = json::parse(c.get("/api/schema").body);
    std::string scanned;
    for (const json& scene : schema["scenes"])
        if (scene.get<std::string>().ends_with("lee-perry-smith.toml")) scanned = scene;
    ASSERT_FALSE(scanned.empty()) << schema["scenes"].dump();
    const json frame = render(c, with(kSmall, {"sss.method=\"separable\""}), "scan", scanned);
    EXPECT_EQ(frame["resolved"]["model"]["source"], "assets:LeePerrySmith/LeePerrySmith.glb");
}

class TuneServerStimulusTest : public TuneServerTest {
protected:
    // A built set's manifest as `stimuli build` writes it (the fields "open" reads): one stimulus of builtin:head.
    void configure(TuneOptions& options) override {
        const auto set = work_ / "set";
        std::filesystem::create_directories(set);
        const json manifest = {
            {"format", "skinlab-stimuli"},
            {"version", 1},
            {"set", "demo"},
            {"stimuli",
             {manifestEntry("head-mid-separable", {{"scene", "builtin:head"},
                                                   {"factors", {{"method", "separable"}}},
                                                   {"reference", false},
                                                   {"overrides",
                                                    {"render.width=160", "render.height=90", "camera.view=\"mid\"",
                                                     "sss.method=\"separable\"", "sss.width_mm=2.5"}}})}}};
        std::ofstream(set / "manifest.json") << manifest.dump(1);
        options.stimulusSets = {set};
    }
};

TEST_F(TuneServerStimulusTest, OpenLoadsAStimulusWithItsExactParameters) {
    HttpClient c = client();
    const json schema = json::parse(c.get("/api/schema").body);
    ASSERT_EQ(schema["stimuli"].size(), 1u);
    EXPECT_EQ(schema["stimuli"][0]["id"], "head-mid-separable");
    const HttpAnswer opened = c.get("/api/open?set=0&id=head-mid-separable");
    ASSERT_EQ(opened.status, 200) << opened.body;
    const json config = json::parse(opened.body);
    EXPECT_EQ(config["scene"], "builtin:head");
    EXPECT_EQ(config["overrides"], json({"render.width=160", "render.height=90", "camera.view=\"mid\"",
                                         "sss.method=\"separable\"", "sss.width_mm=2.5"}));
    const json frame = render(c, config["overrides"].get<std::vector<std::string>>());
    EXPECT_EQ(frame["resolved"]["sss"]["width_mm"], 2.5);
    const HttpAnswer missing = c.get("/api/open?set=0&id=nothing");
    EXPECT_EQ(missing.status, 400);
    EXPECT_NE(json::parse(missing.body)["error"].get<std::string>().find("no stimulus 'nothing'"), std::string::npos);
    EXPECT_EQ(c.get("/api/open?set=7&id=head-mid-separable").status, 404);
}

TEST_F(TuneServerTest, OtherSitesRequestsAreRefused) {
    // What any web page can make a browser send to this server: no-cors fetches and forms (text/plain, another
    // Origin, Sec-Fetch-Site cross-site or same-site), without the page's token. None writes or starts anything.
    HttpClient c = client();
    const std::string own = "http://127.0.0.1:" + std::to_string(port_);
    std::string wrong = pageToken();
    wrong[0] = wrong[0] == 'a' ? 'b' : 'a';
    const json body = {{"scene", "builtin:head"}, {"overrides", kSmall}, {"name", "pwned"}};
    struct Attempt {
        const char* what;
        net::HttpHeaders headers;
        std::string contentType;
        int status;
    };
    const std::vector<Attempt> attempts{
        {"no-cors fetch from another port",
         {{"Origin", "http://127.0.0.1:1"}, {"Sec-Fetch-Site", "cross-site"}},
         "text/plain",
         403},
        {"another origin of the same site, with the token",
         {{"Origin", "http://localhost:" + std::to_string(port_ + 1)},
          {"Sec-Fetch-Site", "same-site"},
          {"X-Skinlab-Token", pageToken()}},
         "application/json",
         403},
        {"another origin, Origin only",
         {{"Origin", "http://127.0.0.1:1"}, {"X-Skinlab-Token", pageToken()}},
         "application/json",
         403},
        {"an opaque origin", {{"Origin", "null"}, {"X-Skinlab-Token", pageToken()}}, "application/json", 403},
        {"cross-site, Sec-Fetch-Site only",
         {{"Sec-Fetch-Site", "cross-site"}, {"X-Skinlab-Token", pageToken()}},
         "application/json",
         403},
        {"text/plain with the token", {{"Origin", own}, {"X-Skinlab-Token", pageToken()}}, "text/plain", 415},
        {"a form", {{"Origin", own}, {"X-Skinlab-Token", pageToken()}}, "application/x-www-form-urlencoded", 415},
        {"no token", {{"Origin", own}, {"Sec-Fetch-Site", "same-origin"}}, "application/json", 403},
        {"a wrong token", {{"Origin", own}, {"X-Skinlab-Token", wrong}}, "application/json", 403},
    };
    for (const Attempt& a : attempts) {
        for (const std::string path : {"/api/export", "/api/reference", "/api/render", "/api/job/cancel"}) {
            const HttpAnswer answer = c.send("POST", path, body.dump(), a.headers, a.contentType);
            EXPECT_EQ(answer.status, a.status) << a.what << " " << path << ": " << answer.body;
            EXPECT_TRUE(json::parse(answer.body).contains("error")) << answer.body;
        }
    }
    EXPECT_FALSE(std::filesystem::exists(work_ / "exports" / "pwned.toml"));
    EXPECT_TRUE(childProcesses(::getpid()).empty()) << "a render was started";
    EXPECT_EQ(c.get("/api/job?id=job1").status, 404);
    // Reading from another site is refused too; the page's own reads pass.
    EXPECT_EQ(c.get("/api/schema", {{"Sec-Fetch-Site", "cross-site"}}).status, 403);
    EXPECT_EQ(c.get("/api/schema", {{"Sec-Fetch-Site", "same-origin"}}).status, 200);
    // The page's own request: its origin, JSON and its token.
    const HttpAnswer mine = c.send(
        "POST", "/api/export", body.dump(),
        {{"Origin", own}, {"Sec-Fetch-Site", "same-origin"}, {"X-Skinlab-Token", pageToken()}}, "application/json");
    EXPECT_EQ(mine.status, 200) << mine.body;
    EXPECT_TRUE(std::filesystem::exists(work_ / "exports" / "pwned.toml"));
    // Each start has its own token.
    TuneOptions options;
    options.workDir = work_ / "other";
    options.executable = SKINLAB_CLI;
    TuneServer second(options);
    net::HttpRequest request;
    request.method = "GET";
    request.path = "/";
    request.target = "/";
    request.headers = {{"host", "127.0.0.1:" + std::to_string(second.bind())}};
    const std::string page = second.handle(request).body;
    const std::string marker = "<meta name=\"skinlab-token\" content=\"";
    ASSERT_NE(page.find(marker), std::string::npos);
    const std::string other = page.substr(page.find(marker) + marker.size(), 64);
    EXPECT_EQ(other.find_first_not_of("0123456789abcdef"), std::string::npos) << other;
    EXPECT_EQ(pageToken().size(), 64u);
    EXPECT_NE(other, pageToken());
}

TEST_F(TuneServerTest, ExportReplacesAFileOnlyWhenAsked) {
    HttpClient c = client();
    const auto folder = work_ / "exports";
    std::filesystem::create_directories(folder);
    std::ofstream(folder / "notes.toml") << "# the researcher's own\n";
    json body = {{"scene", "builtin:head"}, {"overrides", kSmall}, {"name", "notes"}};
    const HttpAnswer refused = post(c, "/api/export", body);
    EXPECT_EQ(refused.status, 409) << refused.body;
    EXPECT_EQ(json::parse(refused.body)["exists"], json({(folder / "notes.toml").string()}));
    EXPECT_EQ(readAll(folder / "notes.toml"), "# the researcher's own\n");
    EXPECT_FALSE(std::filesystem::exists(folder / "notes.include.toml")); // nothing of the export was written

    body["name"] = "tuned";
    ASSERT_EQ(post(c, "/api/export", body).status, 200);
    const std::string first = readAll(folder / "tuned.toml");
    body["overrides"] = with(kSmall, {"sss.method=\"separable\"", "sss.width_mm=3"});
    const HttpAnswer again = post(c, "/api/export", body);
    EXPECT_EQ(again.status, 409);
    EXPECT_EQ(json::parse(again.body)["exists"].size(), 2u);
    EXPECT_EQ(readAll(folder / "tuned.toml"), first);
    body["overwrite"] = "yes";
    EXPECT_EQ(post(c, "/api/export", body).status, 400);
    body["overwrite"] = true;
    ASSERT_EQ(post(c, "/api/export", body).status, 200);
    EXPECT_NE(readAll(folder / "tuned.toml").find("width_mm = 3"), std::string::npos);
    std::vector<std::string> left;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) left.push_back(entry.path().filename());
    std::sort(left.begin(), left.end());
    EXPECT_EQ(left, (std::vector<std::string>{"notes.toml", "tuned.include.toml", "tuned.toml"})); // no temporaries
}

// As `skinlab tune` runs: SIGINT and SIGTERM blocked in every thread (one thread waits for them).
class TuneServerBlockedSignalsTest : public TuneServerTest {
protected:
    void SetUp() override {
        sigset_t blocked;
        sigemptyset(&blocked);
        sigaddset(&blocked, SIGINT);
        sigaddset(&blocked, SIGTERM);
        pthread_sigmask(SIG_BLOCK, &blocked, &saved_);
        TuneServerTest::SetUp();
    }
    void TearDown() override {
        TuneServerTest::TearDown();
        pthread_sigmask(SIG_SETMASK, &saved_, nullptr);
    }
    sigset_t saved_;
};

TEST_F(TuneServerBlockedSignalsTest, OneReferenceAtATimeAndCancelEndsIt) {
    HttpClient c = client();
    std::vector<std::string> started, running;
    for (int i = 0; i < 6; ++i) {
        const HttpAnswer answer =
            post(c, "/api/reference",
                 {{"scene", "builtin:head"},
                  {"overrides", {"render.width=" + std::to_string(640 + 16 * i), "render.height=360"}}});
        const json body = json::parse(answer.body);
        if (answer.status == 200) started.push_back(body["job"]["id"]);
        else {
            EXPECT_EQ(answer.status, 409) << answer.body;
            running.push_back(body.value("running", ""));
        }
    }
    ASSERT_EQ(started.size(), 1u);
    EXPECT_EQ(running, std::vector<std::string>(5, started[0]));
    EXPECT_EQ(childProcesses(::getpid()).size(), 1u);

    std::this_thread::sleep_for(std::chrono::milliseconds(300)); // the render is under way
    const HttpAnswer cancelled = post(c, "/api/job/cancel", {{"id", started[0]}});
    EXPECT_EQ(json::parse(cancelled.body)["cancelled"], true);
    EXPECT_TRUE(childrenEnd(::getpid(), std::chrono::milliseconds(3000))) << "the render outlived its cancel";
    const json status = json::parse(c.get("/api/job?id=" + started[0]).body);
    EXPECT_EQ(status["state"], "cancelled");
    EXPECT_GE(status["elapsed_s"].get<double>(), 0.0);
    EXPECT_LT(status["elapsed_s"].get<double>(), 5.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    EXPECT_EQ(json::parse(c.get("/api/job?id=" + started[0]).body)["elapsed_s"], status["elapsed_s"]); // stopped

    // The next one starts; the server's end ends it.
    const HttpAnswer next = post(c, "/api/reference", {{"scene", "builtin:head"}, {"overrides", {"render.width=320"}}});
    EXPECT_EQ(next.status, 200) << next.body;
    EXPECT_EQ(childProcesses(::getpid()).size(), 1u);
    const auto stopping = std::chrono::steady_clock::now();
    server_->stop();
    thread_.join();
    server_.reset();
    EXPECT_LT(std::chrono::steady_clock::now() - stopping, std::chrono::seconds(3));
    EXPECT_TRUE(childProcesses(::getpid()).empty());
}

TEST(TuneCli, SigtermStopsPromptlyAndEndsRenders) {
    REQUIRE_EGL();
    const test_support::TempFolder folder;
    const auto& work = folder.path();
    SpawnOptions options;
    options.output = work / "out.txt";
    const pid_t tune =
        spawnProcess(SKINLAB_CLI, {"tune", "--port", "0", "--export-dir", (work / "exports").string()}, options);
    const std::string prefix = "tuning on http://127.0.0.1:";
    int port = 0;
    for (int i = 0; i < 600 && port == 0; ++i) {
        const std::string out = readAll(options.output);
        if (const std::size_t at = out.find(prefix); at != std::string::npos && out.find('\n', at) != std::string::npos)
            port = std::stoi(out.substr(at + prefix.size()));
        else std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_NE(port, 0) << readAll(options.output);
    HttpClient c("127.0.0.1", port);
    const std::string page = c.get("/").body;
    const std::string marker = "<meta name=\"skinlab-token\" content=\"";
    const std::size_t at = page.find(marker);
    EXPECT_NE(at, std::string::npos);
    const std::string token = page.substr(at + marker.size(), 64);
    const HttpAnswer started =
        c.send("POST", "/api/reference", json{{"scene", "builtin:head"}, {"overrides", {"render.width=640"}}}.dump(),
               {{"X-Skinlab-Token", at == std::string::npos ? "" : token}});
    EXPECT_EQ(started.status, 200) << started.body;
    std::vector<pid_t> renders;
    for (int i = 0; i < 200 && renders.empty(); ++i) {
        renders = childProcesses(tune);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_EQ(renders.size(), 1u);
    std::this_thread::sleep_for(std::chrono::milliseconds(300)); // the render is under way

    const auto sent = std::chrono::steady_clock::now();
    ASSERT_EQ(::kill(tune, SIGTERM), 0);
    int status = 0;
    while (::waitpid(tune, &status, WNOHANG) == 0 && std::chrono::steady_clock::now() - sent < std::chrono::seconds(20))
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto took = std::chrono::steady_clock::now() - sent;
    if (took >= std::chrono::seconds(20)) { // never: end what is left
        ::kill(tune, SIGKILL);
        for (pid_t r : renders) ::kill(-r, SIGKILL);
        waitProcess(tune);
    }
    EXPECT_LT(took, std::chrono::seconds(3)) << readAll(options.output);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
    for (pid_t r : renders) EXPECT_NE(::kill(r, 0), 0) << "render " << r << " outlived skinlab tune";
    EXPECT_NE(readAll(options.output).find("stopped"), std::string::npos);
}

// A scene file, an assets folder and a stimulus set: the folders the page may name files in.
class TuneServerFoldersTest : public TuneServerTest {
protected:
    void configure(TuneOptions& options) override {
        std::filesystem::create_directories(work_ / "scenes");
        std::filesystem::create_directories(work_ / "assets");
        std::filesystem::create_directories(work_ / "set");
        std::ofstream(work_ / "scenes" / "lab.toml") << *renderer::builtinSceneText("halo");
        for (const auto& file : {work_ / "scenes" / "k.bn", work_ / "assets" / "k.bn", work_ / "set" / "k.bn"})
            std::ofstream(file) << "not a kernel\n";
        std::ofstream(work_ / "set" / "manifest.json")
            << json{{"format", "skinlab-stimuli"}, {"version", 1}, {"set", "s"}, {"stimuli", json::array()}}.dump();
        options.scenes.push_back((work_ / "scenes" / "lab.toml").string());
        options.assetsDir = work_ / "assets";
        options.stimulusSets = {work_ / "set"};
    }
};

TEST_F(TuneServerFoldersTest, PathKeysStayInsideTheOfferedFolders) {
    HttpClient c = client();
    const std::string lab = (work_ / "scenes" / "lab.toml").string();
    const std::vector<std::string> separable = with(kSmall, {"sss.method=\"separable\""});
    struct Case {
        std::string path, scene;
        std::vector<std::string> overrides;
        std::string key;
    };
    const std::vector<Case> outside{
        {"/api/render", "builtin:head", with(separable, {"sss.profile=\"file:/etc/passwd\""}), "sss.profile"},
        {"/api/kernel", "builtin:head", with(separable, {"sss.profile=\"file:/etc/passwd\""}), "sss.profile"},
        {"/api/render", "builtin:head", with(kSmall, {"textures.albedo=\"/etc/passwd\""}), "textures.albedo"},
        {"/api/render", "builtin:head", with(kSmall, {"textures={normal=\"/etc/passwd\"}"}), "textures.normal"},
        {"/api/render", "builtin:head", with(kSmall, {"model.source=\"/etc/passwd\""}), "model.source"},
        {"/api/render", "builtin:head", with(kSmall, {"environment.file=\"/etc/passwd\""}), "environment.file"},
        {"/api/render", "builtin:head", with(kSmall, {"textures.albedo=\"assets:../../../../../../../etc/passwd\""}),
         "textures.albedo"},
        {"/api/render", lab, with(kSmall, {"model.source=\"../../../../../../../../etc/passwd\""}), "model.source"},
        {"/api/render", lab, with(kSmall, {"textures.skin_mask=\"../set/../../../../../../../etc/passwd\""}),
         "textures.skin_mask"},
        {"/api/export", "builtin:head", with(kSmall, {"textures.albedo=\"/etc/passwd\""}), "textures.albedo"},
        {"/api/reference", "builtin:head", with(kSmall, {"model.source=\"/etc/passwd\""}), "model.source"},
        {"/api/render", "builtin:head", with(kSmall, {"sss.method=\"pathtraced\"", "pathtraced.blender=\"/bin/sh\""}),
         "pathtraced.blender"},
        {"/api/render", "builtin:head", with(kSmall, {"sss.method=\"eevee\"", "eevee.blender=\"sh\""}),
         "eevee.blender"},
    };
    for (const Case& k : outside) {
        const HttpAnswer answer =
            post(c, k.path, {{"scene", k.scene}, {"overrides", k.overrides}, {"name", "leak"}, {"client", "x"}});
        EXPECT_EQ(answer.status, 403) << k.path << " " << k.overrides.back() << ": " << answer.body;
        const std::string error = json::parse(answer.body).value("error", "");
        EXPECT_EQ(error.rfind(k.key + ": ", 0), 0u) << error;
        EXPECT_EQ(error.find('\n'), std::string::npos) << error;
    }
    EXPECT_FALSE(std::filesystem::exists(work_ / "exports" / "leak.toml"));
    EXPECT_TRUE(childProcesses(::getpid()).empty());
    // Inside the scene's folder, the assets folder or a set: read (here: not a kernel, the reader's own error).
    for (const auto& file : {work_ / "scenes" / "k.bn", work_ / "assets" / "k.bn", work_ / "set" / "k.bn"}) {
        const HttpAnswer answer =
            post(c, "/api/render",
                 {{"scene", "builtin:head"},
                  {"overrides", with(separable, {"sss.profile=\"file:" + file.string() + "\""})}});
        EXPECT_EQ(answer.status, 400) << answer.body;
        EXPECT_EQ(json::parse(answer.body)["error"].get<std::string>().find("outside"), std::string::npos)
            << answer.body;
    }
    // The scene's own values and its folder's files render.
    EXPECT_EQ(render(c, kSmall, "x", lab)["width"], 160);
}

// A set as `stimuli build` writes it: the spec's file name, each stimulus's scene as the spec wrote it (relative to
// the spec's folder) and the scene it rendered (resolved.scene, absolute). Given to the server by a relative path.
class TuneServerBuiltSetTest : public TuneServerTest {
protected:
    void configure(TuneOptions& options) override {
        const auto set = work_ / "out" / "demo";
        std::filesystem::create_directories(set);
        std::filesystem::create_directories(work_ / "scenes");
        std::filesystem::create_directories(work_ / "specs");
        std::ofstream(work_ / "scenes" / "lab.toml") << *renderer::builtinSceneText("halo");
        std::ofstream(set / "beside.toml") << *renderer::builtinSceneText("halo");
        std::ofstream(work_ / "scenes" / "k.bn") << "not a kernel\n";
        const std::vector<std::string> small{"render.width=96", "render.height=64", "shadow.resolution=256"};
        const json stimuli = {
            manifestEntry("lab-separable",
                          {{"scene", "../scenes/lab.toml"},
                           {"overrides", with(small, {"sss.method=\"separable\""})},
                           {"resolved", {{"scene", (work_ / "specs" / ".." / "scenes" / "lab.toml").string()}}}}),
            manifestEntry("beside-separable",
                          {{"scene", "beside.toml"},
                           {"overrides", with(small, {"sss.method=\"separable\""})},
                           {"resolved", {{"scene", (work_ / "elsewhere" / "beside.toml").string()}}}})};
        std::ofstream(set / "manifest.json") << json{
            {"format", "skinlab-stimuli"},
            {"version", 1},
            {"set", "demo"},
            {"spec", "demo.toml"},
            {"stimuli", stimuli}}.dump(1);
        options.stimulusSets = {std::filesystem::relative(set)};
    }
};

TEST_F(TuneServerBuiltSetTest, OpenFindsTheScenesTheBuildRendered) {
    HttpClient c = client();
    const HttpAnswer lab = c.get("/api/open?set=0&id=lab-separable");
    ASSERT_EQ(lab.status, 200) << lab.body;
    EXPECT_EQ(json::parse(lab.body)["scene"], (work_ / "scenes" / "lab.toml").string());
    const HttpAnswer beside = c.get("/api/open?set=0&id=beside-separable");
    ASSERT_EQ(beside.status, 200) << beside.body;
    EXPECT_EQ(json::parse(beside.body)["scene"], (work_ / "out" / "demo" / "beside.toml").string());
    // Opened scenes render, and their folders are readable.
    for (const HttpAnswer& opened : {lab, beside}) {
        const json config = json::parse(opened.body);
        const json frame = render(c, config["overrides"].get<std::vector<std::string>>(), "x", config["scene"]);
        EXPECT_EQ(frame["width"], 96) << frame.dump().substr(0, 300);
    }
    const HttpAnswer kernel =
        post(c, "/api/kernel",
             {{"scene", json::parse(lab.body)["scene"]},
              {"overrides",
               {"sss.method=\"separable\"", "sss.profile=\"file:" + (work_ / "scenes" / "k.bn").string() + "\""}}});
    EXPECT_EQ(kernel.status, 400) << kernel.body;
    EXPECT_EQ(kernel.body.find("outside"), std::string::npos) << kernel.body;
}

TEST(TuneServerOptions, BeyondLoopbackOnlyWithAToken) {
    TuneOptions options;
    options.host = "0.0.0.0";
    const test_support::TempFolder folder;
    options.workDir = folder.path();
    options.executable = SKINLAB_CLI;
    EXPECT_THROW(TuneServer server(options), InputError);
}

} // namespace
} // namespace skinlab::tune
