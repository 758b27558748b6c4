#include "experiments/recruitment.h"

#include "experiments/study_errors.h"

#include <cctype>

namespace skinlab::experiments {

namespace {

bool isHex(char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; }
bool isAlnum(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; }

// Each rule states the accepted form in its message, so a rejected link says what a valid one looks like.
void checkValue(const std::string& name, const std::string& value, const std::string& platform) {
    auto fail = [&](const std::string& expected) {
        throw InvalidValue(name + ": malformed " + platform + " parameter (expected " + expected + ")");
    };
    if (platform == "prolific") {
        // Prolific ids are 24 hexadecimal digits.
        if (value.size() != 24) fail("24 hexadecimal digits");
        for (char c : value)
            if (!isHex(c)) fail("24 hexadecimal digits");
    } else if (platform == "mturk") {
        // Worker, assignment and HIT ids are upper-case letters and digits (13 to 30 of them in practice).
        if (value.empty() || value.size() > 64) fail("1 to 64 letters and digits");
        for (char c : value)
            if (!isAlnum(c)) fail("1 to 64 letters and digits");
    } else {
        if (value.empty() || value.size() > 64) fail("1 to 64 letters, digits, '-', '_' or '.'");
        for (char c : value)
            if (!(isAlnum(c) || c == '-' || c == '_' || c == '.')) fail("1 to 64 letters, digits, '-', '_' or '.'");
    }
}

// Each platform's ids in one spelling, so that one person is one id however the link spells it (docs/study-protocol.md,
// "Participant identity"). Prolific ids are hexadecimal object ids (case carries no meaning): lower case. MTurk ids
// are upper-case letters and digits: upper case. Other systems (SONA, generic): surrounding blanks and trailing
// dots dropped, lower case (a code typed or pasted by hand differs in nothing else).
std::string normalised(std::string value, const std::string& platform) {
    if (platform == "prolific" || platform == "mturk") {
        for (char& c : value)
            c = static_cast<char>(platform == "mturk" ? std::toupper(static_cast<unsigned char>(c))
                                                      : std::tolower(static_cast<unsigned char>(c)));
        return value;
    }
    const std::size_t first = value.find_first_not_of(" \t");
    value = first == std::string::npos ? "" : value.substr(first, value.find_last_not_of(" \t") - first + 1);
    while (!value.empty() && value.back() == '.') value.pop_back();
    for (char& c : value) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return value;
}

} // namespace

std::string normalisedExternalId(const std::string& platform, const std::string& value) {
    return normalised(value, platform);
}

PlatformParameters platformParameters(const RecruitmentDesign& r) {
    if (r.platform == "prolific") return {"PROLIFIC_PID", "STUDY_ID", "SESSION_ID"};
    if (r.platform == "mturk") return {"workerId", "hitId", "assignmentId"};
    if (r.platform == "sona" || r.platform == "generic") return {r.idParameter, "", ""};
    return {};
}

std::optional<ExternalIds> validateExternalIds(const RecruitmentDesign& recruitment,
                                               const std::map<std::string, std::string>& parameters) {
    const PlatformParameters names = platformParameters(recruitment);
    if (names.id.empty()) return std::nullopt;
    auto value = [&](const std::string& name) -> std::optional<std::string> {
        if (name.empty()) return std::nullopt;
        const auto it = parameters.find(name);
        if (it == parameters.end()) return std::nullopt;
        return it->second;
    };
    ExternalIds ids;
    ids.platform = recruitment.platform;
    if (recruitment.platform == "mturk" && value("assignmentId") == std::string(kMturkPreviewAssignment))
        throw NotAdmitted("assignmentId: this is the HIT's preview (ASSIGNMENT_ID_NOT_AVAILABLE); accept the "
                          "HIT to take part");
    const std::optional<std::string> id = value(names.id);
    if (!id) throw InvalidValue(names.id + ": missing; open the study from its " + recruitment.platform + " link");
    ids.id = normalised(*id, recruitment.platform);
    checkValue(names.id, ids.id, recruitment.platform);
    if (const auto study = value(names.study)) {
        ids.study = normalised(*study, recruitment.platform);
        checkValue(names.study, ids.study, recruitment.platform);
    }
    if (const auto session = value(names.session)) {
        ids.session = normalised(*session, recruitment.platform);
        checkValue(names.session, ids.session, recruitment.platform);
    }
    return ids;
}

std::string completionUrl(const RecruitmentDesign& recruitment, const std::string& code) {
    std::string url = recruitment.completionUrl;
    for (std::size_t at = url.find("{code}"); at != std::string::npos; at = url.find("{code}", at + code.size()))
        url.replace(at, 6, code);
    return url;
}

} // namespace skinlab::experiments
