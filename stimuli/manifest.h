#pragma once
// The stimulus manifest (contract 2, docs/stimuli.md): manifest.json in the set's folder, describing every image
// completely (factor levels, fully resolved scene parameters, renderer, sha256 of each file, timings), plus a
// CSV view (manifest.csv, one row per stimulus). Both are rewritten atomically after every stimulus.
#include "formats/stimulus_manifest.h"
#include "stimuli/expansion.h"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::stimuli {

using formats::kManifestFile;
using formats::kManifestFormat;
using formats::kManifestVersion;
inline constexpr const char* kManifestCsvFile = "manifest.csv";

struct RendererInfo {
    std::string glRenderer;
    std::string glVersion;
    std::string skinlabVersion;
    bool operator==(const RendererInfo&) const = default;
};

struct Manifest {
    std::string set;
    std::string description;
    std::optional<std::int64_t> seed;
    std::string specFile; // file name of the spec (informational)
    std::string specSha256;
    RendererInfo renderer;                            // empty gl strings until something was rendered
    nlohmann::json fixed = nlohmann::json::object();  // fixed scene key → value
    nlohmann::json factors = nlohmann::json::array(); // [{name, key, levels: [{value, label}]}]
    std::optional<Shard> shard;                       // present in a shard's folder
    std::vector<std::string> setIds;                  // every id of the whole set, in expansion order (for merge)
    // The entries (contract 2), in expansion order: typed from the strict reader (formats::manifestEntryFromJson) to
    // the one writer (formats::toJson in writeManifest).
    std::vector<formats::ManifestEntry> stimuli;
    // True when `stimuli` holds every stimulus of this folder's selection (the set, or the shard's slice).
    bool complete = false;
};

// The manifest header of a spec (no stimuli yet).
Manifest manifestHeader(const SetSpec& spec, const std::vector<Stimulus>& all, std::optional<Shard> shard);

nlohmann::json toJson(const Manifest& manifest);
// Throws InputError naming `source` when the JSON is not a skinlab stimulus manifest of a known version.
Manifest manifestFromJson(const nlohmann::json& json, const std::string& source);

// Reads DIR/manifest.json; std::nullopt when the folder has none.
std::optional<Manifest> readManifest(const std::filesystem::path& dir);
// Writes DIR/manifest.json and DIR/manifest.csv atomically.
void writeManifest(const std::filesystem::path& dir, const Manifest& manifest);
// The CSV view: id, block, reference, one column per factor, files, hashes, size, render time.
std::string manifestCsv(const Manifest& manifest);

// Looks up a dotted key ("render.width") in a JSON object; nullptr when absent.
const nlohmann::json* findDotted(const nlohmann::json& json, const std::string& dottedKey);

} // namespace skinlab::stimuli
