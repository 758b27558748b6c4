#include "tune/tune_engine.h"

#include "common/error.h"
#include "common/hash.h"
#include "common/process.h"

#include <algorithm>
#include <csignal>
#include <cstring>
#include <fstream>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

namespace skinlab::tune {

namespace {
double millisecondsBetween(std::chrono::steady_clock::time_point from, std::chrono::steady_clock::time_point to) {
    return std::chrono::duration<double, std::milli>(to - from).count();
}
} // namespace

std::string configKey(const TuneConfig& config) {
    std::string text = config.scene;
    for (const std::string& o : config.overrides) text += "\n" + o;
    return sha256Hex(text).substr(0, 16);
}

// --- RenderQueue ----------------------------------------------------------------------------------------------

RenderQueue::RenderQueue(std::filesystem::path assetsDir)
    : assetsDir_(std::move(assetsDir)), thread_([this] { loop(); }) {}

RenderQueue::~RenderQueue() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

std::string RenderQueue::glRenderer() const {
    std::lock_guard lock(mutex_);
    return glRenderer_;
}

std::uint64_t RenderQueue::rendered() const {
    std::lock_guard lock(mutex_);
    return rendered_;
}

std::optional<TuneFrame> RenderQueue::render(const std::string& client, const TuneConfig& config, bool withLinear,
                                             std::optional<std::uint64_t> sequence) {
    auto pending = std::make_unique<Pending>();
    pending->config = config;
    pending->withLinear = withLinear;
    pending->arrived = std::chrono::steady_clock::now();
    std::future<std::optional<TuneFrame>> answer = pending->answer.get_future();
    {
        std::lock_guard lock(mutex_);
        if (stopping_) throw RuntimeError("tune: the render thread is stopping");
        if (sequence) {
            auto [newest, first] = newest_.try_emplace(client, *sequence);
            if (!first && *sequence < newest->second) return std::nullopt; // a newer one came first
            newest->second = *sequence;
        }
        auto& slot = pending_[client];
        if (slot) slot->answer.set_value(std::nullopt); // replaced before it started: latest wins
        else order_.push_back(client);
        slot = std::move(pending);
    }
    wake_.notify_one();
    return answer.get();
}

void RenderQueue::loop() {
    std::unique_ptr<renderer::Renderer> renderer;
    std::string startError;
    try {
        renderer = std::make_unique<renderer::Renderer>();
        std::lock_guard lock(mutex_);
        glRenderer_ = renderer->glRenderer();
    } catch (const std::exception& e) {
        startError = e.what();
        spdlog::error("tune: no GL context: {}", startError);
    }
    for (;;) {
        std::unique_ptr<Pending> job;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return stopping_ || !order_.empty(); });
            if (order_.empty()) break; // stopping with nothing left
            const std::string client = order_.front();
            order_.pop_front();
            job = std::move(pending_[client]);
            pending_.erase(client);
        }
        const auto started = std::chrono::steady_clock::now();
        try {
            if (!renderer) throw RuntimeError("no GL context: " + startError);
            renderer::RenderRequest request;
            request.scene = job->config.scene;
            request.overrides = job->config.overrides;
            request.assetsDir = assetsDir_;
            TuneFrame frame;
            frame.frame = renderer->renderDisplay(request, job->withLinear);
            const auto finished = std::chrono::steady_clock::now();
            frame.queuedMs = millisecondsBetween(job->arrived, started);
            frame.renderMs = millisecondsBetween(started, finished);
            {
                std::lock_guard lock(mutex_);
                ++rendered_;
            }
            job->answer.set_value(std::move(frame));
        } catch (...) {
            job->answer.set_exception(std::current_exception());
        }
    }
}

// --- JobRunner ------------------------------------------------------------------------------------------------

struct JobRunner::Job {
    JobStatus status;
    std::string key;
    std::string sizeKey;
    pid_t pid = -1; // until reaped
    std::filesystem::path log;
    std::chrono::steady_clock::time_point started;
    std::chrono::steady_clock::time_point finished;
    std::optional<std::chrono::steady_clock::time_point> terminated; // when SIGTERM was sent to its group
    bool killed = false;                                             // SIGKILL sent

    // SIGTERM to the job's process group, once; SIGKILL when it outlives the grace period.
    void end() {
        if (pid <= 0) return;
        const auto now = std::chrono::steady_clock::now();
        if (!terminated) {
            terminated = now;
            kill(-pid, SIGTERM);
        } else if (!killed && now - *terminated >= kKillGrace) {
            killed = true;
            kill(-pid, SIGKILL);
        }
    }
};

JobRunner::JobRunner(std::filesystem::path executable, std::filesystem::path folder, std::filesystem::path assetsDir)
    : executable_(std::move(executable)), folder_(std::move(folder)), assetsDir_(std::move(assetsDir)) {
    std::filesystem::create_directories(folder_);
    reaper_ = std::thread([this] { reap(); });
}

JobRunner::~JobRunner() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
        for (auto& [id, job] : jobs_) job->end();
    }
    wake_.notify_all();
    reaper_.join();
}

std::string JobRunner::start(const TuneConfig& config, const std::string& method, int width, int height) {
    std::lock_guard lock(mutex_);
    if (stopping_) throw RuntimeError("tune: stopping");
    const std::string key = configKey(config);
    for (const auto& [id, job] : jobs_)
        if (job->key == key && (job->status.state == "running" || job->status.state == "done")) return id;
    collectEnded(); // a render that ended since the reaper's last pass (e.g. just cancelled) no longer counts
    // A cancelled render still exiting does not count either: its threads can outlive its main thread (the process
    // shows as a zombie before waitpid can collect it), and the reaper ends it after its grace period.
    for (const auto& [id, job] : jobs_)
        if (job->pid > 0 && job->status.state == "running" && job->status.method == method) throw JobBusy(method, id);

    auto job = std::make_shared<Job>();
    job->status.id = "job" + std::to_string(next_++);
    job->status.state = "running";
    job->status.method = method;
    job->key = key;
    job->sizeKey = method + "|" + std::to_string(width) + "x" + std::to_string(height);
    if (auto found = lastSeconds_.find(job->sizeKey); found != lastSeconds_.end())
        job->status.expectedSeconds = found->second;
    job->status.exr = folder_ / (job->status.id + ".exr");
    job->status.png = folder_ / (job->status.id + ".png");
    job->log = folder_ / (job->status.id + ".log");

    std::vector<std::string> arguments{"render", "--scene", config.scene};
    for (const std::string& o : config.overrides) {
        arguments.push_back("--set");
        arguments.push_back(o);
    }
    if (!assetsDir_.empty()) {
        arguments.push_back("--assets");
        arguments.push_back(assetsDir_.string());
    }
    for (const std::string& a :
         {std::string("-o"), job->status.exr.string(), std::string("--png"), job->status.png.string()})
        arguments.push_back(a);
    SpawnOptions options;
    options.output = job->log;
    options.appendOutput = false;
    options.closeInheritedFiles = true; // not the server's sockets
    options.ownProcessGroup = true;     // cancel ends Blender with it
    pid_t pid = -1;
    try {
        pid = spawnProcess(executable_, arguments, options);
    } catch (const RuntimeError& e) {
        throw RuntimeError(std::string("a background render: ") + e.what());
    }
    job->pid = pid;
    job->started = std::chrono::steady_clock::now();
    jobs_[job->status.id] = job;
    wake_.notify_all();
    return job->status.id;
}

std::optional<JobStatus> JobRunner::status(const std::string& id) const {
    std::lock_guard lock(mutex_);
    const auto found = jobs_.find(id);
    if (found == jobs_.end()) return std::nullopt;
    JobStatus status = found->second->status;
    const auto end = status.state == "running" ? std::chrono::steady_clock::now() : found->second->finished;
    status.elapsedSeconds = millisecondsBetween(found->second->started, end) / 1000.0;
    return status;
}

bool JobRunner::cancel(const std::string& id) {
    std::lock_guard lock(mutex_);
    const auto found = jobs_.find(id);
    if (found == jobs_.end() || found->second->status.state != "running") return false;
    Job& job = *found->second;
    job.end();
    job.status.state = "cancelled";
    job.finished = std::chrono::steady_clock::now();
    wake_.notify_all();
    return true;
}

// One pass over the jobs (mutex_ held): collects every render that has ended, and ends a cancelled one that
// outlived its grace period. Returns whether a render is still running.
bool JobRunner::collectEnded() {
    bool running = false;
    for (auto& [id, job] : jobs_) {
        if (job->pid <= 0) continue;
        int status = 0;
        const pid_t done = waitpid(job->pid, &status, WNOHANG);
        if (done != job->pid) {
            running = true;
            if (job->status.state == "cancelled" || stopping_) job->end(); // SIGKILL after the grace period
            continue;
        }
        job->pid = -1;
        if (job->status.state == "cancelled") continue; // its time stopped at the cancel
        job->finished = std::chrono::steady_clock::now();
        if (stopping_) {
            job->status.state = "cancelled";
        } else if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
            job->status.state = "done";
            lastSeconds_[job->sizeKey] = millisecondsBetween(job->started, job->finished) / 1000.0;
        } else {
            job->status.state = "failed";
            std::ifstream log(job->log);
            std::string line, last;
            while (std::getline(log, line))
                if (!line.empty()) last = line;
            job->status.error = last.empty() ? "the render exited with status " + std::to_string(status) : last;
        }
    }
    return running;
}

void JobRunner::reap() {
    std::unique_lock lock(mutex_);
    for (;;) {
        const bool running = collectEnded();
        if (stopping_ && !running) break;
        wake_.wait_for(lock, std::chrono::milliseconds(50));
    }
}

} // namespace skinlab::tune
