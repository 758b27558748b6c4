// Transmittance through a slab of skin (Jimenez, Whelan, Sundstedt & Gutierrez, "Real-Time Realistic Skin
// Translucency", IEEE CG&A 2010): T(s) = sum_i w_i exp(-s^2 / v_i) with d'Eon & Luebke's six-Gaussian skin profile
// (d'Eon & Luebke, GPU Gems 3 ch. 14, Table 14-1): v_i in mm^2, s the scaled thickness in mm.
// Mirrors deonTransmittance() in renderer/sss/gaussian_sum_profile.cpp lobe by lobe (the same table, blue weight
// 0.649 as published); tests/renderer/gl/test_transmittance_glsl.cpp compares the two. Each channel's weights sum
// to 1, so T(0) = 1 per channel. (The thesis code used other weights and got T(0) = (2.23, 1.64, 1.35): not here.)
vec3 deonTransmittance(float thicknessMm) {
    float s2 = thicknessMm * thicknessMm;
    return vec3(0.233, 0.455, 0.649) * exp(-s2 / 0.0064) +
           vec3(0.100, 0.336, 0.344) * exp(-s2 / 0.0484) +
           vec3(0.118, 0.198, 0.0) * exp(-s2 / 0.187) +
           vec3(0.113, 0.007, 0.007) * exp(-s2 / 0.567) +
           vec3(0.358, 0.004, 0.0) * exp(-s2 / 1.99) +
           vec3(0.078, 0.0, 0.0) * exp(-s2 / 7.41);
}

// The same form with the weights of a [skin] tone on d'Eon's six variances (renderer/sss/skin_model.h,
// skinTransmittance()); each channel's weights sum to 1, so T(0) = 1 per channel.
vec3 toneTransmittance(float thicknessMm, vec3 w0, vec3 w1, vec3 w2, vec3 w3, vec3 w4, vec3 w5) {
    float s2 = thicknessMm * thicknessMm;
    return w0 * exp(-s2 / 0.0064) + w1 * exp(-s2 / 0.0484) + w2 * exp(-s2 / 0.187) + w3 * exp(-s2 / 0.567) +
           w4 * exp(-s2 / 1.99) + w5 * exp(-s2 / 7.41);
}
