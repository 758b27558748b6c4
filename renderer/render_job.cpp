// The renderer's public entry point (render_job.h): scene spec → GL passes → EXR (+ PNG), with timings.
//
// Pipeline (docs/rendering.md, "Pipeline"), one class per pass under renderer/gl/:
//   shadow map → main pass → background → surface AOVs → transmittance → SSS stage → add specular → tone map
//   → read back → EXR / PNG
#include "renderer/render_job.h"

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
#include "renderer/gl/shader_library.h"
#include "renderer/gl/shadow_map_pass.h"
#include "renderer/gl/sss_stage.h"
#include "renderer/gl/surface_aov_pass.h"
#include "renderer/gl/tone_map_pass.h"
#include "renderer/gl/transmittance_pass.h"
#include "renderer/output/display_output.h"
#include "renderer/output/exr_writer.h"
#include "renderer/pathtraced/cycles_render.h"
#include "renderer/shading/tone_mappers.h"
#include "renderer/scene/builtin_geometry.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/mesh_loader.h"
#include "renderer/scene/scene_spec.h"
#include "renderer/scene/texture.h"
#include "renderer/shading/tone_mappers.h"
#include "renderer/sss/sss_params.h"

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
    return out;  // column-major, as GLM / OpenGL
}

// Bounds of the parts whose material is skin (the named views frame them); the whole model without skin.
void skinBounds(const Model& model, const std::vector<gl::GpuMaterial>& materials, glm::vec3& lowest, glm::vec3& highest) {
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

struct Renderer::Impl {
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
    gl::ReferenceMethod referenceMethod{shaders};  // sss.method = "reference": replaces the SSS stage
    gl::AddSpecularPass addSpecularPass{shaders};
    gl::ToneMapPass toneMapPass{shaders};

    // CPU-side caches: a stimulus set renders the same model, maps and environment many times.
    std::map<std::string, std::shared_ptr<const Model>> models;
    std::map<std::string, std::shared_ptr<const Image>> images;
    struct CachedEnvironment {
        std::shared_ptr<const Environment> environment;
        std::array<glm::vec3, 9> radianceSH;
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

    const CachedEnvironment& environment(const EnvironmentSpec& spec) {
        std::string key = spec.file.string();
        if (spec.file.empty())
            key = "constant|" + std::to_string(spec.radiance.x) + "," + std::to_string(spec.radiance.y) + "," +
                  std::to_string(spec.radiance.z);
        if (auto found = environments.find(key); found != environments.end()) return found->second;
        CachedEnvironment cached;
        if (spec.file.empty()) {
            // A constant environment L has radiance SH (L·√(4π), 0, ...); computed through the same projection.
            const Environment constant = makeConstantEnvironment(spec.radiance);
            cached.radianceSH = projectSH9(constant);
        } else {
            auto loaded = std::make_shared<const Environment>(loadEnvironment(spec.file));
            cached.radianceSH = projectSH9(*loaded);
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

RenderResult Renderer::render(const RenderRequest& request) {
    if (request.exrPath.empty()) throw InputError("render: an output EXR path is required (-o out.exr)");
    const auto loadStart = std::chrono::steady_clock::now();
    SceneSpec spec = loadSpec(request);
    Impl& impl = *impl_;
    impl.context.makeCurrent();

    // --- scene data (CPU) -------------------------------------------------------------------------------
    const std::shared_ptr<const Model> model = impl.model(spec);
    std::vector<gl::GpuMaterial> partMaterials;
    {
        std::vector<gl::GpuMaterial> byMaterial;
        for (const MeshMaterial& m : model->materials)
            byMaterial.push_back({m.albedo, m.skin ? 1.0f : 0.0f, m.glossiness, m.specularIntensity});
        for (std::size_t i = 0; i < spec.materials.size(); ++i) {
            const MaterialSpec& override = spec.materials[i];
            bool matched = false;
            for (std::size_t m = 0; m < model->materials.size(); ++m) {
                if (override.name != "*" && override.name != model->materials[m].name) continue;
                matched = true;
                gl::GpuMaterial& target = byMaterial[m];
                if (override.albedo) target.albedo = *override.albedo;
                if (override.skin) target.skin = *override.skin ? 1.0f : 0.0f;
                if (override.glossiness) target.glossiness = static_cast<float>(*override.glossiness);
                if (override.specularIntensity) target.specularIntensity = static_cast<float>(*override.specularIntensity);
            }
            if (!matched) {
                std::string names;
                for (const MeshMaterial& m : model->materials) names += (names.empty() ? "" : ", ") + m.name;
                throwInput(spec.source, "materials[" + std::to_string(i) + "].name",
                           "no material '" + override.name + "' in the model (it has: " + names + "; \"*\" means all)");
            }
        }
        for (const SubMesh& part : model->parts) partMaterials.push_back(byMaterial.at(part.material));
    }
    // A spec's maps replace the ones the model brings (builtin:head's procedural skin detail).
    const auto albedoMap = spec.textures.albedo.empty() ? model->albedoMap : impl.image(spec.textures.albedo, ColorEncoding::sRGB);
    const auto normalMap = spec.textures.normal.empty() ? model->normalMap : impl.image(spec.textures.normal, ColorEncoding::Data);
    const auto specularMap = impl.image(spec.textures.specular, ColorEncoding::Data);
    const auto occlusionMap = impl.image(spec.textures.occlusion, ColorEncoding::Data);
    const auto skinMaskMap = impl.image(spec.textures.skinMask, ColorEncoding::Data);
    const Impl::CachedEnvironment& environment = impl.environment(spec.environment);
    const double loadMs = millisecondsSince(loadStart);

    // --- upload ------------------------------------------------------------------------------------------
    const auto uploadStart = std::chrono::steady_clock::now();
    gl::GpuScene scene;
    scene.uploadModel(*model, partMaterials);
    scene.uploadMaps(albedoMap.get(), normalMap.get(), specularMap.get(), occlusionMap.get(), skinMaskMap.get());
    std::array<glm::vec3, 9> irradiance = irradianceCoefficientsSH9(environment.radianceSH);
    for (glm::vec3& c : irradiance) c *= static_cast<float>(spec.environment.intensity);
    const bool environmentBackground = spec.environment.background == "environment" && environment.environment;
    scene.uploadEnvironment(environmentBackground ? environment.environment.get() : nullptr, irradiance);
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
        scene.lights.push_back(g);
    }
    glm::vec3 frameMin, frameMax;
    skinBounds(*model, partMaterials, frameMin, frameMax);
    const CameraPose camera = frameCamera(spec.camera, frameMin, frameMax, model->boundsMin, model->boundsMax,
                                          spec.width, spec.height);
    impl.targets.resize(spec.width, spec.height);
    const float exposure = static_cast<float>(std::exp2(spec.exposureEv));
    const glm::mat3 environmentFromWorld(
        glm::rotate(glm::mat4(1.0f), static_cast<float>(-glm::radians(spec.environment.rotationDeg)), glm::vec3(0, 1, 0)));
    glFinish();
    const double uploadMs = millisecondsSince(uploadStart);

    // sss.method = "pathtraced": Blender Cycles renders the same triangles, camera, lights and environment
    // (renderer/pathtraced, docs/pathtraced.md) before any pass runs, so a missing or failing Blender leaves
    // nothing done. The passes below still run (the screen-space stage copies through) for the AOVs Cycles does
    // not produce: albedo, normals, transmittance, aux, curvature.
    std::optional<pathtraced::CyclesImage> cycles;
    bool fractionalSkin = !spec.textures.skinMask.empty();
    for (const Vertex& v : model->vertices) fractionalSkin = fractionalSkin || v.skin < 1.0f;
    if (spec.sssMethod == "pathtraced") {
        pathtraced::BlenderSceneInputs cyclesInputs;
        cyclesInputs.spec = &spec;
        cyclesInputs.model = model.get();
        for (const gl::GpuMaterial& m : partMaterials)
            cyclesInputs.partMaterials.push_back({m.albedo, m.skin, m.glossiness, m.specularIntensity});
        cyclesInputs.camera = camera;
        cyclesInputs.params = pathtraced::pathtracedParamsFromJson(spec.pathtraced, spec.source);
        cyclesInputs.sssWidthMm = sss::sssParamsFromJson(spec.sss, spec.source).widthMm;
        cycles = pathtraced::renderWithCycles(cyclesInputs, exposure);
    }

    // --- passes ------------------------------------------------------------------------------------------
    // sss.method = "reference": check its parameters and tessellate (cached) before the first pass, so bad input
    // fails with no pass half done.
    const bool referenceMethod = spec.sssMethod == "reference";
    gl::ReferenceInputs referenceInputs;
    sss::SssParams referenceParams;
    if (referenceMethod) {
        referenceParams = sss::sssParamsFromJson(spec.sss, spec.source);
        referenceInputs.model = model;
        referenceInputs.partMaterials = partMaterials;
        referenceInputs.mmPerUnit = static_cast<float>(spec.mmPerUnit);
        referenceInputs.source = spec.source;
        impl.referenceMethod.prepare(referenceInputs, referenceParams);
    }

    gl::PassTimer& timer = impl.timer;
    timer.reset();
    timer.begin("shadow");
    impl.shadowMapPass.run(scene, model->boundsMin, model->boundsMax, spec.shadowResolution);
    timer.end();

    timer.begin("main");
    gl::MainPassSettings mainSettings;
    mainSettings.camera = camera;
    mainSettings.exposure = exposure;
    mainSettings.normalStrength = static_cast<float>(spec.textures.normalStrength);
    mainSettings.pcfRadius = spec.shadowPcfRadius;
    mainSettings.environmentFromWorld = environmentFromWorld;
    const sss::TransmittanceParams transmittanceParams =
        sss::transmittanceParamsFromJson(spec.transmittance, spec.source);
    mainSettings.transmittanceEnabled = transmittanceParams.enabled;
    mainSettings.translucency = static_cast<float>(transmittanceParams.translucency);
    const sss::SssParams sssParams = sss::sssParamsFromJson(spec.sss, spec.source);
    mainSettings.sssWidthMm = static_cast<float>(sssParams.widthMm);
    mainSettings.transmittanceThesisCurvature =
        transmittanceParams.curvature && transmittanceParams.curvatureForm == "thesis";
    mainSettings.curvatureReferenceMm = static_cast<float>(sssParams.curvatureReferenceMm);
    mainSettings.mmPerUnit = static_cast<float>(spec.mmPerUnit);
    impl.mainPass.run(impl.targets, scene, impl.shadowMapPass.shadowMaps(), mainSettings);
    timer.end();

    timer.begin("background");
    gl::BackgroundSettings backgroundSettings;
    backgroundSettings.camera = camera;
    backgroundSettings.environmentMap = scene.environmentMap();
    backgroundSettings.color = spec.environment.background == "color"
                                   ? spec.environment.backgroundColor
                                   : spec.environment.radiance * static_cast<float>(spec.environment.intensity);
    backgroundSettings.environmentIntensity = static_cast<float>(spec.environment.intensity);
    backgroundSettings.exposure = exposure;
    backgroundSettings.environmentFromWorld = environmentFromWorld;
    impl.backgroundPass.run(impl.targets, backgroundSettings);
    timer.end();

    timer.begin("surface_aovs");
    gl::SurfaceAovSettings surfaceAovSettings;
    surfaceAovSettings.camera = camera;
    surfaceAovSettings.screenCurvature = sssParams.curvatureMeasure == "screen";
    impl.surfaceAovPass.run(impl.targets, surfaceAovSettings);
    timer.end();

    timer.begin("transmittance");
    gl::TransmittanceSettings transmittanceSettings;
    transmittanceSettings.enabled = transmittanceParams.enabled;
    transmittanceSettings.curvature = transmittanceParams.curvature;
    transmittanceSettings.mmPerUnit = static_cast<float>(spec.mmPerUnit);
    transmittanceSettings.thesisForm = transmittanceParams.curvatureForm == "thesis";
    transmittanceSettings.curvatureReferenceMm = static_cast<float>(sssParams.curvatureReferenceMm);
    impl.transmittancePass.run(impl.targets, transmittanceSettings);
    timer.end();

    timer.begin("sss");
    gl::SssStageInputs sssInputs;
    sssInputs.diffuse = impl.targets.diffuse.get();
    sssInputs.linearDepth = impl.targets.linearDepth.get();
    sssInputs.albedo = impl.targets.albedo.get();
    sssInputs.skinMask = impl.targets.mask.get();
    sssInputs.normal = impl.targets.normal.get();
    sssInputs.geometricNormal = impl.targets.geometricNormal.get();
    sssInputs.aux = impl.targets.aux.get();
    sssInputs.curvature = impl.targets.curvature.get();
    sssInputs.width = spec.width;
    sssInputs.height = spec.height;
    sssInputs.focalLengthPixels = camera.focalLengthPixels;
    sssInputs.mmPerUnit = static_cast<float>(spec.mmPerUnit);
    sssInputs.view = camera.view;
    sssInputs.projection = camera.projection;
    sssInputs.cameraPosition = camera.position;
    gl::SssStageSettings sssSettings;
    sssSettings.sss = spec.sss;
    sssSettings.transmittance = spec.transmittance;
    if (referenceMethod) {
        // The object-space reference bakes the main pass's shading at the tessellated vertices itself, so it needs
        // the model, the scene and the main pass's settings rather than the screen-space inputs.
        referenceInputs.scene = &scene;
        referenceInputs.shadowMaps = impl.shadowMapPass.shadowMaps();
        referenceInputs.mainSettings = mainSettings;
        referenceInputs.targets = &impl.targets;
        impl.referenceMethod.run(referenceInputs, referenceParams, impl.targets.scatteredDiffuse.get());
    } else {
        impl.sssStage.run(sssInputs, sssSettings, impl.targets.scatteredDiffuse.get());
    }
    timer.end();

    timer.begin("add_specular");
    impl.addSpecularPass.run(impl.targets);
    timer.end();

    timer.begin("tone_map");
    float reinhardScale = 1.0f;
    if (spec.toneMapper == "reinhard") {
        // Reinhard et al. 2002, Eq. 1: the log-average luminance of the beauty (read back once, on the CPU).
        std::vector<float> linear(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height) * 4);
        gl::readTexture(impl.targets.beauty.get(), spec.width, spec.height, 4, linear.data());
        const double logAverage = reinhardLogAverage(linear.data(), linear.size() / 4, 4);
        reinhardScale = static_cast<float>(spec.reinhardKey / logAverage);
    }
    impl.toneMapPass.run(impl.targets, spec.toneMapper, static_cast<float>(spec.exponentialK),
                         static_cast<float>(spec.filmicWhite), reinhardScale);
    timer.end();

    // --- read back and write -----------------------------------------------------------------------------
    const auto readbackStart = std::chrono::steady_clock::now();
    const int width = spec.width;
    const int height = spec.height;
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    // Read in the textures' own layout (RGBA32F / R32F): Mesa then copies instead of converting per pixel.
    auto read = [&](GLuint texture, int channels) {
        std::vector<float> data(pixels * static_cast<std::size_t>(channels));
        gl::readTexture(texture, width, height, channels, data.data());
        return data;
    };
    const std::vector<float> beauty = read(impl.targets.beauty.get(), 4);
    const std::vector<float> diffuse = read(impl.targets.scatteredDiffuse.get(), 4);
    const std::vector<float> specular = read(impl.targets.specular.get(), 4);
    const std::vector<float> albedo = read(impl.targets.albedo.get(), 4);
    const std::vector<float> depth = read(impl.targets.linearDepth.get(), 1);
    const std::vector<float> normal = read(impl.targets.normal.get(), 4);
    const std::vector<float> geometricNormal = read(impl.targets.geometricNormal.get(), 4);
    const std::vector<float> mask = read(impl.targets.mask.get(), 1);
    const std::vector<float> transmittance = read(impl.targets.transmittance.get(), 4);
    const std::vector<float> aux = read(impl.targets.aux.get(), 1);
    const std::vector<float> curvature = read(impl.targets.curvature.get(), 1);
    if (cycles && pathtraced::pathtracedParamsFromJson(spec.pathtraced, spec.source).specularSource == "rasterizer") {
        // pathtraced.specular_source = "rasterizer": Cycles rendered no specular lobe; its beauty gets the
        // rasterizer's specular pass (same camera), so only the diffuse/subsurface layer comes from Cycles.
        for (std::size_t p = 0; p < pixels; ++p)
            for (std::size_t c = 0; c < 3; ++c) {
                cycles->specular[p * 3 + c] = specular[p * 4 + c];
                cycles->beauty[p * 3 + c] += specular[p * 4 + c];
            }
    }
    std::vector<float> display;
    if (!request.pngPath.empty() && cycles) {
        // Cycles' beauty through the same tone mapper (renderer/shading/tone_mappers.h mirrors the GL pass).
        display.resize(pixels * 3);
        for (std::size_t i = 0; i < pixels * 3; ++i)
            display[i] = toneMap(cycles->beauty[i], spec.toneMapper, static_cast<float>(spec.exponentialK),
                                 static_cast<float>(spec.filmicWhite));
    } else if (!request.pngPath.empty()) {
        const std::vector<float> displayRgba = read(impl.targets.display.get(), 4);
        display.resize(pixels * 3);
        for (std::size_t p = 0; p < pixels; ++p)
            for (std::size_t c = 0; c < 3; ++c) display[p * 3 + c] = displayRgba[p * 4 + c];
    }
    const double readbackMs = millisecondsSince(readbackStart);

    const auto writeStart = std::chrono::steady_clock::now();
    std::vector<ExrChannel> channels;
    auto addChannels = [&](const std::string& layer, const std::vector<float>& data, int stride, const char* names) {
        for (int c = 0; names[c]; ++c) {
            ExrChannel channel;
            channel.name = layer.empty() ? std::string(1, names[c]) : layer + "." + std::string(1, names[c]);
            channel.values.resize(pixels);
            for (std::size_t p = 0; p < pixels; ++p) channel.values[p] = data[p * static_cast<std::size_t>(stride) + static_cast<std::size_t>(c)];
            channels.push_back(std::move(channel));
        }
    };
    if (cycles) {
        // Beauty, diffuse, specular, depth and mask from Cycles; the other AOVs from the rasterizer's passes.
        addChannels("", cycles->beauty, 3, "RGB");
        addChannels("diffuse", cycles->diffuse, 3, "RGB");
        addChannels("specular", cycles->specular, 3, "RGB");
    } else {
        addChannels("", beauty, 4, "RGB");
        addChannels("diffuse", diffuse, 4, "RGB");
        addChannels("specular", specular, 4, "RGB");
    }
    addChannels("albedo", albedo, 4, "RGB");
    addChannels("depth", cycles ? cycles->depth : depth, 1, "Z");
    addChannels("normal", normal, 4, "XYZ");
    addChannels("geonormal", geometricNormal, 4, "XYZ");
    if (cycles && fractionalSkin) {
        // A skin-mask map or per-vertex skin below 1: Cycles' index pass only knows the material's flag, so the
        // rasterizer's mask (same camera, point-sampled) supplies the fraction.
        for (std::size_t p = 0; p < pixels; ++p) cycles->mask[p] *= std::clamp(mask[p], 0.0f, 1.0f);
    }
    addChannels("mask", cycles ? cycles->mask : mask, 1, "Y");
    addChannels("transmittance", transmittance, 4, "RGB");
    addChannels("aux", aux, 1, "Y");
    addChannels("curvature", curvature, 1, "Y");

    const nlohmann::json cameraJson = {{"position", jsonVec3(camera.position)},
                                       {"target", jsonVec3(camera.target)},
                                       {"up", jsonVec3(camera.up)},
                                       {"fov_y_deg", glm::degrees(camera.fovYRadians)},
                                       {"near", camera.nearPlane},
                                       {"far", camera.farPlane},
                                       {"view", jsonMat4(camera.view)},
                                       {"projection", jsonMat4(camera.projection)}};
    ExrMetadata metadata;
    metadata.strings["skinlab:resolved"] = spec.resolved.dump();
    metadata.strings["skinlab:version"] = version();
    metadata.strings["skinlab:gl_renderer"] = impl.context.renderer();
    metadata.strings["skinlab:gl_version"] = impl.context.version();
    metadata.strings["skinlab:camera"] = cameraJson.dump();
    metadata.floats["skinlab:f_px"] = camera.focalLengthPixels;
    metadata.floats["skinlab:mm_per_unit"] = static_cast<float>(spec.mmPerUnit);
    // pathtraced: the support of the profile its radii are matched to (as the object-space reference declares).
    metadata.floats["skinlab:sss_radius_mm"] =
        referenceMethod ? gl::ReferenceMethod::supportRadiusMm(referenceParams, spec.source)
        : cycles        ? gl::ReferenceMethod::supportRadiusMm(sss::sssParamsFromJson(spec.sss, spec.source), spec.source)
                        : impl.sssStage.supportRadiusMm(sssSettings);
    if (cycles) {
        const nlohmann::json params = spec.pathtraced;
        metadata.strings["skinlab:pathtraced"] =
            nlohmann::json{{"samples", params.at("samples")},
                           {"seed", params.at("seed")},
                           {"blender_version", cycles->blenderVersion},
                           {"render_seconds", cycles->renderSeconds},
                           {"wall_seconds", cycles->wallSeconds},
                           {"channels_from_cycles",
                            params.value("specular_source", "cycles") == "rasterizer"
                                ? nlohmann::json{"R, G, B: diffuse only", "diffuse.*", "depth.Z", "mask.Y"}
                                : nlohmann::json{"R", "G", "B", "diffuse.*", "specular.*", "depth.Z", "mask.Y"}}}
                .dump();
        metadata.strings["skinlab:blender_version"] = cycles->blenderVersion;
        metadata.floats["skinlab:pathtraced_samples"] = static_cast<float>(params.at("samples").get<int>());
        metadata.floats["skinlab:pathtraced_seed"] = static_cast<float>(params.at("seed").get<int>());
        metadata.floats["skinlab:render_seconds"] = static_cast<float>(cycles->renderSeconds);
    }
    writeExr(request.exrPath, width, height, channels, metadata);
    if (!request.pngPath.empty()) writePng(request.pngPath, width, height, encodeDisplaySrgb8(display));
    const double writeMs = millisecondsSince(writeStart);

    RenderResult result;
    result.resolved = spec.resolved;
    result.glRenderer = impl.context.renderer();
    result.glVersion = impl.context.version();
    result.timingsMs = timer.json();
    result.timingsMs["cpu"] = {{"load", loadMs}, {"upload", uploadMs}, {"readback", readbackMs}, {"write", writeMs}};
    if (referenceMethod) result.timingsMs["reference"] = impl.referenceMethod.lastRun();  // CPU parts of "sss"
    if (cycles)
        result.timingsMs["pathtraced"] = {{"render", cycles->renderSeconds * 1000.0}, {"blender_wall", cycles->wallSeconds * 1000.0}};
    result.timingsMs["width"] = width;
    result.timingsMs["height"] = height;
    result.timingsMs["gl_renderer"] = result.glRenderer;
    spdlog::debug("rendered {} ({}x{}): gpu {:.1f} ms, wall {:.1f} ms", spec.source, width, height,
                  result.timingsMs["gpu_total"].get<double>(), result.timingsMs["wall_total"].get<double>());
    return result;
}

} // namespace skinlab::renderer
