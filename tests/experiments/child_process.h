#pragma once
// Runs the real `skinlab` executable as a child process (for the crash-safety and CLI tests): its standard
// output is read line by line with a deadline; kill() sends SIGKILL (a crash, no clean-up).
#include <chrono>
#include <string>
#include <sys/types.h>
#include <vector>

namespace skinlab::experiments::test_support {

class ChildProcess {
public:
    explicit ChildProcess(const std::vector<std::string>& arguments);
    ~ChildProcess(); // kills the child if still running
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    // The next line of standard output; empty string with `ok = false` on end of file or timeout.
    std::string readLine(std::chrono::milliseconds timeout, bool& ok);
    void kill(int signal);
    // Waits for the exit; returns the exit status (or 128 + signal).
    int wait();
    pid_t pid() const { return pid_; }

private:
    pid_t pid_ = -1;
    int stdoutFd_ = -1;
    std::string buffer_;
    bool exited_ = false;
    int status_ = 0;
};

struct CommandResult {
    int exitCode = 0;
    std::string out; // stdout
    std::string err; // stderr
};

// Runs a command to completion and captures both streams.
CommandResult runCommand(const std::vector<std::string>& arguments);

} // namespace skinlab::experiments::test_support
