#include "experiments/recruitment.h"

#include "experiments/request_error.h"

#include <cctype>

namespace skinlab::experiments {

namespace {

bool isHex(char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; }
bool isAlnum(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; }

// Each rule states the accepted form in its message, so a rejected link says what a valid one looks like.
void checkValue(const std::string& name, const std::string& value, const std::string& platform) {
    auto fail = [&](const std::string& expected) {
        throw RequestError(400, name + ": malformed " + platform + " parameter (expected " + expected + ")");
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

} // namespace

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
        throw RequestError(403, "assignmentId: this is the HIT's preview (ASSIGNMENT_ID_NOT_AVAILABLE); accept the "
                                "HIT to take part");
    const std::optional<std::string> id = value(names.id);
    if (!id) throw RequestError(400, names.id + ": missing; open the study from its " + recruitment.platform + " link");
    checkValue(names.id, *id, recruitment.platform);
    ids.id = *id;
    if (const auto study = value(names.study)) {
        checkValue(names.study, *study, recruitment.platform);
        ids.study = *study;
    }
    if (const auto session = value(names.session)) {
        checkValue(names.session, *session, recruitment.platform);
        ids.session = *session;
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
