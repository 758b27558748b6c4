#include "common/process.h"

#include "common/error.h"

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace skinlab {

namespace {

// argv for posix_spawn: the program, then the arguments, then a null pointer; `storage` owns the strings.
std::vector<char*> argvOf(const std::filesystem::path& program, const std::vector<std::string>& args,
                          std::vector<std::string>& storage) {
    storage.clear();
    storage.push_back(program.string());
    storage.insert(storage.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& s : storage) argv.push_back(s.data());
    argv.push_back(nullptr);
    return argv;
}

// posix_spawn's file actions and attributes, destroyed with the object.
struct SpawnSetup {
    posix_spawn_file_actions_t actions;
    posix_spawnattr_t attributes;
    // Every child starts with no signal blocked and the default action for every signal: a server blocks SIGINT
    // and SIGTERM in its threads (one thread waits for them), and a child inheriting that would outlive a cancel.
    SpawnSetup() {
        posix_spawn_file_actions_init(&actions);
        posix_spawnattr_init(&attributes);
        sigset_t none, all;
        sigemptyset(&none);
        sigfillset(&all);
        posix_spawnattr_setsigmask(&attributes, &none);
        posix_spawnattr_setsigdefault(&attributes, &all);
        posix_spawnattr_setflags(&attributes, kSignalFlags);
    }
    static constexpr short kSignalFlags = POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF;
    ~SpawnSetup() {
        posix_spawn_file_actions_destroy(&actions);
        posix_spawnattr_destroy(&attributes);
    }
    SpawnSetup(const SpawnSetup&) = delete;
    SpawnSetup& operator=(const SpawnSetup&) = delete;
};

} // namespace

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

pid_t spawnProcess(const std::filesystem::path& program, const std::vector<std::string>& args,
                   const SpawnOptions& options) {
    SpawnSetup setup;
    posix_spawn_file_actions_addopen(&setup.actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    int output = -1;
    if (options.output.empty()) {
        posix_spawn_file_actions_addopen(&setup.actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    } else {
        // Opened here, so that an unwritable file is the caller's error, not a child that dies silently.
        output = ::open(options.output.c_str(),
                        O_WRONLY | O_CREAT | O_CLOEXEC | (options.appendOutput ? O_APPEND : O_TRUNC), 0644);
        if (output < 0)
            throw RuntimeError(options.output.string() + ": cannot write the output of " + program.string() + " (" +
                               std::strerror(errno) + ")");
        posix_spawn_file_actions_adddup2(&setup.actions, output, STDOUT_FILENO);
    }
    posix_spawn_file_actions_adddup2(&setup.actions, STDOUT_FILENO, STDERR_FILENO);
    // posix_spawn_file_actions_addchdir_np and _addclosefrom_np are glibc ≥ 2.29 / 2.34 (Debian 12 has 2.36).
    if (!options.workingDirectory.empty())
        posix_spawn_file_actions_addchdir_np(&setup.actions, options.workingDirectory.c_str());
    if (options.closeInheritedFiles) posix_spawn_file_actions_addclosefrom_np(&setup.actions, 3);
    if (options.ownProcessGroup) {
        posix_spawnattr_setflags(&setup.attributes, SpawnSetup::kSignalFlags | POSIX_SPAWN_SETPGROUP);
        posix_spawnattr_setpgroup(&setup.attributes, 0);
    }
    std::vector<std::string> storage;
    std::vector<char*> argv = argvOf(program, args, storage);
    pid_t pid = -1;
    const int error = ::posix_spawn(&pid, program.c_str(), &setup.actions, &setup.attributes, argv.data(), environ);
    if (output >= 0) ::close(output);
    if (error != 0) throw RuntimeError(program.string() + ": cannot start (" + std::strerror(error) + ")");
    return pid;
}

int waitProcess(pid_t pid) {
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) throw RuntimeError("waitpid " + std::to_string(pid) + ": " + std::strerror(errno));
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    return 255;
}

CapturedRun runCaptured(const std::filesystem::path& program, const std::vector<std::string>& args) {
    int outPipe[2], errPipe[2];
    if (::pipe2(outPipe, O_CLOEXEC) != 0) throw RuntimeError(std::string("pipe: ") + std::strerror(errno));
    if (::pipe2(errPipe, O_CLOEXEC) != 0) {
        ::close(outPipe[0]);
        ::close(outPipe[1]);
        throw RuntimeError(std::string("pipe: ") + std::strerror(errno));
    }
    SpawnSetup setup;
    posix_spawn_file_actions_addopen(&setup.actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&setup.actions, outPipe[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&setup.actions, errPipe[1], STDERR_FILENO);
    std::vector<std::string> storage;
    std::vector<char*> argv = argvOf(program, args, storage);
    pid_t pid = 0;
    const int error = ::posix_spawn(&pid, program.c_str(), &setup.actions, &setup.attributes, argv.data(), environ);
    ::close(outPipe[1]);
    ::close(errPipe[1]);
    if (error != 0) {
        ::close(outPipe[0]);
        ::close(errPipe[0]);
        throw RuntimeError(program.string() + ": cannot run (" + std::strerror(error) + ")");
    }
    CapturedRun run;
    pollfd fds[2] = {{outPipe[0], POLLIN, 0}, {errPipe[0], POLLIN, 0}};
    std::string* sinks[2] = {&run.out, &run.err};
    int open = 2;
    char buffer[4096];
    while (open > 0) {
        if (::poll(fds, 2, -1) < 0) {
            if (errno == EINTR) continue;
            break;
        }
        for (int k = 0; k < 2; ++k) {
            if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
            const ssize_t n = ::read(fds[k].fd, buffer, sizeof buffer);
            if (n > 0) {
                sinks[k]->append(buffer, static_cast<std::size_t>(n));
            } else if (n == 0 || errno != EINTR) {
                ::close(fds[k].fd);
                fds[k].fd = -1;
                --open;
            }
        }
    }
    for (pollfd& fd : fds)
        if (fd.fd >= 0) ::close(fd.fd);
    run.exitCode = waitProcess(pid);
    return run;
}

} // namespace skinlab
