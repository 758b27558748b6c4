#pragma once
// Tone mappers in C++: the reference renderer/shaders/tone_mappers.glsl is tested against. Linear
// scene-referred value (exposure applied) → linear display-referred value in [0, 1].
//   linear:      clamp(x, 0, 1)
//   exponential: 1 - exp(-k x)
//   reinhard:    on luminance (Reinhard et al. 2002, "Photographic tone reproduction for digital images",
//                Eqs. 1–3): log-average L̄ = exp(mean log(δ + L_w)) over the image (Eq. 1, δ = 1e-4), scaled
//                luminance L = (a / L̄) L_w with the key a (Eq. 2, default 0.18), L_d = L / (1 + L) (Eq. 3); the
//                colour keeps its chromaticity: y = x · L_d / L_w = x · (a / L̄) / (1 + L). L_w is the Rec. 709 /
//                sRGB luminance 0.2126 R + 0.7152 G + 0.0722 B of the linear colour.
//   reinhard-rgb: x / (1 + x) per channel (Eq. 3 applied to R, G and B; desaturates bright colours)
//   filmic:      hable(2 x) / hable(W)        (J. Hable 2010, "Filmic tonemapping operators", the Uncharted 2
//                                              curve with its exposure bias 2 and white point W = 11.2)
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

namespace skinlab::renderer {

inline float hableCurve(float x) {
    const float A = 0.15f, B = 0.50f, C = 0.10f, D = 0.20f, E = 0.02f, F = 0.30f;
    return ((x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F)) - E / F;
}

inline constexpr double kReinhardDelta = 1e-4;      // δ of Eq. 1: keeps black pixels out of log(0)
inline constexpr double kReinhardDefaultKey = 0.18; // a of Eq. 2: Reinhard's "normal key"

inline float luminance709(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

// Eq. 1 over `pixels` pixels of interleaved linear RGB(A) (`stride` floats per pixel; negative values count as 0).
inline double reinhardLogAverage(const float* data, std::size_t pixels, int stride) {
    if (pixels == 0) return 1.0;
    double sum = 0.0;
    for (std::size_t p = 0; p < pixels; ++p) {
        const float* x = data + p * static_cast<std::size_t>(stride);
        const float l = luminance709(std::max(x[0], 0.0f), std::max(x[1], 0.0f), std::max(x[2], 0.0f));
        sum += std::log(kReinhardDelta + static_cast<double>(l));
    }
    return std::exp(sum / static_cast<double>(pixels));
}

// The luminance form: `scale` = a / L̄ (Eq. 2's factor). Writes the display-referred RGB, each in [0, 1].
inline void toneMapReinhard(const float x[3], float scale, float y[3]) {
    const float r = std::max(x[0], 0.0f), g = std::max(x[1], 0.0f), b = std::max(x[2], 0.0f);
    const float l = scale * luminance709(r, g, b);
    const float factor = scale / (1.0f + l);
    y[0] = std::clamp(r * factor, 0.0f, 1.0f);
    y[1] = std::clamp(g * factor, 0.0f, 1.0f);
    y[2] = std::clamp(b * factor, 0.0f, 1.0f);
}

// The per-channel operators (every operator but "reinhard", which needs the whole colour: toneMapReinhard).
inline float toneMap(float x, const std::string& toneMapper, float exponentialK = 1.0f, float filmicWhite = 11.2f) {
    x = std::max(x, 0.0f);
    float y = x;
    if (toneMapper == "exponential") y = 1.0f - std::exp(-exponentialK * x);
    else if (toneMapper == "reinhard-rgb") y = x / (1.0f + x);
    else if (toneMapper == "filmic") y = hableCurve(2.0f * x) / hableCurve(filmicWhite);
    return std::clamp(y, 0.0f, 1.0f);
}

} // namespace skinlab::renderer
