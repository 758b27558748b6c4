#pragma once
// How much any choice of pairs can gain over the full design (every pair equally often), asymptotically: the
// Cramér–Rao bound of the Thurstone Case V model (docs/benchmarks.md, "Active sampling").
#include <vector>

namespace skinlab::analysis::scaling {

// Fisher information (1/JOD²) of one comparison of two conditions whose true scores differ by `delta` JOD:
// φ(z)² / (σ² Φ(z) Φ(−z)), z = δ/σ; 2/(π σ²) at δ = 0, falling towards 0 for distant pairs.
double comparisonInformation(double delta);

// A lower bound on N_any / N_full: the share of the full design's comparisons that any allocation of comparisons
// to pairs (an oracle that knows `trueScores`) needs for the full design's summed asymptotic variance of the
// centred scores. 1 when every pair is equally informative (equal scores); 1 − this is an upper bound on the
// saving of any design, active sampling included, in the large-budget limit.
double optimalAllocationShare(const std::vector<double>& trueScores);

// The A-optimal shares w_p themselves (the allocation behind optimalAllocationShare), one per pair (i, j), i < j,
// in increasing (i, j) order; they sum to 1. The oracle design of bench_active_sampling draws its pairs from them.
std::vector<double> optimalAllocation(const std::vector<double>& trueScores);

} // namespace skinlab::analysis::scaling
