#include "renderer/gl/gpu_timer.h"

#include "common/error.h"

#include <cmath>

namespace skinlab::renderer::gl {

double roundMs(double milliseconds) { return std::round(milliseconds * 1000.0) / 1000.0; }

nlohmann::json roundTimings(nlohmann::json timings) {
    if (timings.is_number_float()) return roundMs(timings.get<double>());
    if (timings.is_structured())
        for (auto& value : timings) value = roundTimings(std::move(value));
    return timings;
}

PassTimer::PassTimer() {
    GLuint name = 0;
    glCreateQueries(GL_TIME_ELAPSED, 1, &name);
    query_ = Query(name);
    // Throw-away first query (llvmpipe may return garbage for it).
    glBeginQuery(GL_TIME_ELAPSED, name);
    glEndQuery(GL_TIME_ELAPSED);
    GLuint64 ignored = 0;
    glGetQueryObjectui64v(name, GL_QUERY_RESULT, &ignored);
    checkGl("the first timer query");
}

void PassTimer::reset() {
    if (!current_.empty()) {
        glEndQuery(GL_TIME_ELAPSED);
        glFinish();
        current_.clear();
    }
    records_.clear();
}

void PassTimer::begin(const std::string& pass) {
    if (!current_.empty()) throw RuntimeError("PassTimer::begin(" + pass + "): pass " + current_ + " still open");
    glFinish();
    current_ = pass;
    wallStart_ = std::chrono::steady_clock::now();
    glBeginQuery(GL_TIME_ELAPSED, query_.get());
}

void PassTimer::end() {
    glEndQuery(GL_TIME_ELAPSED);
    glFinish();
    const auto wallEnd = std::chrono::steady_clock::now();
    GLuint64 nanoseconds = 0;
    glGetQueryObjectui64v(query_.get(), GL_QUERY_RESULT, &nanoseconds);
    checkGl("timer query of pass " + current_);
    Record record;
    record.pass = current_;
    record.wallMs = std::chrono::duration<double, std::milli>(wallEnd - wallStart_).count();
    record.gpuMs = static_cast<double>(nanoseconds) * 1e-6;
    // A GPU interval cannot exceed the wall-clock interval that brackets it (plus clock granularity).
    if (record.gpuMs > record.wallMs * 1.05 + 0.05) {
        record.gpuMs = record.wallMs;
        record.replaced = true;
    }
    records_.push_back(record);
    current_.clear();
}

nlohmann::json PassTimer::json() const {
    nlohmann::json passes = nlohmann::json::object();
    nlohmann::json passesWall = nlohmann::json::object();
    nlohmann::json fromWall = nlohmann::json::array();
    double gpuTotal = 0;
    double wallTotal = 0;
    for (const Record& record : records_) {
        passes[record.pass] = roundMs(record.gpuMs);
        passesWall[record.pass] = roundMs(record.wallMs);
        gpuTotal += record.gpuMs;
        wallTotal += record.wallMs;
        if (record.replaced) fromWall.push_back(record.pass);
    }
    nlohmann::json out = {{"passes", passes},
                          {"passes_wall", passesWall},
                          {"gpu_total", roundMs(gpuTotal)},
                          {"wall_total", roundMs(wallTotal)}};
    if (!fromWall.empty()) out["gpu_from_wall"] = fromWall;
    return out;
}

} // namespace skinlab::renderer::gl
