#include "renderer/gl/reference_method.h"

#include "common/error.h"
#include "renderer/reference/surface_convolution.h"
#include "renderer/reference/surface_samples.h"
#include "renderer/reference/tessellation.h"
#include "renderer/sss/method.h"
#include "renderer/sss/methods/reference.h"
#include "renderer/sss/radial_profile.h"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <string_view>

namespace skinlab::renderer::gl {

namespace {

// Width of the bake target in pixels (one vertex per pixel, row by row): 2048 × 3907 holds the 8 M vertices of
// kMaxReferenceVertices, well inside GL 4.5's minimum texture size limit (16384).
constexpr int kBakeWidth = 2048;

// The cutoff of the convolution (surface_convolution.h): at most 0.1 % of each channel's energy lies beyond it, the
// method's declared support (renderer/sss/method.h).
constexpr double kCutoffTail = sss::RadialProfileSupport::kCutoffTail;

// A tessellated fragment is the main pass's surface where its view depth is within this share of the main pass's
// linear depth (1e-4: 0.03 mm at 300 mm). Both lie in the same triangle planes, so a match differs by float
// rounding only (~1e-6 relative); a different surface (an occluder, the far side) differs by far more.
constexpr float kDepthTolerance = 1e-4f;

double millisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// "where: key: message" of an InputError re-addressed to the scene spec and its key: tessellateSkin says
// "reference: edge_mm: ...", makeRadialProfile "sss.profile: ...".
[[noreturn]] void rethrowWithKey(const InputError& error, std::string_view source, std::string_view key,
                                 std::string_view prefix) {
    std::string message = error.what();
    if (message.rfind(prefix, 0) == 0) message.erase(0, prefix.size());
    throwInput(source, key, message);
}

std::unique_ptr<sss::RadialProfile> profileOf(const sss::SssParams& params, std::string_view source) {
    try {
        return sss::makeRadialProfile(params);
    } catch (const InputError& error) {
        rethrowWithKey(error, source, "sss.profile", "sss.profile: ");
    }
}

// A tessellated model with its samples and GL buffers, cached by source model, edge length, mm per unit, the
// parts' skin flags and whether the non-skin parts are refined too (sss.reference_non_skin = "absorbs").
struct TessellatedModel {
    std::shared_ptr<const Model> source; // held, so the key's pointer cannot be reused by another model
    float edgeMm = 0.0f;
    float mmPerUnit = 0.0f;
    std::vector<bool> skinParts;
    bool allParts = false;      // non-skin parts refined too
    std::vector<SubMesh> parts; // of the tessellated model (same order as the source's parts)
    reference::SurfaceSamples samples;
    reference::TessellationStatistics statistics;
    double tessellateMs = 0.0;
    int renders = 0; // runs that used this entry
    Buffer vertexBuffer, indexBuffer;
    VertexArray vertexArray;
    // The bake draws every vertex of a skin part once: the part's distinct vertex indices (a triangle list names
    // each vertex about six times, and llvmpipe's cost is per point), ranges per part into pointIndexBuffer.
    Buffer pointIndexBuffer;
    VertexArray pointVertexArray;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pointRanges; // per part: first, count

    bool matches(const ReferenceInputs& inputs, float edge, const std::vector<bool>& skin, bool all) const {
        return source == inputs.model && edgeMm == edge && mmPerUnit == inputs.mmPerUnit && skinParts == skin &&
               allParts == all;
    }
};

} // namespace

struct ReferenceMethod::Impl {
    ShaderLibrary& shaders;
    std::deque<std::unique_ptr<TessellatedModel>> cache; // most recent first
    Texture bakeDiffuse, bakeTransmittance;
    Framebuffer bakeFramebuffer;
    int bakeHeight = 0;
    Buffer convolvedBuffer;
    Texture drawDepth; // the draw's own depth buffer (the depth mismatch), frame size
    int drawDepthWidth = 0, drawDepthHeight = 0;
    std::size_t convolvedCapacity = 0;

    explicit Impl(ShaderLibrary& library) : shaders(library) {}

    TessellatedModel& tessellated(const ReferenceInputs& inputs, float edgeMm, bool allParts, bool& cached) {
        std::vector<bool> skinParts;
        for (const GpuMaterial& material : inputs.partMaterials) skinParts.push_back(material.skin > 0.5f);
        for (auto it = cache.begin(); it != cache.end(); ++it)
            if ((*it)->matches(inputs, edgeMm, skinParts, allParts)) {
                cached = true;
                std::rotate(cache.begin(), it, it + 1);
                return *cache.front();
            }
        cached = false;
        const auto start = std::chrono::steady_clock::now();
        // The spec's material overrides decide what is skin (builtin:bleed with every material made skin, ...).
        Model model = *inputs.model;
        for (std::size_t p = 0; p < model.parts.size() && p < skinParts.size(); ++p)
            model.materials.at(model.parts[p].material).skin = skinParts[p];
        auto entry = std::make_unique<TessellatedModel>();
        // allParts: every part is refined alike, so that non-skin parts next to skin, the convolution's absorbers
        // (reference::NonSkin::Absorbs), are sampled as densely as the skin they border.
        if (allParts)
            for (MeshMaterial& material : model.materials) material.skin = true;
        try {
            model = reference::tessellateSkin(model, edgeMm, inputs.mmPerUnit, &entry->statistics);
        } catch (const InputError& error) {
            rethrowWithKey(error, inputs.source, "sss.reference_edge_mm", "reference: edge_mm: ");
        }
        for (std::size_t p = 0; p < model.parts.size() && p < skinParts.size(); ++p)
            model.materials.at(model.parts[p].material).skin = skinParts[p];
        entry->samples = reference::gatherSurfaceSamples(model, inputs.mmPerUnit);
        entry->source = inputs.model;
        entry->edgeMm = edgeMm;
        entry->mmPerUnit = inputs.mmPerUnit;
        entry->skinParts = skinParts;
        entry->allParts = allParts;
        entry->parts = model.parts;

        std::vector<std::uint32_t> points;
        std::vector<std::uint8_t> seen(model.vertices.size());
        for (const SubMesh& part : model.parts) {
            const auto first = static_cast<std::uint32_t>(points.size());
            std::fill(seen.begin(), seen.end(), 0);
            for (std::uint32_t i = part.firstIndex; i < part.firstIndex + part.indexCount; ++i) {
                const std::uint32_t v = model.indices[i];
                if (!seen[v]) points.push_back(v);
                seen[v] = 1;
            }
            entry->pointRanges.emplace_back(first, static_cast<std::uint32_t>(points.size()) - first);
        }

        GLuint name = 0;
        glCreateBuffers(1, &name);
        entry->vertexBuffer = Buffer(name);
        glNamedBufferStorage(name, static_cast<GLsizeiptr>(model.vertices.size() * sizeof(Vertex)),
                             model.vertices.data(), 0);
        glCreateBuffers(1, &name);
        entry->indexBuffer = Buffer(name);
        glNamedBufferStorage(name, static_cast<GLsizeiptr>(model.indices.size() * sizeof(std::uint32_t)),
                             model.indices.data(), 0);
        glCreateBuffers(1, &name);
        entry->pointIndexBuffer = Buffer(name);
        glNamedBufferStorage(name,
                             static_cast<GLsizeiptr>(std::max<std::size_t>(points.size(), 1) * sizeof(std::uint32_t)),
                             points.empty() ? nullptr : points.data(), 0);
        // Two vertex arrays over the same vertices, with main_pass.vert's layout: triangles for the draw, points
        // for the bake.
        entry->vertexArray = createModelVertexArray(entry->vertexBuffer.get(), entry->indexBuffer.get());
        entry->pointVertexArray = createModelVertexArray(entry->vertexBuffer.get(), entry->pointIndexBuffer.get());
        checkGl("reference: uploading the tessellated model");
        entry->tessellateMs = millisecondsSince(start);
        // A few entries: one stimulus set renders one or two models at one edge length.
        if (cache.size() >= 4) cache.pop_back();
        cache.push_front(std::move(entry));
        return *cache.front();
    }

    // Bake target rows for `vertices` points; (re)allocated when that grows.
    void prepareBakeTarget(std::size_t vertices) {
        const int rows = static_cast<int>((vertices + kBakeWidth - 1) / kBakeWidth);
        if (rows > bakeHeight || !bakeFramebuffer.get()) {
            bakeHeight = std::max(rows, 1);
            bakeDiffuse = createTexture2D(GL_RGBA32F, kBakeWidth, bakeHeight);
            bakeTransmittance = createTexture2D(GL_RGBA32F, kBakeWidth, bakeHeight);
            GLuint name = 0;
            glCreateFramebuffers(1, &name);
            bakeFramebuffer = Framebuffer(name);
            // main_pass.frag's locations 0 (diffuse) and 7 (transmittance); its other outputs are dropped.
            glNamedFramebufferTexture(name, GL_COLOR_ATTACHMENT0, bakeDiffuse.get(), 0);
            glNamedFramebufferTexture(name, GL_COLOR_ATTACHMENT7, bakeTransmittance.get(), 0);
            const GLenum drawBuffers[8] = {GL_COLOR_ATTACHMENT0, GL_NONE, GL_NONE, GL_NONE, GL_NONE, GL_NONE, GL_NONE,
                                           GL_COLOR_ATTACHMENT7};
            glNamedFramebufferDrawBuffers(name, 8, drawBuffers);
            if (glCheckNamedFramebufferStatus(name, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
                throw RuntimeError("reference: bake framebuffer incomplete (" + std::to_string(kBakeWidth) + " x " +
                                   std::to_string(bakeHeight) + ")");
        }
    }

    // The three steps of run(), in order.
    std::vector<float> bake(const ReferenceInputs& inputs, TessellatedModel& mesh);
    std::vector<glm::vec3> convolve(const TessellatedModel& mesh, const std::vector<float>& baked,
                                    const sss::SssParams& params, const sss::RadialProfile& profile,
                                    std::size_t& skinSamples, reference::ConvolutionReport& report,
                                    std::vector<glm::vec3>& ownShare);
    void draw(const ReferenceInputs& inputs, const TessellatedModel& mesh, const std::vector<glm::vec3>& convolved,
              const std::vector<glm::vec3>& ownShare, GLuint output);
};

ReferenceMethod::ReferenceMethod(ShaderLibrary& shaders) : impl_(std::make_unique<Impl>(shaders)) {}
ReferenceMethod::~ReferenceMethod() = default;

void ReferenceMethod::prepare(const ReferenceInputs& inputs, const sss::SssParams& params) {
    profileOf(params, inputs.source);
    bool cached = false;
    const sss::ReferenceParams own = sss::referenceParams(params); // its own keys
    impl_->tessellated(inputs, static_cast<float>(own.edgeMm), own.nonSkin == sss::ReferenceNonSkin::Absorbs, cached);
}

// Bakes the main pass's shading at every vertex of the skin parts; returns the bake's RGBA (diffuse, mask).
std::vector<float> ReferenceMethod::Impl::bake(const ReferenceInputs& inputs, TessellatedModel& mesh) {
    prepareBakeTarget(mesh.samples.size());
    glBindFramebuffer(GL_FRAMEBUFFER, bakeFramebuffer.get());
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    glClearBufferfv(GL_COLOR, 0, zero);
    glClearBufferfv(GL_COLOR, 7, zero);
    glViewport(0, 0, kBakeWidth, bakeHeight);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_PROGRAM_POINT_SIZE);
    const GLuint bakeProgram = shaders.program("reference_bake.vert", "main_pass.frag");
    glUseProgram(bakeProgram);
    MainPass::bindShading(bakeProgram, *inputs.scene, inputs.shadowMaps, inputs.mainSettings);
    setUniform(bakeProgram, "bakeWidth", kBakeWidth);
    setUniform(bakeProgram, "bakeHeight", bakeHeight);
    glBindVertexArray(mesh.pointVertexArray.get());
    for (std::size_t p = 0; p < mesh.parts.size(); ++p) {
        if (!mesh.skinParts[p]) continue;
        MainPass::setMaterial(bakeProgram, inputs.partMaterials[p]);
        const auto [first, count] = mesh.pointRanges[p];
        glDrawElements(GL_POINTS, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>(static_cast<std::uintptr_t>(first) * sizeof(std::uint32_t)));
    }
    glBindVertexArray(0);
    MainPass::unbindShading();
    glDisable(GL_PROGRAM_POINT_SIZE);
    checkGl("reference: bake");

    const std::size_t bakePixels = static_cast<std::size_t>(kBakeWidth) * static_cast<std::size_t>(bakeHeight);
    std::vector<float> diffuse(bakePixels * 4);
    const auto bytes = static_cast<GLsizei>(bakePixels * 4 * sizeof(float));
    glGetTextureImage(bakeDiffuse.get(), 0, GL_RGBA, GL_FLOAT, bytes, diffuse.data());
    checkGl("reference: bake read back");
    return diffuse;
}

// The convolution over the surface of the baked radiance.
std::vector<glm::vec3> ReferenceMethod::Impl::convolve(const TessellatedModel& mesh, const std::vector<float>& baked,
                                                       const sss::SssParams& params, const sss::RadialProfile& profile,
                                                       std::size_t& skinSamples, reference::ConvolutionReport& report,
                                                       std::vector<glm::vec3>& ownShare) {
    const std::size_t vertexCount = mesh.samples.size();
    reference::SurfaceSamples samples = mesh.samples;
    std::vector<glm::vec3> radiance(vertexCount);
    skinSamples = 0;
    for (std::size_t i = 0; i < vertexCount; ++i) {
        const float* d = &baked[i * 4];
        // Transmittance (location 7) is left out on purpose: the convolution at 3-D distances already carries the
        // light of a lit back face through thin parts (the effect transmittance approximates in screen space), so
        // adding it would count that light twice. docs/extensions.md, "The object-space reference".
        radiance[i] = glm::vec3(d[0], d[1], d[2]);
        samples.albedo[i] = glm::vec3(1.0f); // the bake is E · α already
        // The baked mask (alpha) carries the skin-mask map too; partly masked vertices count as skin from 0.5.
        samples.skin[i] = samples.skin[i] && d[3] >= 0.5f ? 1 : 0;
        skinSamples += samples.skin[i];
    }
    reference::ConvolutionSettings convolution;
    convolution.cutoffTail = kCutoffTail;
    // The growth is declared at the profile's own scale (width_mm = 3) and scales with the profile: a profile
    // widened by s has its far-side factor exp(k d²) at d / s, so each Gaussian lobe widens alike at every width.
    const double scale = sss::profileScale(params.widthMm);
    const sss::ReferenceParams own = sss::referenceParams(params); // its own keys
    for (int c = 0; c < 3; ++c) {
        convolution.throughGain[c] = own.throughGain[c];
        convolution.throughGrowthPerMm2[c] = own.throughGrowthPerMm2[c] / (scale * scale);
        convolution.convexityMm[c] = own.convexityMm[c] * scale; // a length: scales with the profile
    }
    convolution.convexityRadiusMinMm = 20.0 * scale; // 20 mm at width 3 mm: the nose tip, the ear's rim
    convolution.nearFieldMm = 0.5 * mesh.edgeMm;     // a seam's twin, a fan's small triangles: near field
    convolution.nonSkin =
        own.nonSkin == sss::ReferenceNonSkin::Returns ? reference::NonSkin::Returns : reference::NonSkin::Absorbs;
    // sss.reference_near_field = "pixel": the near field split off (surface_convolution.h, ownShare); the draw
    // multiplies each vertex's own share by the main pass's E·α at every pixel, so detail finer than the
    // tessellation keeps its sharpness. With "vertex" every share is 0 and the far field holds the whole sum.
    const bool nearAtPixels = own.nearField == sss::ReferenceNearField::Pixel;
    std::vector<glm::vec3> convolved = reference::convolveSurface(samples, radiance, profile, convolution, nullptr,
                                                                  &report, nearAtPixels ? &ownShare : nullptr);
    if (!nearAtPixels) ownShare.assign(vertexCount, glm::vec3(0.0f));
    return convolved;
}

// Draws the tessellated skin with the convolved radiance (far field + own share × the pixel's E·α) over the main
// pass's diffuse, into `output`.
void ReferenceMethod::Impl::draw(const ReferenceInputs& inputs, const TessellatedModel& mesh,
                                 const std::vector<glm::vec3>& convolved, const std::vector<glm::vec3>& ownShare,
                                 GLuint output) {
    const FrameTargets& targets = *inputs.targets;
    const std::size_t vertexCount = mesh.samples.size();
    // Per vertex: the far field (rgb) and the own share (rgb), reference_draw.vert's layout.
    std::vector<glm::vec4> packed(2 * std::max<std::size_t>(vertexCount, 1), glm::vec4(0.0f));
    for (std::size_t i = 0; i < vertexCount; ++i) {
        packed[2 * i] = glm::vec4(convolved[i], 1.0f);
        packed[2 * i + 1] = glm::vec4(ownShare[i], 0.0f);
    }
    if (packed.size() > convolvedCapacity || !convolvedBuffer.get()) {
        GLuint name = 0;
        glCreateBuffers(1, &name);
        convolvedBuffer = Buffer(name);
        glNamedBufferStorage(name, static_cast<GLsizeiptr>(packed.size() * sizeof(glm::vec4)), nullptr,
                             GL_DYNAMIC_STORAGE_BIT);
        convolvedCapacity = packed.size();
    }
    glNamedBufferSubData(convolvedBuffer.get(), 0, static_cast<GLsizeiptr>(packed.size() * sizeof(glm::vec4)),
                         packed.data());

    glCopyImageSubData(targets.diffuse.get(), GL_TEXTURE_2D, 0, 0, 0, 0, output, GL_TEXTURE_2D, 0, 0, 0, 0,
                       targets.width, targets.height, 1);
    // The visibility test is against the main pass's linear depth, not its depth buffer: a depth-buffer test with
    // a polygon offset let back faces next to a silhouette pass (the offset's slope term is large there) and paint
    // the far side's colour into rim pixels. reference_draw.frag keeps the fragment whose depth matches the main
    // pass's best, through a depth buffer of its own holding the mismatch.
    if (drawDepthWidth != targets.width || drawDepthHeight != targets.height) {
        drawDepth = createTexture2D(GL_DEPTH_COMPONENT32F, targets.width, targets.height);
        drawDepthWidth = targets.width;
        drawDepthHeight = targets.height;
    }
    // A framebuffer per run: the output texture's name is recycled when the frame is resized (as sss_stage.cpp).
    const Framebuffer drawFramebuffer = createFramebuffer("reference draw", &output, 1, drawDepth.get());
    glBindFramebuffer(GL_FRAMEBUFFER, drawFramebuffer.get());
    glViewport(0, 0, targets.width, targets.height);
    const float farthest = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &farthest);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    const GLuint drawProgram = shaders.program("reference_draw.vert", "reference_draw.frag");
    glUseProgram(drawProgram);
    setUniform(drawProgram, "view", inputs.mainSettings.camera.view);
    setUniform(drawProgram, "projection", inputs.mainSettings.camera.projection);
    setUniform(drawProgram, "depthTolerance", kDepthTolerance);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, convolvedBuffer.get());
    glBindTextureUnit(0, targets.diffuse.get());
    glBindTextureUnit(1, targets.mask.get());
    glBindTextureUnit(2, targets.linearDepth.get());
    glBindVertexArray(mesh.vertexArray.get());
    for (std::size_t p = 0; p < mesh.parts.size(); ++p) {
        if (!mesh.skinParts[p]) continue;
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.parts[p].indexCount), GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>(static_cast<std::uintptr_t>(mesh.parts[p].firstIndex) *
                                                     sizeof(std::uint32_t)));
    }
    glBindVertexArray(0);
    glBindTextureUnit(0, 0);
    glBindTextureUnit(1, 0);
    glBindTextureUnit(2, 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, 0);
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
    checkGl("reference: draw");
}

// Tessellation and samples (cached) → bake → convolution over the surface → draw.
void ReferenceMethod::run(const ReferenceInputs& inputs, const sss::SssParams& params, GLuint output) {
    Impl& impl = *impl_;
    const auto profile = profileOf(params, inputs.source);         // refuse a tabulated profile before any work
    const sss::ReferenceParams own = sss::referenceParams(params); // its own keys
    const float edgeMm = static_cast<float>(own.edgeMm);
    bool cached = false;
    TessellatedModel& mesh = impl.tessellated(inputs, edgeMm, own.nonSkin == sss::ReferenceNonSkin::Absorbs, cached);
    cached = mesh.renders > 0; // prepare() of this render may have made the entry: count it as this render's
    ++mesh.renders;

    const auto bakeStart = std::chrono::steady_clock::now();
    const std::vector<float> baked = impl.bake(inputs, mesh);
    const double bakeMs = millisecondsSince(bakeStart);
    const auto convolveStart = std::chrono::steady_clock::now();
    std::size_t skinSamples = 0;
    reference::ConvolutionReport report;
    std::vector<glm::vec3> ownShare;
    const std::vector<glm::vec3> convolved =
        impl.convolve(mesh, baked, params, *profile, skinSamples, report, ownShare);
    const double convolveMs = millisecondsSince(convolveStart);
    impl.draw(inputs, mesh, convolved, ownShare, output);

    lastRun_ = {{"tessellate_ms", cached ? 0.0 : mesh.tessellateMs},
                {"cached", cached},
                {"samples", mesh.samples.size()},
                {"skin_samples", skinSamples},
                {"bake_readback_ms", bakeMs},
                {"convolve_ms", convolveMs},
                {"sources_per_sample", report.meanSources},
                {"cutoff_mm", report.cutoffRadiusMm},
                {"edge_mm", edgeMm},
                {"longest_edge_mm", mesh.statistics.longestSkinEdgeMm}};
}

} // namespace skinlab::renderer::gl
