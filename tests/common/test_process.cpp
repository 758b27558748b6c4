// common/process.h: the one way skinlab starts child processes (Blender, Slurm's commands, tune's background
// renders, Chromium): PATH lookup, output to a file or captured, exit status and signals, a group of its own.
#include "common/error.h"
#include "common/process.h"
#include "tests/common/temp_folder.h"

#include <csignal>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
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
