#pragma once
// Tone mappers in C++: the reference renderer/shaders/tone_mappers.glsl is tested against. Linear
// scene-referred value (exposure applied) → linear display-referred value in [0, 1].
//   linear:      clamp(x, 0, 1)
//   exponential: 1 - exp(-k x)
//   reinhard:    x / (1 + x)                 (Reinhard et al. 2002, "Photographic tone reproduction", Eq. 3)
//   filmic:      hable(2 x) / hable(W)        (J. Hable 2010, "Filmic tonemapping operators", the Uncharted 2
//                                              curve with its exposure bias 2 and white point W = 11.2)
#include <algorithm>
#include <cmath>
#include <string>

namespace skinlab::renderer {

inline float hableCurve(float x) {
    const float A = 0.15f, B = 0.50f, C = 0.10f, D = 0.20f, E = 0.02f, F = 0.30f;
    return ((x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F)) - E / F;
}

inline float toneMap(float x, const std::string& toneMapper, float exponentialK = 1.0f, float filmicWhite = 11.2f) {
    x = std::max(x, 0.0f);
    float y = x;
    if (toneMapper == "exponential") y = 1.0f - std::exp(-exponentialK * x);
    else if (toneMapper == "reinhard") y = x / (1.0f + x);
    else if (toneMapper == "filmic") y = hableCurve(2.0f * x) / hableCurve(filmicWhite);
    return std::clamp(y, 0.0f, 1.0f);
}

} // namespace skinlab::renderer
