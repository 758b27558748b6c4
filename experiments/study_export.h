#pragma once
// Exports of a study's responses and its status report.
//  csv:   contract 3, one row per response: observer,scene,condition_A,condition_B,is_A_selected,A_on_left,
//         trial_kind,correct,response_ms (correct is 1/0 for catch trials, empty otherwise), then the online
//         columns: flagged,page_hidden,focus_lost,fullscreen,device_pixel_ratio,dpr_changed,viewport_width,
//         viewport_height,screen_width,screen_height,screen_width_px,screen_height_px,colour_depth,pixels_per_mm,
//         viewing_distance_mm,pixels_per_degree,platform,external_id,external_study_id,external_session_id
//         (empty = not recorded)
//  pwcmp: the first five columns, test and repeat trials only (Perez-Ortiz & Mantiuk's pwcmp long format), then
//         the same online columns
//  json:  every stored field of every response, with the study's metadata, the participants' platform ids and
//         every session's viewing conditions
#include "experiments/study_store.h"

#include <nlohmann/json.hpp>
#include <string>

namespace skinlab::experiments {

// format: "csv" | "json" | "pwcmp"; anything else throws InputError.
std::string exportResponses(StudyStore& store, const std::string& format);

nlohmann::json statusJson(StudyStore& store);
// Human-readable table: one line per participant (progress, catch accuracy), then totals.
std::string statusText(StudyStore& store);

// CSV field quoting (RFC 4180): quoted when it holds a comma, quote or line break.
std::string csvField(const std::string& value);
// csvField() of text that came from a client or a platform: a leading = + - @ (a spreadsheet formula) is kept as text
// by an apostrophe before it.
std::string csvTextField(const std::string& value);

} // namespace skinlab::experiments
