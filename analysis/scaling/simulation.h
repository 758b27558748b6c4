#pragma once
// Simulated 2AFC observers with known true scores: a Thurstone observer picks the left
// stimulus L over the right R iff q_L + ε_L + b > q_R + ε_R, ε ~ N(0, σ²/2) with σ = 1.4826 JOD (so the
// difference of the two noises has standard deviation σ: P(i ≻ j) = Φ((q_i − q_j)/σ)), b the observer's side
// bias in JOD. With probability `lapseRate` the answer is a coin flip instead. Deliberately bad observers: a
// *random* observer always flips a coin; an *inverted* observer is a Thurstone observer of −q.
#include "analysis/scaling/comparison_data.h"

#include <cstdint>
#include <vector>

namespace skinlab::analysis::scaling {

enum class SimulatedObserverKind { Genuine, Random, Inverted };

struct SimulationDesign {
    std::vector<double> trueScores;         // JOD
    int observers = 20;                     // in all, bad ones included
    int trialsPerPair = 4;                  // per observer and pair; the sides alternate (half with each on the left)
    double lapseRate = 0.0;                 // genuine observers' probability of a random answer
    double sideBiasStandardDeviation = 0.0; // JOD; each genuine observer draws b ~ N(0, sd²)
    int randomObservers = 0;                // of `observers`
    int invertedObservers = 0;              // of `observers`
    // Incomplete designs: each observer judges each pair with this probability (1: every pair), and the
    // conditions fall into `groups` contiguous groups never compared with each other (1: connected).
    double pairFraction = 1.0;
    int groups = 1;
};

struct SimulatedBlock {
    BlockData block;
    std::vector<SimulatedObserverKind> kinds; // per observer
};

// Every within-group pair, each observer judging it with probability pairFraction (the full design by default). Deterministic for a given seed.
SimulatedBlock simulateBlock(const SimulationDesign& design, std::uint64_t seed);

} // namespace skinlab::analysis::scaling
