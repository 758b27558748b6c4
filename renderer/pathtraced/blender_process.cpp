#include "renderer/pathtraced/blender_process.h"

#include "common/error.h"

#include <fstream>

namespace skinlab::renderer::pathtraced {

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
    SpawnOptions options;
    options.output = logPath; // appended: a render's several Blender runs share its log
    options.workingDirectory = workingDirectory;
    pid_t pid = -1;
    try {
        pid = spawnProcess(found, all, options);
    } catch (const RuntimeError& e) {
        throw InputError(e.what());
    }
    const int status = waitProcess(pid);
    if (status != 0)
        throw InputError(found.string() + " failed (exit status " + std::to_string(status) +
                         "): " + lastErrorLine(logPath) + " (log: " + logPath.string() + ")");
}

} // namespace skinlab::renderer::pathtraced
