#pragma once
// Environments for image-based lighting and the background: equirectangular HDR images (or a constant
// radiance) and their diffuse irradiance as 9 spherical-harmonic coefficients (Ramamoorthi & Hanrahan,
// "An Efficient Representation for Irradiance Environment Maps", SIGGRAPH 2001).
//
// Orientation (docs/assets.md, "Environments"): world +Y is up. Image column u = (x + 0.5) / W, row
// v = (y + 0.5) / H, rows top first. v = 0 is the zenith (+Y), v = 1 the nadir (-Y). The image centre
// (u = 0.5, v = 0.5) is the horizon direction -Z: what a camera on +Z looking at the model (towards -Z) sees
// behind it. u grows to the right as seen by that camera: u = 0.75 is +X, u = 0.25 is -X, u = 0 and 1 are +Z.
//   theta = pi * v (polar angle from +Y),  phi = 2 pi (u - 0.5)
//   direction = (sin(theta) sin(phi), cos(theta), -sin(theta) cos(phi))
// GLSL of the inverse (for the background pass):
//   u = 0.5 + atan(d.x, -d.z) / (2 pi),  v = acos(clamp(d.y, -1, 1)) / pi
#include <array>
#include <filesystem>
#include <glm/glm.hpp>
#include <vector>

namespace skinlab::renderer {

// Linear scene-referred radiance, RGB (Rec.709 primaries), equirectangular, rows top first.
struct Environment {
    int width = 0;
    int height = 0;
    std::vector<glm::vec3> pixels; // width * height radiance values

    const glm::vec3& texel(int x, int y) const {
        return pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)];
    }
    // Bilinear lookup of the radiance arriving from `direction` (any length > 0), wrapping in u.
    glm::vec3 radiance(const glm::vec3& direction) const;
};

// Unit direction of equirectangular coordinates (u, v) in [0, 1]² (convention above), and the inverse.
glm::vec3 equirectDirection(float u, float v);
glm::vec2 equirectCoordinates(const glm::vec3& direction);

// Reads an equirectangular HDR image (Radiance .hdr, OpenEXR, or any OpenImageIO float format) as linear
// radiance; grey files are replicated to RGB, alpha dropped. The image must be about 2:1 (width = 2 * height
// ± 1 pixel). Errors: missing/corrupt file, wrong aspect → InputError "PATH: cannot read environment (...)".
Environment loadEnvironment(const std::filesystem::path& path);

// A uniform environment: radiance L from every direction (width × height texels, default 64 × 32).
Environment makeConstantEnvironment(const glm::vec3& radiance, int width = 64, int height = 32);

// Real spherical harmonics basis up to l = 2 in world coordinates, order
//   0: Y00 = 0.282095
//   1: Y1-1 = 0.488603 y   2: Y10 = 0.488603 z   3: Y11 = 0.488603 x
//   4: Y2-2 = 1.092548 xy  5: Y2-1 = 1.092548 yz  6: Y20 = 0.315392 (3 z^2 - 1)
//   7: Y21 = 1.092548 xz   8: Y22 = 0.546274 (x^2 - y^2)
// (R&H 2001, Eq. 3; constants sqrt(1/4pi), sqrt(3/4pi), sqrt(15/4pi), sqrt(5/16pi), sqrt(15/16pi)).
std::array<float, 9> shBasis9(const glm::vec3& unitDirection);

// Radiance SH coefficients L_lm = ∫ L(ω) Y_lm(ω) dω over the sphere (R&H Eq. 10), with each texel weighted
// by its exact solid angle (2π/W)(cos θ_top − cos θ_bottom) and evaluated at its centre direction.
std::array<glm::vec3, 9> projectSH9(const Environment& environment);

// Irradiance E(n) = Σ Â_l L_lm Y_lm(n) with Â_0 = π, Â_1 = 2π/3, Â_2 = π/4 (R&H Eq. 7–8, 12): the cosine-
// weighted integral of the radiance over the hemisphere around `normal` (band-limited to l ≤ 2). A constant
// environment L gives E = π L. Divide by π for the outgoing radiance of a white Lambertian surface.
glm::vec3 irradianceSH9(const std::array<glm::vec3, 9>& radianceCoefficients, const glm::vec3& normal);

// Â_l · L_lm: coefficients to upload to a shader, which then evaluates E(n) = Σ_i c_i · shBasis9(n)_i.
std::array<glm::vec3, 9> irradianceCoefficientsSH9(const std::array<glm::vec3, 9>& radianceCoefficients);

// The irradiance E(n) = ∫ L(ω) max(0, n·ω) dω itself, not band-limited, tabulated over the normals n at the texel
// centres of a width × height equirectangular map (same convention as the radiance). Nine coefficients hold only
// l ≤ 2, which R&H bound by 9 % of the peak irradiance: where the peak is far above the rest (a bright sky over a
// dim street) that is a fifth or more of the irradiance sideways and from below (the sides of a head under such a
// sky). The radiance is first averaged, weighted by solid angle, into at most 2·width × 2·height texels (1.4° at the
// default size), then integrated over them at their centres. A constant environment L gives π L everywhere (within
// the quadrature's 0.5 %). Read bilinearly (wrapping in u) by normal: between the 2.8° texels of the default size a
// point-like sun's terminator, where E has a kink, is missed by up to about 1.5 % of the sun's peak irradiance.
Environment irradianceMap(const Environment& environment, int width = 128, int height = 64);

} // namespace skinlab::renderer
