#pragma once
// Child processes, started one way (posix_spawn, never a shell): Blender for the path-traced methods, Slurm's
// commands, `skinlab tune`'s background renders and the report's headless Chromium.
#include <filesystem>
#include <string>
#include <sys/types.h>
#include <vector>

namespace skinlab {

// The program's full path: `program` itself when it contains a '/' (and is executable), else the first executable
// regular file of that name on PATH; empty when there is none.
std::filesystem::path findProgram(const std::string& program);

struct SpawnOptions {
    // stdout and stderr go to this file (created with mode 0644); empty: both go to /dev/null.
    std::filesystem::path output;
    bool appendOutput = true;               // false: the file is truncated first
    std::filesystem::path workingDirectory; // empty: the caller's
    bool ownProcessGroup = false;           // a group of its own, so kill(-pid) ends its children too
    bool closeInheritedFiles = false;       // close every descriptor ≥ 3 (a server's sockets)
};

// Starts `program args...` with stdin from /dev/null, no signal blocked and every signal's action the default
// (whatever the calling thread blocks or ignores). Returns its pid; throws RuntimeError naming the program and
// the reason when it cannot be started (missing, not executable, output file not writable).
pid_t spawnProcess(const std::filesystem::path& program, const std::vector<std::string>& args,
                   const SpawnOptions& options = {});

// Waits for `pid` (retrying on EINTR): its exit status, 128 + the signal when a signal ended it.
int waitProcess(pid_t pid);

struct CapturedRun {
    int exitCode = -1;
    std::string out, err;
};
// Runs `program args...` to its end (signals as spawnProcess), collecting its stdout and stderr.
CapturedRun runCaptured(const std::filesystem::path& program, const std::vector<std::string>& args);

} // namespace skinlab
