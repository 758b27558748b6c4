// Tone mappers (linear scene-referred → linear display-referred in [0, 1]); mirrored in C++ by
// renderer/shading/tone_mappers.h (tests compare the two).
//   0 linear:       clamp(x)
//   1 exponential:  1 - exp(-k x)
//   2 reinhard-rgb: x / (1 + x) per channel           (Reinhard et al. 2002, Eq. 3 applied to R, G, B)
//   3 filmic:       hable(2 x) / hable(W)              (Hable 2010, "Uncharted 2" curve, exposure bias 2)
//   4 reinhard:     x · s / (1 + s L_w), s = a / L̄    (Reinhard et al. 2002, Eqs. 1–3 on the Rec. 709 luminance
//                   L_w; the log-average L̄ of Eq. 1 is computed on the CPU from the beauty and passed in as s)
float hable(float x) {
    const float A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return ((x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F)) - E / F;
}

vec3 toneMap(vec3 x, int operatorIndex, float exponentialK, float filmicWhite, float reinhardScale) {
    x = max(x, vec3(0.0));
    vec3 y;
    if (operatorIndex == 0) y = x;
    else if (operatorIndex == 1) y = 1.0 - exp(-exponentialK * x);
    else if (operatorIndex == 2) y = x / (1.0 + x);
    else if (operatorIndex == 4) y = x * (reinhardScale / (1.0 + reinhardScale * dot(x, vec3(0.2126, 0.7152, 0.0722))));
    else y = vec3(hable(2.0 * x.r), hable(2.0 * x.g), hable(2.0 * x.b)) / hable(filmicWhite);
    return clamp(y, 0.0, 1.0);
}
