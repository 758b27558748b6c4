#pragma once
// Responses grouped for scaling: per block (contract 3's `scene` column), per observer and per compared pair,
// the number of times each side won. Only test and repeat trials are scaled (as pwcmp's long format); catch
// and practice trials feed the attention report.
#include "analysis/scaling/pairwise_model.h"
#include "analysis/scaling/responses.h"

#include <Eigen/Dense>

#include <array>
#include <string>
#include <vector>

namespace skinlab::analysis::scaling {

struct BlockData {
    std::string name;
    std::vector<std::string> conditions;
    std::vector<std::string> observers;     // observers with at least one scaled trial in this block
    bool hasObservers = true;               // false for a count matrix (one anonymous pseudo-observer)
    std::vector<std::pair<int, int>> pairs; // compared pairs (i < j), in first-appearance order
    Eigen::MatrixXd winsFirst;              // observers × pairs: times pairs[p].first was chosen
    Eigen::MatrixXd winsSecond;             // observers × pairs: times pairs[p].second was chosen
    // Side information per pair: [first on left & first chosen, first on left & second chosen,
    //                             second on left & first chosen, second on left & second chosen].
    std::vector<std::array<double, 4>> sideCounts;
    Eigen::VectorXd leftChosen; // per observer: trials where the left stimulus was chosen
    Eigen::VectorXd sideTrials; // per observer: trials with a known side

    int conditionCount() const { return static_cast<int>(conditions.size()); }
    int observerCount() const { return static_cast<int>(observers.size()); }
    // Counts summed over observers with the given multiplicities (the bootstrap's resampling weights).
    PairCounts weightedCounts(const Eigen::VectorXd& observerWeights) const;
    PairCounts totalCounts() const;
    // D (m × m): D(i, j) = times i was chosen over j.
    Eigen::MatrixXd countMatrix() const;
};

// Attention checks of one observer, over all blocks.
struct ObserverAttention {
    std::string observer;
    int scaledTrials = 0;
    int catchTrials = 0;
    int catchFailures = 0;
    int practiceTrials = 0;
};

struct Dataset {
    std::string file;
    ResponseFormat format = ResponseFormat::SkinlabCsv;
    std::vector<BlockData> blocks;
    std::vector<ObserverAttention> attention; // in first-appearance order
    bool hasSides = false;                    // any trial with a known A_on_left
    std::vector<ExcludedObserver> excluded;   // left out by the protocol's rule before the dataset was built
};

struct DatasetOptions {
    std::vector<std::string> conditionOrder; // if set: the conditions, in this order; others are an error
    std::string onlyBlock;                   // if set: analyse only this block
    bool singleBlock = false;                // if set: more than one block in the file is an error
};

Dataset buildDataset(const ResponseTable& table, const DatasetOptions& options);

} // namespace skinlab::analysis::scaling
