// Tone mappers (linear scene-referred → linear display-referred in [0, 1]); mirrored in C++ by
// renderer/shading/tone_mappers.h (tests compare the two).
//   0 linear:       clamp(x)
//   1 exponential:  1 - exp(-k x)
//   2 reinhard:     x / (1 + x)                       (Reinhard et al. 2002, Eq. 3)
//   3 filmic:       hable(2 x) / hable(W)              (Hable 2010, "Uncharted 2" curve, exposure bias 2)
float hable(float x) {
    const float A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return ((x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F)) - E / F;
}

vec3 toneMap(vec3 x, int operatorIndex, float exponentialK, float filmicWhite) {
    x = max(x, vec3(0.0));
    vec3 y;
    if (operatorIndex == 0) y = x;
    else if (operatorIndex == 1) y = 1.0 - exp(-exponentialK * x);
    else if (operatorIndex == 2) y = x / (1.0 + x);
    else y = vec3(hable(2.0 * x.r), hable(2.0 * x.g), hable(2.0 * x.b)) / hable(filmicWhite);
    return clamp(y, 0.0, 1.0);
}
