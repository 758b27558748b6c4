#include "common/files.h"

#include "common/error.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace skinlab {
namespace fs = std::filesystem;

namespace {
std::atomic<unsigned> tempCounter{0};

fs::path makeTempSibling(const fs::path& finalPath) {
    fs::path dir = finalPath.parent_path();
    std::string name = "." + finalPath.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                       std::to_string(tempCounter.fetch_add(1));
    // Keep the extension last so libraries that pick a format by extension (OpenImageIO, OpenCV) still work.
    name += finalPath.extension().string();
    return dir.empty() ? fs::path(name) : dir / name;
}

void fsyncPath(const fs::path& path) {
    int fd = ::open(path.c_str(), O_RDONLY);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
}
} // namespace

void ensureDirectory(const fs::path& dir) {
    if (dir.empty()) return;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) throwInput(dir.string(), "", "cannot create folder (" + ec.message() + ")");
}

AtomicOutput::AtomicOutput(fs::path finalPath) : final_(std::move(finalPath)), temp_(makeTempSibling(final_)) {
    ensureDirectory(final_.parent_path());
}

AtomicOutput::~AtomicOutput() {
    if (!committed_) {
        std::error_code ec;
        fs::remove(temp_, ec);
    }
}

void AtomicOutput::commit() {
    if (!fs::exists(temp_)) throw RuntimeError(final_.string() + ": nothing was written to " + temp_.string());
    fsyncPath(temp_);
    std::error_code ec;
    fs::rename(temp_, final_, ec);
    if (ec) throwInput(final_.string(), "", "cannot write output (" + ec.message() + ")");
    committed_ = true;
    fsyncPath(final_.parent_path().empty() ? fs::path(".") : final_.parent_path());
}

void writeFileAtomic(const fs::path& path, std::string_view data) {
    AtomicOutput out(path);
    {
        std::ofstream f(out.tempPath(), std::ios::binary | std::ios::trunc);
        if (!f) throwInput(path.string(), "", std::string("cannot write output (") + std::strerror(errno) + ")");
        f.write(data.data(), static_cast<std::streamsize>(data.size()));
        f.flush();
        if (!f) throwInput(path.string(), "", "write failed");
    }
    out.commit();
}

std::string readFile(const fs::path& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throwInput(path.string(), "", std::string("cannot read file (") + std::strerror(errno) + ")");
    std::ostringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

} // namespace skinlab
