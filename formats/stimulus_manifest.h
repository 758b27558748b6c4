#pragma once
// The stimulus manifest (contract 2, docs/stimuli.md): manifest.json in a stimulus set's folder. One typed entry
// per stimulus, one writer (toJson) and one strict reader (readStimulusManifest, manifestEntryFromJson) for every
// module that reads a set: stimuli (build, merge, predictions), experiments (study create), analysis/metrics,
// report and tune. Bad input is an InputError naming the file, the key and the value
// ("set/manifest.json: stimuli[3].files.png: path leaves the stimulus folder: ../x.png").
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::formats {

inline constexpr const char* kManifestFormat = "skinlab-stimuli";
inline constexpr int kManifestVersion = 1;
inline constexpr const char* kManifestFile = "manifest.json";

// One of each file of a stimulus: paths relative to the set's folder, or their sha256 (lower-case hex).
struct StimulusFiles {
    std::string exr;
    std::string png;
    bool operator==(const StimulusFiles&) const = default;
};

// A custom display (a named model changed by --display-*, whose name is "custom"): every parameter, so that a
// reader of the set computes on the exact display ("predicted": {"display": "custom", "display_model": {...}}).
// The fields are those of metrics::CvvdpDisplay (analysis/metrics/cvvdp.h), which converts both ways.
struct DisplayModel {
    std::string description;         // "custom display based on ..."
    std::string eotf;                // "sRGB", "PQ", "HLG", "linear" or a gamma ("2.2")
    double peakLuminance = 0.0;      // cd/m², > 0
    double contrast = 0.0;           // peak / black, >= 1
    double ambientIlluminance = 0.0; // lux, >= 0
    double reflectivity = 0.0;       // [0, 1]
    double pixelsPerDegree = 0.0;    // > 0
    int resolutionWidth = 0;         // the geometry as given; 0 when not (the ppd was given directly)
    int resolutionHeight = 0;
    double diagonalInches = 0.0;
    double viewingDistanceMetres = 0.0;
    bool operator==(const DisplayModel&) const = default;
};

// "predicted": ColorVideoVDP of the presented PNG against its block's reference (stimuli/prediction.h). Only the
// JOD is required; the strings are "" when absent.
struct Prediction {
    std::string metric;  // "ColorVideoVDP v0.5.6"
    std::string display; // display model: its name in display_models.json, or "custom"
    std::string reference;
    double jod = 0.0;
    std::string referencePngSha256; // the images it was computed on, to tell when it is out of date
    std::string pngSha256;
    std::optional<DisplayModel> displayModel; // a custom display's parameters ("display_model")
    bool operator==(const Prediction&) const = default;
};

struct ManifestEntry {
    std::string id;
    StimulusFiles files;  // relative paths, checked to stay inside the set's folder; "" when a hand-made set
                          // lists no render (exr) or no presented image (png); skinlab's sets have both
    StimulusFiles sha256; // of each file
    nlohmann::json factors = nlohmann::json::object(); // factor name → level (a string or number, as in the spec)
    std::string block;                                 // comparisons only happen within a block
    bool reference = false;
    int width = 0; // the presented size (the PNG's), in [1, 16384]; required with a PNG
    int height = 0;
    std::string scene;                                   // the `scene` factor's level ("" when none)
    std::vector<std::string> overrides;                  // the scene overrides of the stimulus
    nlohmann::json resolved = nlohmann::json::object();  // every resolved scene parameter ({} for imported images)
    nlohmann::json timingsMs = nlohmann::json::object(); // the renderer's per-pass timings, stimulus_wall
    std::optional<nlohmann::json> presentation;          // rendered sets: the crop and magnification shown
    std::optional<Prediction> predicted;
    std::optional<nlohmann::json> provenance; // imported sets: where the image came from

    // A factor's level as text (numbers as their JSON text); "" when the entry has no such factor.
    std::string factorText(const std::string& name) const;
};

nlohmann::json toJson(const ManifestEntry& entry);
// An entry before its stimulus is rendered (`stimuli list --format json`): toJson without sha256, width, height,
// timings_ms, predicted and provenance.
nlohmann::json toPlannedJson(const ManifestEntry& entry);
nlohmann::json toJson(const Prediction& prediction);
nlohmann::json toJson(const DisplayModel& display);
// The strict reader of one entry; `file` and `index` name it in errors ("FILE: stimuli[INDEX].KEY: ...").
ManifestEntry manifestEntryFromJson(const nlohmann::json& json, const std::string& file, std::size_t index);
// Every entry of a manifest's "stimuli" array (ids unique).
std::vector<ManifestEntry> manifestEntriesFromJson(const nlohmann::json& stimuli, const std::string& file);

// The header's "format" and "version": InputError unless this is a skinlab stimulus manifest this build reads.
void checkManifestFormat(const nlohmann::json& root, const std::string& file);

// A manifest file as its readers see it: the bytes (a study stores them), the set's name and the entries.
struct StimulusManifest {
    std::filesystem::path folder; // absolute folder holding manifest.json
    std::string file;             // FOLDER/manifest.json as given, the prefix of every error message
    std::string text;             // the file's bytes
    std::string sha256;           // of `text`
    nlohmann::json json;          // the whole document (header fields for the stimuli module)
    std::string set;
    std::vector<ManifestEntry> stimuli;

    const ManifestEntry* find(const std::string& id) const;
};

// Reads FOLDER/manifest.json strictly: format and version, then every entry. InputError when the folder has none
// ("FOLDER/manifest.json: no manifest.json in the stimulus folder").
StimulusManifest readStimulusManifest(const std::filesystem::path& folder);
// The same from a manifest's text (a copy stored in a study); `file` names it in errors.
StimulusManifest parseStimulusManifest(const std::string& text, const std::string& file);

} // namespace skinlab::formats
