#include "experiments/study_definition.h"

#include "common/error.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace skinlab::experiments {

namespace {

std::string joinNames(const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
}

std::string conditionOf(const StudyDesign& design, const ManifestStimulus& s) {
    if (design.conditionFactor == "id") return s.id;
    auto it = s.factors.find(design.conditionFactor);
    return it == s.factors.end() ? std::string() : it->second;
}

// Blocks in manifest order of first appearance, or the design's own list once every name in it is checked.
std::vector<std::string> resolveBlockNames(const StudyDesign& design, const StimulusManifest& manifest) {
    const std::string& file = design.sourceName;
    std::vector<std::string> blockNames;
    for (const ManifestStimulus& s : manifest.stimuli)
        if (std::find(blockNames.begin(), blockNames.end(), s.block) == blockNames.end()) blockNames.push_back(s.block);
    for (const std::string& b : design.blocks)
        if (std::find(blockNames.begin(), blockNames.end(), b) == blockNames.end())
            throwInput(file, "blocks",
                       "\"" + b + "\" is not a block of the stimulus set (blocks: " + joinNames(blockNames) + ")");
    if (!design.blocks.empty()) blockNames = design.blocks;
    return blockNames;
}

// The study's conditions: the design's list (checked against the levels present) or every level present.
std::vector<std::string> resolveConditions(const StudyDesign& design, const StimulusManifest& manifest) {
    const std::string& file = design.sourceName;
    // All condition levels present (in manifest order), for defaults and messages.
    std::vector<std::string> levels;
    for (const ManifestStimulus& s : manifest.stimuli) {
        if (s.reference && design.showReference) continue;
        const std::string c = conditionOf(design, s);
        if (!c.empty() && std::find(levels.begin(), levels.end(), c) == levels.end()) levels.push_back(c);
    }
    if (levels.empty())
        throwInput(file, "condition_factor", "no stimulus has factor \"" + design.conditionFactor + "\"");
    for (const std::string& c : design.conditions)
        if (std::find(levels.begin(), levels.end(), c) == levels.end())
            throwInput(file, "conditions",
                       "\"" + c + "\" is not a level of factor \"" + design.conditionFactor +
                           "\" (levels: " + joinNames(levels) + ")");
    const std::vector<std::string> conditions = design.conditions.empty() ? levels : design.conditions;
    if (conditions.size() < 2) throwInput(file, "conditions", "at least two conditions are needed for a comparison");
    for (const auto& [a, b] : design.pairs)
        for (const std::string& c : {a, b})
            if (std::find(conditions.begin(), conditions.end(), c) == conditions.end())
                throwInput(file, "pairs",
                           "\"" + c + "\" is not one of the study's conditions (" + joinNames(conditions) + ")");
    return conditions;
}

// The index of the stimulus in def.stimuli, appended on its first use.
int addStimulus(StudyDefinition& def, const ManifestStimulus& s, const std::string& condition) {
    for (const StudyStimulus& existing : def.stimuli)
        if (existing.id == s.id) return existing.index;
    StudyStimulus st;
    st.index = static_cast<int>(def.stimuli.size());
    st.id = s.id;
    st.block = s.block;
    st.condition = condition;
    st.pngPath = s.pngPath;
    st.sha256 = s.pngSha256;
    st.width = s.width;
    st.height = s.height;
    st.reference = s.reference;
    def.stimuli.push_back(st);
    return st.index;
}

// One block: its reference, one stimulus per condition (in the study's order) and the pairs to compare.
StudyBlock resolveBlock(StudyDefinition& def, const StimulusManifest& manifest, const std::string& blockName,
                        const std::vector<std::string>& conditions) {
    const StudyDesign& design = def.design;
    const std::string& file = design.sourceName;
    const std::string manifestWhere = (manifest.folder / "manifest.json").string();
    StudyBlock block;
    block.name = blockName;
    std::map<std::string, const ManifestStimulus*> byCondition;
    for (const ManifestStimulus& s : manifest.stimuli) {
        if (s.block != blockName) continue;
        if (s.reference && design.showReference) {
            if (block.referenceStimulus >= 0)
                throwInput(manifestWhere, "stimuli",
                           "block \"" + blockName + "\" has more than one reference stimulus");
            block.referenceStimulus = addStimulus(def, s, "");
            continue;
        }
        const std::string c = conditionOf(design, s);
        if (c.empty() || std::find(conditions.begin(), conditions.end(), c) == conditions.end()) continue;
        if (byCondition.count(c))
            throwInput(file, "condition_factor",
                       "block \"" + blockName + "\" has two stimuli with " + design.conditionFactor + "=" + c + " (\"" +
                           byCondition[c]->id + "\", \"" + s.id +
                           "\"); choose a factor that tells them apart, or split blocks");
        byCondition[c] = &s;
    }
    if (design.showReference && block.referenceStimulus < 0)
        throwInput(file, "reference.show", "block \"" + blockName + "\" has no stimulus with \"reference\": true");
    for (const std::string& c : conditions) {
        auto it = byCondition.find(c);
        if (it == byCondition.end()) continue;
        block.conditions.push_back(c);
        block.conditionStimulus.push_back(addStimulus(def, *it->second, c));
    }
    const int n = static_cast<int>(block.conditions.size());
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j) {
            bool wanted = design.allPairs;
            for (const auto& [a, b] : design.pairs)
                if ((a == block.conditions[i] && b == block.conditions[j]) ||
                    (b == block.conditions[i] && a == block.conditions[j]))
                    wanted = true;
            if (wanted) block.pairs.emplace_back(i, j);
        }
    return block;
}

// Every declared pair must be compared in at least one block.
void checkDeclaredPairs(const StudyDefinition& def) {
    const StudyDesign& design = def.design;
    for (const auto& [a, b] : design.pairs) {
        bool found = false;
        for (const StudyBlock& block : def.blocks)
            for (const auto& [i, j] : block.pairs)
                if ((block.conditions[i] == a && block.conditions[j] == b) ||
                    (block.conditions[i] == b && block.conditions[j] == a))
                    found = true;
        if (!found) throwInput(design.sourceName, "pairs", "no block holds both \"" + a + "\" and \"" + b + "\"");
    }
}

void resolveCatchPairs(StudyDefinition& def, const StimulusManifest& manifest) {
    const StudyDesign& design = def.design;
    const std::string& file = design.sourceName;
    std::size_t index = 0;
    for (const DeclaredCatchPair& c : design.catchPairs) {
        const std::string key = "catch.pairs[" + std::to_string(index++) + "]";
        const ManifestStimulus* first = manifest.find(c.first);
        const ManifestStimulus* second = manifest.find(c.second);
        if (!first) throwInput(file, key + ".first", "no stimulus with id \"" + c.first + "\"");
        if (!second) throwInput(file, key + ".second", "no stimulus with id \"" + c.second + "\"");
        StudyCatchPair pair;
        pair.block = first->block;
        pair.first =
            addStimulus(def, *first, conditionOf(design, *first).empty() ? first->id : conditionOf(design, *first));
        pair.second =
            addStimulus(def, *second, conditionOf(design, *second).empty() ? second->id : conditionOf(design, *second));
        pair.expectFirst = c.expected == c.first;
        pair.repeat = c.repeat;
        def.catchPairs.push_back(pair);
    }
}

// Every trial must fit the declared viewport at one image pixel per device pixel (devicePixelRatio 1).
void checkViewport(const StudyDefinition& def) {
    const StudyDesign& design = def.design;
    const StageNeeds needs = def.stageNeeds();
    const int width = needs.cssWidth(), height = needs.cssHeight();
    if (width > design.display.viewportWidth || height > design.display.viewportHeight) {
        const std::string key =
            width > design.display.viewportWidth ? "display.viewport_width" : "display.viewport_height";
        throwInput(design.sourceName, key,
                   "the trials need " + std::to_string(width) + " × " + std::to_string(height) +
                       " CSS pixels at one image pixel per device pixel (block \"" + needs.widestBlock +
                       "\": " + std::to_string(needs.pairWidth) + " px of images side by side" +
                       (needs.referenceHeight > 0 ? ", a reference above them" : "") + "), more than the declared " +
                       std::to_string(design.display.viewportWidth) + " × " +
                       std::to_string(design.display.viewportHeight) +
                       " viewport; render smaller stimuli, crop them, or declare a larger viewport");
    }
}

} // namespace

StudyDefinition resolveStudy(const StudyDesign& design, const StimulusManifest& manifest) {
    StudyDefinition def;
    def.design = design;
    const std::vector<std::string> blockNames = resolveBlockNames(design, manifest);
    const std::vector<std::string> conditions = resolveConditions(design, manifest);
    for (const std::string& blockName : blockNames) {
        StudyBlock block = resolveBlock(def, manifest, blockName, conditions);
        if (!block.pairs.empty()) def.blocks.push_back(std::move(block));
    }
    if (def.blocks.empty())
        throwInput(design.sourceName, "pairs", "no block holds two of the study's conditions; nothing to compare");
    checkDeclaredPairs(def);
    resolveCatchPairs(def, manifest);
    checkViewport(def);
    return def;
}

int StageNeeds::cssWidth(double dpr) const { return static_cast<int>(std::ceil(pairWidth / dpr + 3 * kMargin)); }

int StageNeeds::cssHeight(double dpr) const {
    return static_cast<int>(
        std::ceil((pairHeight + referenceHeight) / dpr + kTop + kBottom + (referenceHeight > 0 ? kMargin : 0)));
}

nlohmann::json StageNeeds::toJson() const {
    return {{"pair_width", pairWidth},
            {"pair_height", pairHeight},
            {"reference_height", referenceHeight},
            {"margin", kMargin},
            {"top", kTop},
            {"bottom", kBottom}};
}

StageNeeds StudyDefinition::stageNeeds() const {
    StageNeeds needs;
    auto pair = [&](const std::string& block, int first, int second) {
        const StudyStimulus& a = stimuli.at(static_cast<std::size_t>(first));
        const StudyStimulus& b = stimuli.at(static_cast<std::size_t>(second));
        if (a.width + b.width > needs.pairWidth) needs.widestBlock = block;
        needs.pairWidth = std::max(needs.pairWidth, a.width + b.width);
        needs.pairHeight = std::max({needs.pairHeight, a.height, b.height});
    };
    for (const StudyBlock& block : blocks) {
        for (const auto& [i, j] : block.pairs)
            pair(block.name, block.conditionStimulus[static_cast<std::size_t>(i)],
                 block.conditionStimulus[static_cast<std::size_t>(j)]);
        // A blank catch trial shows a stimulus beside a blank panel of its size.
        if (design.blankCatchTrials > 0)
            for (int s : block.conditionStimulus) pair(block.name, s, s);
        if (design.showReference && block.referenceStimulus >= 0)
            needs.referenceHeight =
                std::max(needs.referenceHeight, stimuli.at(static_cast<std::size_t>(block.referenceStimulus)).height);
    }
    for (const StudyCatchPair& c : catchPairs) pair(c.block, c.first, c.second);
    return needs;
}

int StudyDefinition::testTrialCount() const {
    if (design.activePairs) return design.trialsPerParticipant;
    int n = 0;
    for (const StudyBlock& b : blocks) n += static_cast<int>(b.pairs.size());
    return n;
}
int StudyDefinition::repeatTrialCount() const { return testTrialCount() * (design.repetitions - 1); }
int StudyDefinition::catchTrialCount() const {
    int n = design.blankCatchTrials;
    for (const StudyCatchPair& c : catchPairs) n += c.repeat;
    return n;
}

nlohmann::json StudyDefinition::toJson() const {
    nlohmann::json j;
    j["design"] = design.toJson();
    j["stimuli"] = nlohmann::json::array();
    for (const StudyStimulus& s : stimuli)
        j["stimuli"].push_back({{"index", s.index},
                                {"id", s.id},
                                {"block", s.block},
                                {"condition", s.condition},
                                {"png", s.pngPath},
                                {"sha256", s.sha256},
                                {"width", s.width},
                                {"height", s.height},
                                {"reference", s.reference}});
    j["blocks"] = nlohmann::json::array();
    for (const StudyBlock& b : blocks) {
        nlohmann::json pairs = nlohmann::json::array();
        for (const auto& [x, y] : b.pairs) pairs.push_back({x, y});
        j["blocks"].push_back({{"name", b.name},
                               {"conditions", b.conditions},
                               {"condition_stimulus", b.conditionStimulus},
                               {"pairs", pairs},
                               {"reference_stimulus", b.referenceStimulus}});
    }
    j["catch_pairs"] = nlohmann::json::array();
    for (const StudyCatchPair& c : catchPairs)
        j["catch_pairs"].push_back({{"block", c.block},
                                    {"first", c.first},
                                    {"second", c.second},
                                    {"expect_first", c.expectFirst},
                                    {"repeat", c.repeat}});
    return j;
}

StudyDefinition StudyDefinition::fromJson(const nlohmann::json& j) {
    StudyDefinition def;
    def.design = StudyDesign::fromJson(j.at("design"));
    for (const auto& s : j.at("stimuli"))
        def.stimuli.push_back({s.at("index").get<int>(), s.at("id").get<std::string>(),
                               s.at("block").get<std::string>(), s.at("condition").get<std::string>(),
                               s.at("png").get<std::string>(), s.at("sha256").get<std::string>(),
                               s.at("width").get<int>(), s.at("height").get<int>(), s.at("reference").get<bool>()});
    for (const auto& b : j.at("blocks")) {
        StudyBlock block;
        block.name = b.at("name").get<std::string>();
        block.conditions = b.at("conditions").get<std::vector<std::string>>();
        block.conditionStimulus = b.at("condition_stimulus").get<std::vector<int>>();
        for (const auto& p : b.at("pairs")) block.pairs.emplace_back(p.at(0).get<int>(), p.at(1).get<int>());
        block.referenceStimulus = b.at("reference_stimulus").get<int>();
        def.blocks.push_back(std::move(block));
    }
    for (const auto& c : j.at("catch_pairs"))
        def.catchPairs.push_back({c.at("block").get<std::string>(), c.at("first").get<int>(), c.at("second").get<int>(),
                                  c.at("expect_first").get<bool>(), c.at("repeat").get<int>()});
    return def;
}

} // namespace skinlab::experiments
