#include "stimuli/merge.h"

#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"
#include "stimuli/contact_sheet.h"
#include "stimuli/manifest.h"
#include "stimuli/output_folder.h"

#include <map>
#include <set>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

namespace {
std::string shardName(const Shard& s) { return std::to_string(s.index) + "/" + std::to_string(s.count); }
// A built stimulus's two files: relative path and sha256 of its EXR, then of its PNG.
std::vector<std::pair<std::string, std::string>> filesOf(const formats::ManifestEntry& entry) {
    return {{entry.files.exr, entry.sha256.exr}, {entry.files.png, entry.sha256.png}};
}
} // namespace

MergeSummary mergeShards(const std::vector<fs::path>& shardDirs, const fs::path& outputDir, bool contactSheet) {
    if (shardDirs.empty()) throwInput("merge", "", "no shard folders given");
    std::vector<Manifest> shards;
    for (const auto& dir : shardDirs) {
        if (fs::exists(outputDir) && fs::exists(dir) && fs::equivalent(dir, outputDir))
            throwInput(dir.string(), "", "is also the output folder; merge into a new folder");
        std::optional<Manifest> m = readManifest(dir);
        if (!m) throwInput(dir.string(), "", "holds no stimulus set (no manifest.json)");
        if (!m->shard) throwInput(dir.string(), "", "is not a shard (built without --shard i/n)");
        if (!m->complete)
            throwInput(dir.string(), "", "shard " + shardName(*m->shard) + " is incomplete; rerun its build first");
        shards.push_back(std::move(*m));
    }
    const Manifest& first = shards.front();
    // Shards that disagree about the set or the spec (another spec file, another version of it, other --set
    // overrides): name every shard of each version, so the odd ones can be rebuilt.
    std::map<std::string, std::vector<size_t>> bySpec; // set + spec_sha256 → shards
    for (size_t i = 0; i < shards.size(); ++i) bySpec[shards[i].set + "\n" + shards[i].specSha256].push_back(i);
    if (bySpec.size() > 1) {
        std::string versions;
        for (const auto& [key, members] : bySpec) {
            const Manifest& m = shards[members.front()];
            versions += (versions.empty() ? "" : "; ") + std::string("set '") + m.set + "' spec '" + m.specFile +
                        "' sha256 " + m.specSha256.substr(0, 12) + " in";
            for (size_t i : members)
                versions += " " + shardDirs[i].string() + " (shard " + shardName(*shards[i].shard) + ")";
        }
        throwInput("merge", "",
                   "the shards disagree about the spec: " + versions +
                       "; rebuild the odd shards from the same spec and --set values");
    }
    std::map<int, size_t> byIndex;
    for (size_t i = 0; i < shards.size(); ++i) {
        const Manifest& m = shards[i];
        const std::string where = shardDirs[i].string();
        if (m.set != first.set) throwInput(where, "", "holds set '" + m.set + "', not '" + first.set + "'");
        if (m.specSha256 != first.specSha256 || m.setIds != first.setIds)
            throwInput(where, "",
                       "was built from another version of spec '" + first.specFile + "' (spec_sha256 differs)");
        if (!m.stimuli.empty() && !first.stimuli.empty() && !(m.renderer == first.renderer))
            throwInput(where, "",
                       "was rendered by '" + m.renderer.glRenderer + "' (skinlab " + m.renderer.skinlabVersion +
                           "), the first shard by '" + first.renderer.glRenderer + "' (skinlab " +
                           first.renderer.skinlabVersion + "); a set must come from one renderer");
        if (m.shard->count != first.shard->count)
            throwInput(where, "",
                       "is shard " + shardName(*m.shard) + ", the first is shard " + shardName(*first.shard));
        if (byIndex.count(m.shard->index)) throwInput(where, "", "shard " + shardName(*m.shard) + " is given twice");
        byIndex[m.shard->index] = i;
    }
    for (int k = 1; k <= first.shard->count; ++k)
        if (!byIndex.count(k))
            throwInput("merge", "",
                       "shard " + std::to_string(k) + "/" + std::to_string(first.shard->count) + " of set '" +
                           first.set + "' is missing");

    // Gather the entries in the set's order and check every file against its hash before writing anything.
    std::map<std::string, std::pair<const formats::ManifestEntry*, size_t>> entries; // id → entry, shard
    for (size_t i = 0; i < shards.size(); ++i)
        for (const formats::ManifestEntry& s : shards[i].stimuli) entries[s.id] = {&s, i};
    Manifest merged = first;
    merged.shard.reset();
    merged.stimuli.clear();
    for (const auto& id : first.setIds) {
        auto it = entries.find(id);
        if (it == entries.end()) throwInput("merge", "", "stimulus '" + id + "' is in no shard");
        const formats::ManifestEntry& entry = *it->second.first;
        merged.stimuli.push_back(entry);
        for (const auto& [relative, sha256] : filesOf(entry)) {
            const fs::path file = shardDirs[it->second.second] / relative;
            if (!fs::is_regular_file(file)) throwInput(file.string(), "", "missing (listed in its shard's manifest)");
            if (sha256File(file) != sha256)
                throwInput(file.string(), "", "sha256 does not match its shard's manifest; rebuild that shard");
        }
    }
    for (const auto& m : shards)
        if (!m.stimuli.empty()) merged.renderer = m.renderer;
    merged.complete = true;

    std::optional<Manifest> existing = claimOutputFolder(outputDir, merged.set, std::nullopt);
    (void)existing;
    ensureDirectory(outputDir / "exr");
    ensureDirectory(outputDir / "png");
    for (const formats::ManifestEntry& s : merged.stimuli) {
        const auto& source = entries[s.id];
        for (const auto& [relative, sha256] : filesOf(s)) {
            AtomicOutput out(outputDir / relative);
            fs::copy_file(shardDirs[source.second] / relative, out.tempPath(), fs::copy_options::overwrite_existing);
            out.commit();
        }
    }
    tidyOutputFolder(outputDir, first.setIds);
    writeManifest(outputDir, merged);
    MergeSummary summary;
    summary.stimuli = merged.stimuli.size();
    summary.manifest = outputDir / kManifestFile;
    if (contactSheet) summary.contactHtml = writeContactSheet(outputDir, merged).html;
    return summary;
}

} // namespace skinlab::stimuli
