#include "experiments/study_export.h"

#include "common/error.h"

#include <cstdio>

namespace skinlab::experiments {

std::string csvField(const std::string& value) {
    // Quoted also when it starts or ends with a blank, which readers trim from unquoted fields.
    const bool blankEdge = !value.empty() && (value.front() == ' ' || value.front() == '\t' || value.back() == ' ' ||
                                              value.back() == '\t');
    if (!blankEdge && value.find_first_of(",\"\r\n") == std::string::npos) return value;
    std::string out = "\"";
    for (char c : value) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + "\"";
}

namespace {

std::string formatMs(double ms) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.1f", ms);
    return buffer;
}

} // namespace

std::string exportResponses(StudyStore& store, const std::string& format) {
    if (format != "csv" && format != "json" && format != "pwcmp")
        throw InputError("--format: \"" + format + "\" is not one of csv, json, pwcmp");
    const std::vector<ResponseRow> rows = store.responses();
    if (format == "json") {
        nlohmann::json out;
        out["format"] = "skinlab-responses";
        out["version"] = 1;
        out["study"] = {{"title", store.definition().design.title},
                        {"question", store.definition().design.question},
                        {"design_sha256", store.meta("design_sha256")},
                        {"manifest_sha256", store.meta("manifest_sha256")},
                        {"stimulus_set", store.meta("stimulus_set")},
                        {"skinlab_version", store.meta("skinlab_version")}};
        out["participants"] = nlohmann::json::array();
        for (const ParticipantStatus& p : store.status())
            out["participants"].push_back({{"observer", p.participant.label}, {"seed", p.participant.seed},
                                           {"participant_index", p.participant.index},
                                           {"created_at", p.participant.createdAt},
                                           {"answered", p.progress.answered}, {"total", p.progress.total}});
        out["responses"] = nlohmann::json::array();
        for (const ResponseRow& r : rows)
            out["responses"].push_back({{"observer", r.observer}, {"scene", r.scene}, {"condition_A", r.conditionA},
                                        {"condition_B", r.conditionB}, {"is_A_selected", r.aSelected ? 1 : 0},
                                        {"A_on_left", r.aOnLeft ? 1 : 0}, {"trial_kind", trialKindName(r.kind)},
                                        {"correct", r.correct ? nlohmann::json(*r.correct ? 1 : 0) : nlohmann::json()},
                                        {"response_ms", r.responseMs}, {"stimulus_A", r.stimulusA},
                                        {"stimulus_B", r.stimulusB}, {"trial_id", r.trialId}, {"position", r.position},
                                        {"session_id", r.sessionId}, {"client_time", r.clientTime},
                                        {"server_time", r.serverTime}, {"viewport_width", r.viewportWidth},
                                        {"viewport_height", r.viewportHeight},
                                        {"device_pixel_ratio", r.devicePixelRatio}, {"user_agent", r.userAgent}});
        // Stored text is well-formed UTF-8 (validUtf8), but a study file written by an older version may hold raw
        // header bytes: those are replaced (U+FFFD) rather than failing the whole export.
        return out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    }
    const bool pwcmp = format == "pwcmp";
    std::string out = pwcmp ? "observer,scene,condition_A,condition_B,is_A_selected\n"
                            : "observer,scene,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,correct,response_ms\n";
    for (const ResponseRow& r : rows) {
        if (pwcmp && r.kind != TrialKind::test && r.kind != TrialKind::repeat) continue;
        out += csvField(r.observer) + ',' + csvField(r.scene) + ',' + csvField(r.conditionA) + ',' + csvField(r.conditionB) +
               ',' + (r.aSelected ? "1" : "0");
        if (!pwcmp) {
            out += std::string(",") + (r.aOnLeft ? "1" : "0") + ',' + trialKindName(r.kind) + ',' +
                   (r.correct ? (*r.correct ? "1" : "0") : "") + ',' + formatMs(r.responseMs);
        }
        out += '\n';
    }
    return out;
}

nlohmann::json statusJson(StudyStore& store) {
    nlohmann::json out;
    out["title"] = store.definition().design.title;
    out["participants"] = nlohmann::json::array();
    int completed = 0;
    long responses = 0;
    for (const ParticipantStatus& p : store.status()) {
        completed += p.progress.completed() ? 1 : 0;
        responses += p.progress.answered;
        out["participants"].push_back(
            {{"observer", p.participant.label}, {"answered", p.progress.answered}, {"total", p.progress.total},
             {"completed", p.progress.completed()}, {"test_answered", p.testAnswered},
             {"catch_answered", p.catchAnswered}, {"catch_correct", p.catchCorrect},
             {"catch_accuracy", p.catchAnswered ? nlohmann::json(double(p.catchCorrect) / p.catchAnswered) : nlohmann::json()},
             {"created_at", p.participant.createdAt}, {"last_response_at", p.lastResponseAt},
             {"completion_code", p.progress.completed() ? p.participant.completionCode : std::string()}});
    }
    out["completed"] = completed;
    out["responses"] = responses;
    return out;
}

std::string statusText(StudyStore& store) {
    const nlohmann::json status = statusJson(store);
    std::string out = "study: " + status["title"].get<std::string>() + "\n";
    char line[256];
    std::snprintf(line, sizeof line, "%-16s %9s %9s %7s  %-10s %s\n", "observer", "answered", "total", "catch", "code",
                  "last response");
    out += line;
    for (const auto& p : status["participants"]) {
        std::string catchText = "-";
        if (p["catch_answered"].get<int>() > 0)
            catchText = std::to_string(p["catch_correct"].get<int>()) + "/" + std::to_string(p["catch_answered"].get<int>());
        std::snprintf(line, sizeof line, "%-16s %9d %9d %7s  %-10s %s\n", p["observer"].get<std::string>().c_str(),
                      p["answered"].get<int>(), p["total"].get<int>(), catchText.c_str(),
                      p["completion_code"].get<std::string>().c_str(), p["last_response_at"].get<std::string>().c_str());
        out += line;
    }
    std::snprintf(line, sizeof line, "%zu participants, %d completed, %ld responses\n", status["participants"].size(),
                  status["completed"].get<int>(), status["responses"].get<long>());
    return out + line;
}

} // namespace skinlab::experiments
