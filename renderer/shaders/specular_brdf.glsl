// Specular lobe of the thesis, Eq. 4.5 (normalised Blinn-Phong with Schlick's Fresnel):
//   C_spec = (alpha + 2) / 8 * (n.h)^alpha * F_Schlick(F0, l, h) * L_c * (n.l),  alpha = 8192 s^5
// with glossiness s in [0, 1] and skin F0 = 0.028. Returns the factor multiplying the light's L_c.
// Mirrored in C++ by renderer/shading/specular_brdf.h (tests compare the two).
const float kSkinF0 = 0.028;

float fresnelSchlick(float f0, float lightDotHalf) {
    return f0 + (1.0 - f0) * pow(1.0 - clamp(lightDotHalf, 0.0, 1.0), 5.0);
}

float specularEq45(vec3 normal, vec3 toLight, vec3 toViewer, float glossiness, float f0) {
    float normalDotLight = dot(normal, toLight);
    if (normalDotLight <= 0.0) return 0.0;
    vec3 halfVector = normalize(toLight + toViewer);
    float alpha = 8192.0 * pow(glossiness, 5.0);
    // max(.., 1e-8): pow(0, 0) is undefined in GLSL; (1e-8)^alpha is 1 for alpha = 0 and 0 otherwise.
    float normalDotHalf = max(dot(normal, halfVector), 1e-8);
    return (alpha + 2.0) / 8.0 * pow(normalDotHalf, alpha) * fresnelSchlick(f0, dot(toLight, halfVector)) *
           normalDotLight;
}
