#include "experiments/study_export.h"

#include "common/error.h"

#include <cstdio>
#include <string_view>

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

std::string csvTextField(const std::string& value) {
    // A spreadsheet reads a cell starting with = + - @ (or a tab or carriage return before one) as a formula
    // ("-2-3", "=HYPERLINK(...)"): such text from a client or a platform is kept as text by a leading apostrophe
    // (OWASP, "CSV Injection"). Numbers never pass through here.
    if (!value.empty() && std::string_view("=+-@\t\r").find(value.front()) != std::string_view::npos)
        return csvField("'" + value);
    return csvField(value);
}

namespace {

std::string formatMs(double ms) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.1f", ms);
    return buffer;
}

std::string formatNumber(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.6g", value);
    return buffer;
}

// The columns after contract 3's (csv) or pwcmp's five: the online viewing conditions and platform ids of each
// response. An empty field is "not recorded".
constexpr const char* kOnlineColumns =
    "flagged,page_hidden,focus_lost,fullscreen,device_pixel_ratio,dpr_changed,viewport_width,viewport_height,"
    "screen_width,screen_height,screen_width_px,screen_height_px,colour_depth,pixels_per_mm,viewing_distance_mm,"
    "pixels_per_degree,platform,external_id,external_study_id,external_session_id";

std::string flag(bool value) { return value ? "1" : "0"; }

std::string onlineFields(const ResponseRow& r) {
    std::string out;
    auto add = [&](const std::string& field) { out += ',' + field; };
    if (r.conditions) {
        add(flag(r.conditions->flagged()));
        add(flag(r.conditions->pageHidden));
        add(flag(r.conditions->focusLost));
        add(flag(r.conditions->fullscreen));
    } else {
        for (int k = 0; k < 4; ++k) add("");
    }
    add(formatNumber(r.devicePixelRatio));
    add(flag(r.devicePixelRatio != r.sessionDevicePixelRatio));
    add(std::to_string(r.viewportWidth));
    add(std::to_string(r.viewportHeight));
    if (r.viewing) {
        const ViewingConditions& v = *r.viewing;
        add(std::to_string(v.screenWidth));
        add(std::to_string(v.screenHeight));
        add(std::to_string(v.screenWidthPx));
        add(std::to_string(v.screenHeightPx));
        add(std::to_string(v.colourDepth));
        add(v.pixelsPerMm ? formatNumber(*v.pixelsPerMm) : "");
        add(v.viewingDistanceMm ? formatNumber(*v.viewingDistanceMm) : "");
        add(v.pixelsPerDegree ? formatNumber(*v.pixelsPerDegree) : "");
    } else {
        for (int k = 0; k < 8; ++k) add("");
    }
    if (r.external) {
        add(csvTextField(r.external->platform));
        add(csvTextField(r.external->id));
        add(csvTextField(r.external->study));
        add(csvTextField(r.external->session));
    } else {
        for (int k = 0; k < 4; ++k) add("");
    }
    return out;
}

nlohmann::json optionalNumber(const std::optional<double>& value) {
    return value ? nlohmann::json(*value) : nlohmann::json();
}

nlohmann::json viewingJson(const std::optional<ViewingConditions>& viewing) {
    if (!viewing) return nullptr;
    const ViewingConditions& v = *viewing;
    return {{"screen_width", v.screenWidth},
            {"screen_height", v.screenHeight},
            {"screen_width_px", v.screenWidthPx},
            {"screen_height_px", v.screenHeightPx},
            {"colour_depth", v.colourDepth},
            {"fullscreen", v.fullscreen},
            {"pointer_fine", v.pointerFine},
            {"touch_points", v.touchPoints},
            {"mobile", v.mobile},
            {"pixels_per_mm", optionalNumber(v.pixelsPerMm)},
            {"viewing_distance_mm", optionalNumber(v.viewingDistanceMm)},
            {"pixels_per_degree", optionalNumber(v.pixelsPerDegree)}};
}

nlohmann::json externalJson(const std::optional<ExternalIds>& external) {
    if (!external) return nullptr;
    return {{"platform", external->platform},
            {"external_id", external->id},
            {"external_study_id", external->study},
            {"external_session_id", external->session}};
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
        out["study"] = {
            {"title", store.definition().design.title},     {"question", store.definition().design.question},
            {"design_sha256", store.meta("design_sha256")}, {"manifest_sha256", store.meta("manifest_sha256")},
            {"stimulus_set", store.meta("stimulus_set")},   {"skinlab_version", store.meta("skinlab_version")}};
        out["participants"] = nlohmann::json::array();
        for (const ParticipantStatus& p : store.status())
            out["participants"].push_back({{"observer", p.participant.label},
                                           {"seed", p.participant.seed},
                                           {"participant_index", p.participant.index},
                                           {"created_at", p.participant.createdAt},
                                           {"answered", p.progress.answered},
                                           {"total", p.progress.total},
                                           {"recruitment", externalJson(p.external)}});
        out["sessions"] = nlohmann::json::array();
        for (const SessionViewing& v : store.viewingConditions())
            out["sessions"].push_back({{"observer", v.observer},
                                       {"session_id", v.sessionId},
                                       {"started_at", v.startedAt},
                                       {"user_agent", v.userAgent},
                                       {"viewport_width", v.viewportWidth},
                                       {"viewport_height", v.viewportHeight},
                                       {"device_pixel_ratio", v.devicePixelRatio},
                                       {"viewing", viewingJson(v.viewing)}});
        out["responses"] = nlohmann::json::array();
        for (const ResponseRow& r : rows) {
            nlohmann::json row = {{"observer", r.observer},
                                  {"scene", r.scene},
                                  {"condition_A", r.conditionA},
                                  {"condition_B", r.conditionB},
                                  {"is_A_selected", r.aSelected ? 1 : 0},
                                  {"A_on_left", r.aOnLeft ? 1 : 0},
                                  {"trial_kind", trialKindName(r.kind)},
                                  {"correct", r.correct ? nlohmann::json(*r.correct ? 1 : 0) : nlohmann::json()},
                                  {"response_ms", r.responseMs},
                                  {"stimulus_A", r.stimulusA},
                                  {"stimulus_B", r.stimulusB},
                                  {"trial_id", r.trialId},
                                  {"position", r.position},
                                  {"session_id", r.sessionId},
                                  {"client_time", r.clientTime},
                                  {"server_time", r.serverTime},
                                  {"viewport_width", r.viewportWidth},
                                  {"viewport_height", r.viewportHeight},
                                  {"device_pixel_ratio", r.devicePixelRatio},
                                  {"user_agent", r.userAgent}};
            row["flagged"] = r.conditions ? nlohmann::json(r.flagged() ? 1 : 0) : nlohmann::json();
            row["page_hidden"] = r.conditions ? nlohmann::json(r.conditions->pageHidden) : nlohmann::json();
            row["focus_lost"] = r.conditions ? nlohmann::json(r.conditions->focusLost) : nlohmann::json();
            row["fullscreen"] = r.conditions ? nlohmann::json(r.conditions->fullscreen) : nlohmann::json();
            row["dpr_changed"] = r.devicePixelRatio != r.sessionDevicePixelRatio;
            row["viewing"] = viewingJson(r.viewing);
            row["recruitment"] = externalJson(r.external);
            out["responses"].push_back(std::move(row));
        }
        // Stored text is well-formed UTF-8 (validUtf8), but a study file written by an older version may hold raw
        // header bytes: those are replaced (U+FFFD) rather than failing the whole export.
        return out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    }
    const bool pwcmp = format == "pwcmp";
    std::string out = std::string(pwcmp ? "observer,scene,condition_A,condition_B,is_A_selected"
                                        : "observer,scene,condition_A,condition_B,is_A_selected,A_on_left,trial_kind,"
                                          "correct,response_ms") +
                      "," + kOnlineColumns + "\n";
    for (const ResponseRow& r : rows) {
        if (pwcmp && r.kind != TrialKind::test && r.kind != TrialKind::repeat) continue;
        out += csvTextField(r.observer) + ',' + csvField(r.scene) + ',' + csvField(r.conditionA) + ',' +
               csvField(r.conditionB) + ',' + (r.aSelected ? "1" : "0");
        if (!pwcmp) {
            out += std::string(",") + (r.aOnLeft ? "1" : "0") + ',' + trialKindName(r.kind) + ',' +
                   (r.correct ? (*r.correct ? "1" : "0") : "") + ',' + formatMs(r.responseMs);
        }
        out += onlineFields(r) + '\n';
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
            {{"observer", p.participant.label},
             {"answered", p.progress.answered},
             {"total", p.progress.total},
             {"completed", p.progress.completed()},
             {"test_answered", p.testAnswered},
             {"catch_answered", p.catchAnswered},
             {"catch_correct", p.catchCorrect},
             {"catch_accuracy",
              p.catchAnswered ? nlohmann::json(double(p.catchCorrect) / p.catchAnswered) : nlohmann::json()},
             {"created_at", p.participant.createdAt},
             {"last_response_at", p.lastResponseAt},
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
            catchText =
                std::to_string(p["catch_correct"].get<int>()) + "/" + std::to_string(p["catch_answered"].get<int>());
        std::snprintf(line, sizeof line, "%-16s %9d %9d %7s  %-10s %s\n", p["observer"].get<std::string>().c_str(),
                      p["answered"].get<int>(), p["total"].get<int>(), catchText.c_str(),
                      p["completion_code"].get<std::string>().c_str(),
                      p["last_response_at"].get<std::string>().c_str());
        out += line;
    }
    std::snprintf(line, sizeof line, "%zu participants, %d completed, %ld responses\n", status["participants"].size(),
                  status["completed"].get<int>(), status["responses"].get<long>());
    return out + line;
}

} // namespace skinlab::experiments
