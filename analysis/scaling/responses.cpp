#include "analysis/scaling/responses.h"

#include "common/csv.h"
#include "common/error.h"
#include "common/files.h"
#include "common/sqlite_read.h"

#include <nlohmann/json.hpp>
#include <sqlite3.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <set>

namespace skinlab::analysis::scaling {
namespace {

const std::array<const char*, 9> kSkinlabColumns = {"observer",    "scene",         "condition_A",
                                                    "condition_B", "is_A_selected", "A_on_left",
                                                    "trial_kind",  "correct",       "response_ms"};
const std::array<const char*, 5> kPwcmpColumns = {"observer", "scene", "condition_A", "condition_B", "is_A_selected"};
// Columns `skinlab study export` appends to both CSV formats (online studies); accepted after either set.
const std::array<const char*, 20> kOnlineColumns = {
    "flagged",           "page_hidden",      "focus_lost",      "fullscreen",        "device_pixel_ratio",
    "dpr_changed",       "viewport_width",   "viewport_height", "screen_width",      "screen_height",
    "screen_width_px",   "screen_height_px", "colour_depth",    "pixels_per_mm",     "viewing_distance_mm",
    "pixels_per_degree", "platform",         "external_id",     "external_study_id", "external_session_id"};

std::string where(int line, std::string_view column) {
    std::string out = "line " + std::to_string(line);
    if (!column.empty()) out += ": column " + std::string(column);
    return out;
}

bool parseFlag(const std::string& file, int line, std::string_view column, const std::string& value) {
    if (value == "1" || value == "true" || value == "TRUE") return true;
    if (value == "0" || value == "false" || value == "FALSE") return false;
    throwInput(file, where(line, column), "'" + value + "' is not 0 or 1");
}

std::optional<bool> parseOptionalFlag(const std::string& file, int line, std::string_view column,
                                      const std::string& value) {
    if (value.empty() || value == "NULL") return std::nullopt;
    return parseFlag(file, line, column, value);
}

double parseNumber(const std::string& file, int line, std::string_view column, const std::string& value) {
    double number = 0.0;
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), number);
    if (value.empty() || error != std::errc() || end != value.data() + value.size() || !std::isfinite(number))
        throwInput(file, where(line, column), "'" + value + "' is not a number");
    return number;
}

TrialKind parseKind(const std::string& file, int line, const std::string& value) {
    if (value == "test") return TrialKind::test;
    if (value == "repeat") return TrialKind::repeat;
    if (value == "catch") return TrialKind::catchTrial;
    if (value == "practice") return TrialKind::practice;
    throwInput(file, where(line, "trial_kind"), "'" + value + "' is not one of test, repeat, catch, practice");
}

// Checks the fields every long format shares.
void checkResponse(const std::string& file, const Response& r) {
    if (r.observer.empty()) throwInput(file, where(r.line, "observer"), "empty observer");
    if (r.conditionA.empty()) throwInput(file, where(r.line, "condition_A"), "empty condition");
    if (r.conditionB.empty()) throwInput(file, where(r.line, "condition_B"), "empty condition");
    if (r.conditionA == r.conditionB)
        throwInput(file, where(r.line, "condition_B"),
                   "condition '" + r.conditionA + "' is compared with itself (condition_A = condition_B)");
}

std::string joined(const auto& names) {
    std::string out;
    for (const auto& name : names) out += (out.empty() ? "" : ",") + std::string(name);
    return out;
}

// Column index per role (observer, scene, ... and `flagged`); -1 where the file has no such column.
using ColumnIndex = std::map<std::string, long>;

void readLongCsv(ResponseTable& table, const std::vector<CsvRecord>& records, const ColumnIndex& columns) {
    const std::vector<std::string>& header = records.front().fields;
    auto has = [&](const char* role) { return columns.count(role) && columns.at(role) >= 0; };
    const bool full = table.format == ResponseFormat::SkinlabCsv;
    for (size_t r = 1; r < records.size(); ++r) {
        const CsvRecord& record = records[r];
        if (record.fields.size() != header.size())
            throwInput(table.file, where(record.line, ""),
                       "has " + std::to_string(record.fields.size()) + " columns, the header has " +
                           std::to_string(header.size()));
        auto field = [&](const char* role) -> const std::string& {
            return record.fields[static_cast<size_t>(columns.at(role))];
        };
        auto name = [&](const char* role) -> const std::string& {
            return header[static_cast<size_t>(columns.at(role))];
        };
        Response response;
        response.line = record.line;
        response.observer = field("observer");
        if (has("scene")) response.block = field("scene");
        response.conditionA = field("condition_A");
        response.conditionB = field("condition_B");
        response.aSelected = parseFlag(table.file, record.line, name("is_A_selected"), field("is_A_selected"));
        if (has("flagged")) response.flagged = parseOptionalFlag(table.file, record.line, "flagged", field("flagged"));
        if (full) {
            response.aOnLeft = parseOptionalFlag(table.file, record.line, "A_on_left", field("A_on_left"));
            response.kind = parseKind(table.file, record.line, field("trial_kind"));
            response.correct = parseOptionalFlag(table.file, record.line, "correct", field("correct"));
            if (!field("response_ms").empty() && field("response_ms") != "NULL")
                response.responseMs = parseNumber(table.file, record.line, "response_ms", field("response_ms"));
        }
        checkResponse(table.file, response);
        table.responses.push_back(std::move(response));
    }
}

void readCountMatrix(ResponseTable& table, const std::vector<CsvRecord>& records) {
    const CsvRecord& header = records.front();
    const std::vector<std::string> names(header.fields.begin() + 1, header.fields.end());
    if (names.size() < 2) throwInput(table.file, where(header.line, ""), "a count matrix needs at least 2 conditions");
    std::map<std::string, size_t> index;
    for (size_t k = 0; k < names.size(); ++k) {
        if (names[k].empty()) throwInput(table.file, where(header.line, std::to_string(k + 2)), "empty condition name");
        if (!index.emplace(names[k], k).second)
            throwInput(table.file, where(header.line, names[k]), "condition appears twice in the header");
    }
    const size_t m = names.size();
    table.matrixConditions = names;
    table.matrixCounts.assign(m * m, 0.0);
    std::vector<bool> seen(m, false);
    for (size_t r = 1; r < records.size(); ++r) {
        const CsvRecord& record = records[r];
        if (record.fields.size() != m + 1)
            throwInput(table.file, where(record.line, ""),
                       "has " + std::to_string(record.fields.size()) + " columns, the header has " +
                           std::to_string(m + 1));
        const auto found = index.find(record.fields[0]);
        if (found == index.end())
            throwInput(table.file, where(record.line, "condition"),
                       "unknown condition '" + record.fields[0] + "' (not in the header: " + joined(names) + ")");
        const size_t row = found->second;
        if (seen[row])
            throwInput(table.file, where(record.line, "condition"), "row '" + names[row] + "' appears twice");
        seen[row] = true;
        for (size_t col = 0; col < m; ++col) {
            const double count = parseNumber(table.file, record.line, names[col], record.fields[col + 1]);
            if (count < 0)
                throwInput(table.file, where(record.line, names[col]), "negative count " + record.fields[col + 1]);
            if (row == col && count != 0)
                throwInput(table.file, where(record.line, names[col]),
                           "condition '" + names[row] + "' is compared with itself (diagonal count " +
                               record.fields[col + 1] + ", must be 0)");
            table.matrixCounts[row * m + col] = count;
        }
    }
    for (size_t k = 0; k < m; ++k)
        if (!seen[k]) throwInput(table.file, "condition " + names[k], "has no row in the count matrix");
}

ResponseTable readCsv(const std::filesystem::path& path, const ReadOptions& options) {
    ResponseTable table;
    table.file = path.string();
    const std::string text = readFile(path);
    const std::vector<CsvRecord> records = parseCsv(text, table.file);
    if (records.empty()) throwInput(table.file, "", "empty file (expected a header line and responses)");
    const std::vector<std::string>& header = records.front().fields;
    const int headerLine = records.front().line;
    std::map<std::string, size_t> byName;
    std::string duplicate;
    for (size_t k = 0; k < header.size(); ++k)
        if (!byName.emplace(header[k], k).second && duplicate.empty()) duplicate = header[k];
    // Roles: a mapped column (--columns role=name), else the column named after the role.
    ColumnIndex columns;
    std::set<size_t> used;
    for (const auto& [role, name] : options.columns) {
        const auto found = byName.find(name);
        if (found == byName.end())
            throwInput(table.file, "--columns",
                       "column '" + name + "' (for " + role + ") is not in the header (" + joined(header) + ")");
        columns[role] = static_cast<long>(found->second);
    }
    for (const char* role : kSkinlabColumns)
        if (!columns.count(role)) columns[role] = byName.count(role) ? static_cast<long>(byName.at(role)) : -1;
    columns["flagged"] = byName.count("flagged") ? static_cast<long>(byName.at("flagged")) : -1;
    auto has = [&](const char* role) { return columns.at(role) >= 0; };
    const std::array<const char*, 4> skinlabOnly = {"A_on_left", "trial_kind", "correct", "response_ms"};
    const std::array<const char*, 4> pwcmpRequired = {"observer", "condition_A", "condition_B", "is_A_selected"};
    const auto skinlabPresent = std::count_if(skinlabOnly.begin(), skinlabOnly.end(), has);
    const bool pwcmpComplete = std::all_of(pwcmpRequired.begin(), pwcmpRequired.end(), has);
    std::string first = header.front();
    std::transform(first.begin(), first.end(), first.begin(), [](unsigned char c) { return std::tolower(c); });
    if (pwcmpComplete && has("scene") && skinlabPresent == 4) {
        table.format = ResponseFormat::SkinlabCsv;
    } else if (skinlabPresent >= 2) {
        // Closer to a skinlab export than to pwcmp's format: name the first missing column.
        for (const char* role : kSkinlabColumns)
            if (!has(role))
                throwInput(table.file, where(headerLine, role),
                           "missing column; expected the columns " + joined(kSkinlabColumns));
    } else if (pwcmpComplete) {
        table.format = ResponseFormat::PwcmpCsv;
    } else if (options.columns.empty() && (first.empty() || first == "condition")) {
        table.format = ResponseFormat::CountMatrix;
    } else {
        for (const char* role : pwcmpRequired)
            if (!has(role))
                throwInput(table.file, where(headerLine, role),
                           "missing column; expected the columns " + joined(kPwcmpColumns) +
                               " (scene optional; --columns maps other names), a skinlab export or a count matrix "
                               "header 'condition,<names>'");
    }
    if (records.size() < 2) throwInput(table.file, "", "no responses after the header line");
    if (table.format == ResponseFormat::CountMatrix) {
        readCountMatrix(table, records);
        return table;
    }
    if (!duplicate.empty()) throwInput(table.file, where(headerLine, duplicate), "column appears twice in the header");
    // Every column that is neither read nor one of skinlab's own export columns is listed for a note.
    for (const auto& [role, index] : columns)
        if (index >= 0 && (table.format == ResponseFormat::SkinlabCsv ||
                           std::find(skinlabOnly.begin(), skinlabOnly.end(), role) == skinlabOnly.end()))
            used.insert(static_cast<size_t>(index));
    for (size_t k = 0; k < header.size(); ++k)
        if (!used.count(k) &&
            std::find(kOnlineColumns.begin(), kOnlineColumns.end(), header[k]) == kOnlineColumns.end())
            table.ignoredColumns.push_back(header[k]);
    readLongCsv(table, records, columns);
    return table;
}

// `skinlab study export --format json`: {"format": "skinlab-responses", "responses": [{...contract 3 keys...}]}.
ResponseTable readJson(const std::filesystem::path& path) {
    ResponseTable table;
    table.file = path.string();
    table.format = ResponseFormat::SkinlabJson;
    nlohmann::json root;
    try {
        root = nlohmann::json::parse(readFile(path));
    } catch (const nlohmann::json::exception& e) {
        throwInput(table.file, "", std::string("not valid JSON: ") + e.what());
    }
    if (!root.is_object() || root.value("format", std::string()) != "skinlab-responses" ||
        !root.contains("responses") || !root["responses"].is_array())
        throwInput(table.file, "format", "expected a skinlab-responses JSON export with a \"responses\" array");
    int row = 0;
    for (const nlohmann::json& entry : root["responses"]) {
        ++row;
        const std::string at = "responses[" + std::to_string(row - 1) + "]";
        auto text = [&](const char* key) -> std::string {
            if (!entry.is_object() || !entry.contains(key) || !entry[key].is_string())
                throwInput(table.file, at + "." + key, "expected a string");
            return entry[key].get<std::string>();
        };
        auto flag = [&](const char* key, bool optional) -> std::optional<bool> {
            if (!entry.is_object() || !entry.contains(key) || entry[key].is_null()) {
                if (optional) return std::nullopt;
                throwInput(table.file, at + "." + key, "missing");
            }
            const nlohmann::json& v = entry[key];
            if (v.is_boolean()) return v.get<bool>();
            if (v.is_number_integer() && (v.get<std::int64_t>() == 0 || v.get<std::int64_t>() == 1))
                return v.get<std::int64_t>() == 1;
            throwInput(table.file, at + "." + key, "'" + v.dump() + "' is not 0 or 1");
        };
        Response response;
        response.line = row;
        response.observer = text("observer");
        response.block = text("scene");
        response.conditionA = text("condition_A");
        response.conditionB = text("condition_B");
        response.aSelected = *flag("is_A_selected", false);
        response.aOnLeft = flag("A_on_left", true);
        response.kind = parseKind(table.file, row, text("trial_kind"));
        response.correct = flag("correct", true);
        if (entry.contains("response_ms") && entry["response_ms"].is_number())
            response.responseMs = entry["response_ms"].get<double>();
        response.flagged = flag("flagged", true);
        checkResponse(table.file, response);
        table.responses.push_back(std::move(response));
    }
    if (table.responses.empty()) throwInput(table.file, "responses", "no responses");
    return table;
}

ResponseTable readDatabase(const std::filesystem::path& path) {
    ResponseTable table;
    table.file = path.string();
    table.format = ResponseFormat::StudyDatabase;
    // Read only, also on a read-only mount or folder (common/sqlite_read.h).
    sqlite3* database = openSqliteReadOnly(path).handle;
    struct Closer {
        sqlite3* database;
        sqlite3_stmt* statement = nullptr;
        ~Closer() {
            sqlite3_finalize(statement);
            sqlite3_close(database);
        }
    } closer{database};
    sqlite3_busy_timeout(database, 5000); // the study server may be writing
    // `flagged` (online studies) is in the view of study files written or opened by a newer skinlab.
    bool hasFlagged = false;
    {
        sqlite3_stmt* probe = nullptr;
        if (sqlite3_prepare_v2(database,
                               "SELECT COUNT(*) FROM pragma_table_info('responses_long') WHERE name = 'flagged'", -1,
                               &probe, nullptr) == SQLITE_OK &&
            sqlite3_step(probe) == SQLITE_ROW)
            hasFlagged = sqlite3_column_int(probe, 0) == 1;
        sqlite3_finalize(probe);
    }
    // The design (pairs = "active": pairs chosen from earlier answers), from the stored study definition.
    if (sqlite3_prepare_v2(database, "SELECT json_extract(value, '$.design.pairs') FROM meta WHERE key = 'definition'",
                           -1, &closer.statement, nullptr) == SQLITE_OK &&
        sqlite3_step(closer.statement) == SQLITE_ROW) {
        const unsigned char* pairs = sqlite3_column_text(closer.statement, 0);
        table.adaptiveDesign = pairs != nullptr && std::string(reinterpret_cast<const char*>(pairs)) == "active";
    }
    sqlite3_finalize(closer.statement);
    closer.statement = nullptr;
    // Each block's conditions in design order, so that every output lists them as the design does.
    if (sqlite3_prepare_v2(database, "SELECT json_extract(value, '$.blocks') FROM meta WHERE key = 'definition'", -1,
                           &closer.statement, nullptr) == SQLITE_OK &&
        sqlite3_step(closer.statement) == SQLITE_ROW) {
        const unsigned char* blocks = sqlite3_column_text(closer.statement, 0);
        const nlohmann::json parsed =
            blocks ? nlohmann::json::parse(reinterpret_cast<const char*>(blocks), nullptr, false) : nlohmann::json();
        if (parsed.is_array())
            for (const nlohmann::json& block : parsed)
                if (block.is_object() && block.contains("name") && block.contains("conditions"))
                    table.designConditionOrder[block["name"].get<std::string>()] =
                        block["conditions"].get<std::vector<std::string>>();
    }
    sqlite3_finalize(closer.statement);
    closer.statement = nullptr;
    const std::string query =
        std::string("SELECT observer, scene, condition_A, condition_B, is_A_selected, A_on_left, trial_kind, correct, "
                    "response_ms") +
        (hasFlagged ? ", flagged" : "") + " FROM responses_long";
    if (sqlite3_prepare_v2(database, query.c_str(), -1, &closer.statement, nullptr) != SQLITE_OK)
        throwInput(table.file, "responses_long",
                   std::string("cannot read the responses view: ") + sqlite3_errmsg(database));
    auto text = [&](int column) -> std::string {
        const unsigned char* value = sqlite3_column_text(closer.statement, column);
        return value ? reinterpret_cast<const char*>(value) : std::string();
    };
    int row = 0;
    int status = SQLITE_ROW;
    while ((status = sqlite3_step(closer.statement)) == SQLITE_ROW) {
        ++row;
        Response response;
        response.line = row;
        response.observer = text(0);
        response.block = text(1);
        response.conditionA = text(2);
        response.conditionB = text(3);
        response.aSelected = parseFlag(table.file, row, "is_A_selected", text(4));
        response.aOnLeft = parseOptionalFlag(table.file, row, "A_on_left", text(5));
        response.kind = parseKind(table.file, row, text(6));
        response.correct = parseOptionalFlag(table.file, row, "correct", text(7));
        if (sqlite3_column_type(closer.statement, 8) != SQLITE_NULL)
            response.responseMs = sqlite3_column_double(closer.statement, 8);
        if (hasFlagged && sqlite3_column_type(closer.statement, 9) != SQLITE_NULL)
            response.flagged = sqlite3_column_int(closer.statement, 9) != 0;
        checkResponse(table.file, response);
        table.responses.push_back(std::move(response));
    }
    if (status != SQLITE_DONE)
        throwInput(table.file, "responses_long", std::string("cannot read: ") + sqlite3_errmsg(database));
    if (table.responses.empty()) throwInput(table.file, "responses_long", "no responses in the study database");
    return table;
}

} // namespace

const char* trialKindName(TrialKind kind) {
    switch (kind) {
    case TrialKind::test: return "test";
    case TrialKind::repeat: return "repeat";
    case TrialKind::catchTrial: return "catch";
    case TrialKind::practice: return "practice";
    }
    return "test";
}

const char* responseFormatName(ResponseFormat format) {
    switch (format) {
    case ResponseFormat::StudyDatabase: return "study-database";
    case ResponseFormat::SkinlabCsv: return "skinlab-csv";
    case ResponseFormat::PwcmpCsv: return "pwcmp-csv";
    case ResponseFormat::CountMatrix: return "count-matrix";
    case ResponseFormat::SkinlabJson: return "skinlab-json";
    }
    return "skinlab-csv";
}

DroppedFlagged dropFlagged(ResponseTable& table) {
    DroppedFlagged result;
    for (const Response& r : table.responses) result.recorded = result.recorded || r.flagged.has_value();
    const size_t before = table.responses.size();
    std::erase_if(table.responses, [](const Response& r) { return r.flagged.value_or(false); });
    result.dropped = before - table.responses.size();
    if (table.responses.empty() && before > 0)
        throwInput(table.file, "flagged", "every response is flagged; nothing is left to scale");
    return result;
}

const std::vector<std::string>& mappableColumns() {
    static const std::vector<std::string> roles(kPwcmpColumns.begin(), kPwcmpColumns.end());
    return roles;
}

ResponseTable readResponses(const std::filesystem::path& path, const ReadOptions& options) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throwInput(path.string(), "", "cannot open the responses file");
    // A study database may be live: served by this very process (the researcher dashboard scales through here) or
    // by another. Only SQLite may open it. Any other descriptor of the file, once closed, drops every POSIX lock
    // this process holds on it; another process then believes it holds the last connection and removes the
    // write-ahead log under the server (sqlite.org/howtocorrupt.html, section 2.2). So SQLite itself is asked
    // whether the file is a database, before anything else reads it.
    if (looksLikeSqliteDatabase(path)) return readDatabase(path);
    const std::string text = readFile(path);
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && text[first] == '{') return readJson(path);
    return readCsv(path, options);
}

} // namespace skinlab::analysis::scaling
