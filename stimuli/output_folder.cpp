#include "stimuli/output_folder.h"

#include "common/error.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <unistd.h>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

namespace {
std::string shardText(const std::optional<Shard>& shard) {
    return shard ? "shard " + std::to_string(shard->index) + "/" + std::to_string(shard->count) : "the whole set";
}
} // namespace

std::string exrRelativePath(const std::string& id) { return "exr/" + id + ".exr"; }
std::string pngRelativePath(const std::string& id) { return "png/" + id + ".png"; }

std::optional<Manifest> claimOutputFolder(const fs::path& dir, const std::string& set,
                                          const std::optional<Shard>& shard) {
    std::error_code ec;
    if (!fs::exists(dir, ec)) return std::nullopt;
    if (!fs::is_directory(dir, ec)) throwInput(dir.string(), "", "exists and is not a folder");
    std::optional<Manifest> existing = readManifest(dir);
    if (!existing) {
        bool empty = true; // a build killed before its first manifest leaves at most its lock file
        for (const auto& entry : fs::directory_iterator(dir, ec))
            if (entry.path().filename() != kBuildLockFile) empty = false;
        if (!empty)
            throwInput(dir.string(), "",
                       "is not empty and holds no stimulus set (no manifest.json); choose a new or empty folder");
        return std::nullopt;
    }
    if (existing->set != set)
        throwInput(dir.string(), "",
                   "holds stimulus set '" + existing->set + "', not '" + set + "'; choose another folder");
    bool sameShard = existing->shard.has_value() == shard.has_value() &&
                     (!shard || (existing->shard->index == shard->index && existing->shard->count == shard->count));
    if (!sameShard)
        throwInput(dir.string(), "",
                   "holds " + shardText(existing->shard) + " of set '" + set + "', not " + shardText(shard) +
                       "; choose another folder");
    return existing;
}

OutputFolderLock::OutputFolderLock(const fs::path& dir) {
    const fs::path file = dir / kBuildLockFile;
    fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
        throwInput(file.string(), "", std::string("cannot create the build lock (") + std::strerror(errno) + ")");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        int error = errno;
        char holder[256] = {};
        ssize_t n = ::pread(fd_, holder, sizeof holder - 1, 0);
        ::close(fd_);
        fd_ = -1;
        if (error != EWOULDBLOCK)
            throwInput(file.string(), "", std::string("cannot lock the folder (") + std::strerror(error) + ")");
        std::string who = n > 0 ? std::string(holder, static_cast<size_t>(n)) : std::string("unknown");
        while (!who.empty() && (who.back() == '\n' || who.back() == ' ')) who.pop_back();
        throwInput(dir.string(), "",
                   "another skinlab build is writing this folder (" + who + "); wait for it or stop it, then rebuild");
    }
    char host[256] = {};
    ::gethostname(host, sizeof host - 1);
    std::string who = "pid " + std::to_string(::getpid()) + " on " + host + "\n";
    if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, who.data(), who.size(), 0) < 0)
        spdlog::debug("stimuli: cannot record the lock holder in {}", file.string());
}

OutputFolderLock::~OutputFolderLock() {
    if (fd_ >= 0) ::close(fd_); // releases the lock; the file stays (removing it would race with the next build)
}

void tidyOutputFolder(const fs::path& dir, const std::vector<std::string>& keepIds) {
    for (const char* sub : {"exr", "png"}) {
        fs::path folder = dir / sub;
        std::error_code ec;
        if (!fs::is_directory(folder, ec)) continue;
        std::vector<fs::path> remove;
        for (const auto& entry : fs::directory_iterator(folder)) {
            std::string name = entry.path().filename().string();
            bool temporary = !name.empty() && name.front() == '.' && name.find(".tmp-") != std::string::npos;
            bool ours = entry.path().extension() == "." + std::string(sub);
            bool kept = std::find(keepIds.begin(), keepIds.end(), entry.path().stem().string()) != keepIds.end();
            if (temporary || (ours && !kept)) remove.push_back(entry.path());
        }
        for (const auto& path : remove) {
            spdlog::debug("stimuli: removing {}", path.string());
            fs::remove(path, ec);
        }
    }
}

} // namespace skinlab::stimuli
