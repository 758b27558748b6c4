#pragma once
// Progress of a batch build: a redrawn bar with ETA on a terminal, plain log lines otherwise (CI logs, files).
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace skinlab::stimuli {

class Progress {
public:
    // `total`: stimuli to render. `terminal`: draw a bar on stderr (else spdlog info lines).
    Progress(size_t total, bool terminal);
    ~Progress();
    // Called by any worker thread when a stimulus has been rendered and recorded.
    void finished(const std::string& id, double seconds);
    // Ends the bar line (terminal mode).
    void close();

    // True when stderr is a terminal (and TERM is not "dumb").
    static bool stderrIsTerminal();
    // "1:05" (m:ss) or "1:02:03".
    static std::string formatDuration(double seconds);

private:
    size_t total_;
    size_t done_ = 0;
    bool terminal_;
    bool closed_ = false;
    std::chrono::steady_clock::time_point start_;
    std::mutex mutex_;
};

} // namespace skinlab::stimuli
