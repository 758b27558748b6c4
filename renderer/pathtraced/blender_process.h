#pragma once
// Blender as a child process (never linked): found on PATH or by path, run headless with its output kept in a
// log file. docs/pathtraced.md, "Running Blender".
#include "common/process.h"

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::renderer::pathtraced {

using skinlab::findProgram; // common/process.h

// Runs `blender -b --factory-startup -noaudio --python SCRIPT -- ARGS...`. Throws InputError naming the program
// (missing: how to install it, and `key`, the spec key that names the program) or, when it fails, its exit status,
// the last error line of its log and the log's path.
void runBlender(const std::string& program, const std::filesystem::path& script, const std::vector<std::string>& args,
                const std::filesystem::path& workingDirectory, const std::filesystem::path& logPath,
                std::string_view key = "pathtraced.blender");

} // namespace skinlab::renderer::pathtraced
