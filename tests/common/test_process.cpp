// common/process.h: the one way skinlab starts child processes (Blender, Slurm's commands, tune's background
// renders, Chromium): PATH lookup, output to a file or captured, exit status and signals, a group of its own.
#include "common/error.h"
#include "common/process.h"
#include "tests/common/temp_folder.h"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <pthread.h>
#include <sstream>
#include <unistd.h>

namespace skinlab {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& file) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

using skinlab::test_support::TempFolder;

TEST(Process, FindsProgramsOnThePathOrByPath) {
    const fs::path sh = findProgram("sh");
    ASSERT_FALSE(sh.empty());
    EXPECT_TRUE(sh.is_absolute()) << sh;
    EXPECT_EQ(findProgram(sh.string()), sh); // a path is taken as it is
    EXPECT_TRUE(findProgram("skinlab-no-such-program").empty());
    EXPECT_TRUE(findProgram("/nonexistent/sh").empty());
    EXPECT_TRUE(findProgram("").empty());
}

TEST(Process, CapturesOutputAndExitStatus) {
    const CapturedRun run = runCaptured(findProgram("sh"), {"-c", "echo out; echo err >&2; exit 3"});
    EXPECT_EQ(run.exitCode, 3);
    EXPECT_EQ(run.out, "out\n");
    EXPECT_EQ(run.err, "err\n");
    // stdin is /dev/null: a program that reads it sees the end at once instead of waiting.
    EXPECT_EQ(runCaptured(findProgram("cat"), {}).exitCode, 0);
}

TEST(Process, OutputToAFileInItsWorkingDirectoryAppendedOrTruncated) {
    TempFolder folder;
    const fs::path log = folder.path() / "log.txt";
    SpawnOptions options;
    options.output = log;
    options.workingDirectory = folder.path();
    const fs::path sh = findProgram("sh");
    EXPECT_EQ(waitProcess(spawnProcess(sh, {"-c", "pwd; echo e >&2"}, options)), 0);
    EXPECT_EQ(waitProcess(spawnProcess(sh, {"-c", "echo second"}, options)), 0);
    EXPECT_EQ(readAll(log), fs::canonical(folder.path()).string() + "\ne\nsecond\n");
    options.appendOutput = false;
    EXPECT_EQ(waitProcess(spawnProcess(sh, {"-c", "echo only"}, options)), 0);
    EXPECT_EQ(readAll(log), "only\n");
}

TEST(Process, SignalsAndOwnProcessGroup) {
    SpawnOptions options;
    options.ownProcessGroup = true;
    const pid_t pid = spawnProcess(findProgram("sleep"), {"30"}, options);
    EXPECT_EQ(::getpgid(pid), pid); // the leader of its own group
    ASSERT_EQ(::kill(-pid, SIGTERM), 0);
    EXPECT_EQ(waitProcess(pid), 128 + SIGTERM);
}

// A field of /proc/PID/status ("SigBlk", "SigIgn"): its hexadecimal mask.
unsigned long long statusMask(const std::string& status, const std::string& field) {
    const std::size_t at = status.find("\n" + field + ":");
    if (at == std::string::npos) return ~0ull;
    return std::stoull(status.substr(at + field.size() + 2), nullptr, 16);
}

// Restores the calling thread's signal mask and SIGTERM's disposition.
struct SignalsChanged {
    sigset_t mask;
    struct sigaction term;
    SignalsChanged() {
        pthread_sigmask(SIG_SETMASK, nullptr, &mask);
        sigaction(SIGTERM, nullptr, &term);
    }
    ~SignalsChanged() {
        pthread_sigmask(SIG_SETMASK, &mask, nullptr);
        sigaction(SIGTERM, &term, nullptr);
    }
};

TEST(Process, ChildrenStartWithNoBlockedOrIgnoredSignals) {
    // A server blocks SIGINT and SIGTERM in its threads (one thread waits for them); its children must not inherit
    // that, or SIGTERM (cancel, shutdown) never ends them.
    SignalsChanged restore;
    sigset_t blocked;
    sigemptyset(&blocked);
    sigaddset(&blocked, SIGINT);
    sigaddset(&blocked, SIGTERM);
    ASSERT_EQ(pthread_sigmask(SIG_BLOCK, &blocked, nullptr), 0);
    struct sigaction ignore = {};
    ignore.sa_handler = SIG_IGN;
    ASSERT_EQ(sigaction(SIGTERM, &ignore, nullptr), 0);

    const CapturedRun captured = runCaptured(findProgram("cat"), {"/proc/self/status"});
    ASSERT_EQ(captured.exitCode, 0);
    EXPECT_EQ(statusMask(captured.out, "SigBlk"), 0u) << captured.out;
    EXPECT_EQ(statusMask(captured.out, "SigIgn") & (1ull << (SIGTERM - 1)), 0u) << captured.out;

    TempFolder folder;
    SpawnOptions options;
    options.output = folder.path() / "status.txt";
    EXPECT_EQ(waitProcess(spawnProcess(findProgram("cat"), {"/proc/self/status"}, options)), 0);
    const std::string spawned = readAll(options.output);
    EXPECT_EQ(statusMask(spawned, "SigBlk"), 0u) << spawned;
    EXPECT_EQ(statusMask(spawned, "SigIgn") & (1ull << (SIGTERM - 1)), 0u) << spawned;

    // And SIGTERM ends a child at once.
    options.ownProcessGroup = true;
    const pid_t pid = spawnProcess(findProgram("sleep"), {"30"}, options);
    ::usleep(100 * 1000); // let it reach sleep
    const auto sent = std::chrono::steady_clock::now();
    ASSERT_EQ(::kill(-pid, SIGTERM), 0);
    EXPECT_EQ(waitProcess(pid), 128 + SIGTERM);
    EXPECT_LT(std::chrono::steady_clock::now() - sent, std::chrono::seconds(5));
}

TEST(Process, FailuresNameTheProgramOrTheFile) {
    try {
        spawnProcess("/nonexistent/program", {});
        FAIL() << "no error";
    } catch (const RuntimeError& e) {
        EXPECT_STREQ(e.what(), "/nonexistent/program: cannot start (No such file or directory)");
    }
    SpawnOptions options;
    options.output = "/nonexistent/folder/log.txt";
    try {
        spawnProcess(findProgram("true"), {}, options);
        FAIL() << "no error";
    } catch (const RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/folder/log.txt: cannot write the output of"),
                  std::string::npos)
            << e.what();
    }
}

} // namespace
} // namespace skinlab
