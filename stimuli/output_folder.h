#pragma once
// The folder of a stimulus set: exr/ID.exr, png/ID.png, manifest.json, manifest.csv, contact.html, contact.png.
// A folder may only be (re)used for the same set (and the same shard); anything else is refused before any
// rendering, so a build never mixes two sets or overwrites someone's files.
#include "stimuli/manifest.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::stimuli {

// Checks that `dir` is absent, empty, or holds `set` (with the same shard, if any). Returns the manifest it
// holds. Throws InputError ("DIR: holds stimulus set 'x' ...") otherwise.
std::optional<Manifest> claimOutputFolder(const std::filesystem::path& dir, const std::string& set,
                                          const std::optional<Shard>& shard);

// Removes temporary files left by an interrupted build (".NAME.tmp-PID-N.ext") and image files of stimuli that
// are no longer part of the selection (`keepIds`).
void tidyOutputFolder(const std::filesystem::path& dir, const std::vector<std::string>& keepIds);

// An exclusive lock on a set folder for the length of a build (flock(2) on DIR/.skinlab-build.lock, which works on
// local file systems and NFSv4). A second build of the same folder — a requeued cluster task whose earlier run is
// still alive on an unreachable node, or two shells — is refused instead of interleaving its writes:
// "DIR: another skinlab build is writing this folder (pid P on HOST); wait for it or stop it, then rebuild".
class OutputFolderLock {
public:
    explicit OutputFolderLock(const std::filesystem::path& dir);
    ~OutputFolderLock();
    OutputFolderLock(const OutputFolderLock&) = delete;
    OutputFolderLock& operator=(const OutputFolderLock&) = delete;

private:
    int fd_ = -1;
};
inline constexpr const char* kBuildLockFile = ".skinlab-build.lock";

// "exr/ID.exr" and "png/ID.png": paths relative to the set folder.
std::string exrRelativePath(const std::string& id);
std::string pngRelativePath(const std::string& id);

} // namespace skinlab::stimuli
