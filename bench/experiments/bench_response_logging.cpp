// Benchmark: response-logging latency of the study server under concurrent simulated participants on loopback
// (p50/p99 and errors at 50 and 200 participants; target p99 < 50 ms, zero errors, zero lost).
// Each measurement: a fresh study.db (WAL, synchronous=FULL) in a temporary folder, the real HTTP server in this
// process, N simulated observers (one thread and one connection each) answering every trial. Latency is the
// client-side round trip of POST /api/response, which includes validation and the fsynced COMMIT.
//
// With --active M: M conditions and an active design (pairs = "active", 2(M − 1) test trials per participant), so
// the measured round trips include planning a batch from the posterior whenever a participant's batch runs out.
// With --active-batch K as well: the design's active_batch = K (a plan every K test trials of a participant).
// Usage: bench_experiments_response_logging [--observers 50,200] [--think-ms MIN:MAX] [--folder DIR] [--active M]
//                                           [--active-batch K]
// Prints one Markdown table row per run for docs/benchmarks.md.
#include "common/files.h"
#include "bench_stimulus_set.h"
#include "experiments/simulated_observers.h"
#include "experiments/study_creation.h"
#include "experiments/study_server.h"
#include "experiments/study_store.h"

#include <cstdio>
#include <filesystem>
#include <map>
#include <spdlog/spdlog.h>
#include <sstream>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using namespace skinlab::experiments;

namespace {

// Five conditions in one block: 10 pairs × 2 repetitions + 2 catch = 22 responses per participant. The image
// bytes are not decoded by the server, so placeholder bytes (with their real sha256) stand in for PNGs.
int activeConditions = 0; // --active M (0: the fixed five-condition design)
int activeBatch = 0;      // --active-batch K: the design's active_batch (0: whole spanning trees)

void writeSet(const fs::path& folder) {
    skinlab::bench::writeBenchStimulusSet(folder, activeConditions > 0 ? activeConditions : 5, 256, 256,
                                          [](const std::string& id) { return "placeholder image " + id; });
}

struct Run {
    int observers = 0;
    double thinkMin = 0, thinkMax = 0;
    SimulationReport report;
    std::int64_t stored = 0;
    std::size_t lost = 0;
};

Run measure(const fs::path& root, int observers, double thinkMin, double thinkMax, int run) {
    const fs::path folder = root / ("run-" + std::to_string(run));
    fs::remove_all(folder);
    writeSet(folder / "stimuli");
    const std::string pairs =
        activeConditions > 0
            ? "pairs = \"active\"\ntrials_per_participant = " + std::to_string(2 * (activeConditions - 1)) + "\n" +
                  (activeBatch > 0 ? "active_batch = " + std::to_string(activeBatch) + "\n" : std::string())
            : "repetitions = 2\n";
    skinlab::writeFileAtomic(folder / "design.toml",
                             "seed = 1\n" + pairs + "[practice]\ntrials = 0\n[catch]\nblank = 2\n");
    createStudy(folder / "stimuli", folder / "design.toml", {}, folder / "study.db");
    StudyStore store(folder / "study.db");
    ServerOptions options;
    options.port = 0;
    options.threads = 64;
    // Every simulated participant connects from 127.0.0.1: lift the per-address caps meant for real clients.
    options.connectionsPerClient = 4096;
    options.joinBurst = 100000;
    StudyServer server(store, options);
    server.bind();
    std::thread serving([&] { server.run(); });

    SimulationOptions simulation;
    simulation.port = server.port();
    simulation.observers = observers;
    simulation.thinkMinMs = thinkMin;
    simulation.thinkMaxMs = thinkMax;
    simulation.labelPrefix = "bench";
    Run result;
    result.observers = observers;
    result.thinkMin = thinkMin;
    result.thinkMax = thinkMax;
    result.report = simulateObservers(store, simulation);
    server.stop();
    serving.join();
    result.stored = store.responseCount();
    std::map<std::int64_t, bool> stored;
    for (const ResponseRow& r : store.responses()) stored[r.trialId] = r.aSelected == r.aOnLeft;
    for (const ObserverResult& o : result.report.observers)
        for (const auto& [trial, side] : o.acknowledged)
            if (!stored.count(trial) || stored.at(trial) != (side == "left")) ++result.lost;
    return result;
}

} // namespace

int main(int argc, char** argv) {
    std::vector<int> counts{50, 200};
    std::vector<std::pair<double, double>> thinks{{0, 0}, {500, 1500}};
    fs::path root = fs::temp_directory_path() / ("skinlab-bench-experiments-" + std::to_string(::getpid()));
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i], value = argv[i + 1];
        if (key == "--observers") {
            counts.clear();
            std::stringstream ss(value);
            std::string item;
            while (std::getline(ss, item, ',')) counts.push_back(std::stoi(item));
        } else if (key == "--think-ms") {
            const auto colon = value.find(':');
            thinks = {{std::stod(value.substr(0, colon)),
                       std::stod(colon == std::string::npos ? value : value.substr(colon + 1))}};
        } else if (key == "--active") {
            activeConditions = std::stoi(value);
        } else if (key == "--active-batch") {
            activeBatch = std::stoi(value);
        } else if (key == "--folder") {
            root = value;
        } else {
            std::fprintf(stderr, "unknown option %s\n", key.c_str());
            return 2;
        }
    }
    fs::create_directories(root);
    spdlog::set_level(spdlog::level::warn); // no "participant joined" lines in the table
    std::printf("| participants | pause before each answer | responses | p50 ms | p99 ms | max ms | rejected | re-sent "
                "| lost | responses/s |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
    int run = 0;
    for (const auto& [thinkMin, thinkMax] : thinks)
        for (int n : counts) {
            const Run r = measure(root, n, thinkMin, thinkMax, run++);
            double worst = 0;
            for (double ms : r.report.latenciesMs) worst = std::max(worst, ms);
            char pause[64];
            if (thinkMax > 0) std::snprintf(pause, sizeof pause, "%.0f–%.0f ms", thinkMin, thinkMax);
            else std::snprintf(pause, sizeof pause, "none (back to back)");
            std::printf("| %d | %s | %lld | %.2f | %.2f | %.2f | %d | %d | %zu | %.0f |\n", n, pause,
                        static_cast<long long>(r.stored), r.report.latencyPercentile(50),
                        r.report.latencyPercentile(99), worst, r.report.rejected(), r.report.transportRetries(), r.lost,
                        static_cast<double>(r.report.acknowledged()) / r.report.wallSeconds);
            std::fflush(stdout);
            if (r.report.completed() != n)
                std::fprintf(stderr, "only %d of %d observers completed\n", r.report.completed(), n);
        }
    fs::remove_all(root);
    return 0;
}
