#pragma once
// Exports of a study's responses and its status report.
//  csv:   contract 3, one row per response: observer,scene,condition_A,condition_B,is_A_selected,A_on_left,
//         trial_kind,correct,response_ms (correct is 1/0 for catch trials, empty otherwise), then the online
//         columns: flagged,page_hidden,focus_lost,fullscreen,device_pixel_ratio,dpr_changed,viewport_width,
//         viewport_height,screen_width,screen_height,screen_width_px,screen_height_px,colour_depth,pixels_per_mm,
//         viewing_distance_mm,pixels_per_degree,platform,external_id,external_study_id[,external_session_id]
//         (empty = not recorded)
//  pwcmp: the first five columns, test and repeat trials only (Perez-Ortiz & Mantiuk's pwcmp long format), then
//         the same online columns
//  json:  every stored field of every response, with the study's metadata, the participants' platform ids and
//         every session's viewing conditions
// The platform's per-attempt session id (Prolific SESSION_ID, MTurk assignmentId) resumes an unfinished
// participation (StudyStore::join): it is left out (column and key) unless ExportOptions::includeSessionIds.
//
// An export is streamed: ResponseExport reads through a connection of its own inside one read transaction (WAL: a
// snapshot of every answer committed before it began, none after; the participants' writes never wait for it, and
// it takes no lock of the store's) and produces the text piece by piece, so its memory does not grow with the
// study. Figures: docs/benchmarks.md ("Study server under browser-like load").
#include "experiments/study_store.h"

#include <cstddef>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

namespace skinlab::experiments {

class SqliteDatabase;
class SqliteStatement;

struct ExportOptions {
    bool includeSessionIds = false; // the platform's session id (a resume credential): only when asked for
};

class ResponseExport {
public:
    // Pieces are cut at row boundaries once they hold at least this many bytes.
    static constexpr std::size_t kPieceBytes = 64 * 1024;

    // format: "csv" | "json" | "pwcmp"; anything else throws InputError. The snapshot is taken here.
    ResponseExport(StudyStore& store, const std::string& format, ExportOptions options = {});
    ~ResponseExport();
    ResponseExport(const ResponseExport&) = delete;
    ResponseExport& operator=(const ResponseExport&) = delete;

    // The next piece of the text (about kPieceBytes, whole rows); "" once the export is complete, which also ends
    // the read transaction.
    std::string next();

private:
    enum class Part { header, participants, sessions, responses, done };
    void openPart(Part part);
    void endPart(std::string& out); // closes the part whose rows are all written and opens the next
    void writeRow(std::string& out);
    int plannedTotal() const;

    std::string format_;
    ExportOptions options_;
    StudyDefinition definition_;
    nlohmann::json study_; // the study's metadata (json), read in the snapshot
    std::unique_ptr<SqliteDatabase> db_;
    std::unique_ptr<SqliteStatement> rows_;
    Part part_ = Part::header;
    bool firstRow_ = true;
};

// The whole export as one string (small studies and tests; a server or a file streams ResponseExport instead).
std::string exportResponses(StudyStore& store, const std::string& format, ExportOptions options = {});

nlohmann::json statusJson(StudyStore& store);
// Human-readable table: one line per participant (progress, catch accuracy), then totals.
std::string statusText(StudyStore& store);

// csvField() (common/csv.h) of text that came from a client or a platform: a leading = + - @ (a spreadsheet formula) is kept as text
// by an apostrophe before it.
std::string csvTextField(const std::string& value);

} // namespace skinlab::experiments
