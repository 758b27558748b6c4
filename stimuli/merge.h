#pragma once
// `skinlab stimuli merge DIR... -o OUT`: joins the shard folders of one set (built with --shard i/n, possibly on
// different machines) into one set folder equal to a full build: same ids, same files, same hashes, the stimuli
// in the set's order. Refuses shards of different sets, specs or renderers, incomplete or missing shards, and
// files whose sha256 does not match their manifest — before writing anything.
#include <filesystem>
#include <vector>

namespace skinlab::stimuli {

struct MergeSummary {
    size_t stimuli = 0;
    std::filesystem::path manifest;
    std::filesystem::path contactHtml;
};

MergeSummary mergeShards(const std::vector<std::filesystem::path>& shardDirs, const std::filesystem::path& outputDir,
                         bool contactSheet = true);

} // namespace skinlab::stimuli
