#pragma once
// Main pass (main_pass.vert/.frag): lights (with shadows) + IBL irradiance × AO → diffuse × albedo,
// thesis Eq. 4.5 specular in its own buffer, and the AOVs (albedo, linear depth, normals, skin mask).
#include "renderer/gl/frame_targets.h"
#include "renderer/gl/gpu_scene.h"
#include "renderer/gl/shader_library.h"
#include "renderer/scene/scene_spec.h"

#include <array>
#include <optional>

namespace skinlab::renderer::gl {

// Transmittance (Jimenez et al., IEEE CG&A 2010): the shaded point is moved this far inside the surface along its
// geometric normal before its thickness is read from the shadow map, against depth precision and shadow acne. The
// thesis used 0.005 units of its scanned head at 47.9 mm per unit = 0.24 mm.
inline constexpr float kTransmittanceShrinkMm = 0.24f;

struct MainPassSettings {
    CameraPose camera;
    float exposure = 1.0f; // 2^exposure_ev
    float normalStrength = 1.0f;
    int pcfRadius = 1;
    glm::mat3 environmentFromWorld{1.0f};
    // Transmittance (docs/rendering.md, "Transmittance"): [transmittance] enabled / translucency, sss.width_mm and
    // the scene's mm_per_unit. Scaled thickness s = thickness_mm · 16.5 (1 − translucency) / width_mm, the demo's
    // 8.25 (1 − translucency) / sssWidth with width_mm = 2 · sssWidth · mm_per_unit (sss::transmittanceScalePerUnit).
    bool transmittanceEnabled = false;
    float translucency = 0.5f; // 0 opaque … 1 fully translucent (s = 0, T = 1)
    float sssWidthMm = 3.0f;   // mm, > 0
    float mmPerUnit = 1.0f;    // millimetres per world unit
    // transmittance.curvature with curvature_form "thesis": s / (1 + 2c), c = κ · curvature_reference_mm / mm_per_unit
    // uncapped, κ the thesis' screen-space curvature from dFdx / dFdy of the view-space geometric normal (1/world
    // unit: × f_px / 8, as in surface_aovs.frag).
    bool transmittanceThesisCurvature = false;
    float curvatureReferenceMm = 20.0f;
    // The [skin] tone's weights on d'Eon's six variances (sss::skinProfileLobes); empty: d'Eon's own table.
    std::optional<std::array<glm::vec3, 6>> transmittanceWeights;
};

class MainPass {
public:
    explicit MainPass(ShaderLibrary& shaders) : shaders_(shaders) {}
    // Clears the frame targets and draws every part of the scene into them.
    void run(FrameTargets& targets, const GpuScene& scene, GLuint shadowMaps, const MainPassSettings& settings);

    // Sets every uniform of main_pass.frag except the per-part material ones and binds its textures (units 0–5,
    // and unit 6: the shadow maps again through a sampler object without depth comparison, for transmittance),
    // for `program` = main_pass.frag linked with any vertex shader that writes the same outputs as main_pass.vert
    // (the object-space reference bakes the same shading at mesh vertices).
    // unbindShading() unbinds the units again and deletes that sampler object; call it before the next bindShading.
    static void bindShading(GLuint program, const GpuScene& scene, GLuint shadowMaps, const MainPassSettings& settings);
    static void unbindShading();
    // Per-part material uniforms.
    static void setMaterial(GLuint program, const GpuMaterial& material);

private:
    ShaderLibrary& shaders_;
};

} // namespace skinlab::renderer::gl
