#pragma once
// A study design (D.toml): which conditions are compared, in which blocks, how often, with which practice and
// catch trials. Reference: docs/experiments.md ("Design file"). Parsed strictly with SpecReader: an unknown key or
// an out-of-range value is an error naming the file and the key.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace skinlab::experiments {

// A catch trial declared in the design: two stimuli (by id) and the one an attentive observer must choose.
struct DeclaredCatchPair {
    std::string first;
    std::string second;
    std::string expected;
    int repeat = 1; // times per participant
};

// [recruitment]: where participants come from (docs/experiments.md, "Recruitment"). The platform fixes the URL
// parameters carrying the external participant id; sona and generic name theirs with id_parameter.
struct RecruitmentDesign {
    std::string platform = "none"; // none | prolific | mturk | sona | generic
    std::string idParameter;       // sona, generic: the URL parameter holding the participant's id
    std::string completionUrl;     // redirect at the end ("{code}" = the completion code); empty = none
    std::string completionCode;    // the code shown at the end; empty = each participant's own generated code
};

// [display]: the credit-card calibration (pixels per mm) and the viewing distance the study asks for.
struct DisplayDesign {
    bool calibrate = false;
    double viewingDistanceMm = 0; // 0 = not stated
    // The browser viewport the study is designed for, in CSS pixels at devicePixelRatio 1 (a full-screen window
    // of a 1920×1080 display by default). `study create` refuses a design whose trials need more at one image
    // pixel per device pixel.
    int viewportWidth = 1920;
    int viewportHeight = 1080;
};

// [requirements]: a session that does not meet them is refused before the first trial.
struct RequirementsDesign {
    int minScreenWidth = 0; // CSS pixels (screen.width); 0 = any
    int minScreenHeight = 0;
    bool noZoom = false;     // devicePixelRatio a whole number, unchanged during the session
    bool fullscreen = false; // the page in full screen
    bool desktop = false;    // a fine pointer (mouse, trackpad) and no mobile browser
    bool any() const { return minScreenWidth > 0 || minScreenHeight > 0 || noZoom || fullscreen || desktop; }
};

struct StudyDesign {
    std::string sourceName; // file name for messages
    std::string title = "Image comparison";
    std::string question = "Which image looks more like real skin?";
    std::string instructions;               // shown before practice; empty = a default text
    std::string consent;                    // shown first; empty = a default text
    std::uint64_t seed = 1;                 // design seed; participant seeds are derived from it and stored
    std::string conditionFactor = "method"; // manifest factor naming a stimulus's condition ("id" = the stimulus id)
    std::vector<std::string> conditions;    // empty = every level found
    std::vector<std::string> blocks;        // empty = every block of the manifest
    bool allPairs = true;
    std::vector<std::pair<std::string, std::string>> pairs; // when !allPairs: condition pairs to compare
    // pairs = "active": each participant's test trials are planned batch by batch from the answers so far
    // (analysis/scaling/active_sampling.h); `trialsPerParticipant` of them, no repetitions. allPairs stays true
    // (every pair of a block is a candidate).
    bool activePairs = false;
    int trialsPerParticipant = 0;
    // active_batch: test trials planned at a time (then re-planned from the answers so far); 0 = one spanning tree
    // of a block, m − 1 trials. Small batches adapt sooner but need the answers of the batch before (one
    // participant at a time, as in a lab); with many participants at once they compare the same pairs.
    int activeBatch = 0;
    // active_prior_sd: the sd (JOD) of the planner's prior on every score (analysis/scaling/active_sampling.h,
    // PosteriorOptions). 1 suits scores within a few JOD of each other; scores spread wider are planned better
    // with a wider prior (docs/benchmarks.md, "Active sampling").
    double activePriorSd = 1.0;
    int repetitions = 2;                    // times each pair is shown to each participant (alternating sides)
    std::string blockOrder = "interleaved"; // interleaved | grouped
    int breakEvery = 40;                    // a pause screen every K trials (0 = none)
    bool showReference = false;             // show the block's reference stimulus above the pair (reference-based 2AFC)
    int practiceTrials = 2;
    int blankCatchTrials = 2; // stimulus vs a blank grey panel; the stimulus is the right answer
    std::vector<DeclaredCatchPair> catchPairs;
    RecruitmentDesign recruitment;
    DisplayDesign display;
    RequirementsDesign requirements;

    nlohmann::json toJson() const;
    static StudyDesign fromJson(const nlohmann::json& json);
};

// Reads D.toml, applies "key=value" overrides (the --set syntax), and checks every key.
StudyDesign readStudyDesign(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});
StudyDesign parseStudyDesign(std::string_view tomlText, std::string_view sourceName,
                             const std::vector<std::string>& overrides = {});

} // namespace skinlab::experiments
