#pragma once
// Simulated observers that take part in a study through the real HTTP API, many at once — for demos, load tests
// and validating the analysis (docs/analysis.md). Observer k picks i over j iff q_i + ε_i > q_j + ε_j with
// ε ~ N(0, σ²/2), σ = 1.4826, so P(i ≻ j) = Φ((q_i − q_j)/σ) and 1 JOD = 75 % preference (Thurstone Case V as
// scaled by pwcmp, Perez-Ortiz & Mantiuk 2017). Options add a lapse rate (a random answer), a side bias (JOD added
// to the left image) and deliberately random or inverted (q → −q) observers to exercise observer screening.
// An attentive observer answers catch trials correctly (the expected answer is read from study.db).
#include "experiments/study_store.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace skinlab::experiments {

// True quality (JOD) of each condition, optionally per block (a block's entry wins over the global one).
struct SimulationTruth {
    std::map<std::string, double> byCondition;
    std::map<std::string, std::map<std::string, double>> byBlock;
    std::string source; // for messages
    // Throws InputError naming the source when a condition has no score and `required`.
    double quality(const std::string& block, const std::string& condition) const;
};

// {"separable": 1.0, "artistic": 0.0} or {"builtin:head/mid": {"separable": 1.0, ...}, ...}.
SimulationTruth readTruthJson(const std::filesystem::path& path);
// Scores from a numeric factor of the stimulus manifest stored in the study (e.g. "quality").
SimulationTruth truthFromFactor(StudyStore& store, const std::string& factor);
// Scores predicted by a model of vision: each stimulus's predicted JOD against its block's reference, as
// `skinlab stimuli build` records it in the manifest ("predicted": {"jod": …}, ColorVideoVDP); a block's reference
// shown as a condition scores 10 (no visible difference from itself). Throws InputError naming the stimulus when
// the set was built without predictions.
SimulationTruth truthFromPredictions(StudyStore& store);

struct SimulationOptions {
    std::string host = "127.0.0.1";
    int port = 8080;
    int observers = 10;
    SimulationTruth truth;
    double lapseRate = 0.0;    // probability of answering at random
    double sideBias = 0.0;     // JOD added to the left image's utility (positive = prefers left)
    int randomObservers = 0;   // answer every trial at random
    int invertedObservers = 0; // use −q (and fail catch trials)
    std::uint64_t seed = 1;
    double thinkMinMs = 0; // pause before each answer, uniform in [min, max]
    double thinkMaxMs = 0;
    std::string labelPrefix; // observer labels "<prefix>-001[-random|-inverted]"; empty = "sim-<random>"
    bool browserLike = true; // as the participant page does: kept-alive connection, page + study + images (each
                             // once: the browser caches them) around the API calls; false = API calls only, each
                             // on a new connection
    int maxAttempts = 300;   // per request, when the server cannot be reached (restarts); bounded
    int retryDelayMs = 50;
};

struct ObserverResult {
    std::string label;
    std::string kind; // thurstone | random | inverted
    bool completed = false;
    int answered = 0;                                               // acknowledged responses (stored or duplicate)
    int rejected = 0;                                               // 4xx/5xx answers
    int transportRetries = 0;                                       // re-sends after a failed connection
    std::vector<std::pair<std::int64_t, std::string>> acknowledged; // (trial row id, side) in order
    std::string completionCode;
    std::string failure; // why it stopped early, if it did
};

struct SimulationReport {
    std::vector<ObserverResult> observers;
    std::vector<double> latenciesMs; // round trip of every acknowledged response (commit included)
    double wallSeconds = 0;
    int completed() const;
    int rejected() const;
    int transportRetries() const;
    std::size_t acknowledged() const;
    double latencyPercentile(double p) const; // p in [0, 100]
};

// The join key of the simulated observer labelled `label`: the same label joins as the same participant, so an
// interrupted simulation run again with the same --label-prefix continues where it stopped.
std::string simulatedJoinKey(const std::string& label);

// Runs the observers concurrently (one thread each) against a server serving `store`'s study.
SimulationReport simulateObservers(StudyStore& store, const SimulationOptions& options);

} // namespace skinlab::experiments
