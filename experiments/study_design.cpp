#include "experiments/study_design.h"

#include "common/error.h"
#include "common/spec.h"

#include <cctype>
#include <limits>

namespace skinlab::experiments {

namespace {

// pairs: "all", "active" or a list of [A, B] condition pairs.
void readPairs(const SpecReader& spec, StudyDesign& d) {
    if (const toml::node* pairs = spec.raw("pairs")) {
        if (const auto* text = pairs->as_string()) {
            if (text->get() == "active") d.activePairs = true;
            else if (text->get() != "all")
                spec.fail("pairs", "expected \"all\", \"active\" or an array of [A, B] condition pairs, got \"" +
                                       text->get() + "\"");
        } else if (const auto* list = pairs->as_array()) {
            d.allPairs = false;
            std::size_t i = 0;
            for (const toml::node& item : *list) {
                const std::string key = "pairs[" + std::to_string(i++) + "]";
                const auto* pair = item.as_array();
                if (!pair || pair->size() != 2 || !(*pair)[0].is_string() || !(*pair)[1].is_string())
                    spec.fail(key, "expected a pair of condition names [\"A\", \"B\"], got " + describeNode(item));
                std::string a = (*pair)[0].as_string()->get();
                std::string b = (*pair)[1].as_string()->get();
                if (a == b) spec.fail(key, "a condition cannot be compared with itself (\"" + a + "\")");
                d.pairs.emplace_back(a, b);
            }
            if (d.pairs.empty()) spec.fail("pairs", "an empty list compares nothing");
        } else {
            spec.fail("pairs", "expected \"all\" or an array of [A, B] condition pairs, got " + describeNode(*pairs));
        }
    }
}

// trials_per_participant, active_batch and active_prior_sd, which only an active design takes.
void readTrialCounts(const SpecReader& spec, StudyDesign& d) {
    // Active designs (pairs = "active"): trials_per_participant is required, and the keys that only shape a fixed
    // design (repetitions, block_order) are errors rather than silently ignored.
    if (d.activePairs) {
        if (!spec.has("trials_per_participant"))
            spec.fail("trials_per_participant", "required with pairs = \"active\" (test trials per participant)");
        if (spec.has("repetitions"))
            spec.fail("repetitions", "not used with pairs = \"active\" (the planner chooses every test trial; "
                                     "set trials_per_participant)");
        if (spec.has("block_order"))
            spec.fail("block_order", "not used with pairs = \"active\" (each batch is planned for one block)");
        d.trialsPerParticipant = static_cast<int>(spec.integer("trials_per_participant", 0, 1, 10000));
        d.activeBatch = static_cast<int>(spec.integer("active_batch", 0, 0, 10000));
        d.activePriorSd = spec.number("active_prior_sd", 1.0, 0.25, 10.0);
        d.repetitions = 1;
    } else {
        for (const char* key : {"trials_per_participant", "active_batch", "active_prior_sd"})
            if (spec.has(key)) spec.fail(key, "only used with pairs = \"active\"");
    }
}

// [catch]: blank catch trials and [[catch.pairs]].
void readCatch(const SpecReader& spec, StudyDesign& d) {
    SpecReader catchTable = spec.table("catch");
    d.blankCatchTrials = static_cast<int>(catchTable.integer("blank", d.blankCatchTrials, 0, 1000));
    for (const SpecReader& pair : catchTable.tables("pairs")) {
        DeclaredCatchPair c;
        c.first = pair.requiredString("first");
        c.second = pair.requiredString("second");
        c.expected = pair.requiredString("expected");
        c.repeat = static_cast<int>(pair.integer("repeat", 1, 1, 100));
        if (c.first == c.second) pair.fail("second", "must differ from first");
        if (c.expected != c.first && c.expected != c.second)
            pair.fail("expected", "must be the first or the second stimulus id, got \"" + c.expected + "\"");
        d.catchPairs.push_back(std::move(c));
    }
}

// [recruitment]: the platform, its id parameter, the completion link and code.
void readRecruitment(const SpecReader& spec, StudyDesign& d) {
    SpecReader recruitment = spec.table("recruitment");
    d.recruitment.platform = recruitment.choice("platform", "none", {"none", "prolific", "mturk", "sona", "generic"});
    const bool named = d.recruitment.platform == "sona" || d.recruitment.platform == "generic";
    if (named) {
        d.recruitment.idParameter = recruitment.requiredString("id_parameter");
        const std::string& name = d.recruitment.idParameter;
        bool valid = !name.empty() && name.size() <= 64 && name != "p";
        for (char c : name) valid = valid && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-');
        if (!valid)
            recruitment.fail("id_parameter", "\"" + name +
                                                 "\" is not a URL parameter name (1 to 64 letters, digits, "
                                                 "'_' or '-'; not \"p\", the participant link's own)");
    } else if (recruitment.has("id_parameter")) {
        recruitment.fail("id_parameter", "only used with platform = \"sona\" or \"generic\" (platform \"" +
                                             d.recruitment.platform + "\" has fixed parameters)");
    }
    d.recruitment.completionUrl = recruitment.string("completion_url", "");
    if (!d.recruitment.completionUrl.empty()) {
        const std::string& url = d.recruitment.completionUrl;
        bool valid = (url.rfind("https://", 0) == 0 || url.rfind("http://", 0) == 0) && url.size() <= 2000;
        for (char c : url)
            valid = valid && static_cast<unsigned char>(c) > 0x20 && c != 0x7f && c != '"' && c != '<' && c != '>';
        if (!valid)
            recruitment.fail("completion_url", "\"" + url + "\" is not an http(s) URL without spaces or quotes");
    }
    d.recruitment.completionCode = recruitment.string("completion_code", "");
    for (char c : d.recruitment.completionCode)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ||
            d.recruitment.completionCode.size() > 64)
            recruitment.fail("completion_code", "\"" + d.recruitment.completionCode +
                                                    "\": only letters, digits, '-' and '_' (at most 64)");
}

// [display]: calibration, viewing distance and viewport.
void readDisplay(const SpecReader& spec, StudyDesign& d) {
    SpecReader display = spec.table("display");
    d.display.calibrate = display.boolean("calibrate", false);
    if (d.display.calibrate && !display.has("viewing_distance_mm"))
        display.fail("viewing_distance_mm", "required with calibrate = true (pixels per degree need the distance)");
    d.display.viewingDistanceMm = display.number("viewing_distance_mm", 0, 100, 5000);
    d.display.viewportWidth = static_cast<int>(display.integer("viewport_width", 1920, 320, 16384));
    d.display.viewportHeight = static_cast<int>(display.integer("viewport_height", 1080, 240, 16384));
}

// [requirements]: what the participant's screen and browser must offer.
void readRequirements(const SpecReader& spec, StudyDesign& d) {
    SpecReader requirements = spec.table("requirements");
    d.requirements.minScreenWidth = static_cast<int>(requirements.integer("min_screen_width", 0, 0, 100000));
    d.requirements.minScreenHeight = static_cast<int>(requirements.integer("min_screen_height", 0, 0, 100000));
    d.requirements.noZoom = requirements.boolean("no_zoom", false);
    d.requirements.fullscreen = requirements.boolean("fullscreen", false);
    d.requirements.desktop = requirements.boolean("desktop", false);
}

StudyDesign designFromToml(toml::table& root, const std::string& file, const std::vector<std::string>& overrides) {
    for (const std::string& assignment : overrides) applyOverride(root, assignment, "--set");
    SpecReader spec(root, file);
    StudyDesign d;
    d.sourceName = file;
    d.title = spec.string("title", d.title);
    d.question = spec.string("question", d.question);
    if (d.question.empty()) spec.fail("question", "must not be empty");
    d.instructions = spec.string("instructions", d.instructions);
    d.consent = spec.string("consent", d.consent);
    // Seeds are stored as SQLite integers (signed 64-bit), hence the non-negative int64 range.
    d.seed = static_cast<std::uint64_t>(spec.integer("seed", 1, 0, std::numeric_limits<std::int64_t>::max()));
    d.conditionFactor = spec.string("condition_factor", d.conditionFactor);
    if (d.conditionFactor.empty()) spec.fail("condition_factor", "must not be empty");
    d.conditions = spec.strings("conditions", {});
    d.blocks = spec.strings("blocks", {});
    readPairs(spec, d);
    readTrialCounts(spec, d);
    d.repetitions = static_cast<int>(spec.integer("repetitions", d.repetitions, 1, 100));
    d.blockOrder = spec.choice("block_order", d.blockOrder, {"interleaved", "grouped"});
    d.breakEvery = static_cast<int>(spec.integer("break_every", d.breakEvery, 0, 100000));

    SpecReader reference = spec.table("reference");
    d.showReference = reference.boolean("show", false);

    SpecReader practice = spec.table("practice");
    d.practiceTrials = static_cast<int>(practice.integer("trials", d.practiceTrials, 0, 100));

    readCatch(spec, d);
    readRecruitment(spec, d);
    readDisplay(spec, d);
    readRequirements(spec, d);
    spec.finish();
    return d;
}

} // namespace

StudyDesign parseStudyDesign(std::string_view tomlText, std::string_view sourceName,
                             const std::vector<std::string>& overrides) {
    toml::table root = parseTomlString(tomlText, sourceName);
    return designFromToml(root, std::string(sourceName), overrides);
}

StudyDesign readStudyDesign(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
    toml::table root = parseTomlFile(path);
    return designFromToml(root, path.string(), overrides);
}

nlohmann::json StudyDesign::toJson() const {
    nlohmann::json pairsJson = nlohmann::json::array();
    for (const auto& [a, b] : pairs) pairsJson.push_back({a, b});
    nlohmann::json catchJson = nlohmann::json::array();
    for (const DeclaredCatchPair& c : catchPairs)
        catchJson.push_back({{"first", c.first}, {"second", c.second}, {"expected", c.expected}, {"repeat", c.repeat}});
    nlohmann::json out = {{"title", title},
                          {"question", question},
                          {"instructions", instructions},
                          {"consent", consent},
                          {"seed", seed},
                          {"condition_factor", conditionFactor},
                          {"conditions", conditions},
                          {"blocks", blocks},
                          {"pairs", activePairs ? nlohmann::json("active")
                                    : allPairs  ? nlohmann::json("all")
                                                : pairsJson},
                          {"trials_per_participant", trialsPerParticipant},
                          {"repetitions", repetitions},
                          {"block_order", blockOrder},
                          {"break_every", breakEvery},
                          {"reference", {{"show", showReference}}},
                          {"practice", {{"trials", practiceTrials}}},
                          {"catch", {{"blank", blankCatchTrials}, {"pairs", catchJson}}},
                          {"recruitment",
                           {{"platform", recruitment.platform},
                            {"id_parameter", recruitment.idParameter},
                            {"completion_url", recruitment.completionUrl},
                            {"completion_code", recruitment.completionCode}}},
                          {"display",
                           {{"calibrate", display.calibrate},
                            {"viewing_distance_mm", display.viewingDistanceMm},
                            {"viewport_width", display.viewportWidth},
                            {"viewport_height", display.viewportHeight}}},
                          {"requirements",
                           {{"min_screen_width", requirements.minScreenWidth},
                            {"min_screen_height", requirements.minScreenHeight},
                            {"no_zoom", requirements.noZoom},
                            {"fullscreen", requirements.fullscreen},
                            {"desktop", requirements.desktop}}}};
    if (activePairs && activeBatch > 0) out["active_batch"] = activeBatch; // only where set: designs stay as they were
    if (activePairs && activePriorSd != 1.0) out["active_prior_sd"] = activePriorSd;
    return out;
}

StudyDesign StudyDesign::fromJson(const nlohmann::json& j) {
    StudyDesign d;
    d.sourceName = "study.db:design";
    d.title = j.at("title").get<std::string>();
    d.question = j.at("question").get<std::string>();
    d.instructions = j.at("instructions").get<std::string>();
    d.consent = j.at("consent").get<std::string>();
    d.seed = j.at("seed").get<std::uint64_t>();
    d.conditionFactor = j.at("condition_factor").get<std::string>();
    d.conditions = j.at("conditions").get<std::vector<std::string>>();
    d.blocks = j.at("blocks").get<std::vector<std::string>>();
    if (j.at("pairs").is_string()) {
        d.allPairs = true;
        d.activePairs = j.at("pairs").get<std::string>() == "active";
        d.trialsPerParticipant = j.value("trials_per_participant", 0);
        d.activeBatch = j.value("active_batch", 0);
        d.activePriorSd = j.value("active_prior_sd", 1.0);
    } else {
        d.allPairs = false;
        for (const auto& p : j.at("pairs"))
            d.pairs.emplace_back(p.at(0).get<std::string>(), p.at(1).get<std::string>());
    }
    d.repetitions = j.at("repetitions").get<int>();
    d.blockOrder = j.at("block_order").get<std::string>();
    d.breakEvery = j.at("break_every").get<int>();
    d.showReference = j.at("reference").at("show").get<bool>();
    d.practiceTrials = j.at("practice").at("trials").get<int>();
    d.blankCatchTrials = j.at("catch").at("blank").get<int>();
    for (const auto& c : j.at("catch").at("pairs"))
        d.catchPairs.push_back({c.at("first").get<std::string>(), c.at("second").get<std::string>(),
                                c.at("expected").get<std::string>(), c.at("repeat").get<int>()});
    // Study files created before recruitment, display and requirements existed hold none of them.
    if (const auto r = j.find("recruitment"); r != j.end()) {
        d.recruitment.platform = r->at("platform").get<std::string>();
        d.recruitment.idParameter = r->at("id_parameter").get<std::string>();
        d.recruitment.completionUrl = r->at("completion_url").get<std::string>();
        d.recruitment.completionCode = r->at("completion_code").get<std::string>();
    }
    if (const auto display = j.find("display"); display != j.end()) {
        d.display.calibrate = display->at("calibrate").get<bool>();
        d.display.viewingDistanceMm = display->at("viewing_distance_mm").get<double>();
        // Study files created before the declared viewport existed: the default.
        d.display.viewportWidth = display->value("viewport_width", d.display.viewportWidth);
        d.display.viewportHeight = display->value("viewport_height", d.display.viewportHeight);
    }
    if (const auto r = j.find("requirements"); r != j.end()) {
        d.requirements.minScreenWidth = r->at("min_screen_width").get<int>();
        d.requirements.minScreenHeight = r->at("min_screen_height").get<int>();
        d.requirements.noZoom = r->at("no_zoom").get<bool>();
        d.requirements.fullscreen = r->at("fullscreen").get<bool>();
        d.requirements.desktop = r->at("desktop").get<bool>();
    }
    return d;
}

} // namespace skinlab::experiments
