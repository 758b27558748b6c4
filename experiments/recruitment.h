#pragma once
// Recruitment platforms: the URL parameters each platform appends to the study link, their validation, and the
// end of a participation (completion redirect or code). Reference: docs/study-protocol.md ("Running online").
#include "experiments/study_design.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::experiments {

// The URL parameters a platform sends, in the order id, study, session (the last two may be empty names).
struct PlatformParameters {
    std::string id;      // the participant's id on the platform (required)
    std::string study;   // Prolific STUDY_ID, MTurk hitId
    std::string session; // Prolific SESSION_ID, MTurk assignmentId
};

// Empty `id` for platform "none".
PlatformParameters platformParameters(const RecruitmentDesign& recruitment);

// MTurk shows the HIT in preview with this assignmentId: instructions only, no participation.
inline constexpr const char* kMturkPreviewAssignment = "ASSIGNMENT_ID_NOT_AVAILABLE";

// A participant's ids as sent by the platform, validated and normalised (normalisedExternalId()).
struct ExternalIds {
    std::string platform;
    std::string id;
    std::string study;
    std::string session;
};

// The one spelling of a platform id: Prolific lower case; MTurk upper case; SONA and generic without surrounding
// blanks and trailing dots, lower case. Ids are compared and stored in this form.
std::string normalisedExternalId(const std::string& platform, const std::string& value);

// Validates (after normalising) the parameters the page forwarded (name -> value) against the design's platform.
// Throws InvalidValue naming the parameter for a missing or malformed value (the server answers 400) and
// NotAdmitted for MTurk's preview assignment (403; experiments/study_errors.h). nullopt for platform "none".
std::optional<ExternalIds> validateExternalIds(const RecruitmentDesign& recruitment,
                                               const std::map<std::string, std::string>& parameters);

// The redirect at the end ("{code}" replaced by `code`), empty when the design has none.
std::string completionUrl(const RecruitmentDesign& recruitment, const std::string& code);

} // namespace skinlab::experiments
