// End-to-end tests of `skinlab stimuli build|merge` through the real CLI and the real renderer (EGL, llvmpipe
// without a GPU), at 96×64 so the whole file runs in well under a minute on 2 cores:
//  - a rebuild of an unchanged set renders nothing and keeps every file and hash;
//  - a changed level re-renders exactly the stimuli whose resolved parameters changed;
//  - a build killed (SIGKILL) after its first stimulus leaves no corrupt file under a final name, and the rerun
//    completes it with the same hashes as an uninterrupted build;
//  - shards 1/2 + 2/2 merged equal the full build (ids, order, hashes);
//  - a cropped and magnified set built twice, in different seconds, once killed and resumed, gives byte-identical
//    image files;
//  - a custom display (--display-*) is recorded in the manifest and read back exactly by the metrics;
//  - bad input that needs the scene spec (unknown factor key or level, missing asset, folder of another set)
//    fails with one line before anything is rendered.
// Skips with a message when no EGL platform works.
#include "analysis/metrics/cvvdp.h"
#include "analysis/metrics/metric_render.h"
#include "common/hash.h"
#include "renderer/renderer.h"
#include "stimuli/manifest.h"

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <csignal>
#include <cstdio>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <gtest/gtest.h>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

// Each test works in its own folder (ctest runs the tests of this file as parallel processes).
fs::path gRoot = fs::path(SKINLAB_BINARY_DIR) / "tests-tmp" / "stimuli-build";

// 3 views × 2 yaw angles of the built-in head, method none (available in every renderer build), tiny renders.
// The yaw factor has labels so that changing a level keeps the ids (tests "resolved parameters changed").
std::string smallSpec(const std::string& name, const std::string& secondYaw = "30.0") {
    std::ostringstream s;
    s << "[set]\nname = \"" << name << "\"\nscene = \"builtin:head\"\nseed = 7\n\n"
      << "[fixed]\nrender = { width = 96, height = 64 }\nshadow = { resolution = 256 }\n"
      << "sss = { method = \"none\" }\n\n"
      << "[[factor]]\nname = \"view\"\nlevels = [\"close\", \"mid\", \"far\"]\n\n"
      << "[[factor]]\nname = \"camera.yaw_deg\"\nlevels = [0.0, " << secondYaw << "]\nlabels = [\"front\", \"side\"]\n";
    return s.str();
}

fs::path writeSpec(const std::string& fileName, const std::string& text) {
    fs::create_directories(gRoot);
    fs::path path = gRoot / fileName;
    std::ofstream(path) << text;
    return path;
}

struct CliRun {
    int exitCode = -1;
    std::string output; // stdout + stderr
};

// Runs the skinlab CLI with `args`; output to a file so that large outputs cannot block the child.
CliRun runCli(const std::vector<std::string>& args, const fs::path& log = gRoot / "cli.log",
              std::function<void(pid_t)> whileRunning = {}) {
    fs::create_directories(gRoot);
    pid_t pid = ::fork();
    if (pid == 0) {
        int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(fd, 1);
        ::dup2(fd, 2);
        std::vector<char*> argv;
        std::string cli = SKINLAB_CLI;
        argv.push_back(cli.data());
        std::vector<std::string> copy = args;
        for (auto& a : copy) argv.push_back(a.data());
        argv.push_back(nullptr);
        ::execv(cli.c_str(), argv.data());
        ::_exit(127);
    }
    if (whileRunning) whileRunning(pid);
    int status = 0;
    ::waitpid(pid, &status, 0);
    CliRun run;
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    run.output = ss.str();
    return run;
}

nlohmann::json manifestOf(const fs::path& dir) {
    std::ifstream in(dir / "manifest.json");
    return nlohmann::json::parse(in);
}

// id → (exr sha256, png sha256), from the manifest, after checking every file against its hash.
std::map<std::string, std::pair<std::string, std::string>> verifiedHashes(const fs::path& dir) {
    std::map<std::string, std::pair<std::string, std::string>> out;
    const nlohmann::json manifest = manifestOf(dir); // kept alive: a range-for over a temporary's member dangles
    for (const auto& s : manifest["stimuli"]) {
        std::string exr = s["sha256"]["exr"], png = s["sha256"]["png"];
        EXPECT_EQ(skinlab::sha256File(dir / s["files"]["exr"].get<std::string>()), exr) << s["id"];
        EXPECT_EQ(skinlab::sha256File(dir / s["files"]["png"].get<std::string>()), png) << s["id"];
        out[s["id"].get<std::string>()] = {exr, png};
    }
    return out;
}

std::vector<std::string> idsOf(const fs::path& dir) {
    std::vector<std::string> ids;
    const nlohmann::json manifest = manifestOf(dir);
    for (const auto& s : manifest["stimuli"]) ids.push_back(s["id"]);
    return ids;
}

// For runCli: kills the build (SIGKILL) as soon as the manifest in `dir` records its first stimulus; `doneAtKill`
// receives the number of stimuli recorded then.
std::function<void(pid_t)> killAfterFirstStimulus(const fs::path& dir, size_t& doneAtKill) {
    return [&dir, &doneAtKill](pid_t pid) {
        auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
        while (std::chrono::steady_clock::now() < deadline) {
            if (fs::exists(dir / "manifest.json")) {
                try {
                    doneAtKill = manifestOf(dir)["stimuli"].size();
                } catch (const std::exception&) {
                }
                if (doneAtKill >= 1) break;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        ::kill(pid, SIGKILL);
    };
}

class StimuliBuild : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        try {
            skinlab::renderer::Renderer renderer;
            available_ = true;
        } catch (const std::exception& e) {
            reason_ = e.what();
        }
    }
    void SetUp() override {
        if (!available_) GTEST_SKIP() << "no EGL/OpenGL 4.5 renderer available: " << reason_;
        gRoot = fs::path(SKINLAB_BINARY_DIR) / "tests-tmp" / "stimuli-build" /
                ::testing::UnitTest::GetInstance()->current_test_info()->name();
        fs::remove_all(gRoot);
        fs::create_directories(gRoot);
    }

    // The uninterrupted full build the other builds are compared with (built once per test).
    const fs::path& fullBuild() {
        if (full_.empty()) {
            fs::path d = gRoot / "full";
            CliRun run =
                runCli({"stimuli", "build", writeSpec("small.toml", smallSpec("small")).string(), "-o", d.string()});
            EXPECT_EQ(run.exitCode, 0) << run.output;
            full_ = d;
        }
        return full_;
    }
    fs::path full_;

    static inline bool available_ = false;
    static inline std::string reason_;
};

TEST_F(StimuliBuild, FullBuildDescribesEveryImage) {
    const fs::path& dir = fullBuild();
    nlohmann::json m = manifestOf(dir);
    EXPECT_EQ(m["format"], "skinlab-stimuli");
    EXPECT_EQ(m["version"], 1);
    EXPECT_EQ(m["set"], "small");
    EXPECT_EQ(m["seed"], 7);
    EXPECT_TRUE(m["complete"].get<bool>());
    EXPECT_FALSE(m["renderer"]["gl_renderer"].get<std::string>().empty());
    ASSERT_EQ(m["stimuli"].size(), 6u);
    const auto& s = m["stimuli"][3];
    EXPECT_EQ(s["id"], "head-mid-side");
    EXPECT_EQ(s["block"], "builtin:head/mid");
    EXPECT_EQ(s["factors"]["view"], "mid");
    EXPECT_EQ(s["factors"]["camera.yaw_deg"], "30.0");
    EXPECT_EQ(s["width"], 96);
    EXPECT_EQ(s["height"], 64);
    EXPECT_FALSE(s["reference"].get<bool>());
    EXPECT_TRUE(s["resolved"].is_object());
    EXPECT_TRUE(s["timings_ms"].contains("stimulus_wall"));
    verifiedHashes(dir);
    // The EXR is a real image of the requested size.
    auto input = OIIO::ImageInput::open((dir / "exr/head-mid-side.exr").string());
    ASSERT_TRUE(input);
    EXPECT_EQ(input->spec().width, 96);
    EXPECT_EQ(input->spec().height, 64);
    // CSV view and contact sheet.
    std::ifstream csv(dir / "manifest.csv");
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header,
              "id,block,reference,scene,view,camera.yaw_deg,exr,png,sha256_exr,sha256_png,width,height,wall_ms");
    EXPECT_TRUE(fs::exists(dir / "contact.html"));
    auto sheet = OIIO::ImageInput::open((dir / "contact.png").string());
    ASSERT_TRUE(sheet);
    EXPECT_GT(sheet->spec().width, 2 * 96);
}

TEST_F(StimuliBuild, RebuildOfUnchangedSetRendersNothing) {
    fs::path dir = gRoot / "rebuild";
    fs::remove_all(dir);
    fs::copy(fullBuild(), dir, fs::copy_options::recursive);
    auto before = verifiedHashes(dir);
    auto mtime = fs::last_write_time(dir / "exr/head-far-front.exr");
    CliRun run = runCli({"stimuli", "build", (gRoot / "small.toml").string(), "-o", dir.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("stimuli: 6 stimuli (0 rendered, 6 unchanged)"), std::string::npos) << run.output;
    EXPECT_EQ(verifiedHashes(dir), before);
    EXPECT_EQ(fs::last_write_time(dir / "exr/head-far-front.exr"), mtime);

    // Changing one level re-renders exactly the stimuli whose resolved parameters changed (same ids).
    fs::path changed = writeSpec("small-changed.toml", smallSpec("small", "45.0"));
    run = runCli({"stimuli", "build", changed.string(), "-o", dir.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("stimuli: 6 stimuli (3 rendered, 3 unchanged)"), std::string::npos) << run.output;
    auto after = verifiedHashes(dir);
    EXPECT_EQ(after["head-mid-front"], before["head-mid-front"]);
    EXPECT_NE(after["head-mid-side"].first, before["head-mid-side"].first);
    EXPECT_EQ(manifestOf(dir)["stimuli"][3]["factors"]["camera.yaw_deg"], "45.0");
}

TEST_F(StimuliBuild, KilledBuildResumesToTheSameHashes) {
    const fs::path& full = fullBuild();
    fs::path dir = gRoot / "killed";
    fs::remove_all(dir);
    size_t doneAtKill = 0;
    CliRun killed = runCli({"stimuli", "build", (gRoot / "small.toml").string(), "-o", dir.string()},
                           gRoot / "killed.log", killAfterFirstStimulus(dir, doneAtKill));
    ASSERT_EQ(killed.exitCode, 128 + SIGKILL) << killed.output;
    nlohmann::json partial = manifestOf(dir);
    ASSERT_LT(partial["stimuli"].size(), 6u) << "the build finished before it could be killed";
    EXPECT_FALSE(partial["complete"].get<bool>());
    // Every file under a final name is complete: listed ones match their hash, the others are readable images.
    verifiedHashes(dir);
    for (const char* sub : {"exr", "png"})
        for (const auto& entry : fs::directory_iterator(dir / sub)) {
            std::string name = entry.path().filename().string();
            if (name.front() == '.') continue; // a temporary name; the rerun removes it
            auto input = OIIO::ImageInput::open(entry.path().string());
            EXPECT_TRUE(input) << name << " is corrupt";
        }

    CliRun rerun = runCli({"stimuli", "build", (gRoot / "small.toml").string(), "-o", dir.string()});
    ASSERT_EQ(rerun.exitCode, 0) << rerun.output;
    EXPECT_EQ(idsOf(dir), idsOf(full));
    EXPECT_EQ(verifiedHashes(dir), verifiedHashes(full));
    for (const auto& entry : fs::directory_iterator(dir / "exr"))
        EXPECT_NE(entry.path().filename().string().front(), '.') << "temporary file left: " << entry.path();
}

TEST_F(StimuliBuild, MergedShardsEqualTheFullBuild) {
    const fs::path& full = fullBuild();
    std::vector<std::string> shards;
    for (int i = 1; i <= 2; ++i) {
        fs::path dir = gRoot / ("shard" + std::to_string(i));
        fs::remove_all(dir);
        CliRun run = runCli({"stimuli", "build", (gRoot / "small.toml").string(), "-o", dir.string(), "--shard",
                             std::to_string(i) + "/2", "--no-contact-sheet"});
        ASSERT_EQ(run.exitCode, 0) << run.output;
        EXPECT_EQ(manifestOf(dir)["stimuli"].size(), 3u);
        shards.push_back(dir.string());
    }
    fs::path merged = gRoot / "merged";
    fs::remove_all(merged);
    // A missing shard is refused before anything is written.
    CliRun incomplete = runCli({"stimuli", "merge", shards[0], "-o", merged.string()});
    EXPECT_EQ(incomplete.exitCode, 2);
    EXPECT_EQ(incomplete.output, "skinlab: error: merge: shard 2/2 of set 'small' is missing\n");
    EXPECT_FALSE(fs::exists(merged));

    CliRun run = runCli({"stimuli", "merge", shards[1], shards[0], "-o", merged.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_EQ(idsOf(merged), idsOf(full));
    EXPECT_EQ(verifiedHashes(merged), verifiedHashes(full));
    nlohmann::json m = manifestOf(merged), f = manifestOf(full);
    EXPECT_FALSE(m.contains("shard"));
    EXPECT_TRUE(m["complete"].get<bool>());
    for (const char* key : {"set", "spec_sha256", "renderer", "fixed", "factors", "set_ids", "seed"})
        EXPECT_EQ(m[key], f[key]) << key;
    for (size_t i = 0; i < f["stimuli"].size(); ++i) {
        nlohmann::json a = m["stimuli"][i], b = f["stimuli"][i];
        a.erase("timings_ms");
        b.erase("timings_ms");
        EXPECT_EQ(a, b) << i;
    }
    EXPECT_TRUE(fs::exists(merged / "contact.png"));

    // A shard built from another version of the spec (here other --set values) is refused, naming the shards of
    // each version, before anything is written.
    fs::path odd = gRoot / "shard2-odd";
    CliRun oddRun = runCli({"stimuli", "build", (gRoot / "small.toml").string(), "-o", odd.string(), "--shard", "2/2",
                            "--no-contact-sheet", "--set", "set.seed=8"});
    ASSERT_EQ(oddRun.exitCode, 0) << oddRun.output;
    fs::path refused = gRoot / "merged-refused";
    CliRun disagree = runCli({"stimuli", "merge", shards[0], odd.string(), "-o", refused.string()});
    EXPECT_EQ(disagree.exitCode, 2);
    EXPECT_NE(disagree.output.find("skinlab: error: merge: the shards disagree about the spec: "), std::string::npos)
        << disagree.output;
    EXPECT_NE(disagree.output.find(shards[0] + " (shard 1/2)"), std::string::npos) << disagree.output;
    EXPECT_NE(disagree.output.find(odd.string() + " (shard 2/2)"), std::string::npos) << disagree.output;
    EXPECT_EQ(std::count(disagree.output.begin(), disagree.output.end(), '\n'), 1) << disagree.output;
    EXPECT_FALSE(fs::exists(refused));
}

// A second build of a folder that a live build is writing (a requeued cluster task whose first run is still
// alive) is refused with one line; the first build is unaffected.
TEST_F(StimuliBuild, SecondBuildOfABusyFolderIsRefused) {
    const fs::path& full = fullBuild();
    fs::path dir = gRoot / "busy";
    CliRun second;
    CliRun first = runCli(
        {"stimuli", "build", (gRoot / "small.toml").string(), "-o", dir.string()}, gRoot / "first.log", [&](pid_t pid) {
            // Freeze the first build once it has marked the folder, run the second, thaw the first.
            auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
            while (!fs::exists(dir / "manifest.json") && std::chrono::steady_clock::now() < deadline)
                std::this_thread::sleep_for(std::chrono::milliseconds(2));
            ::kill(pid, SIGSTOP);
            second =
                runCli({"stimuli", "build", (gRoot / "small.toml").string(), "-o", dir.string()}, gRoot / "second.log");
            ::kill(pid, SIGCONT);
        });
    ASSERT_EQ(first.exitCode, 0) << first.output;
    EXPECT_EQ(second.exitCode, 2) << second.output;
    EXPECT_EQ(second.output.rfind(
                  "skinlab: error: " + dir.string() + ": another skinlab build is writing this folder (pid ", 0),
              0u)
        << second.output;
    EXPECT_NE(second.output.find("); wait for it or stop it, then rebuild\n"), std::string::npos) << second.output;
    EXPECT_EQ(std::count(second.output.begin(), second.output.end(), '\n'), 1) << second.output;
    EXPECT_EQ(verifiedHashes(dir), verifiedHashes(full));
}

TEST_F(StimuliBuild, ParallelJobsGiveTheSameFiles) {
    const fs::path& full = fullBuild();
    fs::path dir = gRoot / "jobs2";
    fs::remove_all(dir);
    CliRun run = runCli({"stimuli", "build", (gRoot / "small.toml").string(), "-o", dir.string(), "--jobs", "2"});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_EQ(idsOf(dir), idsOf(full));
    EXPECT_EQ(verifiedHashes(dir), verifiedHashes(full));
}

// Bad input that needs the renderer's scene spec: one line, exit 2, nothing rendered, nothing stored lost.
TEST_F(StimuliBuild, BadInputFailsBeforeRendering) {
    fs::path out = gRoot / "bad-out";
    fs::remove_all(out);
    auto build = [&](const std::string& specText, const fs::path& dir) {
        fs::path spec = writeSpec("bad.toml", specText);
        return runCli({"stimuli", "build", spec.string(), "-o", dir.string()});
    };
    const std::string spec = (gRoot / "bad.toml").string();

    // Unknown factor key: the scene spec does not know it.
    CliRun r = build(smallSpec("bad") + "[[factor]]\nname = \"sss.no_such_key\"\nlevels = [1]\n", out);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.output, "skinlab: error: " + spec +
                            ": factor 'sss.no_such_key': level '1': builtin:head: "
                            "sss.no_such_key: unknown key\n");
    EXPECT_FALSE(fs::exists(out));

    // Unknown level of a known factor.
    r = build(smallSpec("bad") + "[[factor]]\nname = \"sss.curvature_measure\"\nlevels = [\"gauss\"]\n", out);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.output, "skinlab: error: " + spec +
                            ": factor 'sss.curvature_measure': level 'gauss': builtin:head: "
                            "sss.curvature_measure: 'gauss' is not one of: normal, screen\n");
    EXPECT_FALSE(fs::exists(out));

    // A key the stimulus' method does not read (the fixed method is none): refused, naming key and method.
    r = build(smallSpec("bad") + "[[factor]]\nname = \"sss.profile\"\nlevels = [\"burley\"]\n", out);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.output.rfind("skinlab: error: " + spec + ": factor: sss.profile: not a parameter of method 'none'", 0),
              0u)
        << r.output;
    EXPECT_FALSE(fs::exists(out));

    // Unknown level of the view (its allowed values are fixed by the scene spec).
    r = build(smallSpec("bad") + "[[include]]\nview = \"overhead\"\n", out);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.output, "skinlab: error: " + spec +
                            ": stimulus 'head-overhead': builtin:head: camera.view: "
                            "'overhead' is not one of: close, mid, far, explicit\n");
    EXPECT_FALSE(fs::exists(out));

    // Missing asset: a scene spec whose model file is absent, named in the message.
    fs::path scene = writeSpec("missing-asset.toml", "[model]\nsource = \"no-such-head.glb\"\n");
    std::string text = smallSpec("bad");
    text.replace(text.find("builtin:head"), 12, scene.filename().string());
    r = build(text, out);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.output, "skinlab: error: " + spec + ": scene 'missing-asset.toml': " + scene.string() +
                            ": model.source: file not found: " + (gRoot / "no-such-head.glb").string() + "\n");
    EXPECT_FALSE(fs::exists(out));

    // A folder holding another set: refused, and the other set's files are untouched.
    fs::path other = gRoot / "other-set";
    fs::remove_all(other);
    fs::copy(fullBuild(), other, fs::copy_options::recursive);
    auto before = verifiedHashes(other);
    r = build(smallSpec("another"), other);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.output, "skinlab: error: " + other.string() +
                            ": holds stimulus set 'small', not 'another'; choose another folder\n");
    EXPECT_EQ(verifiedHashes(other), before);
    EXPECT_EQ(manifestOf(other)["set"], "small");

    // A shard folder reused for the whole set.
    fs::path shard = gRoot / "shard1";
    r = runCli({"stimuli", "build", (gRoot / "small.toml").string(), "-o", shard.string(), "--shard", "1/2"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    auto shardHashes = verifiedHashes(shard);
    r = runCli({"stimuli", "build", (gRoot / "small.toml").string(), "-o", shard.string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.output, "skinlab: error: " + shard.string() +
                            ": holds shard 1/2 of set 'small', not the whole set; choose another folder\n");
    EXPECT_EQ(verifiedHashes(shard), shardHashes);
}

} // namespace

// Presentation: [fixed] crop and magnification and a per-view [[crop]] are applied after rendering. The stimulus
// EXR is exactly the crop of the full render (every channel), the PNG exactly its crop magnified by nearest
// neighbour; the manifest records crop, magnification and presented size; the predicted JOD is ColorVideoVDP on the
// presented PNGs; a crop outside the frame is refused naming its key.
namespace {

struct Pixels {
    int width = 0, height = 0, channels = 0;
    std::vector<float> data;
    float at(int x, int y, int c) const {
        return data[(static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) *
                        static_cast<size_t>(channels) +
                    static_cast<size_t>(c)];
    }
};

Pixels readPixels(const fs::path& path) {
    auto input = OIIO::ImageInput::open(path.string());
    EXPECT_TRUE(input) << path;
    Pixels p;
    if (!input) return p;
    p.width = input->spec().width;
    p.height = input->spec().height;
    p.channels = input->spec().nchannels;
    p.data.resize(static_cast<size_t>(p.width) * static_cast<size_t>(p.height) * static_cast<size_t>(p.channels));
    EXPECT_TRUE(input->read_image(0, 0, 0, p.channels, OIIO::TypeDesc::FLOAT, p.data.data())) << path;
    return p;
}

// True when `shown` is the crop (x, y, w, h) of `full` magnified m times (nearest neighbour), bit for bit.
::testing::AssertionResult isCropOf(const Pixels& shown, const Pixels& full, int x, int y, int w, int h, int m) {
    if (shown.width != w * m || shown.height != h * m || shown.channels != full.channels)
        return ::testing::AssertionFailure() << "size " << shown.width << "×" << shown.height << "×" << shown.channels
                                             << ", expected " << w * m << "×" << h * m << "×" << full.channels;
    for (int j = 0; j < shown.height; ++j)
        for (int i = 0; i < shown.width; ++i)
            for (int c = 0; c < shown.channels; ++c)
                if (shown.at(i, j, c) != full.at(x + i / m, y + j / m, c))
                    return ::testing::AssertionFailure()
                           << "pixel (" << i << ", " << j << ") channel " << c << ": " << shown.at(i, j, c) << " vs "
                           << full.at(x + i / m, y + j / m, c);
    return ::testing::AssertionSuccess();
}

// `method`: the presentation key's value ("" for the default, native).
std::string presentedSpec(const std::string& name, bool crop, const std::string& method = "",
                          const std::string& render = "width = 96, height = 64") {
    std::ostringstream s;
    s << "[set]\nname = \"" << name << "\"\nscene = \"builtin:head\"\n\n"
      << "[fixed]\nrender = { " << render << " }\nshadow = { resolution = 256 }\nsss = { method = \"none\" }\n";
    if (crop) s << "crop = { x = 20, y = 8, width = 40, height = 30 }\nmagnification = 3\n";
    if (!method.empty()) s << "presentation = \"" << method << "\"\n";
    s << "\n[[factor]]\nname = \"view\"\nlevels = [\"close\", \"mid\"]\n\n"
      << "[[factor]]\nname = \"camera.yaw_deg\"\nlevels = [0.0, 30.0]\nlabels = [\"front\", \"side\"]\n\n";
    if (crop) s << "[[crop]]\nview = \"mid\"\ncrop = { x = 50, y = 0, width = 46, height = 64 }\nmagnification = 2\n\n";
    s << "[[reference]]\ncamera.yaw_deg = 15.0\n";
    return s.str();
}

} // namespace

// presentation = "replicate": the render cropped and magnified by nearest neighbour, bit for bit, with a warning.
TEST_F(StimuliBuild, ReplicatedCropAndMagnificationAreAppliedRecordedAndPredictedOn) {
    const fs::path full = gRoot / "whole", shown = gRoot / "presented";
    CliRun run = runCli({"stimuli", "build", writeSpec("whole.toml", presentedSpec("whole", false)).string(), "-o",
                         full.string(), "--no-predict"});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    run =
        runCli({"stimuli", "build", writeSpec("presented.toml", presentedSpec("presented", true, "replicate")).string(),
                "-o", shown.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("fixed.presentation: \"replicate\" magnifies 3× by nearest neighbour"), std::string::npos)
        << run.output;
    const nlohmann::json m = manifestOf(shown);
    ASSERT_EQ(m["stimuli"].size(), 6u);
    const skinlab::metrics::CvvdpDisplay display = skinlab::metrics::cvvdpDisplay("standard_fhd");
    std::map<std::string, std::string> referenceOf; // block → reference PNG
    for (const auto& s : m["stimuli"])
        if (s["reference"].get<bool>()) referenceOf[s["block"]] = s["files"]["png"];
    for (const auto& s : m["stimuli"]) {
        const std::string id = s["id"];
        const bool mid = s["block"] == "builtin:head/mid";
        const int x = mid ? 50 : 20, y = mid ? 0 : 8, w = mid ? 46 : 40, h = mid ? 64 : 30, mag = mid ? 2 : 3;
        const nlohmann::json expected = {{"render", {{"width", 96}, {"height", 64}}},
                                         {"crop", {{"x", x}, {"y", y}, {"width", w}, {"height", h}}},
                                         {"magnification", mag},
                                         {"presented", {{"width", w * mag}, {"height", h * mag}}},
                                         {"method", "replicate"}};
        EXPECT_EQ(s["presentation"], expected) << id;
        EXPECT_EQ(s["width"], w * mag) << id;
        EXPECT_EQ(s["height"], h * mag) << id;
        // The same stimulus rendered whole: the EXR (every AOV) is its crop, the PNG its crop magnified.
        const Pixels fullExr = readPixels(full / "exr" / (id + ".exr"));
        EXPECT_GT(fullExr.channels, 3) << id;
        EXPECT_TRUE(isCropOf(readPixels(shown / "exr" / (id + ".exr")), fullExr, x, y, w, h, 1)) << id;
        EXPECT_TRUE(isCropOf(readPixels(shown / "png" / (id + ".png")), readPixels(full / "png" / (id + ".png")), x, y,
                             w, h, mag))
            << id;
        if (s["reference"].get<bool>()) continue;
        // The prediction is ColorVideoVDP on the presented PNGs (at the display's pixels per degree).
        ASSERT_TRUE(s.contains("predicted")) << id;
        const auto reference =
            skinlab::metrics::loadMetricRender(shown / referenceOf.at(s["block"]), skinlab::metrics::RenderRole::test,
                                               skinlab::metrics::ImageEncoding::srgb);
        const auto test = skinlab::metrics::loadMetricRender(shown / s["files"]["png"].get<std::string>(),
                                                             skinlab::metrics::RenderRole::test,
                                                             skinlab::metrics::ImageEncoding::srgb);
        const double jod = skinlab::metrics::cvvdp(reference.beauty, test.beauty, display, false).jod;
        EXPECT_DOUBLE_EQ(s["predicted"]["jod"].get<double>(), jod) << id;
        EXPECT_LT(jod, 10.0) << id;
    }
    // The contact sheet states how each block is presented.
    std::ifstream html(shown / "contact.html");
    std::stringstream text;
    text << html.rdbuf();
    EXPECT_NE(text.str().find("Presented: crop 20,8 40×30 of 96×64, ×3 → 120×90 px (nearest-neighbour replication)"),
              std::string::npos);
    EXPECT_NE(text.str().find("Presented: crop 50,0 46×64 of 96×64, ×2 → 92×128 px (nearest-neighbour replication)"),
              std::string::npos);
    // A rebuild keeps everything; a changed crop re-renders its block only.
    run = runCli({"stimuli", "build", (gRoot / "presented.toml").string(), "-o", shown.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("(0 rendered, 6 unchanged)"), std::string::npos) << run.output;
    std::string moved = presentedSpec("presented", true, "replicate");
    moved.replace(moved.find("x = 50"), 6, "x = 48");
    run = runCli({"stimuli", "build", writeSpec("presented.toml", moved).string(), "-o", shown.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("(3 rendered, 3 unchanged)"), std::string::npos) << run.output;
    EXPECT_EQ(manifestOf(shown)["stimuli"][3]["presentation"]["crop"]["x"], 48);
}

// The metrics of a set run on what observers see: `analyze metrics --stimuli` scores the presented PNGs (cropped,
// magnified, tone-mapped) on the display of the set's predictions, so its ColorVideoVDP reproduces each stimulus's
// predicted JOD (within 0.05 JOD; the same computation), FLIP runs at the same pixels per degree, and the heat maps
// have the presented size. `stimuli visibility` tabulates every condition at 20–120 pixels per degree: its JOD at the
// display's own pixels per degree is the prediction, the table is in visibility.csv/json, the plot in visibility.svg
// and both in the contact sheet. Fails before the metrics were moved onto the presented images (the EXR crops gave
// other JOD) and before the visibility command existed.
TEST_F(StimuliBuild, SetMetricsReproduceThePredictionsAndVisibilitySpansViewingDistances) {
    const fs::path shown = gRoot / "presented", metrics = gRoot / "metrics";
    // With SSS, so that the reference carries its scattering radius for the bands.
    std::string spec = presentedSpec("presented", true);
    spec.replace(spec.find("method = \"none\""), 15, "method = \"separable\"");
    CliRun run = runCli({"stimuli", "build", writeSpec("presented.toml", spec).string(), "-o", shown.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    run = runCli({"analyze", "metrics", "--stimuli", shown.string(), "-o", metrics.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const nlohmann::json m = manifestOf(shown);
    std::ifstream metricsFile(metrics / "metrics.json");
    const nlohmann::json scores = nlohmann::json::parse(metricsFile);
    const skinlab::metrics::CvvdpDisplay display = skinlab::metrics::cvvdpDisplay("standard_fhd");
    // One viewing geometry, from the set's predictions, stated once and used by FLIP and ColorVideoVDP.
    EXPECT_EQ(scores["settings"]["viewing"]["display"], "standard_fhd");
    EXPECT_NEAR(scores["settings"]["viewing"]["pixels_per_degree"].get<double>(), display.pixelsPerDegree, 1e-9);
    EXPECT_NEAR(scores["settings"]["flip"]["pixels_per_degree"].get<double>(), display.pixelsPerDegree, 1e-9);
    EXPECT_NE(scores["settings"]["viewing"]["source"].get<std::string>().find("predictions"), std::string::npos);
    std::map<std::string, double> predicted;
    std::map<std::string, int> presentedWidth;
    for (const auto& s : m["stimuli"]) {
        presentedWidth[s["id"]] = s["width"].get<int>();
        if (!s["reference"].get<bool>()) predicted[s["id"]] = s["predicted"]["jod"].get<double>();
    }
    ASSERT_EQ(scores["comparisons"].size(), predicted.size());
    for (const auto& c : scores["comparisons"]) {
        const std::string id = c["test"]["name"];
        EXPECT_NEAR(c["cvvdp_jod"].get<double>(), predicted.at(id), 0.05) << id;
        EXPECT_EQ(c["width"].get<int>(), presentedWidth.at(id)) << id; // the presented size, not the crop's
        EXPECT_LT(c["cvvdp_jod"].get<double>(), 10.0) << id;
        // The map has the presented size (plus the 170-pixel legend panel).
        EXPECT_EQ(readPixels(metrics / c["cvvdp_heatmap"].get<std::string>()).width, presentedWidth.at(id) + 170) << id;
    }
    // Another display on the command line is another geometry: the JOD move off the predictions.
    run = runCli({"analyze", "metrics", "--stimuli", shown.string(), "--display", "standard_4k", "--no-heatmaps", "-o",
                  (gRoot / "metrics-4k").string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("will differ from the manifest's predicted JOD"), std::string::npos) << run.output;
    // --exposure has no meaning for images scored as shown.
    run = runCli({"analyze", "metrics", "--stimuli", shown.string(), "--exposure", "2", "-o",
                  (gRoot / "metrics-exposed").string()});
    EXPECT_EQ(run.exitCode, 2) << run.output;
    EXPECT_NE(run.output.find("--exposure: 2"), std::string::npos) << run.output;

    // Visibility at 20–120 pixels per degree, plus the display's own: there it is the prediction.
    char ownPpd[32];
    std::snprintf(ownPpd, sizeof ownPpd, "%.17g", display.pixelsPerDegree);
    run = runCli({"stimuli", "visibility", shown.string(), "--ppd", std::string("20,30,") + ownPpd + ",60,80,120"});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    std::ifstream visibilityFile(shown / "visibility.json");
    const nlohmann::json visibility = nlohmann::json::parse(visibilityFile);
    EXPECT_EQ(visibility["display"]["name"], "standard_fhd");
    ASSERT_EQ(visibility["pixels_per_degree"].size(), 6u);
    ASSERT_EQ(visibility["rows"].size(), predicted.size());
    // 24-inch 1920×1080 at 0.6 m is the model's 37.8 ppd: the distance axis says 0.6 m there.
    EXPECT_NEAR(visibility["distance_m"][2].get<double>(), 0.6, 1e-6);
    for (const auto& row : visibility["rows"]) {
        const std::string id = row["stimulus"];
        EXPECT_NEAR(row["jod"][2].get<double>(), predicted.at(id), 1e-9) << id;
        // The summary agrees with the row: visible everywhere exactly when below 9 JOD at every ppd.
        bool everywhere = true, nowhere = true;
        for (const auto& jod : row["jod"]) {
            EXPECT_LE(jod.get<double>(), 10.0) << id;
            everywhere = everywhere && jod.get<double>() < 9.0;
            nowhere = nowhere && jod.get<double>() >= 9.0;
        }
        EXPECT_EQ(row["visible_everywhere"].get<bool>(), everywhere) << id;
        EXPECT_EQ(row["invisible_everywhere"].get<bool>(), nowhere) << id;
    }
    std::ifstream csv(shown / "visibility.csv");
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header.rfind("block,reference,stimulus,jod_ppd_20,jod_ppd_30,", 0), 0u) << header;
    std::stringstream svg, html;
    svg << std::ifstream(shown / "visibility.svg").rdbuf();
    EXPECT_NE(svg.str().find("<polyline"), std::string::npos);
    html << std::ifstream(shown / "contact.html").rdbuf();
    EXPECT_NE(html.str().find("Visibility against viewing distance"), std::string::npos);
    EXPECT_NE(html.str().find("src=\"visibility.svg\""), std::string::npos);
    EXPECT_NE(html.str().find("<table class=\"visibility\">"), std::string::npos);
    // Unordered values are refused with the option named.
    run = runCli({"stimuli", "visibility", shown.string(), "--ppd", "40,20"});
    EXPECT_EQ(run.exitCode, 2) << run.output;
    EXPECT_NE(run.output.find("--ppd: 20 is not larger than the value before it"), std::string::npos) << run.output;
}

// A custom display (a model changed by --display-*) predicts, is recorded in full, and is what `analyze metrics`
// and `stimuli visibility` read back; a bad value fails before rendering, a bad recorded one names file and key.
TEST_F(StimuliBuild, CustomDisplayIsRecordedAndReadBackExactly) {
    const fs::path set = gRoot / "custom-display", metrics = gRoot / "custom-display-metrics";
    // With SSS, so that the reference carries its scattering radius for the metrics' bands.
    std::string text = presentedSpec("custom-display", false);
    text.replace(text.find("method = \"none\""), 15, "method = \"separable\"");
    const fs::path spec = writeSpec("custom-display.toml", text);
    const std::vector<std::string> build = {"stimuli",    "build",          spec.string(), "-o",
                                            set.string(), "--display-peak", "500",         "--display-contrast",
                                            "2000",       "--display-ppd",  "20",          "--no-contact-sheet"};
    CliRun run = runCli(build);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    skinlab::metrics::CvvdpDisplayOverrides changes;
    changes.peakLuminance = 500.0;
    changes.contrast = 2000.0;
    changes.pixelsPerDegree = 20.0;
    const skinlab::metrics::CvvdpDisplay display =
        skinlab::metrics::applyCvvdpOverrides(skinlab::metrics::cvvdpDisplay("standard_fhd"), changes);
    const nlohmann::json m = manifestOf(set);
    std::map<std::string, std::string> referencePng; // block → PNG
    for (const auto& s : m["stimuli"])
        if (s["reference"].get<bool>()) referencePng[s["block"]] = s["files"]["png"];
    std::map<std::string, double> predicted;
    for (const auto& s : m["stimuli"]) {
        if (s["reference"].get<bool>()) continue;
        const nlohmann::json& p = s["predicted"];
        EXPECT_EQ(p["display"], "custom");
        EXPECT_EQ(p["display_model"]["peak_luminance"], 500.0);
        EXPECT_EQ(p["display_model"]["contrast"], 2000.0);
        EXPECT_EQ(p["display_model"]["pixels_per_degree"], 20.0);
        EXPECT_EQ(p["display_model"]["eotf"], display.eotf);
        using namespace skinlab::metrics;
        const auto reference =
            loadMetricRender(set / referencePng.at(s["block"]), RenderRole::test, ImageEncoding::srgb);
        const auto test =
            loadMetricRender(set / s["files"]["png"].get<std::string>(), RenderRole::test, ImageEncoding::srgb);
        EXPECT_EQ(p["jod"].get<double>(), cvvdp(reference.beauty, test.beauty, display, false).jod) << s["id"];
        predicted[s["id"]] = p["jod"].get<double>();
    }
    ASSERT_EQ(predicted.size(), 4u);
    // The same build again renders nothing and predicts the same JOD on the same display: the same manifest.
    const std::string before = skinlab::sha256File(set / "manifest.json");
    run = runCli(build);
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_EQ(skinlab::sha256File(set / "manifest.json"), before) << run.output;
    EXPECT_NE(run.output.find("(ColorVideoVDP, custom;"), std::string::npos) << run.output;

    // The metrics of the set use the recorded display: its ppd for FLIP and ColorVideoVDP, its JOD.
    run = runCli({"analyze", "metrics", "--stimuli", set.string(), "--no-heatmaps", "-o", metrics.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    std::ifstream metricsFile(metrics / "metrics.json");
    const nlohmann::json scores = nlohmann::json::parse(metricsFile);
    EXPECT_EQ(scores["settings"]["viewing"]["display"], "custom");
    EXPECT_EQ(scores["settings"]["viewing"]["pixels_per_degree"].get<double>(), 20.0);
    for (const auto& c : scores["comparisons"])
        EXPECT_NEAR(c["cvvdp_jod"].get<double>(), predicted.at(c["test"]["name"]), 0.05) << c["test"]["name"];
    // Visibility at the recorded display's own ppd is the prediction.
    run = runCli({"stimuli", "visibility", set.string(), "--ppd", "10,20,40"});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    std::ifstream visibilityFile(set / "visibility.json");
    const nlohmann::json visibility = nlohmann::json::parse(visibilityFile);
    EXPECT_EQ(visibility["display"]["name"], "custom");
    for (const auto& row : visibility["rows"])
        EXPECT_NEAR(row["jod"][1].get<double>(), predicted.at(row["stimulus"]), 1e-9) << row["stimulus"];

    // A bad value is one line naming the option, before anything renders.
    const fs::path refused = gRoot / "custom-display-refused";
    run = runCli({"stimuli", "build", spec.string(), "-o", refused.string(), "--display-contrast", "0.5"});
    EXPECT_EQ(run.exitCode, 2) << run.output;
    EXPECT_NE(run.output.find("--display-contrast: 0.5 must be a number >= 1"), std::string::npos) << run.output;
    EXPECT_FALSE(fs::exists(refused));
    // A bad recorded display names the file, the key and the value.
    nlohmann::json broken = m;
    std::size_t index = 0;
    while (broken["stimuli"][index]["reference"].get<bool>()) ++index;
    broken["stimuli"][index]["predicted"]["display_model"]["contrast"] = 0.5;
    std::ofstream(set / "manifest.json") << broken.dump(2);
    run = runCli({"analyze", "metrics", "--stimuli", set.string(), "--no-heatmaps", "-o", metrics.string()});
    EXPECT_EQ(run.exitCode, 2) << run.output;
    EXPECT_NE(run.output.find("manifest.json: stimuli[" + std::to_string(index) +
                              "].predicted.display_model.contrast: expected a number >= 1, not 0.5"),
              std::string::npos)
        << run.output;
}

namespace {

// Share of the pixels of `shown` whose channels differ from the crop (x, y, w, h) of `full` (same pixel scale) by
// more than `tolerance`; 1 when the sizes differ.
double shareDiffering(const Pixels& shown, const Pixels& full, int x, int y, int w, int h, float tolerance) {
    if (shown.width != w || shown.height != h || shown.channels != full.channels) return 1.0;
    size_t differing = 0;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            for (int c = 0; c < shown.channels; ++c)
                if (std::fabs(shown.at(i, j, c) - full.at(x + i, y + j, c)) > tolerance) {
                    ++differing;
                    break;
                }
    return static_cast<double>(differing) / (static_cast<double>(w) * h);
}

} // namespace

// The default presentation renders each crop natively: the presented image is the crop's part of the camera's
// frustum at magnification × the pixels, the same (within rasterisation round-off at silhouettes) as that region of
// the whole frame rendered at magnification × the size; nothing is a nearest-neighbour upsample.
TEST_F(StimuliBuild, NativeCropEqualsTheRegionOfAMagnifiedWholeRender) {
    const fs::path shown = gRoot / "native";
    CliRun run = runCli(
        {"stimuli", "build", writeSpec("native.toml", presentedSpec("native", true)).string(), "-o", shown.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_EQ(run.output.find("nearest neighbour"), std::string::npos) << run.output;
    // The whole frame at 3× (the close block's magnification) and 2× (the mid block's).
    std::map<int, fs::path> whole;
    for (const auto& [mag, render] :
         std::vector<std::pair<int, std::string>>{{3, "width = 288, height = 192"}, {2, "width = 192, height = 128"}}) {
        const std::string name = "whole" + std::to_string(mag);
        whole[mag] = gRoot / name;
        run = runCli({"stimuli", "build", writeSpec(name + ".toml", presentedSpec(name, false, "", render)).string(),
                      "-o", whole[mag].string(), "--no-predict", "--no-contact-sheet"});
        ASSERT_EQ(run.exitCode, 0) << run.output;
    }
    const nlohmann::json m = manifestOf(shown);
    ASSERT_EQ(m["stimuli"].size(), 6u);
    for (const auto& s : m["stimuli"]) {
        const std::string id = s["id"];
        const bool mid = s["block"] == "builtin:head/mid";
        const int x = mid ? 50 : 20, y = mid ? 0 : 8, w = mid ? 46 : 40, h = mid ? 64 : 30, mag = mid ? 2 : 3;
        EXPECT_EQ(s["presentation"]["method"], "native") << id;
        EXPECT_EQ(s["presentation"]["render"], (nlohmann::json{{"width", 96}, {"height", 64}})) << id;
        EXPECT_EQ(s["resolved"]["render"]["window"],
                  (nlohmann::json{{"x", x * mag}, {"y", y * mag}, {"width", w * mag}, {"height", h * mag}}))
            << id;
        EXPECT_EQ(s["width"], w * mag) << id;
        EXPECT_EQ(s["height"], h * mag) << id;
        const Pixels png = readPixels(shown / "png" / (id + ".png"));
        const Pixels wholePng = readPixels(whole[mag] / "png" / (id + ".png"));
        EXPECT_LT(shareDiffering(png, wholePng, x * mag, y * mag, w * mag, h * mag, 2.5f / 255.0f), 0.005) << id;
        // Not a nearest-neighbour upsample: some m × m block of the presented image is not uniform.
        bool blocky = true;
        for (int j = 0; j + mag <= png.height && blocky; j += mag)
            for (int i = 0; i + mag <= png.width && blocky; i += mag)
                for (int k = 0; k < mag * mag && blocky; ++k)
                    blocky = png.at(i + k % mag, j + k / mag, 0) == png.at(i, j, 0);
        EXPECT_FALSE(blocky) << id;
        // The EXR is the native render, every AOV (the beauty compared in linear light).
        const Pixels exr = readPixels(shown / "exr" / (id + ".exr"));
        const Pixels wholeExr = readPixels(whole[mag] / "exr" / (id + ".exr"));
        EXPECT_EQ(exr.channels, wholeExr.channels) << id;
        EXPECT_EQ(exr.width, w * mag) << id;
        Pixels beauty{exr.width, exr.height, 3, {}}, wholeBeauty{wholeExr.width, wholeExr.height, 3, {}};
        for (size_t p = 0; p < exr.data.size() / static_cast<size_t>(exr.channels); ++p)
            for (int c = 0; c < 3; ++c) beauty.data.push_back(exr.data[p * static_cast<size_t>(exr.channels) + c]);
        for (size_t p = 0; p < wholeExr.data.size() / static_cast<size_t>(wholeExr.channels); ++p)
            for (int c = 0; c < 3; ++c)
                wholeBeauty.data.push_back(wholeExr.data[p * static_cast<size_t>(wholeExr.channels) + c]);
        EXPECT_LT(shareDiffering(beauty, wholeBeauty, x * mag, y * mag, w * mag, h * mag, 0.01f), 0.005) << id;
        if (!s["reference"].get<bool>()) {
            EXPECT_TRUE(s.contains("predicted")) << id;
        }
    }
    std::ifstream html(shown / "contact.html");
    std::stringstream text;
    text << html.rdbuf();
    EXPECT_NE(text.str().find("Presented: crop 20,8 40×30 of 96×64, ×3 → 120×90 px (rendered natively)"),
              std::string::npos);
}

namespace {

// Every image file of a built set (exr/, png/, contact.png) → the sha256 of its bytes.
std::map<std::string, std::string> imageFileHashes(const fs::path& dir) {
    std::map<std::string, std::string> out;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        const std::string extension = entry.path().extension().string();
        if (entry.is_regular_file() && (extension == ".exr" || extension == ".png"))
            out[fs::relative(entry.path(), dir).string()] = skinlab::sha256File(entry.path());
    }
    return out;
}

// Returns once the wall clock's second has changed (image timestamps such as EXR's DateTime count whole seconds).
void waitForTheNextSecond() {
    const auto second = [] {
        return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch());
    };
    const auto start = second();
    while (second() == start) std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

} // namespace

// Same inputs, same bytes: a presented set (its cropped and magnified images are rewritten after rendering) built
// twice in different seconds, the second build killed after its first stimulus and resumed, gives byte-identical
// image files, EXRs, PNGs and the contact sheet alike.
TEST_F(StimuliBuild, ResumedBuildIsByteIdenticalToACleanOne) {
    const fs::path spec = writeSpec("presented.toml", presentedSpec("presented", true));
    const fs::path clean = gRoot / "clean", resumed = gRoot / "resumed";
    CliRun run = runCli({"stimuli", "build", spec.string(), "-o", clean.string(), "--no-predict"});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    waitForTheNextSecond();
    size_t doneAtKill = 0;
    run = runCli({"stimuli", "build", spec.string(), "-o", resumed.string(), "--no-predict"}, gRoot / "killed.log",
                 killAfterFirstStimulus(resumed, doneAtKill));
    ASSERT_EQ(run.exitCode, 128 + SIGKILL) << run.output;
    const size_t kept = manifestOf(resumed)["stimuli"].size();
    ASSERT_LT(kept, 6u) << "the build finished before it could be killed";
    waitForTheNextSecond();
    run = runCli({"stimuli", "build", spec.string(), "-o", resumed.string(), "--no-predict"});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("(" + std::to_string(6 - kept) + " rendered, " + std::to_string(kept) + " unchanged)"),
              std::string::npos)
        << run.output;
    const auto expected = imageFileHashes(clean);
    EXPECT_EQ(expected.size(), 2u * 6u + 1u); // an EXR and a PNG per stimulus, and contact.png
    EXPECT_EQ(imageFileHashes(resumed), expected);
    EXPECT_EQ(verifiedHashes(resumed), verifiedHashes(clean));
}

TEST_F(StimuliBuild, CropOutsideTheFrameIsRefusedBeforeRendering) {
    const fs::path out = gRoot / "out";
    const std::string spec = (gRoot / "bad.toml").string();
    auto refused = [&](const std::string& from, const std::string& to) {
        std::string text = presentedSpec("bad", true);
        text.replace(text.find(from), from.size(), to);
        CliRun run = runCli({"stimuli", "build", writeSpec("bad.toml", text).string(), "-o", out.string()});
        EXPECT_EQ(run.exitCode, 2);
        EXPECT_FALSE(fs::exists(out));
        return run.output;
    };
    EXPECT_EQ(refused("width = 40, height = 30", "width = 80, height = 30"),
              "skinlab: error: " + spec +
                  ": fixed.crop.width: x + width = 100 exceeds the render width 96 (stimulus 'head-close-front')\n");
    EXPECT_EQ(refused("x = 50, y = 0, width = 46, height = 64", "x = 50, y = 1, width = 46, height = 64"),
              "skinlab: error: " + spec +
                  ": crop[0].crop.height: y + height = 65 exceeds the render height 64 (stimulus 'head-mid-front')\n");
    EXPECT_EQ(refused("x = 50, y = 0", "x = 96, y = 0"),
              "skinlab: error: " + spec +
                  ": crop[0].crop.x: 96 lies outside the 96 × 64 render (stimulus 'head-mid-front')\n");
    EXPECT_EQ(refused("magnification = 3", "magnification = 0"),
              "skinlab: error: " + spec + ": fixed.magnification: 0 is out of range [1, 16]\n");
    // A crop that cannot be rendered natively (the presented image over 8192 pixels) names the key and the way out.
    std::string large = presentedSpec("bad", true, "", "width = 960, height = 640");
    const std::string crop = "width = 40, height = 30 }\nmagnification = 3";
    large.replace(large.find(crop), crop.size(), "width = 600, height = 30 }\nmagnification = 16");
    CliRun run = runCli({"stimuli", "build", writeSpec("bad.toml", large).string(), "-o", out.string()});
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(run.output, "skinlab: error: " + spec +
                              ": fixed.magnification: 16 cannot be rendered natively: the presented 9600 × 480 pixels "
                              "(at most 8192 each way) of a 15360 × 10240 frame (at most 65536); lower it, or set "
                              "presentation = \"replicate\" (stimulus 'head-close-front')\n");
    // An unknown presentation names its key.
    std::string unknown = presentedSpec("bad", true, "bicubic");
    run = runCli({"stimuli", "build", writeSpec("bad.toml", unknown).string(), "-o", out.string()});
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(run.output, "skinlab: error: " + spec +
                              ": fixed.presentation: 'bicubic' is not a presentation (native: the crop rendered at "
                              "the presented size; replicate: nearest-neighbour magnification)\n");
}

// `stimuli slurm --dry-run` prints the two sbatch scripts (a job array, one task per shard, and a merge job) and
// writes nothing; the bad-input cases fail with one line. The real cluster run is tests/stimuli/slurm_cluster_test.sh.
TEST_F(StimuliBuild, SlurmDryRunPrintsTheScripts) {
    fs::path spec = writeSpec("small.toml", smallSpec("small"));
    fs::path out = gRoot / "cluster";
    CliRun run = runCli({"stimuli", "slurm", spec.string(), "-o", out.string(), "--shards", "3", "--partition", "gpu",
                         "--time", "0:30:00", "--gpus-per-task", "1", "--account", "lab", "--dry-run"});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    for (const std::string& line : std::vector<std::string>{
             "#SBATCH --array=0-2\n", "#SBATCH --requeue\n", "#SBATCH --partition=gpu\n", "#SBATCH --time=0:30:00\n",
             "#SBATCH --gpus-per-task=1\n", "#SBATCH --account=lab\n", "n=3\n", "i=$((SLURM_ARRAY_TASK_ID + 1))\n",
             "#SBATCH --output=" + (out / "slurm" / "logs" / "build-%A_%a.log").string() + "\n",
             " -o \"$dir\" --shard \"$i/$n\" --progress lines --no-contact-sheet || status=$?\n",
             "--dependency=afterok:ARRAY_JOB_ID", "'" + (out / "set").string() + "'"})
        EXPECT_NE(run.output.find(line), std::string::npos) << line << "\n" << run.output;
    EXPECT_EQ(run.output.find("#SBATCH --gpus-per-task=1", run.output.find("merge.sbatch")), std::string::npos)
        << "the merge job asks for no GPU";
    EXPECT_FALSE(fs::exists(out));

    CliRun one = runCli(
        {"stimuli", "slurm", spec.string(), "-o", out.string(), "--shards", "3", "--only-shard", "2", "--dry-run"});
    ASSERT_EQ(one.exitCode, 0) << one.output;
    EXPECT_NE(one.output.find("#SBATCH --array=1\n"), std::string::npos) << one.output;

    CliRun tooMany = runCli({"stimuli", "slurm", spec.string(), "-o", out.string(), "--shards", "7", "--dry-run"});
    EXPECT_EQ(tooMany.exitCode, 2);
    EXPECT_EQ(tooMany.output, "skinlab: error: --shards: 7 is more than the 6 stimuli of set 'small'\n");

    CliRun badShard = runCli(
        {"stimuli", "slurm", spec.string(), "-o", out.string(), "--shards", "3", "--only-shard", "4", "--dry-run"});
    EXPECT_EQ(badShard.exitCode, 2);
    EXPECT_EQ(badShard.output, "skinlab: error: --only-shard: '4' is not a shard of 1..3\n");

    // Without sbatch on PATH: one line saying what to install; nothing written.
    const char* oldPath = std::getenv("PATH");
    std::string saved = oldPath ? oldPath : "";
    fs::create_directories(gRoot / "empty-bin");
    ::setenv("PATH", (gRoot / "empty-bin").c_str(), 1);
    CliRun noSbatch = runCli({"stimuli", "slurm", spec.string(), "-o", out.string(), "--shards", "3"});
    ::setenv("PATH", saved.c_str(), 1);
    EXPECT_EQ(noSbatch.exitCode, 1);
    EXPECT_EQ(noSbatch.output.rfind("skinlab: failure: sbatch not found: install slurm-client", 0), 0u)
        << noSbatch.output;
    EXPECT_EQ(std::count(noSbatch.output.begin(), noSbatch.output.end(), '\n'), 1) << noSbatch.output;
    EXPECT_FALSE(fs::exists(out));

    CliRun noBuild = runCli({"stimuli", "status", gRoot.string()});
    EXPECT_EQ(noBuild.exitCode, 2);
    EXPECT_EQ(noBuild.output,
              "skinlab: error: " + gRoot.string() +
                  ": holds no Slurm build (no slurm/jobs.json); submit one with `skinlab stimuli slurm`\n");
}

// The shipped demo as built: in every block the stimulus without SSS is predicted at least 1 JOD from the block's
// reference (its truth shows subsurface scattering), the block spreads over at least 1 JOD, and each included
// extension moves its method by at least 0.3 JOD (docs/stimuli-visibility.md, "The demo blocks").
TEST_F(StimuliBuild, ShippedDemoBlocksShowScatteringAgainstTheirReference) {
    const fs::path out = gRoot / "shipped-demo";
    fs::remove_all(out);
    const fs::path spec = fs::path(SKINLAB_SOURCE_DIR) / "stimuli" / "specs" / "demo.toml";
    const CliRun run = runCli({"stimuli", "build", spec.string(), "-o", out.string()});
    ASSERT_EQ(run.exitCode, 0) << run.output;
    std::map<std::string, double> jod;
    std::map<std::string, std::pair<double, double>> blockRange; // block → (lowest, highest)
    const nlohmann::json manifest = manifestOf(out);
    for (const auto& s : manifest["stimuli"]) {
        if (s["reference"].get<bool>()) continue;
        const double j = s["predicted"]["jod"].get<double>();
        jod[s["id"]] = j;
        auto [it, fresh] = blockRange.try_emplace(s["block"].get<std::string>(), j, j);
        it->second = {std::min(it->second.first, j), std::max(it->second.second, j)};
    }
    ASSERT_EQ(blockRange.size(), 3u);
    for (const char* none : {"head-face-none", "halo-silhouette-none", "bleed-patches-none"}) {
        ASSERT_TRUE(jod.count(none)) << none;
        EXPECT_LE(jod[none], 9.0) << none;
    }
    for (const auto& [block, range] : blockRange) EXPECT_GE(range.second - range.first, 1.0) << block;
    const std::vector<std::pair<std::string, std::string>> extensions{
        {"halo-silhouette-separable", "halo-silhouette-separable-no-follow_surface"},
        {"halo-silhouette-gaussian-sum", "halo-silhouette-gaussian-sum-no-follow_surface"},
        {"halo-silhouette-separable-no-follow_surface-cbf", "halo-silhouette-separable-no-follow_surface"},
        {"halo-silhouette-gaussian-sum-no-follow_surface-cbf", "halo-silhouette-gaussian-sum-no-follow_surface"},
        {"bleed-patches-separable-cbf", "bleed-patches-separable"},
        {"bleed-patches-separable-lab_weight-0.09", "bleed-patches-separable"},
        {"bleed-patches-gaussian-sum-cbf", "bleed-patches-gaussian-sum"},
        {"bleed-patches-gaussian-sum-lab_weight-0.5", "bleed-patches-gaussian-sum"}};
    for (const auto& [with, without] : extensions) {
        ASSERT_TRUE(jod.count(with) && jod.count(without)) << with;
        EXPECT_GE(jod[with] - jod[without], 0.3) << with << " against " << without;
    }
    fs::remove_all(out);
}
