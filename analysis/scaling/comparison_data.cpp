#include "analysis/scaling/comparison_data.h"

#include "common/error.h"

#include <algorithm>
#include <map>

namespace skinlab::analysis::scaling {
namespace {

// Indexes names in first-appearance order.
struct NameIndex {
    std::vector<std::string> names;
    std::map<std::string, int> index;
    int add(const std::string& name) {
        const auto [it, inserted] = index.emplace(name, static_cast<int>(names.size()));
        if (inserted) names.push_back(name);
        return it->second;
    }
    int find(const std::string& name) const {
        const auto it = index.find(name);
        return it == index.end() ? -1 : it->second;
    }
};

std::string joined(const std::vector<std::string>& names) {
    std::string out;
    for (const auto& name : names) out += (out.empty() ? "" : ",") + name;
    return out;
}

BlockData blockFromMatrix(const ResponseTable& table, const DatasetOptions& options) {
    BlockData block;
    block.name = std::filesystem::path(table.file).stem().string();
    block.hasObservers = false;
    block.observers = {"(count matrix)"};
    const size_t m = table.matrixConditions.size();
    std::vector<int> order(m); // order[k] = position in the header of the k-th analysed condition
    if (options.conditionOrder.empty()) {
        block.conditions = table.matrixConditions;
        for (size_t k = 0; k < m; ++k) order[k] = static_cast<int>(k);
    } else {
        for (const auto& name : table.matrixConditions)
            if (std::find(options.conditionOrder.begin(), options.conditionOrder.end(), name) ==
                options.conditionOrder.end())
                throwInput(table.file, "line 1: column " + name,
                           "unknown condition '" + name + "' (not in --conditions " + joined(options.conditionOrder) +
                               ")");
        if (options.conditionOrder.size() != m)
            throwInput(table.file, "--conditions", "lists conditions that are not in the count matrix");
        block.conditions = options.conditionOrder;
        for (size_t k = 0; k < m; ++k)
            order[k] = static_cast<int>(
                std::find(table.matrixConditions.begin(), table.matrixConditions.end(), options.conditionOrder[k]) -
                table.matrixConditions.begin());
    }
    std::vector<double> first, second;
    for (size_t i = 0; i < m; ++i)
        for (size_t j = i + 1; j < m; ++j) {
            const double ij = table.matrixCounts[order[i] * m + order[j]];
            const double ji = table.matrixCounts[order[j] * m + order[i]];
            if (ij + ji <= 0) continue;
            block.pairs.emplace_back(static_cast<int>(i), static_cast<int>(j));
            first.push_back(ij);
            second.push_back(ji);
        }
    const auto pairCount = static_cast<Eigen::Index>(block.pairs.size());
    block.winsFirst = Eigen::Map<Eigen::RowVectorXd>(first.data(), pairCount);
    block.winsSecond = Eigen::Map<Eigen::RowVectorXd>(second.data(), pairCount);
    block.sideCounts.assign(block.pairs.size(), {0, 0, 0, 0});
    block.leftChosen = Eigen::VectorXd::Zero(1);
    block.sideTrials = Eigen::VectorXd::Zero(1);
    return block;
}

// Blocks, and per block its conditions and observers, in first-appearance order.
struct ResponseNames {
    NameIndex blocks;
    std::vector<NameIndex> conditions, observers;
};

// Pass 1: blocks, conditions and observers in first-appearance order, with the input checks; each observer's
// attention trials into dataset.attention.
ResponseNames indexResponses(const ResponseTable& table, const DatasetOptions& options, Dataset& dataset) {
    ResponseNames names;
    NameIndex& blocks = names.blocks;
    std::vector<NameIndex>& conditions = names.conditions;
    std::vector<NameIndex>& observers = names.observers;
    NameIndex allObservers;
    std::map<std::string, int> firstLineOfBlock;
    for (const Response& r : table.responses) {
        const std::string blockName = r.block.empty() ? "all" : r.block;
        if (options.singleBlock && blocks.names.size() == 1 && blocks.find(blockName) < 0)
            throwInput(table.file, "line " + std::to_string(r.line) + ": column scene",
                       "block '" + blockName + "' differs from block '" + blocks.names.front() + "' of line " +
                           std::to_string(firstLineOfBlock.at(blocks.names.front())) +
                           " (--single-block allows one block per file)");
        firstLineOfBlock.emplace(blockName, r.line);
        const int b = blocks.add(blockName);
        if (static_cast<size_t>(b) == conditions.size()) {
            conditions.emplace_back();
            observers.emplace_back();
            if (!options.conditionOrder.empty())
                for (const auto& name : options.conditionOrder) conditions[b].add(name);
        }
        const int attentionIndex = allObservers.add(r.observer);
        if (static_cast<size_t>(attentionIndex) == dataset.attention.size()) dataset.attention.push_back({r.observer});
        ObserverAttention& attention = dataset.attention[attentionIndex];
        if (r.aOnLeft) dataset.hasSides = true;
        if (r.kind == TrialKind::catchTrial) {
            ++attention.catchTrials;
            if (r.correct && !*r.correct) ++attention.catchFailures;
            continue;
        }
        if (r.kind == TrialKind::practice) {
            ++attention.practiceTrials;
            continue;
        }
        ++attention.scaledTrials;
        for (const auto& [name, column] : {std::pair{&r.conditionA, "condition_A"}, {&r.conditionB, "condition_B"}}) {
            if (!options.conditionOrder.empty() && conditions[b].find(*name) < 0)
                throwInput(table.file, "line " + std::to_string(r.line) + ": column " + column,
                           "unknown condition '" + *name + "' (not in --conditions " + joined(options.conditionOrder) +
                               ")");
            conditions[b].add(*name);
        }
        observers[b].add(r.observer);
    }
    return names;
}

// A study database lists each block's conditions in the design's order (conditions it does not name follow
// in first-appearance order), so the CLI, the dashboard and the report show them alike.
void orderByDesign(const ResponseTable& table, ResponseNames& seen) {
    std::vector<NameIndex>& conditions = seen.conditions;
    for (size_t b = 0; b < conditions.size(); ++b) {
        const auto design = table.designConditionOrder.find(seen.blocks.names[b]);
        if (design == table.designConditionOrder.end()) continue;
        auto rank = [&](const std::string& name) {
            const auto it = std::find(design->second.begin(), design->second.end(), name);
            return it - design->second.begin();
        };
        std::vector<std::string> names = conditions[b].names;
        std::stable_sort(names.begin(), names.end(),
                         [&](const std::string& x, const std::string& y) { return rank(x) < rank(y); });
        conditions[b] = NameIndex();
        for (const std::string& name : names) conditions[b].add(name);
    }
}

// Pass 2: counts.
std::vector<BlockData> countResponses(const ResponseTable& table, const ResponseNames& names) {
    const NameIndex& blocks = names.blocks;
    const std::vector<NameIndex>& conditions = names.conditions;
    const std::vector<NameIndex>& observers = names.observers;
    std::vector<BlockData> built(blocks.names.size());
    std::vector<std::map<std::pair<int, int>, int>> pairIndex(blocks.names.size());
    for (size_t b = 0; b < built.size(); ++b) {
        built[b].name = blocks.names[b];
        built[b].conditions = conditions[b].names;
        built[b].observers = observers[b].names;
        const auto n = static_cast<Eigen::Index>(built[b].observers.size());
        built[b].leftChosen = Eigen::VectorXd::Zero(n);
        built[b].sideTrials = Eigen::VectorXd::Zero(n);
    }
    // Pairs first (to size the matrices), then the wins.
    for (const Response& r : table.responses) {
        if (r.kind == TrialKind::catchTrial || r.kind == TrialKind::practice) continue;
        const int b = blocks.find(r.block.empty() ? "all" : r.block);
        int a = conditions[b].find(r.conditionA), c = conditions[b].find(r.conditionB);
        const std::pair<int, int> key{std::min(a, c), std::max(a, c)};
        if (pairIndex[b].emplace(key, static_cast<int>(built[b].pairs.size())).second) built[b].pairs.push_back(key);
    }
    for (size_t b = 0; b < built.size(); ++b) {
        const auto n = static_cast<Eigen::Index>(built[b].observers.size());
        const auto pairCount = static_cast<Eigen::Index>(built[b].pairs.size());
        built[b].winsFirst = Eigen::MatrixXd::Zero(n, pairCount);
        built[b].winsSecond = Eigen::MatrixXd::Zero(n, pairCount);
        built[b].sideCounts.assign(built[b].pairs.size(), {0, 0, 0, 0});
    }
    for (const Response& r : table.responses) {
        if (r.kind == TrialKind::catchTrial || r.kind == TrialKind::practice) continue;
        const int b = blocks.find(r.block.empty() ? "all" : r.block);
        BlockData& block = built[b];
        const int a = conditions[b].find(r.conditionA), c = conditions[b].find(r.conditionB);
        const int p = pairIndex[b].at({std::min(a, c), std::max(a, c)});
        const int o = observers[b].find(r.observer);
        const bool aIsFirst = a < c;
        const bool firstChosen = r.aSelected == aIsFirst;
        (firstChosen ? block.winsFirst : block.winsSecond)(o, p) += 1.0;
        if (r.aOnLeft) {
            const bool firstOnLeft = *r.aOnLeft == aIsFirst;
            block.sideCounts[p][(firstOnLeft ? 0 : 2) + (firstChosen ? 0 : 1)] += 1.0;
            block.sideTrials[o] += 1.0;
            if (r.aSelected == *r.aOnLeft) block.leftChosen[o] += 1.0;
        }
    }
    return built;
}

} // namespace

PairCounts BlockData::weightedCounts(const Eigen::VectorXd& observerWeights) const {
    PairCounts counts;
    counts.conditions = conditionCount();
    counts.pairs = pairs;
    counts.first = winsFirst.transpose() * observerWeights;
    counts.second = winsSecond.transpose() * observerWeights;
    return counts;
}

PairCounts BlockData::totalCounts() const { return weightedCounts(Eigen::VectorXd::Ones(observerCount())); }

Eigen::MatrixXd BlockData::countMatrix() const {
    const PairCounts totals = totalCounts();
    Eigen::MatrixXd matrix = Eigen::MatrixXd::Zero(conditionCount(), conditionCount());
    for (size_t p = 0; p < pairs.size(); ++p) {
        matrix(pairs[p].first, pairs[p].second) = totals.first[static_cast<Eigen::Index>(p)];
        matrix(pairs[p].second, pairs[p].first) = totals.second[static_cast<Eigen::Index>(p)];
    }
    return matrix;
}

Dataset buildDataset(const ResponseTable& table, const DatasetOptions& options) {
    Dataset dataset;
    dataset.file = table.file;
    dataset.format = table.format;
    dataset.excluded = table.excludedObservers;
    if (table.format == ResponseFormat::CountMatrix) {
        dataset.blocks.push_back(blockFromMatrix(table, options));
        if (!options.onlyBlock.empty() && options.onlyBlock != dataset.blocks.front().name)
            throwInput(table.file, "--block",
                       "no block '" + options.onlyBlock + "' (a count matrix has one block, '" +
                           dataset.blocks.front().name + "')");
        return dataset;
    }

    ResponseNames names = indexResponses(table, options, dataset);
    if (options.conditionOrder.empty()) orderByDesign(table, names);
    if (!options.onlyBlock.empty() && names.blocks.find(options.onlyBlock) < 0)
        throwInput(table.file, "--block",
                   "no block '" + options.onlyBlock + "' (blocks: " + joined(names.blocks.names) + ")");

    std::vector<BlockData> built = countResponses(table, names);
    for (size_t b = 0; b < built.size(); ++b) {
        if (!options.onlyBlock.empty() && built[b].name != options.onlyBlock) continue;
        if (built[b].pairs.empty()) continue; // a block with only catch/practice trials has nothing to scale
        dataset.blocks.push_back(std::move(built[b]));
    }
    if (dataset.blocks.empty())
        throwInput(table.file, "", "no test or repeat trials to scale (only catch or practice trials)");
    return dataset;
}

} // namespace skinlab::analysis::scaling
