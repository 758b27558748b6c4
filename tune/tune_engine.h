#pragma once
// The engine behind `skinlab tune`: one render thread that owns the Renderer (its GL context, the resident scene
// and lighting targets) and renders the latest request of each page, and background jobs for the slow methods
// (`reference`, `pathtraced`), each a `skinlab render` child process that can be cancelled. docs/tuning.md.
#include "renderer/renderer.h"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace skinlab::tune {

// One configuration: a scene and its `--set` overrides, applied in order (exactly as `skinlab render`).
struct TuneConfig {
    std::string scene;
    std::vector<std::string> overrides;
};

struct TuneFrame {
    renderer::DisplayFrame frame;
    double queuedMs = 0.0; // from the request's arrival to the start of its render
    double renderMs = 0.0; // renderDisplay, including read-back and sRGB encoding
};

// Renders on one thread; each client (a page) has at most one request waiting: a newer one replaces it, and the
// replaced request is answered "superseded" (latest wins). "Newer" is the client's own sequence number when it
// sends one (requests on several kept-alive connections may arrive out of order), else arrival order. Clients are
// served in turn.
class RenderQueue {
public:
    explicit RenderQueue(std::filesystem::path assetsDir);
    ~RenderQueue();
    RenderQueue(const RenderQueue&) = delete;
    RenderQueue& operator=(const RenderQueue&) = delete;

    // Blocks until the request is rendered; nullopt when a newer request of the same client replaced it first, or
    // at once when `sequence` is below one this client already sent. Throws what the render throws (InputError
    // for bad values, RuntimeError for GL failures).
    std::optional<TuneFrame> render(const std::string& client, const TuneConfig& config, bool withLinear,
                                    std::optional<std::uint64_t> sequence = std::nullopt);
    // GL_RENDERER of the render thread's context ("" until it started, or when EGL failed).
    std::string glRenderer() const;
    std::uint64_t rendered() const;

private:
    struct Pending {
        TuneConfig config;
        bool withLinear = false;
        std::chrono::steady_clock::time_point arrived;
        std::promise<std::optional<TuneFrame>> answer;
    };
    void loop();

    std::filesystem::path assetsDir_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::map<std::string, std::unique_ptr<Pending>> pending_; // by client
    std::deque<std::string> order_;                           // clients with a pending request, in arrival order
    std::map<std::string, std::uint64_t> newest_;             // by client: the highest sequence number received
    bool stopping_ = false;
    std::string glRenderer_;
    std::uint64_t rendered_ = 0;
    std::thread thread_;
};

// A background render of a slow method: `skinlab render` as a child process in its own process group (so that
// cancelling it ends Blender too), writing EXR, PNG and timings into the job folder.
struct JobStatus {
    std::string id;
    std::string state; // "running", "done", "failed", "cancelled"
    std::string method;
    double elapsedSeconds = 0.0;
    std::optional<double> expectedSeconds; // the last finished job of the same method and size
    std::string error;                     // failed: the child's last line of output
    std::filesystem::path exr, png;
};

// Thrown by JobRunner::start while a render of the same method runs: at most one runs per method.
class JobBusy : public std::runtime_error {
public:
    JobBusy(const std::string& method, std::string running)
        : std::runtime_error("a " + method + " render is already running (" + running + "): wait for it or cancel it"),
          running_(std::move(running)) {}
    const std::string& running() const { return running_; }

private:
    std::string running_;
};

class JobRunner {
public:
    // `executable`: the skinlab binary; `folder`: where jobs write (created).
    JobRunner(std::filesystem::path executable, std::filesystem::path folder, std::filesystem::path assetsDir);
    ~JobRunner(); // cancels what runs
    JobRunner(const JobRunner&) = delete;
    JobRunner& operator=(const JobRunner&) = delete;

    // Starts a render of `config` unless one of the same configuration runs or is done (then returns its id).
    // Throws JobBusy while another render of `method` runs (a cancelled one counts until its process has ended).
    std::string start(const TuneConfig& config, const std::string& method, int width, int height);
    std::optional<JobStatus> status(const std::string& id) const;
    // Ends the job's process group (SIGTERM, then SIGKILL after kKillGrace); false when no such job or it no
    // longer runs. Its elapsed time stops at the cancel.
    bool cancel(const std::string& id);

    static constexpr std::chrono::milliseconds kKillGrace{1000};

private:
    struct Job;
    void reap();
    bool collectEnded();

    std::filesystem::path executable_, folder_, assetsDir_;
    mutable std::mutex mutex_;
    std::map<std::string, std::shared_ptr<Job>> jobs_;
    std::map<std::string, double> lastSeconds_; // by method and size
    std::uint64_t next_ = 1;
    bool stopping_ = false;
    std::condition_variable wake_;
    std::thread reaper_;
};

// The folder a scene's relative paths are relative to and a stable key of a configuration.
std::string configKey(const TuneConfig& config);

} // namespace skinlab::tune
