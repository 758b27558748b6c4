#pragma once
// Expansion of a stimulus-set spec into its list of stimuli: the full factorial of the factors minus the
// [[exclude]] combinations, plus [[include]] and [[reference]] entries (each expanded over the block factors they
// do not name), each with its id, block and the scene-spec overrides that make it.
#include "stimuli/set_spec.h"

#include <string>
#include <utility>
#include <vector>

namespace skinlab::stimuli {

struct Stimulus {
    std::string id;
    std::string block;      // block factors' values joined by '/', e.g. "builtin:head/mid"
    bool reference = false; // from a [[reference]] entry
    std::string scene;      // what RenderRequest::scene gets: "builtin:NAME" or an absolute scene spec path
    std::vector<std::pair<std::string, Level>> factors; // factor name → level, in factor order (scene first)
    std::vector<std::string> overrides;                 // "key=value": fixed parameters, then the levels
    size_t index = 0;                                   // position in the full expansion (shards keep it)
    Presentation presentation; // crop and magnification: the first matching [[crop]], else [fixed]
};

// Expands the spec. Throws InputError ("SPEC: KEY: message") for an empty factorial, clashing ids, or an
// [[include]] that duplicates a stimulus.
std::vector<Stimulus> expand(const SetSpec& spec);

// A shard: stimuli whose full-expansion index k has k mod count == index - 1 (round robin, so every shard gets
// a similar mix of blocks and methods). index is 1-based.
struct Shard {
    int index = 1;
    int count = 1;
};
// Parses "i/n" (1 ≤ i ≤ n); throws InputError naming `option`.
Shard parseShard(const std::string& text, const std::string& option = "--shard");
std::vector<Stimulus> selectShard(const std::vector<Stimulus>& all, const Shard& shard);

} // namespace skinlab::stimuli
