// skinlab tune over real HTTP on loopback (an in-process TuneServer on an ephemeral port, the project's Beast
// client), real EGL rendering, and the real `skinlab` executable for the CLI's errors and the export round trip.
#include "common/error.h"
#include "experiments/http_client.h"
#include "renderer/renderer.h"
#include "renderer/sss/sss_params.h"
#include "tests/common/cli_run.h"
#include "tune/tune_server.h"

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>
#include <unistd.h>

namespace skinlab::tune {
namespace {

using experiments::HttpAnswer;
using experiments::HttpClient;
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

std::filesystem::path temporaryFolder(const std::string& name) {
    const auto folder =
        std::filesystem::temp_directory_path() / ("skinlab-tune-test-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(folder);
    std::filesystem::create_directories(folder);
    return folder;
}

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

class TuneServerTest : public ::testing::Test {
protected:
    void SetUp() override {
        REQUIRE_EGL();
        work_ = temporaryFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
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
        if (!work_.empty()) std::filesystem::remove_all(work_);
    }
    virtual void configure(TuneOptions&) {}

    HttpClient client() const {
        HttpClient c("127.0.0.1", port_);
        c.setTimeout(std::chrono::seconds(120));
        return c;
    }
    HttpAnswer post(HttpClient& c, const std::string& path, const json& body) const {
        experiments::HttpHeaders headers;
        if (!token_.empty()) headers.emplace_back("Authorization", "Bearer " + token_);
        return c.send("POST", path, body.dump(), headers);
    }
    json render(HttpClient& c, const std::vector<std::string>& overrides, const std::string& clientId = "test",
                const std::string& scene = "builtin:head") const {
        const HttpAnswer answer =
            post(c, "/api/render", {{"client", clientId}, {"scene", scene}, {"overrides", overrides}});
        EXPECT_EQ(answer.status, 200) << answer.body;
        return json::parse(answer.body);
    }

    std::filesystem::path work_;
    std::string token_;
    std::unique_ptr<TuneServer> server_;
    std::thread thread_;
    int port_ = 0;
};

const std::vector<std::string> kSmall{"render.width=160", "render.height=90", "shadow.resolution=512"};

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
        const HttpAnswer answer = c.send("POST", path, body);
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
    EXPECT_EQ(json::parse(c.get("/api/job?id=" + id).body)["state"], "cancelled");
    EXPECT_EQ(c.get("/api/job/image?id=" + id).status, 409);
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
        const json manifest = {{"format", "skinlab-stimuli"},
                               {"version", 1},
                               {"set", "demo"},
                               {"stimuli",
                                {{{"id", "head-mid-separable"},
                                  {"scene", "builtin:head"},
                                  {"factors", {{"method", "separable"}}},
                                  {"reference", false},
                                  {"overrides",
                                   {"render.width=160", "render.height=90", "camera.view=\"mid\"",
                                    "sss.method=\"separable\"", "sss.width_mm=2.5"}}}}}};
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

TEST(TuneServerOptions, BeyondLoopbackOnlyWithAToken) {
    TuneOptions options;
    options.host = "0.0.0.0";
    options.workDir = temporaryFolder("options");
    options.executable = SKINLAB_CLI;
    EXPECT_THROW(TuneServer server(options), InputError);
    std::filesystem::remove_all(options.workDir);
}

} // namespace
} // namespace skinlab::tune
