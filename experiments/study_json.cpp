#include "experiments/study_json.h"

#include "net/request_error.h"
#include "experiments/study_text.h"
#include "experiments/viewing_conditions.h"

#include <algorithm>
#include <cmath>

namespace skinlab::experiments {

using nlohmann::json;

using net::HttpRequest;
using net::RequestError;

json parseJsonBody(const HttpRequest& req) {
    const std::string type = req.header("Content-Type");
    // Requiring JSON also keeps cross-site HTML forms (which cannot send it without a CORS preflight) out.
    if (type.rfind("application/json", 0) != 0) throw RequestError(415, "expected Content-Type: application/json");
    json body;
    try {
        body = json::parse(req.body);
    } catch (const json::exception&) {
        // parse_error, and out_of_range for numbers no double holds (1e400).
        throw RequestError(400, "request body is not valid JSON");
    }
    if (!body.is_object()) throw RequestError(400, "request body must be a JSON object");
    return body;
}

std::string stringField(const json& body, const char* name, std::size_t maxLength, bool required) {
    if (!body.contains(name)) {
        if (required) throw RequestError(400, std::string(name) + ": missing");
        return "";
    }
    if (!body[name].is_string()) throw RequestError(400, std::string(name) + ": expected a string");
    std::string value = body[name].get<std::string>();
    if (value.size() > maxLength)
        throw RequestError(400, std::string(name) + ": longer than " + std::to_string(maxLength) + " characters");
    return value;
}

std::int64_t integerField(const json& body, const char* name, std::int64_t min, std::int64_t max) {
    if (!body.contains(name)) throw RequestError(400, std::string(name) + ": missing");
    const json& v = body[name];
    if (!v.is_number_integer()) throw RequestError(400, std::string(name) + ": expected an integer");
    if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX))
        throw RequestError(400, std::string(name) + ": out of range");
    const std::int64_t value = v.get<std::int64_t>();
    if (value < min || value > max)
        throw RequestError(400, std::string(name) + ": " + std::to_string(value) + " is out of range [" +
                                    std::to_string(min) + ", " + std::to_string(max) + "]");
    return value;
}

double numberField(const json& body, const char* name, double min, double max) {
    if (!body.contains(name)) throw RequestError(400, std::string(name) + ": missing");
    const json& v = body[name];
    if (!v.is_number()) throw RequestError(400, std::string(name) + ": expected a number");
    const double value = v.get<double>();
    if (!(value >= min && value <= max))
        throw RequestError(400, std::string(name) + ": out of range [" + std::to_string(min) + ", " +
                                    std::to_string(max) + "]");
    return value;
}

bool booleanField(const json& body, const char* name) {
    if (!body.contains(name)) throw RequestError(400, std::string(name) + ": missing");
    if (!body[name].is_boolean()) throw RequestError(400, std::string(name) + ": expected true or false");
    return body[name].get<bool>();
}

std::optional<TrialConditions> trialConditionsField(const json& body) {
    if (!body.contains("page_hidden") && !body.contains("focus_lost") && !body.contains("fullscreen"))
        return std::nullopt;
    return TrialConditions{booleanField(body, "page_hidden"), booleanField(body, "focus_lost"),
                           booleanField(body, "fullscreen")};
}

std::map<std::string, std::string> recruitmentField(const json& body) {
    std::map<std::string, std::string> out;
    if (!body.contains("recruitment")) return out;
    const json& r = body["recruitment"];
    if (!r.is_object() || r.size() > 8)
        throw RequestError(400, "recruitment: expected an object of at most 8 parameters");
    for (const auto& [name, value] : r.items()) {
        if (name.size() > 64) throw RequestError(400, "recruitment: parameter name longer than 64 characters");
        if (!value.is_string()) throw RequestError(400, validUtf8(name, 64) + ": expected a string");
        const std::string text = value.get<std::string>();
        if (text.size() > 256) throw RequestError(400, validUtf8(name, 64) + ": longer than 256 characters");
        out[name] = text;
    }
    return out;
}

std::optional<ViewingConditions> viewingConditionsField(const json& body, int width, int height, double dpr,
                                                        const std::string& userAgent, const DisplayDesign& display) {
    if (!body.contains("screen_width")) return std::nullopt;
    ViewingConditions v;
    v.screenWidth = static_cast<int>(integerField(body, "screen_width", 0, 100000));
    v.screenHeight = static_cast<int>(integerField(body, "screen_height", 0, 100000));
    v.screenWidthPx = static_cast<int>(std::lround(v.screenWidth * dpr));
    v.screenHeightPx = static_cast<int>(std::lround(v.screenHeight * dpr));
    v.devicePixelRatio = dpr;
    v.colourDepth = static_cast<int>(integerField(body, "colour_depth", 0, 64));
    v.viewportWidth = width;
    v.viewportHeight = height;
    v.fullscreen = booleanField(body, "fullscreen");
    v.pointerFine = booleanField(body, "pointer_fine");
    v.touchPoints = static_cast<int>(integerField(body, "touch_points", 0, 1000));
    v.mobile = mobileUserAgent(userAgent);
    if (body.contains("card_width")) {
        v.pixelsPerMm = pixelsPerMmFromCard(numberField(body, "card_width", 20, 20000), dpr);
        if (display.viewingDistanceMm > 0) {
            v.viewingDistanceMm = display.viewingDistanceMm;
            v.pixelsPerDegree = pixelsPerDegree(*v.pixelsPerMm, *v.viewingDistanceMm);
        }
    }
    return v;
}

ResponseInput responseInputField(const json& body) {
    ResponseInput in;
    in.token = stringField(body, "token", kMaxTokenLength);
    in.trialId = integerField(body, "trial", 1, INT64_MAX);
    in.side = stringField(body, "side", 8);
    if (in.side != "left" && in.side != "right") throw RequestError(400, "side: expected \"left\" or \"right\"");
    in.sessionId = integerField(body, "session", 1, INT64_MAX);
    in.responseMs = numberField(body, "response_ms", 0, 86400000.0);
    in.clientTime = stringField(body, "client_time", 64);
    in.viewportWidth = static_cast<int>(integerField(body, "viewport_width", 0, 100000));
    in.viewportHeight = static_cast<int>(integerField(body, "viewport_height", 0, 100000));
    in.devicePixelRatio = numberField(body, "device_pixel_ratio", 0.1, 16);
    in.conditions = trialConditionsField(body);
    return in;
}

json studyJson(const StudyDefinition& definition) {
    const StudyDesign& d = definition.design;
    const PlatformParameters names = platformParameters(d.recruitment);
    json parameters = json::array();
    for (const std::string& name : {names.id, names.study, names.session})
        if (!name.empty()) parameters.push_back(name);
    return {
        {"title", d.title},
        {"question", d.question},
        {"instructions", d.instructions},
        {"consent", d.consent},
        {"break_every", d.breakEvery},
        {"recruitment", {{"platform", d.recruitment.platform}, {"id_parameter", names.id}, {"parameters", parameters}}},
        {"display",
         {{"calibrate", d.display.calibrate},
          {"viewing_distance_mm", d.display.viewingDistanceMm},
          {"card_width_mm", kIdCardWidthMm},
          {"card_height_mm", kIdCardHeightMm}}},
        // What every trial needs at one image pixel per device pixel: the page refuses a smaller window before
        // the participant joins, and lays trials out with the same margins.
        {"stage", definition.stageNeeds().toJson()},
        {"requirements",
         {{"min_screen_width", d.requirements.minScreenWidth},
          {"min_screen_height", d.requirements.minScreenHeight},
          {"no_zoom", d.requirements.noZoom},
          {"fullscreen", d.requirements.fullscreen},
          {"desktop", d.requirements.desktop}}}};
}

namespace {

json stimulusJson(const StudyDefinition& definition, int index) {
    const StudyStimulus& s = definition.stimuli[static_cast<std::size_t>(index)];
    return json{{"url", "/stimuli/" + std::to_string(index) + ".png"}, {"width", s.width}, {"height", s.height}};
}

} // namespace

json trialJson(const StudyDefinition& definition, const TrialRecord& t, const std::string& token) {
    const PlannedTrial& p = t.plan;
    const StudyStimulus& a = definition.stimuli[static_cast<std::size_t>(p.stimulusA)];
    json sideA = stimulusJson(definition, p.stimulusA);
    // The blank panel takes the size of the image it is paired with.
    json sideB = p.stimulusB == kBlankStimulus ? json{{"blank", true}, {"width", a.width}, {"height", a.height}}
                                               : stimulusJson(definition, p.stimulusB);
    // Catch trials look like any other trial to the participant; only practice is announced.
    return json{{"id", trialReference(token, t.id)},
                {"position", t.position},
                {"practice", p.kind == TrialKind::practice},
                {"left", p.aOnLeft ? sideA : sideB},
                {"right", p.aOnLeft ? sideB : sideA},
                {"reference", p.referenceStimulus >= 0 ? stimulusJson(definition, p.referenceStimulus) : json()}};
}

json participantStateJson(const StudyDefinition& definition, const ParticipantRecord& p,
                          const std::vector<TrialRecord>& all, const std::optional<TrialRecord>& next,
                          const Progress& progress) {
    int practiceTotal = 0;
    for (const TrialRecord& t : all) practiceTotal += t.plan.kind == TrialKind::practice ? 1 : 0;
    const int practiceAnswered = next ? std::min(next->position, practiceTotal) : practiceTotal;
    json state{{"observer", p.label},
               {"answered", progress.answered - practiceAnswered},
               {"total", progress.total - practiceTotal},
               {"practice_answered", practiceAnswered},
               {"practice_total", practiceTotal},
               {"trial", next ? trialJson(definition, *next, p.token) : json()},
               {"completed", !next.has_value()}};
    if (!next) {
        const RecruitmentDesign& recruitment = definition.design.recruitment;
        const std::string code = recruitment.completionCode.empty() ? p.completionCode : recruitment.completionCode;
        state["completion_code"] = code;
        const std::string url = completionUrl(recruitment, code);
        if (!url.empty()) state["completion_url"] = url;
    }
    return state;
}

} // namespace skinlab::experiments
