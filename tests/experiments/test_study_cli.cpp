// Integration tests through the real `skinlab study ...` executable: create/status/export and their errors,
// and crash safety — the server is killed with SIGKILL in the middle of a simulated session, restarted, and the
// session finished: no acknowledged response may be lost or duplicated.
#include "child_process.h"
#include "common/files.h"
#include "common/hash.h"
#include "net/http_client.h"
#include "experiments/simulated_observers.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_store.h"
#include "stimulus_set_fixture.h"
#include "store_answer.h"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <gtest/gtest.h>
#include <map>
#include <random>
#include <regex>
#include <sys/stat.h>
#include <thread>

using namespace skinlab::experiments;
using namespace skinlab::experiments::test_support;
using namespace skinlab::net;
using namespace skinlab::net;
namespace fs = std::filesystem;

namespace {

const char* kDesign = R"(
title = "CLI test"
seed = 5
repetitions = 2
[practice]
trials = 1
[catch]
blank = 2
)";

struct StudyFiles {
    TempFolder folder{"cli"};
    fs::path stimuli = folder.path() / "stimuli";
    fs::path design;
    fs::path database = folder.path() / "study.db";
    StudyFiles() {
        writeStimulusSet(stimuli);
        design = writeText(folder.path(), "design.toml", kDesign);
    }
    // `skinlab study create` of this set and design into `database`; the exit code.
    int create() const;
};

CommandResult runSkinlab(std::vector<std::string> arguments) {
    arguments.insert(arguments.begin(), SKINLAB_CLI);
    return runCommand(arguments);
}

int StudyFiles::create() const {
    return runSkinlab(
               {"study", "create", "--stimuli", stimuli.string(), "--design", design.string(), "-o", database.string()})
        .exitCode;
}

// Starts `skinlab study serve` and returns the port it printed.
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

} // namespace

TEST(StudyCli, CreateStatusExportAndTheirErrors) {
    StudyFiles files;
    CommandResult created = runSkinlab({"study", "create", "--stimuli", files.stimuli.string(), "--design",
                                        files.design.string(), "-o", files.database.string()});
    ASSERT_EQ(created.exitCode, 0) << created.err;
    EXPECT_NE(created.out.find("per participant 27 trials (1 practice, 12 test, 12 repeat, 2 catch)"),
              std::string::npos)
        << created.out;
    EXPECT_EQ(created.out.find("not studied"), std::string::npos) << created.out;
    // A block of the set the design leaves out is named, with the reason.
    const fs::path oneBlock = files.folder.path() / "one-block.db";
    CommandResult partial =
        runSkinlab({"study", "create", "--stimuli", files.stimuli.string(), "--design", files.design.string(), "-o",
                    oneBlock.string(), "--set", "blocks=[\"scene:a/mid\"]"});
    ASSERT_EQ(partial.exitCode, 0) << partial.err;
    EXPECT_NE(partial.out.find(": 1 block(s),"), std::string::npos) << partial.out;
    EXPECT_NE(partial.out.find("not studied: block scene:b/close (not among the design's blocks: scene:a/mid)\n"),
              std::string::npos)
        << partial.out;

    // Never overwrites a study; the existing file is untouched.
    const std::string before = skinlab::sha256File(files.database);
    CommandResult again = runSkinlab({"study", "create", "--stimuli", files.stimuli.string(), "--design",
                                      files.design.string(), "-o", files.database.string()});
    EXPECT_EQ(again.exitCode, 2);
    EXPECT_EQ(again.err,
              "skinlab: error: " + files.database.string() +
                  ": already exists; a study file is never overwritten (it may hold responses) — choose another "
                  "-o or remove it first\n");
    EXPECT_EQ(skinlab::sha256File(files.database), before);

    // Design errors name the file and key, and leave no output behind.
    const fs::path other = files.folder.path() / "other.db";
    CommandResult badKey = runSkinlab({"study", "create", "--stimuli", files.stimuli.string(), "--design",
                                       files.design.string(), "-o", other.string(), "--set", "repetitions=0"});
    EXPECT_EQ(badKey.exitCode, 2);
    EXPECT_EQ(badKey.err, "skinlab: error: " + files.design.string() + ": repetitions: 0 is out of range [1, 100]\n");
    EXPECT_FALSE(fs::exists(other));
    CommandResult noManifest = runSkinlab({"study", "create", "--stimuli", files.folder.path().string(), "--design",
                                           files.design.string(), "-o", other.string()});
    EXPECT_EQ(noManifest.exitCode, 2);
    EXPECT_EQ(noManifest.err, "skinlab: error: " + (files.folder.path() / "manifest.json").string() +
                                  ": no manifest.json in the stimulus folder\n");
    // A stimulus changed after the set was built: its hash no longer matches.
    skinlab::writeFileAtomic(files.stimuli / "png" / "1-artistic.png", "not a png");
    CommandResult changed = runSkinlab({"study", "create", "--stimuli", files.stimuli.string(), "--design",
                                        files.design.string(), "-o", other.string()});
    EXPECT_EQ(changed.exitCode, 2);
    EXPECT_NE(changed.err.find("1-artistic.png: sha256 differs from the manifest"), std::string::npos) << changed.err;
    EXPECT_FALSE(fs::exists(other));

    CommandResult status = runSkinlab({"study", "status", files.database.string()});
    EXPECT_EQ(status.exitCode, 0);
    EXPECT_NE(status.out.find("0 participants, 0 completed, 0 responses"), std::string::npos) << status.out;
    CommandResult csv = runSkinlab({"study", "export", files.database.string(), "--format", "csv"});
    // Contract 3's columns, then the online columns (docs/experiments.md), and no rows.
    EXPECT_EQ(
        csv.out.rfind("observer,scene,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,correct,response_ms,"
                      "flagged,",
                      0),
        0u)
        << csv.out;
    EXPECT_EQ(std::count(csv.out.begin(), csv.out.end(), '\n'), 1) << csv.out;
    CommandResult badFormat = runSkinlab({"study", "export", files.database.string(), "--format", "xls"});
    EXPECT_NE(badFormat.exitCode, 0);
    CommandResult missing = runSkinlab({"study", "status", (files.folder.path() / "nope.db").string()});
    EXPECT_EQ(missing.exitCode, 2);
    EXPECT_EQ(missing.err, "skinlab: error: " + (files.folder.path() / "nope.db").string() + ": no such study file\n");

    // `--observers` is a list of observer counts (study plan, analyze validate); simulate's count is --observer-count.
    CommandResult oldSpelling = runSkinlab({"study", "simulate", files.database.string(), "--observers", "3"});
    EXPECT_EQ(oldSpelling.exitCode, 2);
    EXPECT_EQ(oldSpelling.err, "skinlab: error: --observers: \"3\": study simulate takes the number of observers as "
                               "--observer-count N (--observers is a list of observer counts, in study plan and "
                               "analyze validate)\n");
    CommandResult noCount = runSkinlab({"study", "simulate", files.database.string()});
    EXPECT_EQ(noCount.exitCode, 2);
    EXPECT_EQ(noCount.err, "skinlab: error: --observer-count: required (the number of simultaneous observers)\n");
}

// A set built by the real renderer with a crop and a magnification: `study create` checks the presented images
// (the crop magnified, what a participant sees), not the render, against the design's viewport.
TEST(StudyCli, CreateRefusesPresentedStimuliLargerThanTheViewport) {
    TempFolder folder{"cli-magnified"};
    // 40 × 30 renders; a 20 × 15 crop magnified 16× is presented at 320 × 240, two side by side 640 px wide.
    const fs::path spec = writeText(folder.path(), "tiny.toml", R"(
[set]
name = "tiny"
scene = "builtin:head"
block = ["view"]
[fixed]
render = { width = 40, height = 30, exposure_ev = 0.0 }
tone_map = { operator = "filmic" }
shadow = { resolution = 256 }
camera = { view = "close" }
crop = { x = 10, y = 8, width = 20, height = 15 }
magnification = 16
[[factor]]
name = "method"
levels = ["none", "separable"]
)");
    const fs::path stimuli = folder.path() / "stimuli";
    CommandResult built = runSkinlab({"stimuli", "build", spec.string(), "-o", stimuli.string()});
    ASSERT_EQ(built.exitCode, 0) << built.err;
    const fs::path design = writeText(folder.path(), "design.toml", std::string(kDesign) + R"(
[display]
viewport_width = 500
viewport_height = 400
)");
    // The renders (40 px wide, a pair 80 px) fit 500 × 400; the presented pair (640 px) does not.
    const fs::path database = folder.path() / "study.db";
    CommandResult refused = runSkinlab(
        {"study", "create", "--stimuli", stimuli.string(), "--design", design.string(), "-o", database.string()});
    EXPECT_EQ(refused.exitCode, 2) << refused.out;
    EXPECT_EQ(refused.err.rfind("skinlab: error: " + design.string() + ": display.viewport_width: the trials need ", 0),
              0u)
        << refused.err;
    EXPECT_NE(refused.err.find("640 px of images side by side"), std::string::npos) << refused.err;
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
    EXPECT_FALSE(fs::exists(database));
    // A viewport the presented pair fits is accepted.
    CommandResult accepted = runSkinlab({"study", "create", "--stimuli", stimuli.string(), "--design", design.string(),
                                         "-o", database.string(), "--set", "display.viewport_width=1000"});
    EXPECT_EQ(accepted.exitCode, 0) << accepted.err;
    EXPECT_TRUE(fs::exists(database));
}

TEST(StudyCli, KillNineDuringASessionLosesAndDuplicatesNothing) {
    StudyFiles files;
    ASSERT_EQ(files.create(), 0);
    std::unique_ptr<ChildProcess> server;
    const int port = startServer(server, files.database, 0);
    ASSERT_GT(port, 0);

    StudyStore store(files.database);
    SimulationOptions options;
    options.port = port;
    options.observers = 12;
    options.seed = 3;
    options.labelPrefix = "crash";
    options.thinkMinMs = 2; // keeps the session going while the server is killed
    options.thinkMaxMs = 8;
    options.truth.byCondition = {{"reference-like", 1}, {"separable", 0.5}, {"artistic", 0}, {"reference", 2}};
    SimulationReport report;
    std::thread simulation([&] { report = simulateObservers(store, options); });

    // Kill the server twice in mid-session, each time restarting it on the same port.
    const std::int64_t total = 12 * 27;
    int kills = 0;
    for (std::int64_t threshold : {total / 4, total / 2}) {
        for (int i = 0; i < 3000 && store.responseCount() < threshold; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        ASSERT_LT(store.responseCount(), total) << "the session ended before the kill; make it longer";
        server->kill(SIGKILL);
        EXPECT_EQ(server->wait(), 128 + SIGKILL);
        ++kills;
        std::this_thread::sleep_for(std::chrono::milliseconds(300)); // requests fail meanwhile and are re-sent
        ASSERT_EQ(startServer(server, files.database, port), port);
    }
    simulation.join();
    EXPECT_EQ(kills, 2);
    for (const ObserverResult& o : report.observers) EXPECT_TRUE(o.failure.empty()) << o.label << ": " << o.failure;
    EXPECT_EQ(report.completed(), 12);
    EXPECT_GT(report.transportRetries(), 0) << "the kills should have interrupted requests";

    // Exactly one stored response per planned trial, and every acknowledged answer stored as acknowledged.
    EXPECT_EQ(store.responseCount(), total);
    std::map<std::int64_t, bool> storedLeft;
    for (const ResponseRow& r : store.responses())
        EXPECT_TRUE(storedLeft.emplace(r.trialId, r.aSelected == r.aOnLeft).second);
    std::size_t acknowledged = 0;
    for (const ObserverResult& o : report.observers)
        for (const auto& [trial, side] : o.acknowledged) {
            ASSERT_TRUE(storedLeft.count(trial)) << "acknowledged response to trial " << trial << " lost";
            EXPECT_EQ(storedLeft.at(trial), side == "left");
            ++acknowledged;
        }
    EXPECT_EQ(acknowledged, static_cast<std::size_t>(total));
    SqliteDatabase db(files.database.string(), false);
    SqliteStatement check = db.prepare("PRAGMA integrity_check");
    ASSERT_TRUE(check.step());
    EXPECT_EQ(check.text(0), "ok");

    // The CLI's own simulate, status and export work against the restarted server.
    CommandResult simulated = runSkinlab({"study", "simulate", files.database.string(), "--observer-count", "2",
                                          "--url", "http://127.0.0.1:" + std::to_string(port), "--truth-factor",
                                          "quality", "--lapse", "0.1", "--label-prefix", "cli"});
    EXPECT_EQ(simulated.exitCode, 0) << simulated.out << simulated.err;
    EXPECT_NE(simulated.out.find("2/2 observers completed, 54 responses acknowledged, 0 rejected"), std::string::npos)
        << simulated.out;
    CommandResult status = runSkinlab({"study", "status", files.database.string()});
    EXPECT_NE(status.out.find("14 participants, 14 completed, 378 responses"), std::string::npos) << status.out;
    const fs::path exported = files.folder.path() / "responses.csv";
    ASSERT_EQ(
        runSkinlab({"study", "export", files.database.string(), "--format", "pwcmp", "-o", exported.string()}).exitCode,
        0);
    const std::string pwcmp = skinlab::readFile(exported);
    EXPECT_EQ(std::count(pwcmp.begin(), pwcmp.end(), '\n'), 1 + 14 * 24);

    server->kill(SIGTERM);
    EXPECT_EQ(server->wait(), 0) << "SIGTERM stops the server cleanly";
}

namespace {

// Descriptors the process holds on files that were removed meanwhile ("/path (deleted)" in /proc/PID/fd): a study
// file's -wal or -shm among them means another process believed it held the last connection and removed them.
std::vector<std::string> deletedDescriptors(pid_t pid, const fs::path& database) {
    std::vector<std::string> found;
    std::error_code ec;
    const fs::path fds = fs::path("/proc") / std::to_string(pid) / "fd";
    for (const fs::directory_entry& entry : fs::directory_iterator(fds, ec)) {
        const fs::path target = fs::read_symlink(entry.path(), ec);
        if (ec) continue;
        const std::string text = target.string();
        if (text.rfind(database.string(), 0) == 0 && text.find("(deleted)") != std::string::npos) found.push_back(text);
    }
    return found;
}

// Everything a researcher may run on a study while it is served (docs/experiments.md): the dashboard (which scales
// the answers inside the server), `study status`, `study export`, `study backup` and `analyze scale`.
void readWhileServing(const StudyFiles& files, int port, int round) {
    HttpClient client("127.0.0.1", port);
    for (int attempt = 0; attempt < 100; ++attempt) {
        const HttpAnswer answer =
            client.get("/api/researcher/dashboard", {{"Authorization", "Bearer researcher-token-0123456789"}});
        ASSERT_EQ(answer.status, 200) << answer.body;
        // The first request may find the scale still being computed; the reading is what matters.
        if (answer.body.find("\"computing\"") == std::string::npos) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    const std::string tag = std::to_string(round);
    for (const std::vector<std::string>& command : std::vector<std::vector<std::string>>{
             {"study", "status", files.database.string()},
             {"study", "export", files.database.string(), "--format", "csv", "-o",
              (files.folder.path() / ("export-" + tag + ".csv")).string()},
             {"study", "backup", files.database.string(), (files.folder.path() / ("backup-" + tag + ".db")).string()},
             {"analyze", "scale", files.database.string(), "-o", (files.folder.path() / ("scale-" + tag)).string(),
              "--bootstrap", "100"}}) {
        const CommandResult result = runSkinlab(command);
        // analyze scale may find too few answers in an early round; it must fail cleanly, never crash.
        EXPECT_TRUE(result.exitCode == 0 || (command[0] == "analyze" && result.exitCode == 2))
            << command[0] << " " << command[1] << ": " << result.err;
    }
}

} // namespace

// Reading a served study from other processes and from the dashboard never costs an answer: the readers run while
// observers answer and between waves of observers (when no other connection is open, which is when a lost lock
// lets a reader remove the server's write-ahead log), the server is killed with SIGKILL at seeded random points,
// and every acknowledged answer must be stored exactly once, every observer must finish, and the server must never
// hold a descriptor of a removed study file.
TEST(StudyCli, ReadersWhileServingNeitherLoseNorDuplicateAnswers) {
    StudyFiles files;
    ASSERT_EQ(files.create(), 0);
    std::unique_ptr<ChildProcess> server;
    const int port = startServer(server, files.database, 0);
    ASSERT_GT(port, 0);
    std::mt19937 random(20261202);
    constexpr int kRounds = 3;
    constexpr int kObservers = 4;
    constexpr std::int64_t kTrials = 27;
    std::map<std::int64_t, bool> acknowledgedLeft;
    int kills = 0;
    for (int round = 0; round < kRounds; ++round) {
        std::int64_t before = 0;
        {
            // The simulation reads the plan through its own connection; it is closed before the idle readers run.
            StudyStore store(files.database);
            before = store.responseCount();
            SimulationOptions options;
            options.port = port;
            options.observers = kObservers;
            options.seed = static_cast<std::uint64_t>(round + 1);
            options.labelPrefix = "wave" + std::to_string(round);
            options.thinkMinMs = 2;
            options.thinkMaxMs = 8;
            options.truth.byCondition = {{"reference-like", 1}, {"separable", 0.5}, {"artistic", 0}, {"reference", 2}};
            SimulationReport report;
            std::thread simulation([&] { report = simulateObservers(store, options); });
            // Readers while observers answer, then a kill at a random point of the wave.
            const std::int64_t wave = kObservers * kTrials;
            const std::int64_t killAt =
                before + std::uniform_int_distribution<std::int64_t>(wave / 5, wave / 2)(random);
            readWhileServing(files, port, round * 2);
            for (int i = 0; i < 4000 && store.responseCount() < killAt; ++i)
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            EXPECT_TRUE(deletedDescriptors(server->pid(), files.database).empty());
            server->kill(SIGKILL);
            EXPECT_EQ(server->wait(), 128 + SIGKILL);
            ++kills;
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
            ASSERT_EQ(startServer(server, files.database, port), port);
            simulation.join();
            for (const ObserverResult& o : report.observers) {
                EXPECT_TRUE(o.completed) << o.label << ": " << o.failure;
                for (const auto& [trial, side] : o.acknowledged)
                    EXPECT_TRUE(acknowledgedLeft.emplace(trial, side == "left").second)
                        << "trial " << trial << " acknowledged twice";
            }
        }
        // No connection of this process is open now: the readers alone, then the server's descriptors.
        readWhileServing(files, port, round * 2 + 1);
        const std::vector<std::string> deleted = deletedDescriptors(server->pid(), files.database);
        EXPECT_TRUE(deleted.empty()) << "round " << round << ": the server holds " << deleted.size()
                                     << " descriptors of removed files, e.g. " << deleted.front();
        // Sometimes a kill right after the readers, before the next wave joins.
        if (std::uniform_int_distribution<int>(0, 1)(random) == 1) {
            server->kill(SIGKILL);
            EXPECT_EQ(server->wait(), 128 + SIGKILL);
            ++kills;
            ASSERT_EQ(startServer(server, files.database, port), port);
        }
    }
    server->kill(SIGTERM);
    EXPECT_EQ(server->wait(), 0);

    // Every acknowledged answer is stored exactly once, with the side it was acknowledged with.
    StudyStore store(files.database);
    EXPECT_EQ(acknowledgedLeft.size(), static_cast<std::size_t>(kRounds * kObservers * kTrials));
    EXPECT_EQ(store.responseCount(), kRounds * kObservers * kTrials);
    std::map<std::int64_t, bool> storedLeft;
    for (const ResponseRow& r : store.responses())
        EXPECT_TRUE(storedLeft.emplace(r.trialId, r.aSelected == r.aOnLeft).second) << "trial " << r.trialId;
    for (const auto& [trial, left] : acknowledgedLeft) {
        ASSERT_TRUE(storedLeft.count(trial)) << "acknowledged answer to trial " << trial << " lost";
        EXPECT_EQ(storedLeft.at(trial), left);
    }
    SqliteDatabase db(files.database.string(), false);
    SqliteStatement check = db.prepare("PRAGMA integrity_check");
    ASSERT_TRUE(check.step());
    EXPECT_EQ(check.text(0), "ok");
    EXPECT_GE(kills, kRounds);
}

// The researcher token from a file or the environment: never on the command line (every user reads it in `ps`) nor
// in the output (often a log). Study files and the nginx site file are readable by their owner only.
TEST(StudyCli, ResearcherTokenFromAFileOrTheEnvironmentAndPrivateFiles) {
    StudyFiles files;
    const mode_t previous = ::umask(022);
    ASSERT_EQ(files.create(), 0);
    auto mode = [](const fs::path& file) { return fs::status(file).permissions() & fs::perms::all; };
    EXPECT_EQ(mode(files.database), fs::perms::owner_read | fs::perms::owner_write);

    const std::string secret = "file-token-" + randomHex(16);
    const fs::path tokenFile = writeText(files.folder.path(), "token", secret + "\n");
    const std::string environmentSecret = "env-token-" + randomHex(16);
    for (const bool fromFile : {true, false}) {
        std::vector<std::string> arguments{SKINLAB_CLI, "study", "serve", files.database.string(), "--port", "0"};
        if (fromFile) {
            arguments.push_back("--token-file");
            arguments.push_back(tokenFile.string());
        } else {
            ::setenv("SKINLAB_RESEARCHER_TOKEN", environmentSecret.c_str(), 1);
        }
        const std::string token = fromFile ? secret : environmentSecret;
        ChildProcess child(arguments);
        ::unsetenv("SKINLAB_RESEARCHER_TOKEN");
        std::string output;
        int port = -1;
        static const std::regex serving(R"(serving .* on http://127\.0\.0\.1:(\d+)/)");
        for (int i = 0; i < 8; ++i) {
            bool ok = false;
            const std::string line = child.readLine(std::chrono::seconds(20), ok);
            if (!ok) break;
            output += line + "\n";
            std::smatch m;
            if (std::regex_search(line, m, serving)) port = std::stoi(m[1].str());
            if (line.rfind("dashboard:", 0) == 0) break;
        }
        ASSERT_GT(port, 0) << output;
        EXPECT_EQ(output.find(token), std::string::npos) << "the token was printed: " << output;
        const std::string commandLine = skinlab::readFile("/proc/" + std::to_string(child.pid()) + "/cmdline");
        EXPECT_EQ(commandLine.find(token), std::string::npos) << "the token is visible in ps";
        HttpClient client("127.0.0.1", port);
        EXPECT_EQ(client.get("/api/researcher/status", {{"Authorization", "Bearer " + token}}).status, 200);
        EXPECT_EQ(client.get("/api/researcher/status", {{"Authorization", "Bearer wrong"}}).status, 403);
        child.kill(SIGTERM);
        child.wait();
    }
    EXPECT_EQ(mode(files.database), fs::perms::owner_read | fs::perms::owner_write);
    const fs::path backup = files.folder.path() / "backup.db";
    EXPECT_EQ(runSkinlab({"study", "backup", files.database.string(), backup.string()}).exitCode, 0);
    EXPECT_EQ(mode(backup), fs::perms::owner_read | fs::perms::owner_write);
    const fs::path pem = writeText(files.folder.path(), "cert.pem", "-----BEGIN CERTIFICATE-----\nMIIB\n");
    const fs::path site = files.folder.path() / "site.conf";
    const CommandResult deployed =
        runSkinlab({"study", "deploy-config", "--server-name", "study.example.org", "--upstream", "127.0.0.1:8080",
                    "--cert", pem.string(), "--key", pem.string(), "-o", site.string()});
    EXPECT_EQ(deployed.exitCode, 0) << deployed.err;
    EXPECT_EQ(mode(site), fs::perms::owner_read | fs::perms::owner_write);
    // Both sources at once is a mistake.
    const CommandResult both =
        runSkinlab({"study", "serve", files.database.string(), "--token", "x", "--token-file", tokenFile.string()});
    EXPECT_EQ(both.exitCode, 2) << both.err;
    ::umask(previous);
}

namespace {

const char* kUnshare = "/usr/bin/unshare"; // util-linux
// Mounts $1 read-only at $2, then runs the rest of the arguments.
const char* kReadOnlyMount = R"(mount --bind "$1" "$2" && mount -o remount,bind,ro "$2" && shift 2 && exec "$@")";

// Runs `skinlab COMMAND…` with `folder` seen read-only at `mountPoint`: a bind mount remounted read-only in a mount
// namespace of the command's own (`unshare -rm`: no privilege needed where user namespaces are allowed). At most
// `seconds` (then killed: exit code 124).
CommandResult runOnReadOnlyMount(const fs::path& folder, const fs::path& mountPoint,
                                 const std::vector<std::string>& command, int seconds = 120) {
    std::vector<std::string> arguments{kUnshare,
                                       "-rm",
                                       "sh",
                                       "-c",
                                       kReadOnlyMount,
                                       "sh",
                                       folder.string(),
                                       mountPoint.string(),
                                       "/usr/bin/timeout",
                                       std::to_string(seconds),
                                       SKINLAB_CLI};
    arguments.insert(arguments.end(), command.begin(), command.end());
    return runCommand(arguments);
}

// Whether this machine gives a process a read-only bind mount (a file cannot be created through it).
bool readOnlyMountsWork(const fs::path& scratch) {
    if (!fs::exists(kUnshare)) return false;
    fs::create_directories(scratch / "folder");
    fs::create_directories(scratch / "mounted");
    const fs::path probe = scratch / "mounted" / "probe";
    return runCommand({kUnshare, "-rm", "sh", "-c", kReadOnlyMount, "sh", (scratch / "folder").string(),
                       (scratch / "mounted").string(), "/bin/sh", "-c", "! touch \"$0\" 2>/dev/null", probe.string()})
               .exitCode == 0;
}

// A participant answering every trial through the store: catch trials right, test trials for the panel A.
void answerEveryTrial(StudyStore& store, const std::string& label) {
    const ParticipantRecord p = store.join(label);
    const std::int64_t session = store.startSession(p.id, "test", 1280, 800, 1.0);
    while (const std::optional<TrialRecord> t = store.nextTrial(p.id)) {
        const bool chooseA = t->plan.expected != 'B';
        store.recordResponse(storeAnswer(p, session, *t, chooseA == t->plan.aOnLeft ? "left" : "right"));
    }
}

bool oneLine(const std::string& text) { return !text.empty() && text.find('\n') == text.size() - 1; }

} // namespace

// A study file on a read-only mount: `study status`, `export`, `backup` and `analyze scale` read it — with no
// write-ahead log beside it, and with the log and index of a server writing it through another (writable) mount —
// and say in one line when they cannot (a log without its index); `study serve` refuses it at start, in one line,
// before printing the participant link.
TEST(StudyCli, ReadOnlyStudyFilesAreReadAndNeverServed) {
    StudyFiles files;
    ASSERT_EQ(files.create(), 0);
    if (!readOnlyMountsWork(files.folder.path() / "probe"))
        GTEST_SKIP() << "no read-only bind mount on this machine (unshare -rm)";
    const fs::path data = files.folder.path() / "data", mounted = files.folder.path() / "mounted";
    fs::create_directories(data);
    fs::create_directories(mounted);
    {
        StudyStore store(files.database);
        answerEveryTrial(store, "P-one");
        answerEveryTrial(store, "P-two");
    }
    fs::copy_file(files.database, data / "study.db");
    ASSERT_FALSE(fs::exists(data / "study.db-wal")) << "closed: every answer is in the file itself";
    const std::string seen = (mounted / "study.db").string();
    const fs::path out = files.folder.path();

    const CommandResult status = runOnReadOnlyMount(data, mounted, {"study", "status", seen});
    EXPECT_EQ(status.exitCode, 0) << status.err;
    EXPECT_NE(status.out.find("P-two"), std::string::npos) << status.out;
    const CommandResult exported =
        runOnReadOnlyMount(data, mounted, {"study", "export", seen, "-o", (out / "export.csv").string()});
    EXPECT_EQ(exported.exitCode, 0) << exported.err;
    ASSERT_EQ(runSkinlab({"study", "export", files.database.string(), "-o", (out / "expected.csv").string()}).exitCode,
              0);
    EXPECT_TRUE(fs::exists(out / "export.csv") &&
                skinlab::sha256File(out / "export.csv") == skinlab::sha256File(out / "expected.csv"))
        << "the export differs from the writable file's";
    const CommandResult backup =
        runOnReadOnlyMount(data, mounted, {"study", "backup", seen, (out / "copy.db").string()});
    EXPECT_EQ(backup.exitCode, 0) << backup.err;
    EXPECT_NE(backup.out.find("2 participants, 54 responses"), std::string::npos) << backup.out;
    const CommandResult scaled = runOnReadOnlyMount(
        data, mounted, {"analyze", "scale", seen, "-o", (out / "scale").string(), "--bootstrap", "100"});
    EXPECT_EQ(scaled.exitCode, 0) << scaled.err;
    EXPECT_EQ(scaled.err.find("missing column"), std::string::npos) << "read as a CSV file: " << scaled.err;

    // A server writing the file through a writable mount: its log and index lie beside the file, and the readers
    // on the read-only mount see its latest answers.
    StudyStore live(data / "study.db");
    answerEveryTrial(live, "P-three");
    ASSERT_TRUE(fs::exists(data / "study.db-wal") && fs::file_size(data / "study.db-wal") > 0);
    const CommandResult liveStatus = runOnReadOnlyMount(data, mounted, {"study", "status", seen});
    EXPECT_EQ(liveStatus.exitCode, 0) << liveStatus.err;
    EXPECT_NE(liveStatus.out.find("P-three"), std::string::npos) << liveStatus.out;

    // Served from the read-only mount: refused at start, before the participant link.
    const CommandResult served = runOnReadOnlyMount(data, mounted, {"study", "serve", seen, "--port", "0"}, 10);
    EXPECT_EQ(served.exitCode, 2) << served.out << served.err;
    EXPECT_TRUE(oneLine(served.err)) << served.err;
    EXPECT_NE(served.err.find(seen + ": the study file is not writable here"), std::string::npos) << served.err;
    EXPECT_EQ(served.out.find("participant link"), std::string::npos) << served.out;

    // The log of a killed server without its index: not readable without writing; one line says so.
    const fs::path stranded = files.folder.path() / "stranded";
    fs::create_directories(stranded);
    fs::copy_file(data / "study.db", stranded / "study.db");
    fs::copy_file(data / "study.db-wal", stranded / "study.db-wal");
    for (const char* command : {"status", "export"}) {
        const CommandResult refused = runOnReadOnlyMount(stranded, mounted, {"study", command, seen});
        EXPECT_EQ(refused.exitCode, 2) << command << ": " << refused.err;
        EXPECT_TRUE(oneLine(refused.err)) << refused.err;
        EXPECT_NE(refused.err.find("study.db-wal (committed transactions not yet in the file)"), std::string::npos)
            << refused.err;
    }
}

// A researcher token must carry 128 bits: a short one, from any source, is refused at start in one line naming its
// source, before anything is served.
TEST(StudyCli, WeakResearcherTokensAreRefused) {
    StudyFiles files;
    ASSERT_EQ(files.create(), 0);
    const fs::path shortFile = writeText(files.folder.path(), "short-token", "ab\n");
    const fs::path repeated = writeText(files.folder.path(), "repeated-token", std::string(40, 'a') + "\n");
    const fs::path hex = writeText(files.folder.path(), "hex-token", "0123456789abcdef0123456789abcde\n"); // 124 bits
    const fs::path good = writeText(files.folder.path(), "good-token", randomHex(16) + "\n");
    // `study serve` with these options, stopped after 10 s should it serve (exit code 124).
    auto serveFor10s = [&](const std::vector<std::string>& options) {
        std::vector<std::string> arguments{"/usr/bin/timeout",      "10",     SKINLAB_CLI, "study", "serve",
                                           files.database.string(), "--port", "0"};
        arguments.insert(arguments.end(), options.begin(), options.end());
        return runCommand(arguments);
    };
    for (const fs::path& weak : {shortFile, repeated, hex}) {
        const CommandResult served = serveFor10s({"--token-file", weak.string()});
        EXPECT_EQ(served.exitCode, 2) << weak << ": " << served.err;
        EXPECT_EQ(served.err.rfind("skinlab: error: " + weak.string() + ": the researcher token is too weak (", 0), 0u)
            << served.err;
        EXPECT_TRUE(std::count(served.err.begin(), served.err.end(), '\n') == 1) << served.err;
        EXPECT_EQ(served.out.find("participant link"), std::string::npos) << served.out;
    }
    const CommandResult onCommandLine = serveFor10s({"--token", "t0ken"});
    EXPECT_EQ(onCommandLine.exitCode, 2) << onCommandLine.err;
    EXPECT_NE(onCommandLine.err.find("--token: the researcher token is too weak"), std::string::npos);
    ::setenv("SKINLAB_RESEARCHER_TOKEN", "short-secret", 1);
    const CommandResult fromEnvironment = serveFor10s({});
    ::unsetenv("SKINLAB_RESEARCHER_TOKEN");
    EXPECT_EQ(fromEnvironment.exitCode, 2) << fromEnvironment.err;
    EXPECT_NE(fromEnvironment.err.find("SKINLAB_RESEARCHER_TOKEN: the researcher token is too weak"),
              std::string::npos);

    // 32 hexadecimal digits (openssl rand -hex 16) are enough.
    ChildProcess server(
        {SKINLAB_CLI, "study", "serve", files.database.string(), "--port", "0", "--token-file", good.string()});
    bool ok = false;
    const std::string first = server.readLine(std::chrono::seconds(20), ok);
    EXPECT_TRUE(ok && first.rfind("serving ", 0) == 0) << first;
    server.kill(SIGTERM);
    server.wait();
}

// Exports hold personal data and, unless asked for, never the platform's session id (Prolific SESSION_ID, MTurk
// assignmentId): with it anyone who reads the file resumes an unfinished participation. Every format, written with
// -o under the usual umask, is readable by its owner only; --include-session-ids adds the ids.
TEST(StudyCli, ExportsArePrivateAndLeaveOutSessionIds) {
    StudyFiles files;
    skinlab::writeFileAtomic(files.design, std::string(kDesign) + "[recruitment]\nplatform = \"prolific\"\n");
    ASSERT_EQ(files.create(), 0);
    const std::string sessionId = "60bb1b2c3d4e5f6a7b8c9d22";
    {
        StudyStore store(files.database);
        const ParticipantRecord p = store.join(
            "", "key-1", ExternalIds{"prolific", "5f8a1b2c3d4e5f6a7b8c9d0e", "60aa1b2c3d4e5f6a7b8c9d11", sessionId});
        const std::int64_t session = store.startSession(p.id, "test", 1280, 800, 1.0);
        for (int i = 0; i < 3; ++i)
            store.recordResponse(storeAnswer(p, session, *store.nextTrial(p.id), i % 2 ? "left" : "right"));
    }
    const mode_t previous = ::umask(022);
    for (const std::string format : {"csv", "pwcmp", "json"}) {
        for (const bool asked : {false, true}) {
            const fs::path file = files.folder.path() / ("export-" + std::to_string(asked) + "." + format);
            std::vector<std::string> arguments{"study", "export",     files.database.string(), "--format", format,
                                               "-o",    file.string()};
            if (asked) arguments.push_back("--include-session-ids");
            const CommandResult exported = runSkinlab(arguments);
            ASSERT_EQ(exported.exitCode, 0) << exported.err;
            EXPECT_EQ(fs::status(file).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write)
                << file;
            const std::string text = skinlab::readFile(file);
            EXPECT_NE(text.find("5f8a1b2c3d4e5f6a7b8c9d0e"), std::string::npos) << format << ": " << text;
            if (format == "pwcmp") continue; // the three answers may all be practice or catch trials
            EXPECT_EQ(text.find(sessionId) != std::string::npos, asked) << format << ": " << text;
            EXPECT_EQ(text.find("external_session_id") != std::string::npos, asked) << format;
        }
    }
    // Standard output carries the same (the researcher chooses where it goes).
    const CommandResult printed = runSkinlab({"study", "export", files.database.string(), "--format", "csv"});
    EXPECT_EQ(printed.out, skinlab::readFile(files.folder.path() / "export-0.csv"));
    ::umask(previous);
}
