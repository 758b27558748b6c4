#include "tune/tune_export.h"

#include "common/error.h"
#include "common/files.h"
#include "common/spec.h"
#include "formats/stimulus_manifest.h"
#include "renderer/renderer.h"
#include "renderer/scene/builtin_scenes.h"
#include "renderer/sss/burley_profile.h"
#include "renderer/sss/gaussian_sum_profile.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/method.h"
#include "renderer/sss/materials.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace skinlab::tune {

namespace sss = renderer::sss;

toml::table sceneTable(const std::string& scene) {
    if (scene.rfind("builtin:", 0) == 0) {
        const auto text = renderer::builtinSceneText(scene.substr(8));
        if (!text) throw InputError("unknown built-in scene '" + scene + "'");
        return parseTomlString(*text, scene);
    }
    return parseTomlFile(scene);
}

namespace {

// Relative file paths of a scene file, made absolute against its folder ("assets:" and "builtin:" stay).
void absolutePaths(toml::table& table, const std::filesystem::path& folder) {
    auto fix = [&](toml::node* node) {
        if (!node || !node->is_string()) return;
        const std::string value = node->as_string()->get();
        if (value.empty() || value.rfind("assets:", 0) == 0 || value.rfind("builtin:", 0) == 0) return;
        if (std::filesystem::path(value).is_absolute()) return;
        *node->as_string() = (folder / value).lexically_normal().string();
    };
    if (auto* model = table["model"].as_table()) fix(model->get("source"));
    if (auto* textures = table["textures"].as_table())
        for (const char* key : {"albedo", "normal", "specular", "occlusion", "skin_mask"}) fix(textures->get(key));
    if (auto* environment = table["environment"].as_table()) fix(environment->get("file"));
}

std::string tomlText(const toml::table& table) {
    std::ostringstream out;
    out << table;
    return out.str();
}

void checkName(const std::string& name) {
    if (name.empty() || name.size() > 64 ||
        !std::all_of(name.begin(), name.end(),
                     [](char c) {
                         return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-';
                     }) ||
        name.front() == '.')
        throw InputError("name: '" + name + "' must be 1-64 characters of a-z 0-9 . _ - (not starting with '.')");
}

// "key=value" → (key, the value as TOML text): as written when it is a TOML value (2.35 stays 2.35), else the bare
// string --set takes it for, quoted.
std::pair<std::string, std::string> splitOverride(const std::string& assignment) {
    const std::size_t equals = assignment.find('=');
    const std::string key = assignment.substr(0, equals);
    const std::string written = equals == std::string::npos ? "" : assignment.substr(equals + 1);
    try {
        parseTomlString("v = " + written, "--set");
        return {key, written};
    } catch (const InputError&) {
        return {key, nlohmann::json(written).dump()}; // a bare string (camera.view=close)
    }
}

} // namespace

std::string exportedSceneText(const TuneConfig& config, const std::filesystem::path& assetsDir) {
    toml::table table = sceneTable(config.scene);
    for (const std::string& o : config.overrides) applyOverride(table, o, "--set");
    if (config.scene.rfind("builtin:", 0) != 0)
        absolutePaths(table, std::filesystem::absolute(config.scene).parent_path());
    std::string header = "# Exported by `skinlab tune`: the scene " + config.scene + " with the overrides\n";
    for (const std::string& o : config.overrides) header += "#   --set " + o + "\n";
    header += "# Render it: skinlab render --scene THIS_FILE -o out.exr --png out.png\n";
    const std::string text = header + tomlText(table) + "\n";
    // The file must read back as the same scene: check it as `skinlab render` will.
    const std::filesystem::path probe =
        std::filesystem::temp_directory_path() / ("skinlab-tune-export-" + configKey(config) + ".toml");
    writeFileAtomic(probe, text);
    try {
        renderer::RenderRequest request;
        request.scene = probe.string();
        request.assetsDir = assetsDir;
        renderer::resolveScene(request);
    } catch (...) {
        std::filesystem::remove(probe);
        throw;
    }
    std::filesystem::remove(probe);
    return text;
}

std::string includeSnippet(const TuneConfig& config) {
    std::string text = "# For a stimulus-set spec with set.scene = \"" + config.scene + "\" (docs/stimuli.md)\n";
    text += "[[include]]\n";
    for (const std::string& o : config.overrides) {
        auto [key, value] = splitOverride(o);
        if (key == "sss.method") key = "method";
        else if (key == "camera.view") key = "view";
        text += key + " = " + value + "\n";
    }
    return text;
}

namespace {
std::string existingList(const std::vector<std::filesystem::path>& files) {
    std::string names;
    for (const auto& f : files) names += (names.empty() ? "" : ", ") + f.filename().string();
    return names;
}

// Writes `text` to `path` atomically unless `path` exists: the complete file is linked to its final name, which
// link(2) refuses when the name is taken. False when it exists.
bool writeNewFileAtomic(const std::filesystem::path& path, const std::string& text) {
    const std::filesystem::path temporary =
        path.parent_path() / ("." + path.filename().string() + ".new-" + std::to_string(::getpid()));
    writeFileAtomic(temporary, text);
    const int linked = ::link(temporary.c_str(), path.c_str());
    const int error = errno;
    std::filesystem::remove(temporary);
    if (linked == 0) return true;
    if (error == EEXIST) return false;
    throw InputError(path.string() + ": cannot write (" + std::strerror(error) + ")");
}
} // namespace

ExportExists::ExportExists(std::vector<std::filesystem::path> files)
    : InputError("name: " + existingList(files) + " already in the export folder; replacing needs \"overwrite\": true"),
      files_(std::move(files)) {}

ExportedFiles exportConfig(const TuneConfig& config, const std::filesystem::path& folder, const std::string& name,
                           const std::filesystem::path& assetsDir, bool overwrite) {
    checkName(name);
    ExportedFiles files;
    files.sceneText = exportedSceneText(config, assetsDir);
    files.includeText = includeSnippet(config);
    std::filesystem::create_directories(folder);
    files.scene = folder / (name + ".toml");
    files.include = folder / (name + ".include.toml");
    if (overwrite) {
        writeFileAtomic(files.scene, files.sceneText);
        writeFileAtomic(files.include, files.includeText);
        return files;
    }
    std::vector<std::filesystem::path> existing;
    for (const auto& f : {files.scene, files.include}) {
        std::error_code error;
        if (std::filesystem::exists(std::filesystem::symlink_status(f, error))) existing.push_back(f);
    }
    if (!existing.empty()) throw ExportExists(existing);
    if (!writeNewFileAtomic(files.scene, files.sceneText)) throw ExportExists({files.scene});
    if (!writeNewFileAtomic(files.include, files.includeText)) {
        std::filesystem::remove(files.scene); // written just now: nothing of this export is left
        throw ExportExists({files.include});
    }
    return files;
}

// Both read the set's manifest with the one strict reader of contract 2 (formats/stimulus_manifest.h).
nlohmann::json stimulusEntries(const std::filesystem::path& setFolder) {
    const formats::StimulusManifest manifest = formats::readStimulusManifest(setFolder);
    nlohmann::json out = nlohmann::json::array();
    for (const formats::ManifestEntry& s : manifest.stimuli)
        out.push_back({{"id", s.id},
                       {"scene", s.scene},
                       {"factors", s.factors},
                       {"reference", s.reference},
                       {"set", manifest.set}});
    return out;
}

TuneConfig stimulusConfig(const std::filesystem::path& setFolder, const std::string& id) {
    const formats::StimulusManifest manifest = formats::readStimulusManifest(setFolder);
    const formats::ManifestEntry* s = manifest.find(id);
    if (!s) throw InputError(manifest.file + ": id: no stimulus '" + id + "' in the set");
    TuneConfig config;
    config.scene = s->scene;
    if (config.scene.empty()) throw InputError(manifest.file + ": stimuli[" + id + "].scene: missing");
    // A relative scene file: taken from the manifest's folder when it is there, else the file the build
    // rendered (the manifest's resolved scene, absolute; the spec named it relative to the spec's folder).
    if (config.scene.rfind("builtin:", 0) != 0 && !std::filesystem::path(config.scene).is_absolute()) {
        const std::filesystem::path beside = (std::filesystem::absolute(setFolder) / config.scene).lexically_normal();
        const nlohmann::json* resolvedScene = s->resolved.contains("scene") ? &s->resolved["scene"] : nullptr;
        const std::filesystem::path rendered =
            resolvedScene && resolvedScene->is_string() ? resolvedScene->get<std::string>() : "";
        std::error_code error;
        const bool besideExists = std::filesystem::is_regular_file(beside, error);
        if (!besideExists && rendered.is_absolute() && std::filesystem::is_regular_file(rendered, error))
            config.scene = rendered.lexically_normal().string();
        else config.scene = beside.string();
    }
    config.overrides = s->overrides;
    return config;
}

nlohmann::json kernelCurves(const TuneConfig& config) {
    // The [sss] table of the configuration: the base scene's and its sss.* overrides, read by the scene reader.
    toml::table root;
    const toml::table base = sceneTable(config.scene);
    if (const toml::table* table = base["sss"].as_table()) root.insert_or_assign("sss", *table);
    for (const std::string& o : config.overrides)
        if (o.rfind("sss.", 0) == 0) applyOverride(root, o, "--set");
    const SpecReader reader(root, config.scene);
    const sss::SssParams params = sss::readSssParams(reader);
    nlohmann::json out;
    out["params"] = params.toJson();
    const sss::Kernel kernel = sss::makeKernel(params);
    out["kernel"] = kernel.toJson();

    // A common radius axis: the widest of the method's support and the comparison profiles' 99.8 % radius.
    const double scale = sss::profileScale(params.widthMm);
    const sss::GaussianSumProfile deon(sss::deonSkinLobes(), "d'Eon six-Gaussian skin profile");
    const sss::BurleyProfile burley(sss::burleyShapeMm("skin"), "Burley normalized diffusion, material skin");
    double radius =
        std::max(deon.truncationRadiusMm(sss::kTruncatedTail), burley.truncationRadiusMm(sss::kTruncatedTail)) * scale;
    radius = std::max(radius, kernel.supportRadiusMm() * 1.1);
    if (!(radius > 0.0)) radius = 3.0;
    constexpr int kPoints = 160;
    std::vector<double> x(kPoints);
    for (int i = 0; i < kPoints; ++i) x[static_cast<std::size_t>(i)] = radius * (i + 0.5) / kPoints;
    auto curve = [&](const sss::Marginal& marginal) {
        nlohmann::json channels = nlohmann::json::array();
        for (int c = 0; c < 3; ++c) {
            nlohmann::json values = nlohmann::json::array();
            for (double xi : x) {
                const double d = marginal.density(c, xi / scale) / scale; // 1/mm on the surface
                values.push_back(std::isfinite(d) ? d : 0.0);
            }
            channels.push_back(values);
        }
        return channels;
    };
    out["radius_mm"] = x;
    out["deon"] = curve(deon);
    out["burley"] = curve(burley);
    if (const auto marginal = sss::methodInfo(params.method).model->profileMarginal(params)) {
        out["method_curve"] = curve(*marginal);
        out["method_curve_source"] = marginal->description();
    }
    // The taps' density: each tap's weight over the spacing around it (what the method integrates against).
    nlohmann::json stages = nlohmann::json::array();
    for (const sss::KernelStage& stage : kernel.stages) {
        nlohmann::json taps = nlohmann::json::array();
        const auto& t = stage.taps;
        for (std::size_t i = 0; i < t.size(); ++i) {
            if (t[i].offsetMm < 0.0) continue;
            const double left = i > 0 ? t[i - 1].offsetMm : t[i].offsetMm;
            const double right = i + 1 < t.size() ? t[i + 1].offsetMm : t[i].offsetMm;
            const double spacing = std::max((right - left) / 2.0, 1e-9);
            std::array<double, 3> density{};
            for (std::size_t c = 0; c < 3; ++c) density[c] = t[i].weight[c] / spacing;
            taps.push_back({{"offset_mm", t[i].offsetMm}, {"weight", t[i].weight}, {"density", density}});
        }
        stages.push_back({{"taps", taps}, {"accumulate", stage.accumulate}});
    }
    out["stages"] = stages;
    out["support_mm"] = kernel.supportRadiusMm();
    return out;
}

} // namespace skinlab::tune
