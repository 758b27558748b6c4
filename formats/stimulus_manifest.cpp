#include "formats/stimulus_manifest.h"

#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"

#include <cmath>
#include <limits>
#include <set>

namespace skinlab::formats {

namespace fs = std::filesystem;

namespace {

// A manifest path must be relative and stay inside the set's folder: the study server later serves exactly these
// files, so a manifest must not be able to point it at /etc/passwd.
bool staysInside(const std::string& relative) {
    if (relative.empty()) return false;
    fs::path p(relative);
    if (p.is_absolute() || p.has_root_name() || p.has_root_directory()) return false;
    for (const fs::path& part : p)
        if (part == "..") return false;
    return true;
}

// Reads the members of one JSON object, naming "FILE: PREFIX.KEY" in every error.
class Members {
public:
    Members(const nlohmann::json& object, const std::string& file, const std::string& prefix)
        : object_(object), file_(file), prefix_(prefix) {
        if (!object.is_object()) throwInput(file_, prefix_, "expected an object, not " + object.dump());
    }
    std::string key(const std::string& name) const { return prefix_ + "." + name; }
    const nlohmann::json* find(const std::string& name) const {
        return object_.contains(name) ? &object_.at(name) : nullptr;
    }
    const nlohmann::json& required(const std::string& name) const {
        if (const nlohmann::json* value = find(name)) return *value;
        throwInput(file_, key(name), "missing");
    }
    std::string string(const std::string& name) const {
        const nlohmann::json& value = required(name);
        if (!value.is_string() || value.get<std::string>().empty())
            throwInput(file_, key(name), "expected a non-empty string, not " + value.dump());
        return value.get<std::string>();
    }
    std::string optionalString(const std::string& name) const {
        const nlohmann::json* value = find(name);
        if (!value) return "";
        if (!value->is_string()) throwInput(file_, key(name), "expected a string, not " + value->dump());
        return value->get<std::string>();
    }
    bool optionalBool(const std::string& name) const {
        const nlohmann::json* value = find(name);
        if (!value) return false;
        if (!value->is_boolean()) throwInput(file_, key(name), "expected true or false, not " + value->dump());
        return value->get<bool>();
    }
    int size(const std::string& name) const {
        const nlohmann::json& value = required(name);
        if (!value.is_number_integer() || value.get<std::int64_t>() < 1 || value.get<std::int64_t>() > 16384)
            throwInput(file_, key(name), "expected an integer in [1, 16384], not " + value.dump());
        return value.get<int>();
    }
    // A finite number in [low, high] (`what` says so in the error).
    double number(const std::string& name, double low, double high, const std::string& what) const {
        const nlohmann::json& value = required(name);
        if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < low ||
            value.get<double>() > high)
            throwInput(file_, key(name), "expected " + what + ", not " + value.dump());
        return value.get<double>();
    }
    std::optional<nlohmann::json> optionalObject(const std::string& name) const {
        const nlohmann::json* value = find(name);
        if (!value) return std::nullopt;
        if (!value->is_object()) throwInput(file_, key(name), "expected an object, not " + value->dump());
        return *value;
    }
    std::string relativePath(const std::string& name) const {
        const std::string path = string(name);
        if (!staysInside(path)) throwInput(file_, key(name), "path leaves the stimulus folder: " + path);
        return path;
    }

private:
    const nlohmann::json& object_;
    const std::string& file_;
    std::string prefix_;
};

} // namespace

std::string ManifestEntry::factorText(const std::string& name) const {
    if (!factors.contains(name)) return "";
    const nlohmann::json& value = factors.at(name);
    return value.is_string() ? value.get<std::string>() : value.dump();
}

nlohmann::json toJson(const DisplayModel& d) {
    nlohmann::json j = {{"description", d.description},
                        {"eotf", d.eotf},
                        {"peak_luminance", d.peakLuminance},
                        {"contrast", d.contrast},
                        {"ambient_illuminance", d.ambientIlluminance},
                        {"reflectivity", d.reflectivity},
                        {"pixels_per_degree", d.pixelsPerDegree}};
    if (d.resolutionWidth > 0) j["resolution"] = {d.resolutionWidth, d.resolutionHeight};
    if (d.diagonalInches > 0.0) j["diagonal_in"] = d.diagonalInches;
    if (d.viewingDistanceMetres > 0.0) j["viewing_distance_m"] = d.viewingDistanceMetres;
    return j;
}

nlohmann::json toJson(const Prediction& p) {
    nlohmann::json j = {{"metric", p.metric},
                        {"display", p.display},
                        {"reference", p.reference},
                        {"jod", p.jod},
                        {"reference_png_sha256", p.referencePngSha256},
                        {"png_sha256", p.pngSha256}};
    if (p.displayModel) j["display_model"] = toJson(*p.displayModel);
    return j;
}

namespace {

DisplayModel displayModelFromJson(const Members& d, const std::string& file) {
    constexpr double kMax = std::numeric_limits<double>::max();
    DisplayModel model;
    model.description = d.optionalString("description");
    model.eotf = d.string("eotf");
    model.peakLuminance = d.number("peak_luminance", std::numeric_limits<double>::min(), kMax, "a positive number");
    model.contrast = d.number("contrast", 1.0, kMax, "a number >= 1");
    model.ambientIlluminance = d.number("ambient_illuminance", 0.0, kMax, "a number >= 0");
    model.reflectivity = d.number("reflectivity", 0.0, 1.0, "a number in [0, 1]");
    model.pixelsPerDegree =
        d.number("pixels_per_degree", std::numeric_limits<double>::min(), kMax, "a positive number");
    if (const nlohmann::json* resolution = d.find("resolution")) {
        const bool pair = resolution->is_array() && resolution->size() == 2 && (*resolution)[0].is_number_integer() &&
                          (*resolution)[1].is_number_integer() && (*resolution)[0].get<std::int64_t>() > 0 &&
                          (*resolution)[1].get<std::int64_t>() > 0 && (*resolution)[0].get<std::int64_t>() < 1 << 20 &&
                          (*resolution)[1].get<std::int64_t>() < 1 << 20;
        if (!pair)
            throwInput(file, d.key("resolution"), "expected [WIDTH, HEIGHT] in pixels, not " + resolution->dump());
        model.resolutionWidth = (*resolution)[0].get<int>();
        model.resolutionHeight = (*resolution)[1].get<int>();
    }
    if (d.find("diagonal_in"))
        model.diagonalInches = d.number("diagonal_in", std::numeric_limits<double>::min(), kMax, "a positive number");
    if (d.find("viewing_distance_m"))
        model.viewingDistanceMetres =
            d.number("viewing_distance_m", std::numeric_limits<double>::min(), kMax, "a positive number");
    return model;
}

} // namespace

namespace {
// The files an entry lists (a hand-made set may lack one kind): path or sha256 of each.
nlohmann::json listedFiles(const ManifestEntry& e, const StimulusFiles& values) {
    nlohmann::json j = nlohmann::json::object();
    if (!e.files.exr.empty()) j["exr"] = values.exr;
    if (!e.files.png.empty()) j["png"] = values.png;
    return j;
}
} // namespace

nlohmann::json toPlannedJson(const ManifestEntry& e) {
    nlohmann::json j = {{"id", e.id},
                        {"files", listedFiles(e, e.files)},
                        {"factors", e.factors},
                        {"block", e.block},
                        {"reference", e.reference},
                        {"scene", e.scene},
                        {"overrides", e.overrides},
                        {"resolved", e.resolved}};
    if (e.presentation) j["presentation"] = *e.presentation;
    return j;
}

nlohmann::json toJson(const ManifestEntry& e) {
    nlohmann::json j = toPlannedJson(e);
    j["sha256"] = listedFiles(e, e.sha256);
    j["width"] = e.width;
    j["height"] = e.height;
    j["timings_ms"] = e.timingsMs;
    if (e.presentation) j["presentation"] = *e.presentation;
    if (e.predicted) j["predicted"] = toJson(*e.predicted);
    if (e.provenance) j["provenance"] = *e.provenance;
    return j;
}

ManifestEntry manifestEntryFromJson(const nlohmann::json& json, const std::string& file, std::size_t index) {
    const Members m(json, file, "stimuli[" + std::to_string(index) + "]");
    ManifestEntry e;
    e.id = m.string("id");
    const Members files(m.required("files"), file, m.key("files"));
    const Members sha256(m.required("sha256"), file, m.key("sha256"));
    // Every set skinlab builds or imports has both files; a hand-made set may list only its renders (what image
    // metrics read) or only its presented images (what a study shows). Each reader asks for the one it needs.
    if (!files.find("exr") && !files.find("png")) throwInput(file, m.key("files"), "expected an exr or a png path");
    if (files.find("exr")) {
        e.files.exr = files.relativePath("exr");
        e.sha256.exr = sha256.string("exr");
    }
    if (files.find("png")) {
        e.files.png = files.relativePath("png");
        e.sha256.png = sha256.string("png");
        e.width = m.size("width");
        e.height = m.size("height");
    }
    if (auto factors = m.optionalObject("factors")) e.factors = *factors;
    e.block = m.string("block");
    e.reference = m.optionalBool("reference");
    e.scene = m.optionalString("scene");
    if (const nlohmann::json* overrides = m.find("overrides")) {
        if (!overrides->is_array()) throwInput(file, m.key("overrides"), "expected a list of strings");
        for (const nlohmann::json& o : *overrides) {
            if (!o.is_string()) throwInput(file, m.key("overrides"), "expected a list of strings, not " + o.dump());
            e.overrides.push_back(o.get<std::string>());
        }
    }
    if (auto resolved = m.optionalObject("resolved")) e.resolved = *resolved;
    if (auto timings = m.optionalObject("timings_ms")) e.timingsMs = *timings;
    e.presentation = m.optionalObject("presentation");
    e.provenance = m.optionalObject("provenance");
    if (auto predicted = m.optionalObject("predicted")) {
        const Members p(*predicted, file, m.key("predicted"));
        Prediction prediction;
        const nlohmann::json& jod = p.required("jod");
        if (!jod.is_number()) throwInput(file, p.key("jod"), "expected a number, not " + jod.dump());
        prediction.jod = jod.get<double>();
        // `stimuli build` writes them all; a prediction written by other tools may carry only its JOD.
        prediction.metric = p.optionalString("metric");
        prediction.display = p.optionalString("display");
        prediction.reference = p.optionalString("reference");
        prediction.referencePngSha256 = p.optionalString("reference_png_sha256");
        prediction.pngSha256 = p.optionalString("png_sha256");
        if (auto model = p.optionalObject("display_model")) {
            if (prediction.display != "custom")
                throwInput(file, p.key("display"),
                           "\"" + prediction.display + "\" with a display_model: expected \"custom\"");
            prediction.displayModel = displayModelFromJson(Members(*model, file, p.key("display_model")), file);
        } else if (prediction.display == "custom") {
            throwInput(file, p.key("display_model"), "missing: a custom display lists its parameters");
        }
        e.predicted = prediction;
    }
    return e;
}

std::vector<ManifestEntry> manifestEntriesFromJson(const nlohmann::json& stimuli, const std::string& file) {
    if (!stimuli.is_array()) throwInput(file, "stimuli", "expected an array");
    std::vector<ManifestEntry> entries;
    std::set<std::string> ids;
    for (std::size_t i = 0; i < stimuli.size(); ++i) {
        ManifestEntry entry = manifestEntryFromJson(stimuli[i], file, i);
        if (!ids.insert(entry.id).second)
            throwInput(file, "stimuli[" + std::to_string(i) + "].id", "duplicate stimulus id \"" + entry.id + "\"");
        entries.push_back(std::move(entry));
    }
    return entries;
}

const ManifestEntry* StimulusManifest::find(const std::string& id) const {
    for (const ManifestEntry& s : stimuli)
        if (s.id == id) return &s;
    return nullptr;
}

void checkManifestFormat(const nlohmann::json& root, const std::string& file) {
    if (!root.is_object()) throwInput(file, "", "expected a JSON object");
    if (!root.contains("format") || root["format"] != kManifestFormat)
        throwInput(file, "format", "expected \"skinlab-stimuli\"");
    if (!root.contains("version") || !root["version"].is_number_integer() ||
        root["version"].get<int>() != kManifestVersion)
        throwInput(file, "version", "expected 1 (the only manifest version this build reads)");
}

StimulusManifest parseStimulusManifest(const std::string& text, const std::string& file) {
    StimulusManifest manifest;
    manifest.file = file;
    manifest.text = text;
    manifest.sha256 = sha256Hex(text);
    try {
        manifest.json = nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
        throwInput(file, "", std::string("not valid JSON: ") + e.what());
    }
    const nlohmann::json& root = manifest.json;
    checkManifestFormat(root, file);
    if (!root.contains("set") || !root["set"].is_string()) throwInput(file, "set", "expected the set's name");
    manifest.set = root["set"].get<std::string>();
    if (!root.contains("stimuli")) throwInput(file, "stimuli", "missing");
    manifest.stimuli = manifestEntriesFromJson(root["stimuli"], file);
    return manifest;
}

StimulusManifest readStimulusManifest(const fs::path& folder) {
    const std::string file = (folder / kManifestFile).string();
    std::error_code ec;
    const fs::path absolute = fs::absolute(folder, ec);
    if (!fs::is_regular_file(absolute / kManifestFile, ec))
        throwInput(file, "", "no manifest.json in the stimulus folder");
    StimulusManifest manifest = parseStimulusManifest(readFile(absolute / kManifestFile), file);
    manifest.folder = absolute;
    return manifest;
}

} // namespace skinlab::formats
