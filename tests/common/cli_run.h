#pragma once
// Runs the real `skinlab` executable (SKINLAB_CLI, set by skinlab_add_gtest) with a command line and captures its
// standard output and error together, for tests of command-line behaviour (exit codes, one-line errors).
#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace skinlab::test_support {

struct CliRun {
    int exitCode = -1;
    std::string output; // stdout and stderr
};

inline CliRun runCli(const std::string& arguments) {
    const std::string command = std::string(SKINLAB_CLI) + " " + arguments + " 2>&1";
    CliRun result;
    FILE* pipe = popen(command.c_str(), "r");
    char buffer[4096];
    while (size_t n = fread(buffer, 1, sizeof buffer, pipe)) result.output.append(buffer, n);
    const int status = pclose(pipe);
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

} // namespace skinlab::test_support
