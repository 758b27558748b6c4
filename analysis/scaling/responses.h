#pragma once
// Reading 2AFC responses for scaling. Accepted inputs (detected from the file's first bytes / header line):
//  - a study database (SQLite): the VIEW `responses_long` (contract 3);
//  - a CSV export of that view (`skinlab study export --format csv`): columns observer, scene, condition_A,
//    condition_B, is_A_selected, A_on_left, trial_kind, correct, response_ms (any order, all required), optionally
//    followed by the online columns of the export (flagged, external_id, ...; only `flagged` is read);
//  - a pwcmp long-format CSV: observer, condition_A, condition_B, is_A_selected and usually scene (pwcmp's own
//    files, e.g. its examples/ex3_tmo_cmp_data.csv, add columns such as session_id and criterion: any other column
//    is ignored and listed in ResponseTable::ignoredColumns); ReadOptions::columns maps other column names;
//  - a JSON export (`skinlab study export --format json`, key "responses");
//  - a count matrix CSV: header `condition,<name 1>,...,<name m>`, then one row per condition
//    `<name i>,D_i1,...,D_im` with D_ij = times i was chosen over j (one block, no observers).
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::analysis::scaling {

// A trial's kind (contract 3's trial_kind). The one enum of the project: experiments' trial plans use it too
// (experiments/trial_plan.h), so the study's rows reach the scaling without a conversion.
enum class TrialKind { test, repeat, catchTrial, practice };
const char* trialKindName(TrialKind kind); // "test", "repeat", "catch", "practice" (contract 3)

struct Response {
    std::string observer;
    std::string block; // contract 3's column `scene` (the block name, e.g. "builtin:head/mid")
    std::string conditionA;
    std::string conditionB;
    bool aSelected = false;
    std::optional<bool> aOnLeft; // unknown in pwcmp files
    TrialKind kind = TrialKind::test;
    std::optional<bool> correct; // catch trials only
    std::optional<double> responseMs;
    std::optional<bool> flagged; // page hidden or focus lost while shown (online studies); unknown when absent
    int line = 0;                // 1-based line (CSV) or row (SQLite) it came from, for error messages
};

enum class ResponseFormat { StudyDatabase, SkinlabCsv, PwcmpCsv, CountMatrix, SkinlabJson };
const char* responseFormatName(ResponseFormat format);

// An observer left out of the scale by the protocol's exclusion rule (screening.h, excludeObservers).
struct ExcludedObserver {
    std::string observer;
    std::string reason;
};

struct ResponseTable {
    std::string file; // as given, used as the prefix of every error message
    ResponseFormat format = ResponseFormat::SkinlabCsv;
    std::vector<Response> responses;
    // Count-matrix files only: the block's conditions (header order) and the counts D (row-major, m × m).
    std::vector<std::string> matrixConditions;
    std::vector<double> matrixCounts;
    // Study databases only: the pairs were chosen from earlier answers (a study with pairs = "active").
    bool adaptiveDesign = false;
    // Study databases only: each block's conditions in the design's order (the order every output lists them in).
    std::map<std::string, std::vector<std::string>> designConditionOrder;
    // Long CSVs: header columns that were not read (pwcmp's session_id, criterion, ...), for a note to the user.
    std::vector<std::string> ignoredColumns;
    // Observers whose responses excludeObservers removed, with the reason.
    std::vector<ExcludedObserver> excludedObservers;
};

struct ReadOptions {
    // Long CSVs: role → column name in the file, for the roles observer, scene, condition_A, condition_B and
    // is_A_selected (pwcmp's pw_scale_table takes the same column names as arguments; its default selection column
    // is `selected_A`). Unmapped roles keep their own names.
    std::vector<std::pair<std::string, std::string>> columns;
};

// The roles ReadOptions::columns may map.
const std::vector<std::string>& mappableColumns();

// Reads any accepted format; throws InputError "FILE: line N: column C: message" on bad input.
ResponseTable readResponses(const std::filesystem::path& path, const ReadOptions& options = {});

// Removes the responses flagged as given while the page was hidden or without focus (`analyze scale
// --drop-flagged`). Returns how many were removed; `recorded` tells whether any response carried a flag at all.
struct DroppedFlagged {
    size_t dropped = 0;
    bool recorded = false;
};
DroppedFlagged dropFlagged(ResponseTable& table);

} // namespace skinlab::analysis::scaling
