#pragma once
// The JSON of the study server's participant API (docs/experiments.md, "HTTP API"): reading request bodies, each
// malformed field a RequestError 400 naming it, and the projections of the study's records into answers (the study,
// a trial as the participant sees it, the participant's state).
#include "net/http_server.h"
#include "experiments/study_definition.h"
#include "experiments/study_records.h"

#include <cstddef>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::experiments {

// ---- Request bodies ----

// Longest participant token, label or join key a request may carry.
inline constexpr std::size_t kMaxTokenLength = 64;

// The body as a JSON object: 415 unless Content-Type is application/json, 400 for anything but one JSON object.
nlohmann::json parseJsonBody(const net::HttpRequest& request);
// Field readers: 400 naming the field when it is missing (and required), of another type or out of range.
std::string stringField(const nlohmann::json& body, const char* name, std::size_t maxLength, bool required = true);
std::int64_t integerField(const nlohmann::json& body, const char* name, std::int64_t min, std::int64_t max);
double numberField(const nlohmann::json& body, const char* name, double min, double max);
bool booleanField(const nlohmann::json& body, const char* name);
// The optional per-trial conditions of a response: all three fields or none.
std::optional<TrialConditions> trialConditionsField(const nlohmann::json& body);
// The recruitment parameters the page forwarded from its URL: {"NAME": "value", ...} (strings only).
std::map<std::string, std::string> recruitmentField(const nlohmann::json& body);
// The viewing conditions of POST /api/session, reported by the page as a group (an older client sends none of them:
// nullopt). `userAgent`: the request's User-Agent header (a mobile one is recorded as such); `display`: the design's
// calibration settings (a card width gives pixels per mm, and with a viewing distance pixels per degree).
std::optional<ViewingConditions> viewingConditionsField(const nlohmann::json& body, int viewportWidth,
                                                        int viewportHeight, double devicePixelRatio,
                                                        const std::string& userAgent, const DisplayDesign& display);
// The fields of POST /api/response (everything but the User-Agent, which is the request's).
ResponseInput responseInputField(const nlohmann::json& body);

// ---- Answers ----

// GET /api/study: what the page shows and needs before a participant joins.
nlohmann::json studyJson(const StudyDefinition& definition);
// A trial as its participant sees it: its reference (trialReference), the images by number and side; catch trials
// look like any other, only practice is announced.
nlohmann::json trialJson(const StudyDefinition& definition, const TrialRecord& trial, const std::string& token);
// The participant's state: progress (practice counted apart), the next trial (null when done), and the completion
// code (and the platform's completion URL) when done. `trials`: every stored trial of the participant, read before
// `next` was.
nlohmann::json participantStateJson(const StudyDefinition& definition, const ParticipantRecord& participant,
                                    const std::vector<TrialRecord>& trials, const std::optional<TrialRecord>& next,
                                    const Progress& progress);

} // namespace skinlab::experiments
