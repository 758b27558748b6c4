#pragma once
// The SSS stage slot of the pipeline (docs/methods.md): between the main pass, which writes the diffuse
// (irradiance × albedo) buffer and the AOVs, and add_specular. It reads the diffuse buffer and writes the
// scattered diffuse buffer; every method of renderer/sss plugs in behind run().
//
// Contract for the methods:
//  - all textures are GL_TEXTURE_2D, width × height, sampled with texelFetch (no filtering, no mipmaps);
//  - colours are linear Rec.709, scene-referred, exposure already applied (the main pass scales by
//    2^exposure_ev; every method is linear in the colour, so this commutes), specular NOT included;
//  - linear depth is view-space distance along the view axis in world units; background pixels are +inf;
//  - the skin mask is 0..1 (0 on background and non-skin); methods blur skin pixels only;
//  - the stage must write every pixel of `output` (non-skin and background: copy the input through);
//  - the stage may allocate its own scratch textures/framebuffers (keep them between frames when the size is
//    unchanged) and must leave GL state as it found it: no bound framebuffer/program, viewport = full frame,
//    depth test and blending off.
#include "renderer/sss/sss_params.h"

#include <epoxy/gl.h>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

namespace skinlab::renderer::gl {

class ShaderLibrary;

// Textures the main pass hands to the SSS stage (all owned by the pipeline, read-only for the stage).
struct SssStageInputs {
    GLuint diffuse = 0;         // GL_RGBA32F: rgb = lights + IBL irradiance × AO × albedo (+ transmittance), a = mask
    GLuint linearDepth = 0;     // GL_R32F: view-space depth along -Z, world units, +inf on background
    GLuint albedo = 0;          // GL_RGBA32F: rgb = linear albedo (texture × vertex colour × material), a = mask
    GLuint skinMask = 0;        // GL_R32F: 0..1, 0 on background
    GLuint normal = 0;          // GL_RGBA32F: xyz = world-space normal after normal mapping, unit length
    GLuint geometricNormal = 0; // GL_RGBA32F: xyz = world-space interpolated geometric normal, unit length
    GLuint aux = 0;             // GL_R32F: Mikkelsen's auxiliary image F (sss.cbf), 0 off skin
    GLuint curvature = 0;       // GL_R32F: smoothed curvature, 1/world unit, ≥ 0 (sss.curvature)
    int width = 0;              // pixels
    int height = 0;             // pixels
    float focalLengthPixels = 0; // f_px = (height/2) / tan(fovY/2); a kernel offset of o mm at depth z covers
                                 // o / mmPerUnit * f_px / z pixels (docs/methods.md, same scale on both axes)
    float mmPerUnit = 1;         // millimetres per world unit of the scene
    // Where the view axis meets the image, pixels (row 0 at the bottom); NaN: the image centre (W/2, H/2). Off the
    // centre for a render.window (an off-axis projection).
    glm::vec2 principalPoint{std::numeric_limits<float>::quiet_NaN()};
    glm::mat4 view{1.0f};           // world → view (camera looks down -Z)
    glm::mat4 projection{1.0f};     // view → clip (OpenGL convention)
    glm::vec3 cameraPosition{0.0f}; // world units
};

// The scene's typed [sss] and [transmittance] parameters (renderer/sss/sss_params.h). The method is sss.method.
struct SssStageSettings {
    sss::SssParams sss;
    sss::TransmittanceParams transmittance;
};

class SssStage {
public:
    explicit SssStage(ShaderLibrary& shaders);
    ~SssStage();
    SssStage(const SssStage&) = delete;
    SssStage& operator=(const SssStage&) = delete;

    // Writes the scattered diffuse into `output` (GL_RGBA32F, same size as the inputs, not one of the inputs).
    // Method "none" copies `inputs.diffuse` through unchanged. Throws InputError for a method it does not know.
    void run(const SssStageInputs& inputs, const SssStageSettings& settings, GLuint output);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace skinlab::renderer::gl
