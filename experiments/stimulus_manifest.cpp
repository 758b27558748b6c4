#include "experiments/stimulus_manifest.h"

#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"

namespace skinlab::experiments {
namespace fs = std::filesystem;

const ManifestStimulus* StimulusManifest::find(const std::string& id) const {
    for (const ManifestStimulus& s : stimuli)
        if (s.id == id) return &s;
    return nullptr;
}

namespace {

// A manifest path must be relative and stay inside the set's folder: the server later serves exactly these
// files, so a manifest must not be able to point it at /etc/passwd.
bool staysInside(const std::string& relative) {
    if (relative.empty()) return false;
    fs::path p(relative);
    if (p.is_absolute() || p.has_root_name() || p.has_root_directory()) return false;
    for (const fs::path& part : p)
        if (part == "..") return false;
    return true;
}

std::string factorText(const nlohmann::json& value) {
    if (value.is_string()) return value.get<std::string>();
    return value.dump();
}

} // namespace

StimulusManifest readStimulusManifest(const fs::path& folder) {
    StimulusManifest manifest;
    std::error_code ec;
    manifest.folder = fs::absolute(folder, ec);
    const fs::path file = manifest.folder / "manifest.json";
    const std::string where = (folder / "manifest.json").string();
    if (!fs::is_regular_file(file)) throwInput(where, "", "no manifest.json in the stimulus folder");
    manifest.text = readFile(file);
    manifest.sha256 = sha256Hex(manifest.text);
    nlohmann::json root;
    try {
        root = nlohmann::json::parse(manifest.text);
    } catch (const nlohmann::json::parse_error& e) {
        throwInput(where, "", std::string("not valid JSON: ") + e.what());
    }
    if (!root.is_object()) throwInput(where, "", "expected a JSON object");
    if (root.value("format", std::string()) != "skinlab-stimuli")
        throwInput(where, "format", "expected \"skinlab-stimuli\"");
    if (!root.contains("version") || !root["version"].is_number_integer() || root["version"].get<int>() != 1)
        throwInput(where, "version", "expected 1 (the only manifest version this build reads)");
    manifest.set = root.value("set", std::string());
    if (!root.contains("stimuli") || !root["stimuli"].is_array() || root["stimuli"].empty())
        throwInput(where, "stimuli", "expected a non-empty array");
    std::size_t index = 0;
    for (const nlohmann::json& entry : root["stimuli"]) {
        const std::string key = "stimuli[" + std::to_string(index++) + "]";
        if (!entry.is_object()) throwInput(where, key, "expected an object");
        ManifestStimulus s;
        auto requireString = [&](const nlohmann::json& obj, const char* name, const std::string& path) {
            if (!obj.contains(name) || !obj[name].is_string() || obj[name].get<std::string>().empty())
                throwInput(where, path, "expected a non-empty string");
            return obj[name].get<std::string>();
        };
        s.id = requireString(entry, "id", key + ".id");
        if (manifest.find(s.id)) throwInput(where, key + ".id", "duplicate stimulus id \"" + s.id + "\"");
        if (!entry.contains("files") || !entry["files"].is_object())
            throwInput(where, key + ".files", "expected an object with a \"png\" path");
        s.pngPath = requireString(entry["files"], "png", key + ".files.png");
        if (!staysInside(s.pngPath))
            throwInput(where, key + ".files.png", "path leaves the stimulus folder: " + s.pngPath);
        if (entry.contains("sha256") && entry["sha256"].is_object() && entry["sha256"].contains("png") &&
            entry["sha256"]["png"].is_string())
            s.pngSha256 = entry["sha256"]["png"].get<std::string>();
        else throwInput(where, key + ".sha256.png", "expected the PNG's sha256 (hex)");
        s.block = requireString(entry, "block", key + ".block");
        s.reference = entry.value("reference", false);
        for (const char* dim : {"width", "height"}) {
            if (!entry.contains(dim) || !entry[dim].is_number_integer() || entry[dim].get<int>() < 1 ||
                entry[dim].get<int>() > 16384)
                throwInput(where, key + "." + dim, "expected an integer in [1, 16384]");
        }
        s.width = entry["width"].get<int>();
        s.height = entry["height"].get<int>();
        if (entry.contains("factors")) {
            if (!entry["factors"].is_object()) throwInput(where, key + ".factors", "expected an object");
            for (auto it = entry["factors"].begin(); it != entry["factors"].end(); ++it)
                s.factors[it.key()] = factorText(it.value());
        }
        manifest.stimuli.push_back(std::move(s));
    }
    return manifest;
}

void verifyStimulusFiles(const StimulusManifest& manifest, const std::vector<std::string>& ids) {
    for (const std::string& id : ids) {
        const ManifestStimulus* s = manifest.find(id);
        if (!s)
            throwInput((manifest.folder / "manifest.json").string(), "stimuli", "no stimulus with id \"" + id + "\"");
        const fs::path png = manifest.folder / s->pngPath;
        if (!fs::is_regular_file(png)) throwInput(png.string(), "", "stimulus image missing (stimulus \"" + id + "\")");
        if (sha256File(png) != s->pngSha256)
            throwInput(png.string(), "",
                       "sha256 differs from the manifest (stimulus \"" + id +
                           "\"); the set changed after it was built");
    }
}

} // namespace skinlab::experiments
