#include "experiments/study_export.h"

#include "common/csv.h"
#include "common/error.h"
#include "experiments/sqlite_database.h"
#include "experiments/study_rows.h"
#include "experiments/study_schema.h"

#include <cstdio>
#include <string_view>

namespace skinlab::experiments {

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
    "pixels_per_degree,platform,external_id,external_study_id";
constexpr const char* kSessionIdColumn = "external_session_id";

std::string flag(bool value) { return value ? "1" : "0"; }

std::string onlineFields(const ResponseRow& r, bool includeSessionIds) {
    std::string out;
    auto add = [&](const std::string& field) { out += ',' + field; };
    if (r.conditions) {
        add(flag(r.flagged.value_or(false)));
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
        if (includeSessionIds) add(csvTextField(r.external->session));
    } else {
        for (int k = includeSessionIds ? 0 : 1; k < 4; ++k) add("");
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

nlohmann::json externalJson(const std::optional<ExternalIds>& external, bool includeSessionIds) {
    if (!external) return nullptr;
    nlohmann::json out = {
        {"platform", external->platform}, {"external_id", external->id}, {"external_study_id", external->study}};
    if (includeSessionIds) out["external_session_id"] = external->session;
    return out;
}

// A value as nlohmann::json::dump(2) writes it at `depth` inside a document: every line after the first indented
// by 2 × depth more. Stored text is well-formed UTF-8 (validUtf8), but a study file written by an older version may
// hold raw header bytes: those are replaced (U+FFFD) rather than failing the whole export.
std::string dumpAt(const nlohmann::json& value, int depth) {
    const std::string text = value.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
    const std::string indent(static_cast<std::size_t>(2 * depth), ' ');
    std::string out;
    out.reserve(text.size() + text.size() / 8);
    for (char c : text) {
        out += c;
        if (c == '\n') out += indent;
    }
    return out;
}

nlohmann::json participantJson(const ParticipantStatus& p, bool includeSessionIds) {
    return {{"observer", p.participant.label},
            {"seed", p.participant.seed},
            {"participant_index", p.participant.index},
            {"created_at", p.participant.createdAt},
            {"answered", p.progress.answered},
            {"total", p.progress.total},
            {"recruitment", externalJson(p.external, includeSessionIds)}};
}

nlohmann::json sessionJson(const SessionViewing& v) {
    return {{"observer", v.observer},
            {"session_id", v.sessionId},
            {"started_at", v.startedAt},
            {"user_agent", v.userAgent},
            {"viewport_width", v.viewportWidth},
            {"viewport_height", v.viewportHeight},
            {"device_pixel_ratio", v.devicePixelRatio},
            {"viewing", viewingJson(v.viewing)}};
}

nlohmann::json responseJson(const ResponseRow& r, bool includeSessionIds) {
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
    row["flagged"] = r.flagged ? nlohmann::json(*r.flagged ? 1 : 0) : nlohmann::json();
    row["page_hidden"] = r.conditions ? nlohmann::json(r.conditions->pageHidden) : nlohmann::json();
    row["focus_lost"] = r.conditions ? nlohmann::json(r.conditions->focusLost) : nlohmann::json();
    row["fullscreen"] = r.conditions ? nlohmann::json(r.conditions->fullscreen) : nlohmann::json();
    row["dpr_changed"] = r.devicePixelRatio != r.sessionDevicePixelRatio;
    row["viewing"] = viewingJson(r.viewing);
    row["recruitment"] = externalJson(r.external, includeSessionIds);
    return row;
}

std::string csvRow(const ResponseRow& r, bool pwcmp, bool includeSessionIds) {
    std::string out = csvTextField(r.observer) + ',' + csvField(r.scene) + ',' + csvField(r.conditionA) + ',' +
                      csvField(r.conditionB) + ',' + (r.aSelected ? "1" : "0");
    if (!pwcmp)
        out += std::string(",") + (r.aOnLeft ? "1" : "0") + ',' + trialKindName(r.kind) + ',' +
               (r.correct ? (*r.correct ? "1" : "0") : "") + ',' + formatMs(r.responseMs);
    return out + onlineFields(r, includeSessionIds) + '\n';
}

} // namespace

ResponseExport::ResponseExport(StudyStore& store, const std::string& format, ExportOptions options)
    : format_(format), options_(options), definition_(store.definition()) {
    if (format != "csv" && format != "json" && format != "pwcmp")
        throw InputError("--format: \"" + format + "\" is not one of csv, json, pwcmp");
    db_ = SqliteDatabase::openReadOnly(store.path().string()); // also on a read-only mount
    db_->execute("PRAGMA query_only=ON");
    // The snapshot: a read transaction, begun by its first read (below) and held until the export is complete.
    db_->execute("BEGIN");
    const std::string path = store.path().string();
    study_ = {{"title", definition_.design.title},
              {"question", definition_.design.question},
              {"design_sha256", studyMeta(*db_, path, "design_sha256")},
              {"manifest_sha256", studyMeta(*db_, path, "manifest_sha256")},
              {"stimulus_set", studyMeta(*db_, path, "stimulus_set")},
              {"skinlab_version", studyMeta(*db_, path, "skinlab_version")}};
}

ResponseExport::~ResponseExport() = default;

void ResponseExport::openPart(Part part) {
    part_ = part;
    firstRow_ = true;
    rows_.reset();
    switch (part) {
    case Part::participants: rows_ = std::make_unique<SqliteStatement>(db_->prepare(participantStatusQuery())); break;
    case Part::responses: rows_ = std::make_unique<SqliteStatement>(db_->prepare(responseRowsQuery())); break;
    case Part::sessions: rows_ = std::make_unique<SqliteStatement>(db_->prepare(sessionViewingsQuery())); break;
    case Part::header:
    case Part::done: break;
    }
}

int ResponseExport::plannedTotal() const {
    const StudyDefinition& d = definition_;
    if (!d.design.activePairs) return 0;
    return d.design.practiceTrials + d.testTrialCount() + d.repeatTrialCount() + d.catchTrialCount();
}

void ResponseExport::writeRow(std::string& out) {
    const bool sessionIds = options_.includeSessionIds;
    if (format_ != "json") {
        const ResponseRow r = readResponseRow(*rows_);
        if (format_ == "pwcmp" && r.kind != TrialKind::test && r.kind != TrialKind::repeat) return;
        out += csvRow(r, format_ == "pwcmp", sessionIds);
        return;
    }
    nlohmann::json row;
    if (part_ == Part::participants) row = participantJson(readParticipantStatus(*rows_, plannedTotal()), sessionIds);
    else if (part_ == Part::sessions) row = sessionJson(readSessionViewing(*rows_));
    else row = responseJson(readResponseRow(*rows_), sessionIds);
    out += firstRow_ ? "[\n    " : ",\n    ";
    out += dumpAt(row, 2);
    firstRow_ = false;
}

// The JSON document is written as nlohmann::json::dump(2) writes it (keys in alphabetical order: format,
// participants, responses, sessions, study, version), one array element at a time.
void ResponseExport::endPart(std::string& out) {
    if (format_ != "json") return openPart(part_ == Part::header ? Part::responses : Part::done);
    if (part_ != Part::header) out += firstRow_ ? "[]" : "\n  ]";
    switch (part_) {
    case Part::header:
        out += "{\n  \"format\": \"skinlab-responses\",\n  \"participants\": ";
        return openPart(Part::participants);
    case Part::participants: out += ",\n  \"responses\": "; return openPart(Part::responses);
    case Part::responses: out += ",\n  \"sessions\": "; return openPart(Part::sessions);
    case Part::sessions:
        out += ",\n  \"study\": " + dumpAt(study_, 1) + ",\n  \"version\": 1\n}\n";
        return openPart(Part::done);
    case Part::done: return;
    }
}

std::string ResponseExport::next() {
    std::string out;
    while (part_ != Part::done && out.size() < kPieceBytes) {
        if (part_ == Part::header && format_ != "json") {
            out += std::string(format_ == "pwcmp" ? "observer,scene,condition_A,condition_B,is_A_selected"
                                                  : "observer,scene,condition_A,condition_B,is_A_selected,A_on_left,"
                                                    "trial_kind,correct,response_ms") +
                   "," + kOnlineColumns + (options_.includeSessionIds ? std::string(",") + kSessionIdColumn : "") +
                   "\n";
        }
        if (rows_ && rows_->step()) writeRow(out);
        else endPart(out);
    }
    if (part_ == Part::done && db_) {
        rows_.reset();
        db_.reset(); // ends the read transaction
    }
    return out;
}

std::string exportResponses(StudyStore& store, const std::string& format, ExportOptions options) {
    ResponseExport exporter(store, format, options);
    std::string out;
    for (std::string piece = exporter.next(); !piece.empty(); piece = exporter.next()) out += piece;
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
