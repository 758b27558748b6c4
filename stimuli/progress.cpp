#include "stimuli/progress.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <spdlog/spdlog.h>
#include <unistd.h>

namespace skinlab::stimuli {

Progress::Progress(size_t total, bool terminal)
    : total_(total), terminal_(terminal), start_(std::chrono::steady_clock::now()) {
    if (terminal_ && total_ > 0) {
        std::fprintf(stderr, "\r\033[K[%s] 0/%zu", std::string(30, '.').c_str(), total_);
        std::fflush(stderr);
    }
}

Progress::~Progress() { close(); }

bool Progress::stderrIsTerminal() {
    const char* term = std::getenv("TERM");
    return ::isatty(STDERR_FILENO) == 1 && !(term && std::strcmp(term, "dumb") == 0);
}

std::string Progress::formatDuration(double seconds) {
    long total = std::lround(std::max(0.0, seconds));
    long h = total / 3600, m = (total / 60) % 60, s = total % 60;
    char buffer[32];
    if (h > 0) std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", h, m, s);
    else std::snprintf(buffer, sizeof buffer, "%ld:%02ld", m, s);
    return buffer;
}

void Progress::finished(const std::string& id, double seconds) {
    std::lock_guard lock(mutex_);
    ++done_;
    double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    // ETA from the mean wall time per finished stimulus so far (covers parallel jobs too).
    double eta = elapsed / static_cast<double>(done_) * static_cast<double>(total_ - done_);
    if (terminal_) {
        constexpr int width = 30;
        int filled = static_cast<int>(width * done_ / std::max<size_t>(total_, 1));
        std::string bar = std::string(filled, '#') + std::string(width - filled, '.');
        std::fprintf(stderr, "\r\033[K[%s] %zu/%zu  elapsed %s  ETA %s  %s", bar.c_str(), done_, total_,
                     formatDuration(elapsed).c_str(), formatDuration(eta).c_str(), id.c_str());
        std::fflush(stderr);
    } else {
        spdlog::info("stimuli: [{}/{}] {} rendered in {:.2f} s; elapsed {}, ETA {}", done_, total_, id, seconds,
                     formatDuration(elapsed), formatDuration(eta));
    }
}

void Progress::close() {
    std::lock_guard lock(mutex_);
    if (terminal_ && !closed_ && total_ > 0) {
        std::fprintf(stderr, "\n");
        std::fflush(stderr);
    }
    closed_ = true;
}

} // namespace skinlab::stimuli
