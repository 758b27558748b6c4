#include "renderer/pathtraced/blender_process.h"

#include "common/error.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <spawn.h>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace skinlab::renderer::pathtraced {

std::filesystem::path findProgram(const std::string& program) {
    if (program.empty()) return {};
    if (program.find('/') != std::string::npos)
        return ::access(program.c_str(), X_OK) == 0 ? std::filesystem::path(program) : std::filesystem::path();
    const char* path = std::getenv("PATH");
    std::stringstream folders(path ? path : "/usr/local/bin:/usr/bin:/bin");
    std::string folder;
    while (std::getline(folders, folder, ':')) {
        if (folder.empty()) folder = ".";
        const std::filesystem::path candidate = std::filesystem::path(folder) / program;
        std::error_code error;
        if (std::filesystem::is_regular_file(candidate, error) && ::access(candidate.c_str(), X_OK) == 0)
            return candidate;
    }
    return {};
}

int runProcess(const std::filesystem::path& program, const std::vector<std::string>& args,
               const std::filesystem::path& workingDirectory, const std::filesystem::path& logPath) {
    const int log = ::open(logPath.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (log < 0) throw InputError(logPath.string() + ": cannot write log (" + std::strerror(errno) + ")");
    const int devNull = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (devNull >= 0) posix_spawn_file_actions_adddup2(&actions, devNull, 0);
    posix_spawn_file_actions_adddup2(&actions, log, 1);
    posix_spawn_file_actions_adddup2(&actions, log, 2);
    // posix_spawn_file_actions_addchdir_np is glibc ≥ 2.29 (Debian 12 has 2.36).
    posix_spawn_file_actions_addchdir_np(&actions, workingDirectory.c_str());
    std::vector<std::string> argvStrings;
    argvStrings.push_back(program.string());
    argvStrings.insert(argvStrings.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& s : argvStrings) argv.push_back(s.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    const int spawnError = ::posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(log);
    if (devNull >= 0) ::close(devNull);
    if (spawnError != 0) throw InputError(program.string() + ": cannot start (" + std::strerror(spawnError) + ")");
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) throw RuntimeError(program.string() + ": waitpid failed (" + std::strerror(errno) + ")");
    }
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    return 255;
}

namespace {
// The most telling line of a failed run's log: the script's own error line, else Blender's "Error:", else the
// last non-empty line.
std::string lastErrorLine(const std::filesystem::path& logPath) {
    std::ifstream in(logPath);
    std::string line, script, blenderError, last;
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        last = line;
        if (line.rfind("skinlab-cycles: error: ", 0) == 0) script = line.substr(23);
        else if (line.find("Error") != std::string::npos) blenderError = line;
    }
    std::string chosen = !script.empty() ? script : !blenderError.empty() ? blenderError : last;
    if (chosen.size() > 200) chosen = chosen.substr(0, 200) + "...";
    return chosen;
}
} // namespace

void runBlender(const std::string& program, const std::filesystem::path& script, const std::vector<std::string>& args,
                const std::filesystem::path& workingDirectory, const std::filesystem::path& logPath,
                std::string_view key) {
    const std::filesystem::path found = findProgram(program);
    if (found.empty())
        throw InputError(std::string(key) + ": program '" + program +
                         "' not found (install the Debian package blender, or set " + std::string(key) +
                         " to its path)");
    std::vector<std::string> all = {"-b", "--factory-startup", "-noaudio",      "--python-exit-code",
                                    "1",  "--python",          script.string(), "--"};
    all.insert(all.end(), args.begin(), args.end());
    const int status = runProcess(found, all, workingDirectory, logPath);
    if (status != 0)
        throw InputError(found.string() + " failed (exit status " + std::to_string(status) +
                         "): " + lastErrorLine(logPath) + " (log: " + logPath.string() + ")");
}

} // namespace skinlab::renderer::pathtraced
