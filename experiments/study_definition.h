#pragma once
// A design resolved against a stimulus manifest: the blocks, their conditions and the stimulus showing each
// condition, the pairs to compare, and the catch pairs. Stored in study.db; the server and the trial planner work
// only from this (never from the manifest folder's current contents).
#include "experiments/stimulus_manifest.h"
#include "experiments/study_design.h"

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace skinlab::experiments {

struct StudyStimulus {
    int index = 0;  // position in StudyDefinition::stimuli; also the public URL /stimuli/<index>.png
    std::string id; // manifest id
    std::string block;
    std::string condition; // level of the design's condition factor ("" for a reference stimulus)
    std::string pngPath;   // relative to the stimulus folder
    std::string sha256;
    int width = 0;
    int height = 0;
    bool reference = false;
};

struct StudyBlock {
    std::string name;
    std::vector<std::string> conditions;    // in design order
    std::vector<int> conditionStimulus;     // stimulus index per condition
    std::vector<std::pair<int, int>> pairs; // indices into `conditions`, first < second in design order
    int referenceStimulus = -1;             // shown above the pair when the design asks for it
};

struct StudyCatchPair {
    std::string block;
    int first = -1; // stimulus indices
    int second = -1;
    bool expectFirst = true;
    int repeat = 1;
};

// What the participant page needs to show every trial at one image pixel per device pixel: the widest pair (the
// two images side by side) and the tallest stimulus row, in device pixels, plus the page's fixed margins in CSS
// pixels. The page lays trials out with exactly these figures (GET /api/study "stage"), so the check at
// `study create`, the check before joining and the layout of a trial agree.
struct StageNeeds {
    static constexpr int kMargin = 16; // CSS px between and around the images
    static constexpr int kTop = 64;    // CSS px reserved above the images for the question (and practice label)
    static constexpr int kBottom = 36; // CSS px reserved below the images for the key hint
    int pairWidth = 0;                 // device px: the widest left + right pair
    int pairHeight = 0;                // device px: the tallest pair
    int referenceHeight = 0;           // device px: the tallest reference shown above a pair (0: none shown)
    std::string widestBlock;           // the block of the widest pair, for messages
    // CSS pixels needed at devicePixelRatio `dpr`.
    int cssWidth(double dpr = 1.0) const;
    int cssHeight(double dpr = 1.0) const;
    nlohmann::json toJson() const;
};

struct StudyDefinition {
    StudyDesign design;
    std::vector<StudyStimulus> stimuli;
    std::vector<StudyBlock> blocks;
    std::vector<StudyCatchPair> catchPairs;

    nlohmann::json toJson() const;
    static StudyDefinition fromJson(const nlohmann::json& json);
    // Number of planned trials per participant by kind.
    int testTrialCount() const;   // first showings (kind "test")
    int repeatTrialCount() const; // further repetitions (kind "repeat")
    int catchTrialCount() const;
    StageNeeds stageNeeds() const;
};

// Resolves `design` against `manifest`. Errors name the design file and key (e.g.
// "D.toml: conditions: \"separabel\" is not a level of factor \"method\" (levels: artistic, separable)").
StudyDefinition resolveStudy(const StudyDesign& design, const StimulusManifest& manifest);

} // namespace skinlab::experiments
