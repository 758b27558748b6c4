#include "stimuli/build.h"

#include "common/error.h"
#include "common/files.h"
#include "common/hash.h"
#include "common/version.h"
#include "renderer/renderer.h"
#include "renderer/sss/sss_params.h"
#include "stimuli/contact_sheet.h"
#include "stimuli/prediction.h"
#include "stimuli/presentation.h"
#include "stimuli/output_folder.h"
#include "stimuli/progress.h"

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <spdlog/spdlog.h>
#include <thread>
#include <tuple>

namespace skinlab::stimuli {

namespace fs = std::filesystem;
using renderer::RenderRequest;

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

RenderRequest requestFor(const std::string& scene, const std::vector<std::string>& overrides, const fs::path& assets) {
    RenderRequest request;
    request.scene = scene;
    request.overrides = overrides;
    request.assetsDir = assets;
    return request;
}

// The fixed parameters that hold for every stimulus whatever its method: an [sss] key that only some methods read
// applies to the stimuli whose method reads it (expansion.h), so it is checked with those stimuli.
std::vector<std::string> fixedOverrides(const SetSpec& spec) {
    const auto common = renderer::sss::kCommonSssKeys;
    const auto known = renderer::sss::allSssKeys();
    std::vector<std::string> out;
    for (const auto& p : spec.fixed) {
        if (p.key.rfind("sss.", 0) == 0) {
            const std::string_view name = std::string_view(p.key).substr(4);
            const bool methodSpecific = std::find(known.begin(), known.end(), name) != known.end() &&
                                        std::find(common.begin(), common.end(), name) == common.end();
            if (methodSpecific) continue;
        }
        out.push_back(p.key + "=" + p.level.overrideText);
    }
    return out;
}

// Checks the fixed parameters with every scene, then every factor level with the method of the first stimulus that
// renders it (the method decides which [sss] keys apply), so that an unknown factor key, an unknown level or a missing
// asset is reported naming the scene, or the factor and level, before anything renders. Levels that every
// stimulus excludes are not rendered and not checked.
void validateLevels(const SetSpec& spec, const std::vector<Stimulus>& all, const fs::path& assets) {
    const Factor& scenes = spec.factors.front();
    const std::vector<std::string> fixed = fixedOverrides(spec);
    for (const auto& scene : scenes.levels) {
        try {
            renderer::resolveScene(requestFor(scene.overrideText, fixed, assets));
        } catch (const InputError& e) {
            throw InputError(spec.fileName + ": scene '" + scene.value + "': " + e.what());
        }
    }
    auto firstWith = [&](const std::string& factor, const Level& level) -> const Stimulus* {
        for (const auto& stimulus : all)
            for (const auto& [name, l] : stimulus.factors)
                if (name == factor && l.overrideText == level.overrideText) return &stimulus;
        return nullptr;
    };
    for (const auto& factor : spec.factors) {
        if (factor.name == "scene") continue;
        for (const auto& level : factor.levels) {
            const Stimulus* stimulus = firstWith(factor.name, level);
            if (!stimulus) continue;
            // The stimulus' fixed parameters (those its method reads), its method and this level.
            std::vector<std::string> overrides;
            for (const auto& o : stimulus->overrides) {
                const std::string key = o.substr(0, o.find('='));
                const bool isFixed =
                    std::any_of(spec.fixed.begin(), spec.fixed.end(), [&](const auto& p) { return p.key == key; });
                if (isFixed || (key == "sss.method" && factor.key != "sss.method")) overrides.push_back(o);
            }
            overrides.push_back(factor.key + "=" + level.overrideText);
            try {
                renderer::resolveScene(requestFor(stimulus->scene, overrides, assets));
            } catch (const InputError& e) {
                throw InputError(spec.fileName + ": factor '" + factor.name + "': level '" + level.value +
                                 "': " + e.what());
            }
        }
    }
}

std::pair<int, int> renderSize(const nlohmann::json& resolved) {
    const nlohmann::json* width = findDotted(resolved, "render.width");
    const nlohmann::json* height = findDotted(resolved, "render.height");
    if (!width || !height || !width->is_number_integer() || !height->is_number_integer())
        throw RuntimeError("the resolved scene has no render.width/render.height");
    return {width->get<int>(), height->get<int>()};
}

} // namespace

std::pair<int, int> presentationFrame(const Stimulus& stimulus, const nlohmann::json& resolved) {
    auto [width, height] = renderSize(resolved);
    const Presentation& p = stimulus.presentation;
    if (p.method == PresentationMethod::native && presents(p) && findDotted(resolved, "render.window"))
        return {width / p.magnification, height / p.magnification};
    return {width, height};
}

namespace {

nlohmann::json presentationOf(const Stimulus& stimulus, const nlohmann::json& resolved) {
    auto [width, height] = presentationFrame(stimulus, resolved);
    return presentationJson(stimulus.presentation, width, height);
}

std::pair<int, int> imageSize(const fs::path& path) {
    auto input = OIIO::ImageInput::open(path.string());
    if (!input) throw RuntimeError(path.string() + ": cannot read the rendered image (" + OIIO::geterror() + ")");
    std::pair<int, int> size{input->spec().width, input->spec().height};
    input->close();
    return size;
}

// Renders one stimulus into temporary files and renames them into place; returns its complete manifest entry.
formats::ManifestEntry renderStimulus(renderer::Renderer& renderer, const Stimulus& stimulus,
                                      const std::vector<std::string>& overrides, const nlohmann::json& resolved,
                                      const fs::path& dir, const fs::path& assets) {
    auto start = std::chrono::steady_clock::now();
    AtomicOutput exr(dir / exrRelativePath(stimulus.id));
    AtomicOutput png(dir / pngRelativePath(stimulus.id));
    RenderRequest request = requestFor(stimulus.scene, overrides, assets);
    request.exrPath = exr.tempPath();
    request.pngPath = png.tempPath();
    renderer::RenderResult result = renderer.render(request);
    applyPresentation(exr.tempPath(), png.tempPath(), stimulus.presentation);
    exr.commit();
    png.commit();
    if (result.resolved != resolved)
        spdlog::warn("stimuli: {}: the renderer resolved other parameters than resolveScene(); reruns will "
                     "re-render it",
                     stimulus.id);

    formats::ManifestEntry entry = stimulusEntry(stimulus, resolved);
    entry.sha256 = {sha256File(exr.finalPath()), sha256File(png.finalPath())};
    // The presented size (what a participant sees at one image pixel per device pixel): the PNG's.
    std::tie(entry.width, entry.height) = imageSize(png.finalPath());
    nlohmann::json timings =
        result.timingsMs.is_object() ? result.timingsMs : nlohmann::json{{"render", result.timingsMs}};
    timings["stimulus_wall"] = secondsSince(start) * 1000.0; // render + write + hash, ms
    entry.timingsMs = timings;
    return entry;
}

// An earlier entry is still valid when its resolved parameters are identical and both files are intact.
bool entryStillValid(const formats::ManifestEntry& entry, const nlohmann::json& resolved,
                     const nlohmann::json& presentation, const fs::path& dir) {
    if (entry.resolved != resolved) return false;
    if (!entry.presentation || *entry.presentation != presentation) return false;
    using File = std::pair<const std::string&, const std::string&>; // relative path, sha256
    for (const File& file : {File{entry.files.exr, entry.sha256.exr}, File{entry.files.png, entry.sha256.png}}) {
        const auto& [relative, sha256] = file;
        if (relative.empty()) return false;
        const fs::path path = dir / relative;
        if (!fs::is_regular_file(path) || sha256File(path) != sha256) return false;
    }
    return true;
}

} // namespace

formats::ManifestEntry stimulusEntry(const Stimulus& stimulus, const nlohmann::json& resolved) {
    formats::ManifestEntry entry;
    entry.id = stimulus.id;
    entry.files = {exrRelativePath(stimulus.id), pngRelativePath(stimulus.id)};
    for (const auto& [name, level] : stimulus.factors) {
        entry.factors[name] = level.value;
        if (name == "scene") entry.scene = level.value;
    }
    entry.block = stimulus.block;
    entry.reference = stimulus.reference;
    entry.overrides = stimulus.overrides;
    entry.resolved = resolved;
    entry.presentation = presentationOf(stimulus, resolved);
    return entry;
}

nlohmann::json plannedEntryJson(const Stimulus& stimulus, const nlohmann::json& resolved) {
    return formats::toPlannedJson(stimulusEntry(stimulus, resolved));
}

BuildPlan planBuild(const fs::path& specPath, const std::vector<std::string>& specOverrides,
                    const std::optional<Shard>& shard, const fs::path& assetsDir) {
    BuildPlan plan;
    plan.spec = readSetSpec(specPath, specOverrides);
    plan.all = expand(plan.spec);
    plan.selected = shard ? selectShard(plan.all, *shard) : plan.all;
    validateLevels(plan.spec, plan.all, assetsDir);
    for (const auto& stimulus : plan.selected) {
        nlohmann::json resolved;
        try {
            resolved = renderer::resolveScene(requestFor(stimulus.scene, stimulus.overrides, assetsDir));
        } catch (const InputError& e) {
            throw InputError(plan.spec.fileName + ": stimulus '" + stimulus.id + "': " + e.what());
        }
        auto [width, height] = renderSize(resolved);
        checkPresentation(stimulus.presentation, width, height, plan.spec.fileName, stimulus.id);
        // A native presentation renders the crop's window of a magnified frame (presentation.h).
        std::vector<std::string> overrides = stimulus.overrides;
        const std::vector<std::string> native = nativeRenderOverrides(stimulus.presentation, width, height);
        if (!native.empty()) {
            if (findDotted(resolved, "render.window"))
                throwInput(plan.spec.fileName, stimulus.presentation.methodWhere,
                           "native presentation of stimulus '" + stimulus.id +
                               "', whose scene sets its own render.window: remove it, or set presentation = "
                               "\"replicate\"");
            overrides.insert(overrides.end(), native.begin(), native.end());
            try {
                resolved = renderer::resolveScene(requestFor(stimulus.scene, overrides, assetsDir));
            } catch (const InputError& e) {
                throw InputError(plan.spec.fileName + ": stimulus '" + stimulus.id + "': " + e.what());
            }
        }
        plan.resolved.push_back(std::move(resolved));
        plan.renderOverrides.push_back(std::move(overrides));
    }
    return plan;
}

namespace {

// One warning per spec key that asks for nearest-neighbour magnification: its blocks of pixels are an artefact
// observers see (and the predicted JOD includes), not a property of any condition.
void warnReplicated(const BuildPlan& plan) {
    std::vector<std::string> warned;
    for (const auto& s : plan.selected) {
        const Presentation& p = s.presentation;
        if (p.method != PresentationMethod::replicate || p.magnification == 1) continue;
        if (std::find(warned.begin(), warned.end(), p.methodWhere) != warned.end()) continue;
        warned.push_back(p.methodWhere);
        spdlog::warn("stimuli: {}: {}: \"replicate\" magnifies {}× by nearest neighbour (blocks of {}×{} pixels in "
                     "every stimulus); presentation = \"native\" renders the crop at the presented size",
                     plan.spec.fileName, p.methodWhere, p.magnification, p.magnification, p.magnification);
    }
}

// The entries of an earlier build of this version that are still valid, by id (the earlier renderer into
// manifest.renderer).
std::map<std::string, formats::ManifestEntry>
keptEntries(const BuildPlan& plan, const std::optional<Manifest>& existing, const fs::path& dir, Manifest& manifest) {
    std::map<std::string, formats::ManifestEntry> entries; // id → entry of every stimulus done
    if (existing && existing->renderer.skinlabVersion == version()) {
        manifest.renderer = existing->renderer;
        for (size_t i = 0; i < plan.selected.size(); ++i) {
            const Stimulus& s = plan.selected[i];
            for (const formats::ManifestEntry& kept : existing->stimuli) {
                if (kept.id != s.id ||
                    !entryStillValid(kept, plan.resolved[i], presentationOf(s, plan.resolved[i]), dir))
                    continue;
                formats::ManifestEntry entry = stimulusEntry(s, plan.resolved[i]);
                entry.sha256 = kept.sha256;
                entry.width = kept.width;
                entry.height = kept.height;
                entry.timingsMs = kept.timingsMs;
                entries[s.id] = std::move(entry);
            }
        }
    }
    return entries;
}

// The manifest with every entry done so far, in the selection's order; complete once all are there.
void writeCurrentManifest(const fs::path& dir, const BuildPlan& plan,
                          const std::map<std::string, formats::ManifestEntry>& entries, Manifest& manifest) {
    manifest.stimuli.clear();
    for (const auto& s : plan.selected)
        if (auto it = entries.find(s.id); it != entries.end()) manifest.stimuli.push_back(it->second);
    manifest.complete = manifest.stimuli.size() == plan.selected.size();
    writeManifest(dir, manifest);
}

// Renders the stimuli of toRender (all of them when the kept ones came from another renderer) on options.jobs
// threads, the manifest rewritten after each; returns how many were rendered.
size_t renderStimuli(const BuildOptions& options, const BuildPlan& plan, Manifest& manifest,
                     std::map<std::string, formats::ManifestEntry>& entries, std::vector<size_t>& toRender) {
    const fs::path& dir = options.outputDir;
    auto first = std::make_unique<renderer::Renderer>();
    RendererInfo current{first->glRenderer(), first->glVersion(), version()};
    if (!entries.empty() && !(current == manifest.renderer)) {
        // A set is made by one renderer: images of another GPU/driver are not comparable pixel for pixel.
        spdlog::warn("stimuli: the set was rendered by '{}', this machine has '{}': re-rendering all of it",
                     manifest.renderer.glRenderer, current.glRenderer);
        entries.clear();
        toRender.clear();
        for (size_t i = 0; i < plan.selected.size(); ++i) toRender.push_back(i);
    }
    manifest.renderer = current;
    writeCurrentManifest(dir, plan, entries, manifest);

    bool terminal = options.progress == BuildOptions::ProgressStyle::bar ||
                    (options.progress == BuildOptions::ProgressStyle::automatic && Progress::stderrIsTerminal());
    Progress progress(toRender.size(), terminal);
    std::mutex manifestMutex;
    size_t rendered = 0;
    std::atomic<size_t> next{0};
    std::atomic<bool> stop{false};
    std::exception_ptr failure;
    // Every renderer lives until all workers are done: they may share one EGL display, which the first
    // destroyed renderer would terminate under the others.
    int jobs = std::min<int>(options.jobs, static_cast<int>(toRender.size()));
    std::vector<std::unique_ptr<renderer::Renderer>> renderers(static_cast<size_t>(jobs));
    renderers[0] = std::move(first);
    auto work = [&](size_t slot) {
        try {
            if (!renderers[slot]) renderers[slot] = std::make_unique<renderer::Renderer>();
            renderer::Renderer* renderer = renderers[slot].get();
            while (!stop) {
                size_t k = next++;
                if (k >= toRender.size()) return;
                const size_t i = toRender[k];
                auto t0 = std::chrono::steady_clock::now();
                formats::ManifestEntry entry;
                try {
                    entry = renderStimulus(*renderer, plan.selected[i], plan.renderOverrides[i], plan.resolved[i], dir,
                                           options.assetsDir);
                } catch (const InputError& e) {
                    throw InputError(plan.spec.fileName + ": stimulus '" + plan.selected[i].id + "': " + e.what());
                } catch (const RuntimeError& e) {
                    throw RuntimeError("stimulus '" + plan.selected[i].id + "': " + e.what());
                }
                std::lock_guard lock(manifestMutex);
                entries[plan.selected[i].id] = std::move(entry);
                writeCurrentManifest(dir, plan, entries, manifest);
                ++rendered;
                progress.finished(plan.selected[i].id, secondsSince(t0));
            }
        } catch (...) {
            std::lock_guard lock(manifestMutex);
            if (!failure) failure = std::current_exception();
            stop = true;
        }
    };
    std::vector<std::thread> threads;
    for (size_t j = 1; j < renderers.size(); ++j) threads.emplace_back(work, j);
    work(0);
    for (auto& t : threads) t.join();
    progress.close();
    if (failure) std::rethrow_exception(failure);
    return rendered;
}

} // namespace

BuildSummary buildSet(const BuildOptions& options) {
    auto start = std::chrono::steady_clock::now();
    if (options.jobs < 1) throwInput("--jobs", "", std::to_string(options.jobs) + " is not a positive number");
    BuildPlan plan = planBuild(options.spec, options.specOverrides, options.shard, options.assetsDir);
    const fs::path& dir = options.outputDir;
    std::optional<Manifest> existing = claimOutputFolder(dir, plan.spec.name, options.shard);
    ensureDirectory(dir);
    OutputFolderLock folderLock(dir); // one build per folder at a time (a requeued task whose first run still lives)
    existing = claimOutputFolder(dir, plan.spec.name, options.shard); // re-read: a build may have ended meanwhile

    Manifest manifest = manifestHeader(plan.spec, plan.all, options.shard);
    std::map<std::string, formats::ManifestEntry> entries = keptEntries(plan, existing, dir, manifest);
    std::vector<size_t> toRender;
    std::vector<std::string> selectedIds;
    for (size_t i = 0; i < plan.selected.size(); ++i) {
        selectedIds.push_back(plan.selected[i].id);
        if (!entries.count(plan.selected[i].id)) toRender.push_back(i);
    }

    // Marks the folder as this set's before anything renders (or creates a subfolder).
    writeCurrentManifest(dir, plan, entries, manifest);
    ensureDirectory(dir / "exr");
    ensureDirectory(dir / "png");
    tidyOutputFolder(dir, selectedIds);
    spdlog::info("stimuli: set '{}': {} stimuli, {} unchanged, {} to render", plan.spec.name, plan.selected.size(),
                 entries.size(), toRender.size());
    warnReplicated(plan);

    BuildSummary summary;
    summary.stimuli = plan.selected.size();
    if (!toRender.empty()) summary.rendered = renderStimuli(options, plan, manifest, entries, toRender);
    summary.kept = summary.stimuli - summary.rendered;
    summary.manifest = dir / kManifestFile;
    // Predicted visibility against each block's reference, once every stimulus is there (kept when up to date).
    if (options.predict && manifest.complete) {
        PredictionOptions prediction;
        prediction.display = options.display;
        const PredictionSummary predicted = predictStimuli(dir, manifest, prediction);
        if (predicted.predicted > 0) writeManifest(dir, manifest);
        summary.predictions = predictionLines(predicted, prediction);
        summary.invisibleBlock = std::any_of(predicted.blocks.begin(), predicted.blocks.end(),
                                             [](const BlockPrediction& b) { return b.invisible; });
    }
    if (options.contactSheet && manifest.complete) summary.contactHtml = writeContactSheet(dir, manifest).html;
    summary.wallSeconds = secondsSince(start);
    return summary;
}

} // namespace skinlab::stimuli
