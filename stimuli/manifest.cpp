#include "stimuli/manifest.h"

#include "common/csv.h"
#include "common/error.h"
#include "common/files.h"

#include <cstdio>
#include <sstream>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

Manifest manifestHeader(const SetSpec& spec, const std::vector<Stimulus>& all, std::optional<Shard> shard) {
    Manifest m;
    m.set = spec.name;
    m.description = spec.description;
    m.seed = spec.seed;
    m.specFile = spec.file.filename().string();
    m.specSha256 = spec.sha256;
    for (const auto& p : spec.fixed) m.fixed[p.key] = p.level.json;
    for (const auto& f : spec.factors) {
        nlohmann::json levels = nlohmann::json::array();
        for (const auto& l : f.levels) levels.push_back({{"value", l.value}, {"label", l.label}});
        m.factors.push_back({{"name", f.name}, {"key", f.key}, {"levels", levels}});
    }
    m.shard = shard;
    for (const auto& s : all) m.setIds.push_back(s.id);
    return m;
}

nlohmann::json toJson(const Manifest& m) {
    nlohmann::json j;
    j["format"] = kManifestFormat;
    j["version"] = kManifestVersion;
    j["set"] = m.set;
    j["description"] = m.description;
    j["seed"] = m.seed ? nlohmann::json(*m.seed) : nlohmann::json(nullptr);
    j["spec"] = m.specFile;
    j["spec_sha256"] = m.specSha256;
    j["renderer"] = {{"gl_renderer", m.renderer.glRenderer},
                     {"gl_version", m.renderer.glVersion},
                     {"skinlab_version", m.renderer.skinlabVersion}};
    j["fixed"] = m.fixed;
    j["factors"] = m.factors;
    if (m.shard) j["shard"] = {{"index", m.shard->index}, {"count", m.shard->count}};
    j["set_ids"] = m.setIds;
    j["complete"] = m.complete;
    j["stimuli"] = nlohmann::json::array();
    for (const formats::ManifestEntry& entry : m.stimuli) j["stimuli"].push_back(formats::toJson(entry));
    return j;
}

Manifest manifestFromJson(const nlohmann::json& j, const std::string& source) {
    formats::checkManifestFormat(j, source);
    try {
        Manifest m;
        m.set = j.at("set").get<std::string>();
        m.description = j.value("description", "");
        if (j.contains("seed") && !j["seed"].is_null()) m.seed = j["seed"].get<std::int64_t>();
        m.specFile = j.value("spec", "");
        m.specSha256 = j.at("spec_sha256").get<std::string>();
        const auto& r = j.at("renderer");
        m.renderer = {r.at("gl_renderer").get<std::string>(), r.at("gl_version").get<std::string>(),
                      r.at("skinlab_version").get<std::string>()};
        m.fixed = j.value("fixed", nlohmann::json::object());
        m.factors = j.value("factors", nlohmann::json::array());
        if (j.contains("shard")) m.shard = Shard{j["shard"].at("index").get<int>(), j["shard"].at("count").get<int>()};
        m.setIds = j.at("set_ids").get<std::vector<std::string>>();
        m.complete = j.value("complete", false);
        m.stimuli = formats::manifestEntriesFromJson(j.at("stimuli"), source); // the one strict reader of the entries
        return m;
    } catch (const nlohmann::json::exception& e) {
        throwInput(source, "", std::string("malformed manifest (") + e.what() + ")");
    }
}

std::optional<Manifest> readManifest(const fs::path& dir) {
    fs::path path = dir / kManifestFile;
    if (!fs::exists(path)) return std::nullopt;
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(readFile(path));
    } catch (const nlohmann::json::parse_error& e) {
        throwInput(path.string(), "", std::string("not valid JSON (") + e.what() + ")");
    }
    return manifestFromJson(j, path.string());
}

void writeManifest(const fs::path& dir, const Manifest& manifest) {
    writeFileAtomic(dir / kManifestCsvFile, manifestCsv(manifest));
    writeFileAtomic(dir / kManifestFile, toJson(manifest).dump(2) + "\n");
}

namespace {

std::string wallText(const nlohmann::json& j) {
    if (!j.is_number()) return "";
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.1f", j.get<double>());
    return buffer;
}
} // namespace

std::string manifestCsv(const Manifest& m) {
    std::vector<std::string> factorNames;
    for (const auto& f : m.factors) factorNames.push_back(f.at("name").get<std::string>());
    for (const formats::ManifestEntry& s : m.stimuli) // extra keys of [[include]]/[[reference]] entries
        for (auto it = s.factors.begin(); it != s.factors.end(); ++it)
            if (std::find(factorNames.begin(), factorNames.end(), it.key()) == factorNames.end())
                factorNames.push_back(it.key());
    std::ostringstream out;
    out << "id,block,reference";
    for (const auto& n : factorNames) out << ',' << csvField(n);
    out << ",exr,png,sha256_exr,sha256_png,width,height,wall_ms\n";
    for (const formats::ManifestEntry& s : m.stimuli) {
        out << csvField(s.id) << ',' << csvField(s.block) << ',' << (s.reference ? 1 : 0);
        for (const auto& n : factorNames) out << ',' << (s.factors.contains(n) ? csvField(s.factorText(n)) : "");
        out << ',' << csvField(s.files.exr) << ',' << csvField(s.files.png) << ',' << s.sha256.exr << ','
            << s.sha256.png << ',' << s.width << ',' << s.height << ','
            << wallText(s.timingsMs.value("stimulus_wall", nlohmann::json())) << '\n';
    }
    return out.str();
}

const nlohmann::json* findDotted(const nlohmann::json& json, const std::string& dottedKey) {
    const nlohmann::json* node = &json;
    size_t start = 0;
    while (true) {
        size_t dot = dottedKey.find('.', start);
        std::string part = dottedKey.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
        if (!node->is_object() || !node->contains(part)) return nullptr;
        node = &(*node)[part];
        if (dot == std::string::npos) return node;
        start = dot + 1;
    }
}

} // namespace skinlab::stimuli
