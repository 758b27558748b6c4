// The renderer's public entry point (renderer.h): scene spec → GL passes → EXR (+ PNG), with timings.
//
// One pipeline of stages (Impl::runPipeline; docs/architecture.md, "Renderer"), each declaring what of the resolved
// record it reads (StageReads): upload (model, materials, maps, environment) → camera → [Blender, for the methods it
// renders] → shadows → lighting (main pass → background → surface AOVs → transmittance) → SSS stage → add specular →
// resolve → tone map, one class per pass under renderer/gl/. renderDisplay re-runs only the stages whose reads
// changed; render() runs them all, then reads back and writes, both driven by one AOV table (kAovs) → EXR / PNG.
#include "renderer/renderer.h"

#include "common/check.h"
#include "common/error.h"
#include "common/version.h"
#include "renderer/gl/add_specular_pass.h"
#include "renderer/gl/background_pass.h"
#include "renderer/gl/egl_context.h"
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/gpu_scene.h"
#include "renderer/gl/gpu_timer.h"
#include "renderer/gl/main_pass.h"
#include "renderer/gl/reference_method.h"
#include "renderer/gl/resolve_pass.h"
#include "renderer/gl/shader_library.h"
#include "renderer/gl/shadow_map_pass.h"
#include "renderer/gl/sss_stage.h"
#include "renderer/gl/surface_aov_pass.h"
#include "renderer/gl/tone_map_pass.h"
#include "renderer/gl/transmittance_pass.h"
#include "renderer/output/display_output.h"
#include "renderer/output/exr_writer.h"
#include "renderer/pathtraced/blender_merge.h"
#include "renderer/sss/eevee_params.h"
#include "renderer/sss/method.h"
#include "renderer/scene/builtin_geometry.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/mesh_loader.h"
#include "renderer/scene/scene_spec.h"
#include "renderer/scene/texture.h"
#include "renderer/shading/tone_mappers.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>
#include <optional>
#include <spdlog/spdlog.h>

namespace skinlab::renderer {

namespace {

std::vector<std::string> allOverrides(const RenderRequest& request) {
    std::vector<std::string> overrides = request.overrides;
    if (request.method) overrides.push_back("sss.method=" + *request.method);
    if (request.width) overrides.push_back("render.width=" + std::to_string(*request.width));
    if (request.height) overrides.push_back("render.height=" + std::to_string(*request.height));
    return overrides;
}

SceneSpec loadSpec(const RenderRequest& request) {
    return loadSceneSpec(request.scene, allOverrides(request), request.assetsDir);
}

double millisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

nlohmann::json jsonVec3(const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }
nlohmann::json jsonMat4(const glm::mat4& m) {
    nlohmann::json out = nlohmann::json::array();
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 4; ++row) out.push_back(m[column][row]);
    return out; // column-major, as GLM / OpenGL
}

// Bounds of the parts whose material is skin (the named views frame them); the whole model without skin.
void skinBounds(const Model& model, const std::vector<gl::GpuMaterial>& materials, glm::vec3& lowest,
                glm::vec3& highest) {
    lowest = glm::vec3(std::numeric_limits<float>::max());
    highest = glm::vec3(std::numeric_limits<float>::lowest());
    bool any = false;
    for (std::size_t p = 0; p < model.parts.size(); ++p) {
        if (materials[p].skin <= 0.0f) continue;
        const SubMesh& part = model.parts[p];
        for (std::uint32_t i = part.firstIndex; i < part.firstIndex + part.indexCount; ++i) {
            const glm::vec3& position = model.vertices[model.indices[i]].position;
            lowest = glm::min(lowest, position);
            highest = glm::max(highest, position);
            any = true;
        }
    }
    if (!any) {
        lowest = model.boundsMin;
        highest = model.boundsMax;
    }
}

} // namespace

nlohmann::json resolveScene(const RenderRequest& request) { return loadSpec(request).resolved; }

namespace {
// What the passes of one render need besides the frame targets: the scene, its model and materials as uploaded,
// the camera and, for sss.method = "reference", the reference method's inputs.
struct Frame {
    const SceneSpec* spec = nullptr;
    std::shared_ptr<const Model> model;
    std::vector<gl::GpuMaterial> partMaterials; // one per part of the model
    gl::GpuScene* scene = nullptr;
    // The passes run at the internal size: the output size × the supersampling factor (1 without anti-aliasing);
    // the camera's focal length in pixels is the internal one, so every mm → pixel conversion of the passes (SSS
    // kernels, transmittance, the reference) follows the internal grid while the kernels stay the same in mm.
    int width = 0;
    int height = 0;
    int ssaaFactor = 1;
    CameraPose camera;
    float exposure = 1.0f; // 2^exposure_ev
    glm::mat3 environmentFromWorld{1.0f};
    gl::ReferenceInputs referenceInputs; // prepared before the passes (reference method only)
};

// What one run of the pipeline did.
struct PipelineRun {
    std::vector<std::string> reran; // the stages re-run: "upload", "shadows", "lighting", "sss" (the last always)
    float supportRadiusMm = 0.0f;   // the method's, for skinlab:sss_radius_mm
    double uploadMs = 0.0;          // upload, camera, Blender and the reference's preparation (CPU, wall clock)
    std::optional<pathtraced::CyclesImage> blender; // sss.method = "pathtraced" / "eevee": Blender's frame
};

// How the pipeline runs each executor (the Execution of a method's row, sss_params.h): the stages it adds or
// replaces, one row per executor. The stages ask this table, never a method's name.
struct ExecutorStages {
    sss::Execution execution;
    bool objectSpace; // the SSS stage is the object-space reference, which draws into the lighting targets itself
    std::optional<pathtraced::BlenderEngine> blender; // Blender renders the frame before the passes
    const char* timings;                              // its record in render()'s timings ("": none)
};
const std::array<ExecutorStages, 6> kExecutorStages{{
    {sss::Execution::CopyThrough, false, std::nullopt, ""},
    {sss::Execution::TapPasses, false, std::nullopt, ""},
    {sss::Execution::Pscbf, false, std::nullopt, ""},
    {sss::Execution::ObjectSpace, true, std::nullopt, "reference"},
    {sss::Execution::Cycles, false, pathtraced::BlenderEngine::Cycles, "pathtraced"},
    {sss::Execution::Eevee, false, pathtraced::BlenderEngine::Eevee, "eevee"},
}};

const ExecutorStages& stagesOf(const sss::SssParams& params) {
    const sss::Execution execution = sss::methodInfo(params.method).execution;
    const auto found = std::find_if(kExecutorStages.begin(), kExecutorStages.end(),
                                    [&](const ExecutorStages& row) { return row.execution == execution; });
    SKINLAB_CHECK(found != kExecutorStages.end());
    return *found;
}

// A frame read back for render(): every AOV of the table (kAovs order) and the display image (RGB).
struct FrameImages {
    std::vector<std::vector<float>> aovs;
    std::vector<float> display;
    pathtraced::BlenderMerge blenderMerge;
};
} // namespace

struct Renderer::Impl {
    // The stages of one frame, in order (runPipeline; docs/architecture.md, "Renderer").
    Frame loadFrame(const SceneSpec& spec);
    void uploadScene(const Frame& frame);
    void placeCamera(Frame& frame);
    pathtraced::CyclesImage renderBlender(const Frame& frame, pathtraced::BlenderEngine engine);
    PipelineRun runPipeline(Frame& frame, bool everything);
    // `shadows` false: the shadow maps of the previous call are kept (same model, lights and shadow settings).
    gl::MainPassSettings runLightingPasses(const Frame& frame, bool shadows = true);
    float runSssPasses(const Frame& frame, const gl::MainPassSettings& mainSettings);
    // sss.method = "reference": its inputs from the uploaded model, its parameters checked and the surface
    // tessellated (cached), before any pass runs.
    void prepareReferenceMethod(Frame& frame, const SceneSpec& spec);
    // Read-back and write (render()).
    std::vector<float> readOutput(const Frame& frame, GLuint texture, int channels);
    std::vector<float> readDisplay(const Frame& frame);
    FrameImages readFrame(const Frame& frame, PipelineRun& run, bool display);
    ExrMetadata frameMetadata(const Frame& frame, const PipelineRun& run, const FrameImages& images);

    gl::EglContext context;
    gl::ShaderLibrary shaders;
    gl::PassTimer timer;
    gl::FrameTargets targets;
    gl::ShadowMapPass shadowMapPass{shaders};
    gl::MainPass mainPass{shaders};
    gl::BackgroundPass backgroundPass{shaders};
    gl::SurfaceAovPass surfaceAovPass{shaders};
    gl::TransmittancePass transmittancePass{shaders};
    gl::SssStage sssStage{shaders};
    gl::ReferenceMethod referenceMethod{shaders}; // sss.method = "reference": replaces the SSS stage
    gl::AddSpecularPass addSpecularPass{shaders};
    gl::ResolvePass resolvePass{shaders};
    gl::ToneMapPass toneMapPass{shaders};
    // With anti-aliasing, the output-size layers the resolve pass writes (beauty, display and, for render() and
    // renderDisplay's linear layers, the AOVs); without, `targets` is the output.
    gl::FrameTargets resolvedTargets;
    gl::FrameTargets& output(const Frame& frame) { return frame.ssaaFactor > 1 ? resolvedTargets : targets; }
    // Resolves one layer of `targets` into the same layer of `resolvedTargets` (no-op without anti-aliasing).
    void resolve(const Frame& frame, gl::Texture gl::FrameTargets::*layer, gl::ResolveMode mode) {
        if (frame.ssaaFactor <= 1) return;
        resolvePass.run(targets, (targets.*layer).get(), resolvedTargets, (resolvedTargets.*layer).get(),
                        frame.ssaaFactor, mode);
    }

    // The resident state: the uploaded scene and what the frame targets hold, with the key of what each stage read
    // in its last run (readsKey; empty: not held). Declared after the context: destroyed before it.
    std::unique_ptr<gl::GpuScene> residentScene;
    std::string residentSceneKey;
    std::string shadowKey;
    std::string lightingKey;
    gl::MainPassSettings residentMainSettings;

    // CPU-side caches: a stimulus set renders the same model, maps and environment many times.
    std::map<std::string, std::shared_ptr<const Model>> models;
    std::map<std::string, std::shared_ptr<const Image>> images;
    struct CachedEnvironment {
        std::shared_ptr<const Environment> environment;
        std::array<glm::vec3, 9> radianceSH;
        std::shared_ptr<const Environment> irradiance; // environment.irradiance = "exact": E(n) by normal
    };
    std::map<std::string, CachedEnvironment> environments;

    std::shared_ptr<const Model> model(const SceneSpec& spec) {
        std::string key = spec.modelSource;
        if (spec.modelSource == "builtin:halo") key += "|" + std::to_string(spec.depthGapMm);
        if (spec.modelSource == "builtin:ear") key += "|" + std::to_string(spec.thicknessMm);
        if (spec.modelSource == "builtin:head" && !spec.skinDetail) key += "|smooth";
        if (spec.flipV) key += "|flip_v";
        if (auto found = models.find(key); found != models.end()) return found->second;
        Model loaded;
        if (spec.modelSource == "builtin:halo") loaded = makeHaloScene(static_cast<float>(spec.depthGapMm));
        else if (spec.modelSource == "builtin:bleed") loaded = makeBleedScene();
        else if (spec.modelSource == "builtin:ear") loaded = makeEarScene(static_cast<float>(spec.thicknessMm));
        else if (spec.modelSource == "builtin:head") loaded = makeHeadScene(spec.skinDetail);
        else {
            ModelLoadOptions options;
            options.flipV = spec.flipV;
            loaded = loadModel(spec.modelSource, options);
        }
        if (loaded.indices.empty() || loaded.parts.empty())
            throw InputError(spec.modelSource + ": cannot load model (no triangles)");
        auto shared = std::make_shared<const Model>(std::move(loaded));
        if (models.size() > 8) models.clear();
        models[key] = shared;
        return shared;
    }

    std::shared_ptr<const Image> image(const std::filesystem::path& path, ColorEncoding encoding) {
        if (path.empty()) return nullptr;
        const std::string key = path.string() + (encoding == ColorEncoding::sRGB ? "|srgb" : "|data");
        if (auto found = images.find(key); found != images.end()) return found->second;
        auto shared = std::make_shared<const Image>(loadTexture(path, encoding));
        if (images.size() > 16) images.clear();
        images[key] = shared;
        return shared;
    }

    // The albedo map the scene shows: the spec's file, re-toned through the skin model under [skin]
    // (sss::retoneAlbedo), or the model's own map (builtin:head's procedural detail, which the tone's material
    // albedo multiplies).
    std::shared_ptr<const Image> albedoMapOf(const SceneSpec& spec, const Model& model) {
        if (spec.textures.albedo.empty()) return model.albedoMap;
        const auto loaded = image(spec.textures.albedo, ColorEncoding::sRGB);
        if (!spec.skin) return loaded;
        const sss::SkinTone& tone = spec.skin->tone;
        const std::string key = spec.textures.albedo.string() + "|retone|" + std::to_string(tone.melanin) + "|" +
                                std::to_string(tone.melaninBlend);
        if (auto found = images.find(key); found != images.end()) return found->second;
        Image retoned = *loaded;
        sss::retoneAlbedo(retoned.pixels, tone, spec.source, tone.level.empty() ? "skin.melanin" : "skin.tone");
        auto shared = std::make_shared<const Image>(std::move(retoned));
        if (images.size() > 16) images.clear();
        images[key] = shared;
        return shared;
    }

    const CachedEnvironment& environment(const EnvironmentSpec& spec) {
        std::string key = spec.file.string();
        if (spec.file.empty())
            key = "constant|" + std::to_string(spec.radiance.x) + "," + std::to_string(spec.radiance.y) + "," +
                  std::to_string(spec.radiance.z);
        key += "|" + spec.irradiance;
        if (auto found = environments.find(key); found != environments.end()) return found->second;
        CachedEnvironment cached;
        if (spec.file.empty()) {
            // A constant environment L has radiance SH (L·√(4π), 0, ...); computed through the same projection.
            const Environment constant = makeConstantEnvironment(spec.radiance);
            cached.radianceSH = projectSH9(constant); // exact for a constant: "exact" needs no map here
        } else {
            auto loaded = std::make_shared<const Environment>(loadEnvironment(spec.file));
            cached.radianceSH = projectSH9(*loaded);
            if (spec.irradiance == "exact")
                cached.irradiance = std::make_shared<const Environment>(irradianceMap(*loaded));
            cached.environment = loaded;
        }
        if (environments.size() > 8) environments.clear();
        return environments[key] = cached;
    }
};

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {}
Renderer::~Renderer() = default;
std::string Renderer::glRenderer() const { return impl_->context.renderer(); }
std::string Renderer::glVersion() const { return impl_->context.version(); }

namespace {

// The internal size the passes run at: the output size × render.ssaa_factor (× 1 without anti-aliasing).
void setInternalSize(Frame& frame, const SceneSpec& spec) {
    frame.ssaaFactor = spec.ssaaFactor;
    frame.width = spec.width * spec.ssaaFactor;
    frame.height = spec.height * spec.ssaaFactor;
}

// The render.window in pixels of the internal (supersampled) frame: every pass runs at ssaa_factor × the frame.
std::optional<RenderWindow> internalWindow(const SceneSpec& spec) {
    if (!spec.window) return std::nullopt;
    const int f = spec.ssaaFactor;
    return RenderWindow{spec.window->x * f, spec.window->y * f, spec.window->width * f, spec.window->height * f};
}

// --- materials -----------------------------------------------------------------------------------------------
// One GPU material per part of the model: the model's own materials with the scene's [[materials]] overrides.
std::vector<gl::GpuMaterial> partMaterialsOf(const SceneSpec& spec, const Model& model) {
    std::vector<gl::GpuMaterial> byMaterial;
    for (const MeshMaterial& m : model.materials)
        byMaterial.push_back({m.albedo, m.skin ? 1.0f : 0.0f, m.glossiness, m.specularIntensity});
    std::vector<bool> explicitAlbedo(model.materials.size(), false);
    for (std::size_t i = 0; i < spec.materials.size(); ++i) {
        const MaterialSpec& override = spec.materials[i];
        bool matched = false;
        for (std::size_t m = 0; m < model.materials.size(); ++m) {
            if (override.name != "*" && override.name != model.materials[m].name) continue;
            matched = true;
            gl::GpuMaterial& target = byMaterial[m];
            if (override.albedo) target.albedo = *override.albedo, explicitAlbedo[m] = true;
            if (override.skin) target.skin = *override.skin ? 1.0f : 0.0f;
            if (override.glossiness) target.glossiness = static_cast<float>(*override.glossiness);
            if (override.specularIntensity) target.specularIntensity = static_cast<float>(*override.specularIntensity);
        }
        if (!matched) {
            std::string names;
            for (const MeshMaterial& m : model.materials) names += (names.empty() ? "" : ", ") + m.name;
            throwInput(spec.source, "materials[" + std::to_string(i) + "].name",
                       "no material '" + override.name + "' in the model (it has: " + names + "; \"*\" means all)");
        }
    }
    // [skin] without an albedo map of the spec: skin materials take the tone's albedo (builtin:head's procedural map
    // multiplies it, so its detail stays); a spec's albedo map is re-toned instead (albedoMapOf). [[materials]]
    // albedo overrides win.
    if (spec.skin && spec.textures.albedo.empty())
        for (std::size_t m = 0; m < byMaterial.size(); ++m)
            if (byMaterial[m].skin > 0.0f && !explicitAlbedo[m]) {
                const auto& a = spec.skin->albedo;
                byMaterial[m].albedo =
                    glm::vec3(static_cast<float>(a[0]), static_cast<float>(a[1]), static_cast<float>(a[2]));
            }
    std::vector<gl::GpuMaterial> parts;
    for (const SubMesh& part : model.parts) parts.push_back(byMaterial.at(part.material));
    return parts;
}

// --- lights --------------------------------------------------------------------------------------------------
std::vector<gl::GpuLight> gpuLightsOf(const SceneSpec& spec) {
    std::vector<gl::GpuLight> lights;
    for (const LightSpec& light : spec.lights) {
        gl::GpuLight g;
        g.radiance = light.color * static_cast<float>(light.intensity);
        g.castsShadow = light.shadow;
        if (light.type == "directional") {
            g.type = 0;
            g.direction = glm::normalize(light.direction);
        } else {
            g.type = 1;
            g.position = light.position;
            g.direction = glm::normalize(light.target - light.position);
            g.referenceDistance = glm::length(light.target - light.position);
            g.cosInner = static_cast<float>(std::cos(glm::radians(light.innerAngleDeg)));
            g.cosOuter = static_cast<float>(std::cos(glm::radians(light.outerAngleDeg)));
        }
        lights.push_back(g);
    }
    return lights;
}

// --- AOVs ----------------------------------------------------------------------------------------------------
// One table drives both the read-back and the EXR channels (docs/rendering.md, "EXR layout"): each AOV's frame
// target, its layout there, its channel names in the EXR and, for sss.method = "pathtraced" or "eevee", the Blender
// image that replaces it (the other AOVs come from the rasterizer's passes in every method).
struct Aov {
    const char* layer;                                   // EXR layer; "" = the beauty's R, G, B
    const char* channels;                                // one letter per EXR channel, e.g. "RGB", "Z"
    gl::Texture gl::FrameTargets::*texture;              // where the passes write it
    int textureChannels;                                 // 4: RGBA32F, 1: R32F
    std::vector<float> pathtraced::CyclesImage::*cycles; // nullptr: never from Cycles
    int cyclesChannels;                                  // components per pixel in the Cycles image
    gl::ResolveMode resolve;                             // how anti-aliasing's samples combine (resolve.frag)
};

using gl::ResolveMode;
const std::array<Aov, 11> kAovs{{
    {"", "RGB", &gl::FrameTargets::beauty, 4, &pathtraced::CyclesImage::beauty, 3, ResolveMode::Average},
    {"diffuse", "RGB", &gl::FrameTargets::scatteredDiffuse, 4, &pathtraced::CyclesImage::diffuse, 3,
     ResolveMode::Average},
    {"specular", "RGB", &gl::FrameTargets::specular, 4, &pathtraced::CyclesImage::specular, 3, ResolveMode::Average},
    {"albedo", "RGB", &gl::FrameTargets::albedo, 4, nullptr, 0, ResolveMode::Average},
    {"depth", "Z", &gl::FrameTargets::linearDepth, 1, &pathtraced::CyclesImage::depth, 1, ResolveMode::Nearest},
    {"normal", "XYZ", &gl::FrameTargets::normal, 4, nullptr, 0, ResolveMode::CoveredDirection},
    {"geonormal", "XYZ", &gl::FrameTargets::geometricNormal, 4, nullptr, 0, ResolveMode::CoveredDirection},
    {"mask", "Y", &gl::FrameTargets::mask, 1, &pathtraced::CyclesImage::mask, 1, ResolveMode::Average},
    {"transmittance", "RGB", &gl::FrameTargets::transmittance, 4, nullptr, 0, ResolveMode::Average},
    {"aux", "Y", &gl::FrameTargets::aux, 1, nullptr, 0, ResolveMode::CoveredAverage},
    {"curvature", "Y", &gl::FrameTargets::curvature, 1, nullptr, 0, ResolveMode::CoveredAverage},
}};

std::size_t aovIndex(std::string_view layer) {
    for (std::size_t i = 0; i < kAovs.size(); ++i)
        if (layer == kAovs[i].layer) return i;
    return kAovs.size();
}

// The EXR channels of every AOV, from Cycles where the table says so and a Cycles image is given.
std::vector<ExrChannel> exrChannels(const std::vector<std::vector<float>>& readBack,
                                    const pathtraced::CyclesImage* cycles, std::size_t pixels) {
    std::vector<ExrChannel> channels;
    for (std::size_t a = 0; a < kAovs.size(); ++a) {
        const Aov& aov = kAovs[a];
        const bool fromCycles = cycles && aov.cycles;
        const std::vector<float>& data = fromCycles ? cycles->*aov.cycles : readBack[a];
        const std::size_t stride = static_cast<std::size_t>(fromCycles ? aov.cyclesChannels : aov.textureChannels);
        const std::string layer = aov.layer;
        for (std::size_t c = 0; aov.channels[c]; ++c) {
            ExrChannel channel;
            channel.name =
                layer.empty() ? std::string(1, aov.channels[c]) : layer + "." + std::string(1, aov.channels[c]);
            channel.values.resize(pixels);
            for (std::size_t p = 0; p < pixels; ++p) channel.values[p] = data[p * stride + c];
            channels.push_back(std::move(channel));
        }
    }
    return channels;
}

} // namespace

// shadow map → main pass → background → surface AOVs → transmittance: everything the SSS stage reads.
gl::MainPassSettings Renderer::Impl::runLightingPasses(const Frame& frame, bool shadows) {
    const SceneSpec& spec = *frame.spec;
    gl::PassTimer& passTimer = timer;
    if (shadows) {
        passTimer.begin("shadow");
        shadowMapPass.run(*frame.scene, frame.model->boundsMin, frame.model->boundsMax, spec.shadowResolution);
        passTimer.end();
    }

    passTimer.begin("main");
    gl::MainPassSettings mainSettings;
    mainSettings.camera = frame.camera;
    mainSettings.exposure = frame.exposure;
    mainSettings.normalStrength = static_cast<float>(spec.textures.normalStrength);
    mainSettings.pcfRadius = spec.shadowPcfRadius;
    mainSettings.environmentFromWorld = frame.environmentFromWorld;
    mainSettings.transmittanceEnabled = spec.transmittance.enabled;
    mainSettings.translucency = static_cast<float>(spec.transmittance.translucency);
    mainSettings.sssWidthMm = static_cast<float>(spec.sss.widthMm);
    mainSettings.transmittanceThesisCurvature =
        spec.transmittance.curvature && spec.transmittance.curvatureForm == "thesis";
    mainSettings.curvatureReferenceMm = static_cast<float>(spec.sss.curvatureReferenceMm);
    mainSettings.mmPerUnit = static_cast<float>(spec.mmPerUnit);
    if (spec.sss.skinLobeWeights) {
        std::array<glm::vec3, 6> weights{};
        for (std::size_t k = 0; k < 6; ++k) {
            const auto& w = (*spec.sss.skinLobeWeights)[k];
            weights[k] = glm::vec3(static_cast<float>(w[0]), static_cast<float>(w[1]), static_cast<float>(w[2]));
        }
        mainSettings.transmittanceWeights = weights;
    }
    mainPass.run(targets, *frame.scene, shadowMapPass.shadowMaps(), mainSettings);
    passTimer.end();

    passTimer.begin("background");
    gl::BackgroundSettings backgroundSettings;
    backgroundSettings.camera = frame.camera;
    backgroundSettings.environmentMap = frame.scene->environmentMap();
    backgroundSettings.color = spec.environment.background == "color"
                                   ? spec.environment.backgroundColor
                                   : spec.environment.radiance * static_cast<float>(spec.environment.intensity);
    backgroundSettings.environmentIntensity = static_cast<float>(spec.environment.intensity);
    backgroundSettings.exposure = frame.exposure;
    backgroundSettings.environmentFromWorld = frame.environmentFromWorld;
    backgroundPass.run(targets, backgroundSettings);
    passTimer.end();

    passTimer.begin("surface_aovs");
    gl::SurfaceAovSettings surfaceAovSettings;
    surfaceAovSettings.camera = frame.camera;
    surfaceAovSettings.screenCurvature = spec.sss.curvatureMeasure == "screen";
    surfaceAovPass.run(targets, surfaceAovSettings);
    passTimer.end();

    passTimer.begin("transmittance");
    gl::TransmittanceSettings transmittanceSettings;
    transmittanceSettings.enabled = spec.transmittance.enabled;
    transmittanceSettings.curvature = spec.transmittance.curvature;
    transmittanceSettings.mmPerUnit = static_cast<float>(spec.mmPerUnit);
    transmittanceSettings.thesisForm = spec.transmittance.curvatureForm == "thesis";
    transmittanceSettings.curvatureReferenceMm = static_cast<float>(spec.sss.curvatureReferenceMm);
    transmittancePass.run(targets, transmittanceSettings);
    passTimer.end();
    return mainSettings;
}

// SSS stage (or the object-space reference) → add specular → tone map, on the lighting passes' targets (which it
// only reads, so it may run again on them with other [sss] or tone-map values). Returns the SSS support radius.
float Renderer::Impl::runSssPasses(const Frame& frame, const gl::MainPassSettings& mainSettings) {
    const SceneSpec& spec = *frame.spec;
    gl::PassTimer& passTimer = timer;
    passTimer.begin("sss");
    float supportRadiusMm = 0.0f;
    gl::SssStageSettings sssSettings;
    sssSettings.sss = spec.sss;
    sssSettings.transmittance = spec.transmittance;
    if (stagesOf(spec.sss).objectSpace) {
        // The object-space reference bakes the main pass's shading at the tessellated vertices itself, so it needs
        // the model, the scene and the main pass's settings rather than the screen-space inputs.
        gl::ReferenceInputs referenceInputs = frame.referenceInputs;
        referenceInputs.scene = frame.scene;
        referenceInputs.shadowMaps = shadowMapPass.shadowMaps();
        referenceInputs.mainSettings = mainSettings;
        referenceInputs.targets = &targets;
        referenceMethod.run(referenceInputs, spec.sss, targets.scatteredDiffuse.get());
    } else {
        gl::SssStageInputs sssInputs;
        sssInputs.diffuse = targets.diffuse.get();
        sssInputs.linearDepth = targets.linearDepth.get();
        sssInputs.albedo = targets.albedo.get();
        sssInputs.skinMask = targets.mask.get();
        sssInputs.normal = targets.normal.get();
        sssInputs.geometricNormal = targets.geometricNormal.get();
        sssInputs.aux = targets.aux.get();
        sssInputs.curvature = targets.curvature.get();
        sssInputs.width = frame.width;
        sssInputs.height = frame.height;
        sssInputs.focalLengthPixels = frame.camera.focalLengthPixels;
        sssInputs.principalPoint = frame.camera.principalPoint;
        sssInputs.mmPerUnit = static_cast<float>(spec.mmPerUnit);
        sssInputs.view = frame.camera.view;
        sssInputs.projection = frame.camera.projection;
        sssInputs.cameraPosition = frame.camera.position;
        sssStage.run(sssInputs, sssSettings, targets.scatteredDiffuse.get());
    }
    // The method's support, prepared with its kernel (renderer/sss/method.h; pathtraced, eevee and reference: the
    // radial profile's).
    supportRadiusMm = static_cast<float>(sss::prepareMethod(spec.sss)->supportRadiusMm);
    passTimer.end();

    passTimer.begin("add_specular");
    addSpecularPass.run(targets);
    passTimer.end();

    // Anti-aliasing: the beauty at the output size, each pixel the box-filtered mean of its samples in linear
    // light; the tone map below maps that resolved beauty (the EXR's), so the PNG is the EXR's beauty tone mapped.
    if (frame.ssaaFactor > 1) {
        passTimer.begin("resolve");
        resolve(frame, &gl::FrameTargets::beauty, gl::ResolveMode::Average);
        passTimer.end();
    }

    passTimer.begin("tone_map");
    gl::FrameTargets& display = output(frame);
    float reinhardScale = 1.0f;
    if (spec.toneMapper == "reinhard") {
        // Reinhard et al. 2002, Eq. 1: the log-average luminance of the beauty (read back once, on the CPU).
        std::vector<float> linear(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) * 4);
        gl::readTexture(display.beauty.get(), spec.width, spec.height, 4, linear.data());
        const double logAverage = reinhardLogAverage(linear.data(), linear.size() / 4, 4);
        reinhardScale = static_cast<float>(spec.reinhardKey / logAverage);
    }
    toneMapPass.run(display, spec.toneMapper, static_cast<float>(spec.exponentialK),
                    static_cast<float>(spec.filmicWhite), reinhardScale);
    passTimer.end();
    return supportRadiusMm;
}

namespace {
// --- what each stage reads -----------------------------------------------------------------------------------
// A stage of the pipeline declares what of the resolved record it reads: whole tables, or every table but some, and
// the values it derives from tables it reads only in part. renderDisplay re-runs a stage when what it reads differs
// from its last run or a stage before it re-ran; render() runs every stage.
struct StageReads {
    std::vector<std::string> tables;
    std::vector<std::string> allTablesBut;
    nlohmann::json (*partly)(const SceneSpec&) = nullptr;
};

// The [sss] keys the lighting passes read: the main pass width_mm (for the transmittance), the surface AOVs
// curvature_measure, both curvature_reference_mm.
nlohmann::json lightingSssKeys(const SceneSpec& spec) {
    return {{"curvature_measure", spec.sss.curvatureMeasure},
            {"curvature_reference_mm", spec.sss.curvatureReferenceMm},
            {"width_mm", spec.transmittance.enabled ? spec.sss.widthMm : 0.0}};
}

// upload: the model, its materials and maps, the environment.
const StageReads kUploadReads{{"scene", "mm_per_unit", "model", "textures", "materials", "skin", "environment"}, {}};
// shadows: the lights and the shadow settings (not the camera or the exposure).
const StageReads kShadowReads{{"lights", "shadow"}, {}};
// lighting (main … transmittance): everything but the tone map and the [sss] keys it does not read.
const StageReads kLightingReads{{}, {"tone_map", "sss"}, lightingSssKeys};
// The SSS stage, add specular and tone map read the rest and always run.

std::string readsKey(const SceneSpec& spec, const StageReads& reads) {
    const nlohmann::json& resolved = spec.resolved;
    nlohmann::json key = nlohmann::json::object();
    for (const std::string& table : reads.tables) key[table] = resolved.value(table, nlohmann::json());
    if (!reads.allTablesBut.empty())
        for (const auto& [table, value] : resolved.items())
            if (std::find(reads.allTablesBut.begin(), reads.allTablesBut.end(), table) == reads.allTablesBut.end())
                key[table] = value;
    if (reads.partly) key["partly"] = reads.partly(spec);
    return key.dump();
}

double secondsToMs(double seconds) { return gl::roundMs(seconds * 1000.0); }

// The Blender engine of a method rendered by Blender, none for the others.
std::optional<pathtraced::BlenderEngine> blenderEngineOf(const sss::SssParams& params) {
    return stagesOf(params).blender;
}

// The EXR channels the AOV table takes from a Blender image: "R", "G", "B", "diffuse.*", ..., "depth.Z", "mask.Y".
nlohmann::json blenderChannels() {
    nlohmann::json channels = nlohmann::json::array();
    for (const Aov& aov : kAovs) {
        if (!aov.cycles) continue;
        const std::string layer = aov.layer, letters = aov.channels;
        if (layer.empty())
            for (const char c : letters) channels.push_back(std::string(1, c));
        else channels.push_back(layer + "." + (letters.size() == 1 ? letters : std::string("*")));
    }
    return channels;
}

nlohmann::json cameraJson(const CameraPose& camera) {
    return {{"position", jsonVec3(camera.position)},
            {"target", jsonVec3(camera.target)},
            {"up", jsonVec3(camera.up)},
            {"fov_y_deg", glm::degrees(camera.fovYRadians)},
            {"near", camera.nearPlane},
            {"far", camera.farPlane},
            {"view", jsonMat4(camera.view)},
            {"projection", jsonMat4(camera.projection)}};
}
} // namespace

void Renderer::Impl::prepareReferenceMethod(Frame& frame, const SceneSpec& spec) {
    frame.referenceInputs.model = frame.model;
    frame.referenceInputs.partMaterials = frame.partMaterials;
    frame.referenceInputs.mmPerUnit = static_cast<float>(spec.mmPerUnit);
    frame.referenceInputs.source = spec.source;
    referenceMethod.prepare(frame.referenceInputs, spec.sss);
}

// --- the stages ----------------------------------------------------------------------------------------------
Frame Renderer::Impl::loadFrame(const SceneSpec& spec) {
    Frame frame;
    frame.spec = &spec;
    frame.model = model(spec);
    frame.partMaterials = partMaterialsOf(spec, *frame.model);
    return frame;
}

// upload: geometry, maps (a spec's maps replace the ones the model brings, e.g. builtin:head's procedural skin
// detail) and environment, into a new resident scene.
void Renderer::Impl::uploadScene(const Frame& frame) {
    const SceneSpec& spec = *frame.spec;
    residentScene.reset();
    const auto albedoMap = albedoMapOf(spec, *frame.model);
    const auto normalMap =
        spec.textures.normal.empty() ? frame.model->normalMap : image(spec.textures.normal, ColorEncoding::Data);
    const auto specularMap = image(spec.textures.specular, ColorEncoding::Data);
    const auto occlusionMap = image(spec.textures.occlusion, ColorEncoding::Data);
    const auto skinMaskMap = image(spec.textures.skinMask, ColorEncoding::Data);
    const CachedEnvironment& cached = environment(spec.environment);
    auto scene = std::make_unique<gl::GpuScene>();
    scene->uploadModel(*frame.model, frame.partMaterials);
    scene->uploadMaps(albedoMap.get(), normalMap.get(), specularMap.get(), occlusionMap.get(), skinMaskMap.get());
    std::array<glm::vec3, 9> irradiance = irradianceCoefficientsSH9(cached.radianceSH);
    for (glm::vec3& c : irradiance) c *= static_cast<float>(spec.environment.intensity);
    const bool environmentBackground = spec.environment.background == "environment" && cached.environment;
    std::unique_ptr<Environment> irradianceByNormal; // the irradiance map times the intensity
    if (cached.irradiance) {
        irradianceByNormal = std::make_unique<Environment>(*cached.irradiance);
        for (glm::vec3& e : irradianceByNormal->pixels) e *= static_cast<float>(spec.environment.intensity);
    }
    scene->uploadEnvironment(environmentBackground ? cached.environment.get() : nullptr, irradiance,
                             irradianceByNormal.get());
    glFinish();
    residentScene = std::move(scene);
}

// The camera framing the skin, the internal size, the exposure and the environment's rotation.
void Renderer::Impl::placeCamera(Frame& frame) {
    const SceneSpec& spec = *frame.spec;
    glm::vec3 frameMin, frameMax;
    skinBounds(*frame.model, frame.partMaterials, frameMin, frameMax);
    setInternalSize(frame, spec);
    frame.camera =
        frameCamera(spec.camera, frameMin, frameMax, frame.model->boundsMin, frame.model->boundsMax,
                    spec.frameWidth * frame.ssaaFactor, spec.frameHeight * frame.ssaaFactor, internalWindow(spec));
    frame.exposure = static_cast<float>(std::exp2(spec.exposureEv));
    frame.environmentFromWorld = glm::mat3(glm::rotate(
        glm::mat4(1.0f), static_cast<float>(-glm::radians(spec.environment.rotationDeg)), glm::vec3(0, 1, 0)));
}

// sss.method = "pathtraced" / "eevee": Blender renders the same triangles, camera, lights and environment
// (renderer/pathtraced, docs/pathtraced.md) before any pass runs, so a missing or failing Blender leaves nothing
// done. The passes still run (the screen-space stage copies through) for the AOVs Blender does not produce: albedo,
// normals, transmittance, aux, curvature.
pathtraced::CyclesImage Renderer::Impl::renderBlender(const Frame& frame, pathtraced::BlenderEngine engine) {
    const SceneSpec& spec = *frame.spec;
    pathtraced::BlenderSceneInputs inputs;
    inputs.spec = &spec;
    inputs.model = frame.model.get();
    for (const gl::GpuMaterial& m : frame.partMaterials)
        inputs.partMaterials.push_back({m.albedo, m.skin, m.glossiness, m.specularIntensity});
    inputs.camera = frame.camera;
    inputs.sssWidthMm = spec.sss.widthMm;
    const auto albedoMap = albedoMapOf(spec, *frame.model);
    if (spec.skin && !spec.textures.albedo.empty()) inputs.retonedAlbedoMap = albedoMap.get();
    return pathtraced::renderBlenderFrame(engine, std::move(inputs), frame.exposure);
}

// The pipeline of one frame: upload → camera → [Blender] → shadows → lighting (main … transmittance) → SSS stage (or
// the object-space reference) → add specular → resolve → tone map. `everything`: every stage runs (render());
// otherwise a stage runs when what it reads (StageReads) changed since its last run or a stage before it re-ran.
PipelineRun Renderer::Impl::runPipeline(Frame& frame, bool everything) {
    const SceneSpec& spec = *frame.spec;
    PipelineRun run;
    const auto uploadStart = std::chrono::steady_clock::now();
    const std::string uploadKey = readsKey(spec, kUploadReads);
    const bool upload = everything || !residentScene || residentSceneKey != uploadKey;
    if (upload) {
        residentSceneKey.clear();
        shadowKey.clear();
        lightingKey.clear();
        uploadScene(frame);
        residentSceneKey = uploadKey;
        run.reran.push_back("upload");
    }
    frame.scene = residentScene.get();
    // The shadow maps are kept, with the lights' shadow matrices the shadow pass set, while what they read stays.
    const std::string shadowKeyNow = readsKey(spec, kShadowReads);
    const bool shadows = upload || shadowKey != shadowKeyNow;
    if (shadows) frame.scene->lights = gpuLightsOf(spec);
    placeCamera(frame);
    if (const auto engine = blenderEngineOf(spec.sss)) run.blender = renderBlender(frame, *engine);
    // sss.method = "reference": its parameters checked and the surface tessellated (cached) before the first pass,
    // so bad input fails with no pass half done.
    const bool objectSpace = stagesOf(spec.sss).objectSpace;
    if (objectSpace) prepareReferenceMethod(frame, spec);
    run.uploadMs = millisecondsSince(uploadStart);

    timer.reset();
    const std::string lightingKeyNow = readsKey(spec, kLightingReads);
    if (shadows || lightingKey != lightingKeyNow) {
        lightingKey.clear();
        shadowKey.clear();
        targets.resize(frame.width, frame.height);
        residentMainSettings = runLightingPasses(frame, shadows);
        shadowKey = shadowKeyNow;
        lightingKey = lightingKeyNow;
        if (shadows) run.reran.push_back("shadows");
        run.reran.push_back("lighting");
    }
    // The reference method draws into the frame targets itself: the lighting is not kept after it.
    if (objectSpace) lightingKey.clear();
    if (frame.ssaaFactor > 1) resolvedTargets.resize(spec.width, spec.height);
    run.supportRadiusMm = runSssPasses(frame, residentMainSettings);
    run.reran.push_back("sss");
    return run;
}

// Reads `layer` of the output targets (in the texture's own layout, RGBA32F or R32F: Mesa then copies instead of
// converting per pixel).
std::vector<float> Renderer::Impl::readOutput(const Frame& frame, GLuint texture, int channels) {
    const SceneSpec& spec = *frame.spec;
    std::vector<float> data(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) *
                            static_cast<std::size_t>(channels));
    gl::readTexture(texture, spec.width, spec.height, channels, data.data());
    return data;
}

// The display image's RGB (of an RGBA read-back).
std::vector<float> Renderer::Impl::readDisplay(const Frame& frame) {
    const std::vector<float> rgba = readOutput(frame, output(frame).display.get(), 4);
    std::vector<float> display(rgba.size() / 4 * 3);
    for (std::size_t p = 0; p < rgba.size() / 4; ++p)
        for (std::size_t c = 0; c < 3; ++c) display[p * 3 + c] = rgba[p * 4 + c];
    return display;
}

DisplayFrame Renderer::renderDisplay(const RenderRequest& request, bool withLinear) {
    const auto start = std::chrono::steady_clock::now();
    SceneSpec spec = loadSpec(request);
    if (blenderEngineOf(spec.sss))
        throw InputError(spec.source + ": sss.method: '" + std::string(sss::methodName(spec.sss.method)) +
                         "' renders through Blender; use skinlab render");
    Impl& impl = *impl_;
    impl.context.makeCurrent();
    Frame frame = impl.loadFrame(spec);
    const double loadMs = millisecondsSince(start);

    const PipelineRun run = impl.runPipeline(frame, false);
    DisplayFrame out;
    out.reran = run.reran;
    out.supportRadiusMm = run.supportRadiusMm;
    if (withLinear) {
        impl.resolve(frame, &gl::FrameTargets::linearDepth, gl::ResolveMode::Nearest);
        impl.resolve(frame, &gl::FrameTargets::mask, gl::ResolveMode::Average);
    }

    const auto readbackStart = std::chrono::steady_clock::now();
    out.srgb8 = encodeDisplaySrgb8(impl.readDisplay(frame));
    if (withLinear) {
        const gl::FrameTargets& targets = impl.output(frame);
        const std::vector<float> rgba = impl.readOutput(frame, targets.beauty.get(), 4);
        out.beauty.resize(rgba.size() / 4 * 3);
        for (std::size_t p = 0; p < rgba.size() / 4; ++p)
            for (std::size_t c = 0; c < 3; ++c) out.beauty[p * 3 + c] = rgba[p * 4 + c];
        out.depth = impl.readOutput(frame, targets.linearDepth.get(), 1);
        out.mask = impl.readOutput(frame, targets.mask.get(), 1);
    }
    const double readbackMs = millisecondsSince(readbackStart);

    out.width = spec.width;
    out.height = spec.height;
    out.focalLengthPixels = frame.camera.focalLengthPixels / static_cast<float>(frame.ssaaFactor);
    out.mmPerUnit = spec.mmPerUnit;
    out.resolved = spec.resolved;
    out.timingsMs = impl.timer.json();
    out.timingsMs["cpu"] = {
        {"load", gl::roundMs(loadMs)}, {"upload", gl::roundMs(run.uploadMs)}, {"readback", gl::roundMs(readbackMs)}};
    out.timingsMs["call_wall"] = gl::roundMs(millisecondsSince(start));
    return out;
}

// --- render(): the display path, every AOV read back, the EXR and PNG written ------------------------------------
// Every AOV of the table read back at the output size (resolved with anti-aliasing; the beauty is resolved before
// the tone map already) and, when asked, the display image; a Blender frame merged with them.
FrameImages Renderer::Impl::readFrame(const Frame& frame, PipelineRun& run, bool display) {
    const SceneSpec& spec = *frame.spec;
    if (frame.ssaaFactor > 1) {
        timer.begin("resolve_aovs");
        for (const Aov& aov : kAovs)
            if (aov.texture != &gl::FrameTargets::beauty) resolve(frame, aov.texture, aov.resolve);
        timer.end();
    }
    FrameImages images;
    for (const Aov& aov : kAovs)
        images.aovs.push_back(readOutput(frame, (output(frame).*aov.texture).get(), aov.textureChannels));
    if (run.blender) {
        pathtraced::RasterizerLayers layers;
        layers.specular = &images.aovs[aovIndex("specular")];
        layers.depth = &images.aovs[aovIndex("depth")];
        layers.mask = &images.aovs[aovIndex("mask")];
        layers.antialiased = frame.ssaaFactor > 1;
        layers.fractionalSkin = !spec.textures.skinMask.empty();
        for (const Vertex& v : frame.model->vertices) layers.fractionalSkin = layers.fractionalSkin || v.skin < 1.0f;
        images.blenderMerge = pathtraced::mergeRasterizerLayers(*run.blender, *blenderEngineOf(spec.sss), spec, layers);
    }
    if (display && run.blender) {
        // Blender's beauty through the same tone mapper (renderer/shading/tone_mappers.h mirrors the GL pass).
        images.display.resize(run.blender->beauty.size());
        for (std::size_t i = 0; i < images.display.size(); ++i)
            images.display[i] = toneMap(run.blender->beauty[i], spec.toneMapper, static_cast<float>(spec.exponentialK),
                                        static_cast<float>(spec.filmicWhite));
    } else if (display) {
        images.display = readDisplay(frame);
    }
    return images;
}

// The EXR's attributes: the resolved record, versions, camera, scale, SSS support and, for Blender, its record.
ExrMetadata Renderer::Impl::frameMetadata(const Frame& frame, const PipelineRun& run, const FrameImages& images) {
    const SceneSpec& spec = *frame.spec;
    ExrMetadata metadata;
    metadata.strings["skinlab:resolved"] = spec.resolved.dump();
    metadata.strings["skinlab:version"] = version();
    metadata.strings["skinlab:gl_renderer"] = context.renderer();
    metadata.strings["skinlab:gl_version"] = context.version();
    metadata.strings["skinlab:camera"] = cameraJson(frame.camera).dump();
    // The output image's focal length (the passes ran at ssaa_factor × it).
    metadata.floats["skinlab:f_px"] = frame.camera.focalLengthPixels / static_cast<float>(frame.ssaaFactor);
    if (spec.window) // the part of the render.width × render.height frame this image is (x y width height, y from the top)
        metadata.strings["skinlab:window"] = std::to_string(spec.window->x) + " " + std::to_string(spec.window->y) +
                                             " " + std::to_string(spec.window->width) + " " +
                                             std::to_string(spec.window->height);
    metadata.floats["skinlab:mm_per_unit"] = static_cast<float>(spec.mmPerUnit);
    metadata.floats["skinlab:sss_radius_mm"] = run.supportRadiusMm;
    if (run.blender)
        pathtraced::addBlenderMetadata(metadata, *blenderEngineOf(spec.sss), spec, *run.blender, images.blenderMerge,
                                       blenderChannels());
    return metadata;
}

RenderResult Renderer::render(const RenderRequest& request) {
    if (request.exrPath.empty()) throw InputError("render: an output EXR path is required (-o out.exr)");
    const auto loadStart = std::chrono::steady_clock::now();
    SceneSpec spec = loadSpec(request);
    Impl& impl = *impl_;
    impl.context.makeCurrent();
    Frame frame = impl.loadFrame(spec);
    const double loadMs = millisecondsSince(loadStart);

    PipelineRun run = impl.runPipeline(frame, true);
    const auto readbackStart = std::chrono::steady_clock::now();
    const FrameImages images = impl.readFrame(frame, run, !request.pngPath.empty());
    const double readbackMs = millisecondsSince(readbackStart);

    const auto writeStart = std::chrono::steady_clock::now();
    const std::size_t pixels = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height);
    writeExr(request.exrPath, spec.width, spec.height,
             exrChannels(images.aovs, run.blender ? &*run.blender : nullptr, pixels),
             impl.frameMetadata(frame, run, images));
    if (!request.pngPath.empty())
        writePng(request.pngPath, spec.width, spec.height, encodeDisplaySrgb8(images.display));
    const double writeMs = millisecondsSince(writeStart);

    RenderResult result;
    result.resolved = spec.resolved;
    result.glRenderer = impl.context.renderer();
    result.glVersion = impl.context.version();
    result.timingsMs = impl.timer.json();
    result.timingsMs["cpu"] = {{"load", gl::roundMs(loadMs)},
                               {"upload", gl::roundMs(run.uploadMs)},
                               {"readback", gl::roundMs(readbackMs)},
                               {"write", gl::roundMs(writeMs)}};
    const ExecutorStages& stages = stagesOf(spec.sss);
    if (stages.objectSpace)
        result.timingsMs[stages.timings] = gl::roundTimings(impl.referenceMethod.lastRun()); // CPU parts of "sss"
    if (run.blender)
        result.timingsMs[stages.timings] = {{"render", secondsToMs(run.blender->renderSeconds)},
                                            {"blender_wall", secondsToMs(run.blender->wallSeconds)}};
    result.timingsMs["width"] = spec.width;
    result.timingsMs["height"] = spec.height;
    result.timingsMs["gl_renderer"] = result.glRenderer;
    spdlog::debug("rendered {} ({}x{}): gpu {:.1f} ms, wall {:.1f} ms", spec.source, spec.width, spec.height,
                  result.timingsMs["gpu_total"].get<double>(), result.timingsMs["wall_total"].get<double>());
    return result;
}

} // namespace skinlab::renderer
