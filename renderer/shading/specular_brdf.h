#pragma once
// The specular lobe of the thesis, Eq. 4.5, in C++: the reference the shader (renderer/shaders/
// specular_brdf.glsl) is tested against. Normalised Blinn-Phong with Schlick's Fresnel:
//   C_spec = (alpha + 2) / 8 * (n.h)^alpha * F_Schlick(F0, l, h) * L_c * (n.l),   alpha = 8192 s^5,
//   F_Schlick = F0 + (1 - F0) (1 - l.h)^5,  skin F0 = 0.028.
// Returns the factor that multiplies the light's L_c (the radiance of a white Lambertian surface facing it).
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>

namespace skinlab::renderer {

inline constexpr float kSkinF0 = 0.028f;

inline float fresnelSchlick(float f0, float lightDotHalf) {
    return f0 + (1.0f - f0) * std::pow(1.0f - std::clamp(lightDotHalf, 0.0f, 1.0f), 5.0f);
}

// Unit vectors: surface normal, direction to the light, direction to the viewer.
inline float specularEq45(const glm::vec3& normal, const glm::vec3& toLight, const glm::vec3& toViewer,
                          float glossiness, float f0 = kSkinF0) {
    const float normalDotLight = glm::dot(normal, toLight);
    if (normalDotLight <= 0.0f) return 0.0f;
    const glm::vec3 halfVector = glm::normalize(toLight + toViewer);
    const float alpha = 8192.0f * std::pow(glossiness, 5.0f);
    const float normalDotHalf = std::max(glm::dot(normal, halfVector), 1e-8f); // as the shader (pow(0, 0))
    return (alpha + 2.0f) / 8.0f * std::pow(normalDotHalf, alpha) * fresnelSchlick(f0, glm::dot(toLight, halfVector)) *
           normalDotLight;
}

} // namespace skinlab::renderer
