#include "experiments/study_dashboard.h"

#include "common/time.h"
#include "analysis/scaling/responses.h"
#include "analysis/scaling/scale_analysis.h"
#include "analysis/scaling/screening.h"
#include "common/error.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_rows.h"
#include "experiments/study_store.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <spdlog/spdlog.h>
#include <vector>

namespace skinlab::experiments {

using nlohmann::json;
namespace scaling = skinlab::analysis::scaling;

namespace {

// Response-time histogram edges (ms): finer where 2AFC answers mostly fall, the last bin open-ended.
constexpr double kEdges[] = {0, 250, 500, 750, 1000, 1250, 1500, 2000, 2500, 3000, 4000, 5000, 7500, 10000, 15000};

double percentile(const std::vector<double>& sorted, double p) {
    if (sorted.empty()) return std::numeric_limits<double>::quiet_NaN();
    const double position = p / 100.0 * static_cast<double>(sorted.size() - 1);
    const auto low = static_cast<std::size_t>(std::floor(position));
    const std::size_t high = std::min(low + 1, sorted.size() - 1);
    return sorted[low] + (sorted[high] - sorted[low]) * (position - static_cast<double>(low));
}

json number(double value) { return std::isfinite(value) ? json(value) : json(); }

} // namespace

StudyDashboard::StudyDashboard(StudyStore& store, std::chrono::milliseconds interval, DashboardScaleOptions scale)
    : store_(store), interval_(interval), scaleOptions_(scale) {
    db_ = std::make_unique<SqliteDatabase>(store_.path().string(), false);
    db_->execute("PRAGMA query_only=ON");
}

StudyDashboard::~StudyDashboard() = default;

json StudyDashboard::snapshot() {
    json out = counts();
    out["scale"] = scale(out["totals"]["responses"].get<std::int64_t>());
    out["viewing_conditions"] = viewingConditions();
    out["flagged_trials"] = flaggedTrials();
    out["refused_platform_ids"] = refusedPlatformIds();
    return out;
}

json StudyDashboard::viewingConditions() {
    // One row per session (page load); "recorded" is false until a page reported its screen.
    json sessions = json::array();
    bool recorded = false;
    for (const SessionViewing& v : store_.viewingConditions()) {
        json row = {{"observer", v.observer},
                    {"session", v.sessionId},
                    {"started_at", v.startedAt},
                    {"viewport", {v.viewportWidth, v.viewportHeight}},
                    {"device_pixel_ratio", v.devicePixelRatio}};
        if (v.viewing) {
            recorded = true;
            const ViewingConditions& c = *v.viewing;
            row["screen_css"] = {c.screenWidth, c.screenHeight};
            row["screen_px"] = {c.screenWidthPx, c.screenHeightPx};
            row["colour_depth"] = c.colourDepth;
            row["fullscreen"] = c.fullscreen;
            row["mobile"] = c.mobile;
            row["pixels_per_degree"] = c.pixelsPerDegree ? json(*c.pixelsPerDegree) : json();
        }
        sessions.push_back(std::move(row));
    }
    return {{"recorded", recorded}, {"note", recorded ? "" : "not recorded"}, {"sessions", std::move(sessions)}};
}

json StudyDashboard::flaggedTrials() {
    // Trials during which the page was hidden or lost the focus ("recorded" once any answer carried the flags).
    json trials = json::array();
    for (const ResponseRow& r : store_.flaggedTrials())
        trials.push_back({{"observer", r.observer},
                          {"position", r.position},
                          {"block", r.scene},
                          {"page_hidden", r.conditions && r.conditions->pageHidden},
                          {"focus_lost", r.conditions && r.conditions->focusLost}});
    bool recorded = !trials.empty();
    if (!recorded) {
        std::lock_guard lock(readMutex_);
        SqliteStatement s = db_->prepare("SELECT EXISTS (SELECT 1 FROM trial_conditions)");
        recorded = s.step() && s.integer(0) != 0;
    }
    const std::size_t count = trials.size();
    return {{"recorded", recorded},
            {"note", recorded ? "" : "not recorded"},
            {"count", count},
            {"trials", std::move(trials)}};
}

json StudyDashboard::refusedPlatformIds() {
    // A platform id joined with again without the participant's join key or platform session id: the participant in
    // another browser or from another link, or someone else who knows the id — possibly the one who joined first
    // with another person's id (squatting). Remedy: docs/deployment.md ("Refused platform ids").
    std::lock_guard lock(readMutex_);
    SqliteStatement s = db_->prepare(
        "SELECT p.label, rec.platform, rec.external_id, COUNT(*), COUNT(DISTINCT v.client_address), MIN(v.recorded_at),"
        " MAX(v.recorded_at) FROM participant_visits v JOIN participants p ON p.id = v.participant_id"
        " JOIN recruitment rec ON rec.participant_id = p.id WHERE v.outcome = 'refused' GROUP BY p.id ORDER BY p.id");
    json rows = json::array();
    while (s.step())
        rows.push_back({{"observer", s.text(0)},
                        {"platform", s.text(1)},
                        {"external_id", s.text(2)},
                        {"attempts", s.integer(3)},
                        {"attempts_capped", s.integer(3) >= kMaxVisitsPerParticipant},
                        {"addresses", s.integer(4)},
                        {"first_attempt_at", s.text(5)},
                        {"last_attempt_at", s.text(6)}});
    return rows;
}

json StudyDashboard::counts() {
    const StudyDefinition& definition = store_.definition();
    const StudyDesign& design = definition.design;
    const int planned = design.practiceTrials + definition.testTrialCount() + definition.repeatTrialCount() +
                        definition.catchTrialCount();
    json out;
    out["study"] = {{"title", design.title},
                    {"blocks", definition.blocks.size()},
                    {"stimuli", definition.stimuli.size()},
                    {"generated_at", utcTimestamp()}};
    std::lock_guard lock(readMutex_);
    SqliteTransaction readTransaction(*db_, false); // one consistent view of every table
    json participants = json::array();
    int completed = 0, catchAnswered = 0, catchCorrect = 0;
    std::int64_t responses = 0;
    {
        SqliteStatement s = db_->prepare(
            "SELECT p.label, p.created_at, COALESCE(a.client_address, ''), COALESCE(a.source, ''),"
            " (SELECT COUNT(*) FROM trials t WHERE t.participant_id = p.id),"
            " (SELECT COUNT(*) FROM responses r WHERE r.participant_id = p.id),"
            " (SELECT COUNT(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE r.participant_id = p.id AND "
            "t.kind = 'catch'),"
            " (SELECT COUNT(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE r.participant_id = p.id AND " +
            std::string(kCorrectSql) +
            " = 1),"
            " (SELECT COALESCE(MAX(server_time), '') FROM responses r WHERE r.participant_id = p.id),"
            " (SELECT COUNT(*) FROM participant_visits v WHERE v.participant_id = p.id AND v.outcome = 'resumed'),"
            " (SELECT COUNT(*) FROM participant_visits v WHERE v.participant_id = p.id AND v.outcome = 'refused')"
            " FROM participants p LEFT JOIN participant_addresses a ON a.participant_id = p.id ORDER BY p.id");
        while (s.step()) {
            const int total = design.activePairs ? planned : static_cast<int>(s.integer(4));
            const int answered = static_cast<int>(s.integer(5));
            const int catchN = static_cast<int>(s.integer(6)), catchOk = static_cast<int>(s.integer(7));
            completed += answered >= total ? 1 : 0;
            catchAnswered += catchN;
            catchCorrect += catchOk;
            responses += answered;
            participants.push_back({{"observer", s.text(0)},
                                    {"joined_at", s.text(1)},
                                    {"client_address", s.text(2)},
                                    {"address_source", s.text(3)},
                                    {"answered", answered},
                                    {"total", total},
                                    {"completed", answered >= total},
                                    {"catch_answered", catchN},
                                    {"catch_correct", catchOk},
                                    {"last_response_at", s.text(8)},
                                    {"resumes", s.integer(9)},
                                    {"refused_attempts", s.integer(10)}});
        }
    }
    std::vector<double> times;
    {
        SqliteStatement s = db_->prepare("SELECT r.response_ms FROM responses r JOIN trials t ON t.id = r.trial_id"
                                         " WHERE t.kind <> 'practice' ORDER BY r.response_ms");
        while (s.step()) times.push_back(s.real(0));
    }
    out["participants"] = std::move(participants);
    out["totals"] = {
        {"participants", out["participants"].size()},
        {"completed", completed},
        {"responses", responses},
        {"catch_answered", catchAnswered},
        {"catch_correct", catchCorrect},
        {"catch_accuracy", catchAnswered > 0 ? json(static_cast<double>(catchCorrect) / catchAnswered) : json()}};
    json bins = json::array();
    const std::size_t edges = std::size(kEdges);
    for (std::size_t i = 0; i < edges; ++i) {
        const double from = kEdges[i];
        const double to = i + 1 < edges ? kEdges[i + 1] : std::numeric_limits<double>::infinity();
        const auto first = std::lower_bound(times.begin(), times.end(), from);
        const auto last = std::lower_bound(times.begin(), times.end(), to);
        bins.push_back({{"from_ms", from}, {"to_ms", number(to)}, {"count", last - first}});
    }
    out["response_times"] = {{"count", times.size()},
                             {"excludes", "practice trials"},
                             {"bins", std::move(bins)},
                             {"p10_ms", number(percentile(times, 10))},
                             {"median_ms", number(percentile(times, 50))},
                             {"p90_ms", number(percentile(times, 90))}};
    return out;
}

json StudyDashboard::scale(std::int64_t responseCount) {
    std::unique_lock lock(scaleMutex_);
    const auto now = std::chrono::steady_clock::now();
    const bool fresh = !scale_.is_null() && (responseCount == scaleResponses_ || now - scaleComputed_ < interval_);
    if (fresh || computing_) {
        if (scale_.is_null()) return {{"state", "computing"}};
        return scale_;
    }
    computing_ = true;
    lock.unlock();
    json computed;
    try {
        computed = computeScale();
    } catch (const std::exception& e) {
        computed = {{"state", "error"}, {"message", e.what()}};
    }
    lock.lock();
    computing_ = false;
    scale_ = std::move(computed);
    scaleResponses_ = responseCount;
    scaleComputed_ = std::chrono::steady_clock::now();
    return scale_;
}

json StudyDashboard::computeScale() const {
    const auto start = std::chrono::steady_clock::now();
    json out{{"computed_at", utcTimestamp()}, {"bootstrap_samples", scaleOptions_.bootstrapSamples}};
    scaling::ResponseTable table;
    scaling::Dataset dataset;
    try {
        // The same reading as `skinlab analyze scale study.db` (VIEW responses_long, its own read-only connection).
        table = scaling::readResponses(store_.path());
        scaling::excludeObservers(table); // the protocol's rule, as `analyze scale` and `report` apply it
        dataset = scaling::buildDataset(table, {});
    } catch (const InputError& e) {
        // No test answers yet: nothing to scale, which is not an error.
        out["state"] = "none";
        out["message"] = e.what();
        return out;
    }
    scaling::AnalysisOptions options;
    options.intervals = scaling::defaultIntervals(table.adaptiveDesign); // as `analyze scale` chooses
    options.intervalReason = table.adaptiveDesign ? "active design" : "fixed design";
    options.bootstrap.samples = scaleOptions_.bootstrapSamples;
    options.bootstrap.threads = scaleOptions_.threads;
    options.bootstrap.seed = 1;
    const scaling::Analysis analysis = scaling::analyzeDataset(dataset, options);
    json blocks = json::array();
    for (const scaling::BlockAnalysis& block : analysis.blocks) {
        json conditions = json::array();
        for (std::size_t i = 0; i < block.conditions.size(); ++i) {
            const auto k = static_cast<Eigen::Index>(i);
            const bool fallback = i < block.intervalFlags.size() && block.intervalFlags[i].fallback;
            // A condition never compared has no score: null values, "measured": false (shown as "not measured").
            const bool measured = i >= block.measured.size() || block.measured[i];
            conditions.push_back({{"condition", block.conditions[i]},
                                  {"measured", measured},
                                  {"jod", measured ? number(block.thurstone.scores[k]) : json()},
                                  {"low", measured ? number(block.low[k]) : json()},
                                  {"high", measured ? number(block.high[k]) : json()},
                                  {"interval_fallback", fallback}});
        }
        blocks.push_back({{"block", block.name},
                          {"observers", block.observers.size()},
                          {"interval_method", block.intervalMethod},
                          {"conditions", std::move(conditions)},
                          {"warnings", block.warnings}});
    }
    out["state"] = "ok";
    out["level"] = options.bootstrap.level;
    out["responses"] = table.responses.size();
    out["blocks"] = std::move(blocks);
    out["warnings"] = analysis.warnings;
    out["compute_ms"] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return out;
}

} // namespace skinlab::experiments
