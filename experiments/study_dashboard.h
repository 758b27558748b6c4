#pragma once
// The researcher's live dashboard (GET /researcher, data from GET /api/researcher/dashboard): participants and
// their progress, catch-trial accuracy, the response-time distribution, and the current JOD scale with its
// intervals from the analysis library (analysis/scaling, as `skinlab analyze scale study.db`).
//
// The counts are read on each call through a connection of the dashboard's own (WAL: readers never wait for the
// participants' writes, and take no lock the participant requests need). The scale is the costly part: it is
// recomputed at most once per `interval`, only when responses were added, by one caller at a time while the
// others get the previous one; the figures: docs/benchmarks.md ("Study dashboard").
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

namespace skinlab::experiments {

class StudyStore;
class SqliteDatabase;

struct DashboardScaleOptions {
    int bootstrapSamples = 500; // studentized bootstrap over observers
    int threads = 1;            // leaves the other cores to the participants' requests
};

class StudyDashboard {
public:
    StudyDashboard(StudyStore& store, std::chrono::milliseconds interval, DashboardScaleOptions scale = {});
    ~StudyDashboard();

    // The whole dashboard as JSON (schema: docs/experiments.md, "Researcher dashboard").
    nlohmann::json snapshot();

private:
    nlohmann::json counts();             // participants, progress, catch trials, response times (fresh)
    nlohmann::json viewingConditions();  // per session: screen, zoom, full screen, pixels per degree (fresh)
    nlohmann::json flaggedTrials();      // trials shown while the page was hidden or unfocused (fresh)
    nlohmann::json refusedPlatformIds(); // participants whose platform id others tried to join with (fresh)
    nlohmann::json scale(std::int64_t responseCount); // cached (see above)
    nlohmann::json computeScale() const;

    StudyStore& store_;
    std::chrono::milliseconds interval_;
    DashboardScaleOptions scaleOptions_;
    std::mutex readMutex_; // the dashboard's connection
    std::unique_ptr<SqliteDatabase> db_;
    std::mutex scaleMutex_;
    nlohmann::json scale_;             // null until first computed
    std::int64_t scaleResponses_ = -1; // response count it was computed from
    std::chrono::steady_clock::time_point scaleComputed_;
    bool computing_ = false;
};

} // namespace skinlab::experiments
