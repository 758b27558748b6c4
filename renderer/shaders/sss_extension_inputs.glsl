// The inputs of the artifact extensions (sss.cbf, sss.lab_weight, sss.curvature; docs/extensions.md) for any
// screen-space SSS pass, and the per-pixel / per-texel helpers built on renderer/shaders/sss_extensions.glsl.
// Include it AFTER sss_extensions.glsl (the shader library does not follow nested includes).
//
// The uniforms are set, and the three textures bound, by renderer/gl/sss_extension_settings.h
// (SssExtensionSettings::bind); samplers get their texture units from there, so a pass chooses its own units.
// The tap weights (E1, E2) are compiled only with SSS_EXTENSION_WEIGHTS defined, so that a pass with the extensions
// off runs exactly the shader it ran before they existed (bit-identical output).
//
// CPU mirror: renderer/sss/cpu_blur.cpp (same functions, same float arithmetic order).

uniform sampler2D extensionAlbedo;     // rgb = linear albedo (AOV albedo.*), for sss.lab_weight
uniform sampler2D extensionAux;        // r = Mikkelsen's auxiliary image F (AOV aux.Y), for sss.cbf
uniform sampler2D extensionCurvature;  // r = curvature κ, 1/world unit, ≥ 0 (AOV curvature.Y), for sss.curvature
uniform sampler2D extensionLit;        // rgb = the colour this pass blurs, for sss.extension_input = "lit"
uniform int extensionInputLit;         // sss.extension_input: 0 albedo, 1 lit
uniform float extensionLabBeta;        // β of sss.lab_weight, 1/ΔE*ab; 0: off
uniform int extensionCbf;              // sss.cbf: 0 or 1
uniform float extensionCbfLambda;      // λ of sss.cbf, dimensionless
uniform int extensionCurvatureStrategy;  // kCurvatureOff … kCurvatureReduceFloor (sss_extensions.glsl)
uniform float extensionCurvatureFloor;   // sss.curvature_floor, [0, 1]
uniform float extensionCurvatureReferenceMm;  // sss.curvature_reference_mm

// E3: the multiplier of the kernel's footprint (pixels per mm) at pixel p. Exactly 1 with sss.curvature = off.
float extensionWidthScale(ivec2 p, float mmPerUnit) {
    if (extensionCurvatureStrategy == kCurvatureOff) return 1.0;
    float c = normalisedCurvature(texelFetch(extensionCurvature, p, 0).r, mmPerUnit, extensionCurvatureReferenceMm);
    return curvatureWidthScale(extensionCurvatureStrategy, c, extensionCurvatureFloor);
}

// E1/E2 inputs of texel q (extensionColour / extensionAuxiliary of renderer/sss/cpu_blur.h): the albedo and the
// stored F, or the lit colour and F with the lit grey in place of the albedo grey (litAuxiliaryValue).
vec3 extensionColour(ivec2 q) {
    return extensionInputLit != 0 ? texelFetch(extensionLit, q, 0).rgb : texelFetch(extensionAlbedo, q, 0).rgb;
}

float extensionAuxiliary(ivec2 q) {
    float stored = texelFetch(extensionAux, q, 0).r;
    if (extensionInputLit == 0) return stored;
    vec3 albedo = texelFetch(extensionAlbedo, q, 0).rgb;
    vec3 lit = texelFetch(extensionLit, q, 0).rgb;
    float albedoGrey = (albedo.r + albedo.g + albedo.b) / 3.0;
    float litGrey = (lit.r + lit.g + lit.b) / 3.0;
    return albedoGrey > 1e-6 ? stored / albedoGrey * litGrey : 0.0;
}

// What the tap weights compare against: the centre pixel's CIELAB albedo and auxiliary value.
struct ExtensionCentre {
    vec3 lab;
    float aux;
};

ExtensionCentre extensionCentre(ivec2 p) {
    ExtensionCentre centre;
    centre.lab = extensionLabBeta > 0.0 ? linearRec709ToLab(extensionColour(p)) : vec3(0.0);
    centre.aux = extensionCbf != 0 ? extensionAuxiliary(p) : 0.0;
    return centre;
}

// E1 × E2 weight of the texel q against the centre (1 where both are off).
float extensionTexelWeight(ExtensionCentre centre, ivec2 q) {
    float weight = 1.0;
    if (extensionLabBeta > 0.0)
        weight *= labWeight(centre.lab, linearRec709ToLab(extensionColour(q)), extensionLabBeta);
    if (extensionCbf != 0)
        weight *= auxiliaryWeight(centre.aux, extensionAuxiliary(q), extensionCbfLambda);
    return weight;
}

// resolveWeightedSum per channel (kernel weights are RGB, so each channel has its own weight sum): Σ w c / Σ w, or
// the unblurred centre where Σ w < kMinimumWeightSum (no black dots).
vec3 resolveWeightedSumPerChannel(vec3 weightedSum, vec3 weightSum, vec3 centre) {
    return vec3(resolveWeightedSum(vec3(weightedSum.r), weightSum.r, vec3(centre.r)).r,
                resolveWeightedSum(vec3(weightedSum.g), weightSum.g, vec3(centre.g)).r,
                resolveWeightedSum(vec3(weightedSum.b), weightSum.b, vec3(centre.b)).r);
}
