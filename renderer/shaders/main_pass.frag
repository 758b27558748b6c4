#version 450 core
#extension GL_GOOGLE_include_directive : require
// Main pass (thesis ch. 4): per pixel
//   diffuse  = exposure * (sum_lights L_c (n.l) shadow + E_SH(n) / pi * AO) * albedo
//   specular = exposure * sum_lights L_c * Eq. 4.5 * shadow * specular intensity
// plus the AOVs the SSS stage and the EXR need: albedo, linear depth (world units along the view axis),
// mapped and geometric normals (world space), skin mask. All linear Rec.709. Light "L_c" is the radiance of a
// white Lambertian surface facing the light, so diffuse = albedo * L_c * (n.l) needs no 1/pi (thesis).
// Transmittance (Jimenez et al., IEEE CG&A 2010; docs/rendering.md "Transmittance") is written to its own output
// (location 7); the transmittance pass adds it to the diffuse buffer before the SSS stage.
#include "specular_brdf.glsl"
#include "transmittance_profile.glsl"

#define MAX_LIGHTS 4

in vec3 worldPosition;
in vec3 worldNormal;
in vec4 worldTangent;
in vec2 textureCoordinate;
in vec3 vertexColor;
in float vertexSkin;

layout(location = 0) out vec4 outDiffuse;          // rgb diffuse radiance, a = mask
layout(location = 1) out vec4 outSpecular;         // rgb specular radiance
layout(location = 2) out vec4 outAlbedo;           // rgb linear albedo, a = mask
layout(location = 3) out float outLinearDepth;     // world units
layout(location = 4) out vec4 outNormal;           // world-space mapped normal
layout(location = 5) out vec4 outGeometricNormal;  // world-space geometric normal
layout(location = 6) out float outMask;            // skin mask 0..1
layout(location = 7) out vec4 outTransmittance;    // rgb light through thin parts (added to diffuse later), 0 if off

uniform vec3 cameraPosition;
uniform mat4 view;
uniform float exposure;  // 2^exposure_ev

uniform vec3 materialAlbedo;
uniform float materialSkin;
uniform float glossiness;
uniform float specularIntensity;
uniform float normalStrength;
uniform int hasAlbedoMap;
uniform int hasNormalMap;
uniform int hasSpecularMap;
uniform int hasOcclusionMap;
uniform int hasSkinMaskMap;
layout(binding = 0) uniform sampler2D albedoMap;     // linear (decoded from sRGB on load)
layout(binding = 1) uniform sampler2D normalMap;     // tangent space, data
layout(binding = 2) uniform sampler2D specularMap;   // data, red
layout(binding = 3) uniform sampler2D occlusionMap;  // data, red
layout(binding = 4) uniform sampler2D skinMaskMap;   // data, red
layout(binding = 5) uniform sampler2DArrayShadow shadowMaps;

uniform int lightCount;
uniform int lightType[MAX_LIGHTS];               // 0 directional, 1 spot
uniform vec3 lightDirection[MAX_LIGHTS];         // direction light travels (directional) / spot axis
uniform vec3 lightPosition[MAX_LIGHTS];          // spot, world units
uniform vec3 lightRadiance[MAX_LIGHTS];          // colour * intensity (L_c)
uniform float lightReferenceDistance[MAX_LIGHTS];  // spot: distance at which L_c holds
uniform float lightCosInner[MAX_LIGHTS];
uniform float lightCosOuter[MAX_LIGHTS];
uniform int lightShadowLayer[MAX_LIGHTS];        // -1: no shadow
uniform mat4 lightViewProjection[MAX_LIGHTS];
uniform float lightNormalOffset[MAX_LIGHTS];     // world units: receiver offset along the normal (acne)
uniform int pcfRadius;

// Transmittance (MainPassSettings, set in MainPass::bindShading). The shadow maps again, through a sampler object
// with compare mode off, to read the raw stored depth (window depth 0..1 of the light's clip space).
layout(binding = 6) uniform sampler2DArray shadowDepths;
uniform mat4 lightInverseViewProjection[MAX_LIGHTS];  // light clip space -> world
uniform int transmittanceEnabled;
uniform float transmittanceShrink;  // world units: the point is moved this far inside along the geometric normal
uniform float transmittanceScale;   // scaled thickness s (mm) per world unit of thickness
uniform int transmittanceThesisCurvature;   // transmittance.curvature_form = "thesis": s / (1 + 2c)
uniform float transmittanceCurvatureScale;  // c per unit of the thesis' raw measure: f_px / 8 · reference mm / mm_per_unit
uniform int transmittanceToneWeights;       // 1: the [skin] tone's weights below instead of d'Eon's table
uniform vec3 transmittanceWeight0;          // the tone's weights of d'Eon's lobes 0 … 5 (renderer/sss/skin_model.h)
uniform vec3 transmittanceWeight1;
uniform vec3 transmittanceWeight2;
uniform vec3 transmittanceWeight3;
uniform vec3 transmittanceWeight4;
uniform vec3 transmittanceWeight5;

uniform vec3 irradianceSH[9];        // A_l * L_lm (renderer/scene/environment.h), environment frame
uniform mat3 environmentFromWorld;   // inverse of the environment's rotation about +Y
uniform int hasIrradianceMap;        // 1: environment.irradiance = "exact", E(n) read from irradianceMap
layout(binding = 7) uniform sampler2D irradianceMap;  // E(n), equirectangular by normal (irradianceMap())

// Irradiance E(n): the irradiance map's bilinear value at the normal's equirectangular coordinates
// (renderer/scene/environment.h), or from 9 SH coefficients (Ramamoorthi & Hanrahan 2001), same basis as shBasis9().
vec3 irradiance(vec3 n) {
    if (hasIrradianceMap != 0) {
        const float pi = 3.14159265358979;
        n = normalize(n);
        return texture(irradianceMap, vec2(0.5 + atan(n.x, -n.z) / (2.0 * pi), acos(clamp(n.y, -1.0, 1.0)) / pi)).rgb;
    }
    return irradianceSH[0] * 0.282095 + irradianceSH[1] * (0.488603 * n.y) + irradianceSH[2] * (0.488603 * n.z) +
           irradianceSH[3] * (0.488603 * n.x) + irradianceSH[4] * (1.092548 * n.x * n.y) +
           irradianceSH[5] * (1.092548 * n.y * n.z) + irradianceSH[6] * (0.315392 * (3.0 * n.z * n.z - 1.0)) +
           irradianceSH[7] * (1.092548 * n.x * n.z) + irradianceSH[8] * (0.546274 * (n.x * n.x - n.y * n.y));
}

// Percentage-closer filtering: (2r+1)^2 hardware depth comparisons with bilinear filtering each.
float shadowVisibility(int light, vec3 position, vec3 geometricNormal) {
    int layer = lightShadowLayer[light];
    if (layer < 0) return 1.0;
    vec4 clip = lightViewProjection[light] * vec4(position + geometricNormal * lightNormalOffset[light], 1.0);
    vec3 ndc = clip.xyz / clip.w;
    vec3 coordinate = ndc * 0.5 + 0.5;
    if (any(lessThan(coordinate.xy, vec2(0.0))) || any(greaterThan(coordinate.xy, vec2(1.0))) || coordinate.z >= 1.0)
        return 1.0;  // outside the light's frustum: unshadowed
    vec2 texel = 1.0 / vec2(textureSize(shadowMaps, 0).xy);
    float sum = 0.0;
    for (int y = -pcfRadius; y <= pcfRadius; ++y)
        for (int x = -pcfRadius; x <= pcfRadius; ++x)
            sum += texture(shadowMaps, vec4(coordinate.xy + vec2(x, y) * texel, float(layer), coordinate.z));
    float taps = float((2 * pcfRadius + 1) * (2 * pcfRadius + 1));
    return sum / taps;
}

// Thickness of the object between `position` and the light (world units), from the light's shadow map (Jimenez
// et al. 2010): the point, shrunk inside along the normal against shadow-map precision and acne, is projected into
// the light's clip space; the depth stored there (the surface nearest the light) is unprojected with the inverse
// light view-projection, which serves orthographic and perspective lights alike, and its distance to the shrunk
// point (whose unprojection is the point itself) is the thickness along the light ray. Negative: the point lies
// outside the shadow map (no transmittance).
float thicknessToLight(int light, vec3 position, vec3 geometricNormal) {
    vec3 inside = position - geometricNormal * transmittanceShrink;
    vec4 clip = lightViewProjection[light] * vec4(inside, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    vec2 coordinate = ndc.xy * 0.5 + 0.5;
    if (any(lessThan(coordinate, vec2(0.0))) || any(greaterThan(coordinate, vec2(1.0))) || abs(ndc.z) > 1.0)
        return -1.0;
    // Averaged over the same (2r+1)^2 taps as the shadow's PCF: a single tap aliases into dotted lines along the
    // terminator, where the thickness grows from 0 within a shadow texel or two.
    vec2 texel = 1.0 / vec2(textureSize(shadowDepths, 0).xy);
    float sum = 0.0;
    for (int y = -pcfRadius; y <= pcfRadius; ++y)
        for (int x = -pcfRadius; x <= pcfRadius; ++x) {
            vec2 offset = vec2(x, y) * texel;
            float storedDepth = texture(shadowDepths, vec3(coordinate + offset, float(lightShadowLayer[light]))).r;
            // On the point's own light ray: the taps filter the stored depth, not the position.
            vec4 nearest = lightInverseViewProjection[light] * vec4(ndc.xy, storedDepth * 2.0 - 1.0, 1.0);
            sum += distance(nearest.xyz / nearest.w, inside);
        }
    return sum / float((2 * pcfRadius + 1) * (2 * pcfRadius + 1));
}

void main() {
    vec3 geometricNormal = normalize(worldNormal);
    vec3 tangent = normalize(worldTangent.xyz);
    if (!gl_FrontFacing) {
        geometricNormal = -geometricNormal;
        tangent = -tangent;
    }
    vec3 normal = geometricNormal;
    if (hasNormalMap != 0) {
        vec3 m = texture(normalMap, textureCoordinate).xyz * 2.0 - 1.0;
        m.xy *= normalStrength;
        vec3 bitangent = worldTangent.w * cross(geometricNormal, tangent);
        vec3 mapped = tangent * m.x + bitangent * m.y + geometricNormal * m.z;
        if (dot(mapped, mapped) > 1e-12) normal = normalize(mapped);
    }

    vec3 albedo = materialAlbedo * vertexColor;
    if (hasAlbedoMap != 0) albedo *= texture(albedoMap, textureCoordinate).rgb;
    float specularScale = specularIntensity;
    if (hasSpecularMap != 0) specularScale *= texture(specularMap, textureCoordinate).r;
    float occlusion = hasOcclusionMap != 0 ? texture(occlusionMap, textureCoordinate).r : 1.0;
    float mask = clamp(materialSkin * vertexSkin, 0.0, 1.0);
    if (hasSkinMaskMap != 0) mask *= clamp(texture(skinMaskMap, textureCoordinate).r, 0.0, 1.0);

    // The thesis' curvature-modulated transmittance (its main-pass shader): the profile widened inside the exponent,
    // sssWidth × (1 + 2c), i.e. s / (1 + 2c), with its screen-space curvature (cross(n − dx, n + dx).y −
    // cross(n − dy, n + dy).x) · 2 / distance, dx, dy = dFdx, dFdy of the view-space geometric normal, clamped ≥ 0,
    // normalised like the curvature AOV but not capped at 1. Derivatives in uniform control flow, before the loop.
    vec3 viewGeometricNormal = normalize(mat3(view) * geometricNormal);
    vec3 normalDx = dFdx(viewGeometricNormal);
    vec3 normalDy = dFdy(viewGeometricNormal);
    float transmittanceWidening = 1.0;
    if (transmittanceThesisCurvature != 0) {
        float raw = (cross(viewGeometricNormal - normalDx, viewGeometricNormal + normalDx).y -
                     cross(viewGeometricNormal - normalDy, viewGeometricNormal + normalDy).x) *
                    2.0 / length((view * vec4(worldPosition, 1.0)).xyz);
        transmittanceWidening = 1.0 + 2.0 * max(raw, 0.0) * transmittanceCurvatureScale;
    }

    vec3 toViewer = normalize(cameraPosition - worldPosition);
    vec3 lightSum = vec3(0.0);
    vec3 specularSum = vec3(0.0);
    vec3 transmittedSum = vec3(0.0);
    for (int i = 0; i < lightCount; ++i) {
        vec3 toLight;
        vec3 radiance = lightRadiance[i];
        if (lightType[i] == 0) {
            toLight = -lightDirection[i];
        } else {
            vec3 offset = lightPosition[i] - worldPosition;
            float distance = length(offset);
            toLight = offset / distance;
            float ratio = lightReferenceDistance[i] / distance;
            float cone = smoothstep(lightCosOuter[i], lightCosInner[i], dot(-toLight, lightDirection[i]));
            radiance *= ratio * ratio * cone;
        }
        float visibility = shadowVisibility(i, worldPosition, geometricNormal);
        lightSum += radiance * max(dot(normal, toLight), 0.0) * visibility;
        specularSum += radiance * specularEq45(normal, toLight, toViewer, glossiness, kSkinF0) * visibility;
        // Light through the object (Jimenez et al. 2010): L_c T(s) saturate(0.3 + L.(-N)), only lights with a
        // shadow map; not shadowed (the light travels through the occluder the thickness describes).
        // The shadow-map taps are read only where the facing term is not 0 (most of the lit side skips them).
        float facing = clamp(0.3 + dot(toLight, -geometricNormal), 0.0, 1.0);
        if (transmittanceEnabled != 0 && lightShadowLayer[i] >= 0 && mask > 0.0 && facing > 0.0) {
            float thickness = thicknessToLight(i, worldPosition, geometricNormal);
            if (thickness >= 0.0) {
                float s = thickness * transmittanceScale / transmittanceWidening;
                vec3 t = transmittanceToneWeights != 0
                             ? toneTransmittance(s, transmittanceWeight0, transmittanceWeight1, transmittanceWeight2,
                                                 transmittanceWeight3, transmittanceWeight4, transmittanceWeight5)
                             : deonTransmittance(s);
                transmittedSum += radiance * t * facing;
            }
        }
    }
    vec3 ambient = max(irradiance(environmentFromWorld * normal), vec3(0.0)) / 3.14159265358979 * occlusion;

    outDiffuse = vec4(exposure * (lightSum + ambient) * albedo, mask);
    outSpecular = vec4(exposure * specularSum * specularScale, 1.0);
    outAlbedo = vec4(albedo, mask);
    outLinearDepth = -(view * vec4(worldPosition, 1.0)).z;
    outNormal = vec4(normal, 0.0);
    outGeometricNormal = vec4(geometricNormal, 0.0);
    outMask = mask;
    // Skin only, weighted by the mask like the SSS stage's inputs; alpha 0 (the pass adds rgb only).
    outTransmittance = vec4(exposure * transmittedSum * albedo * mask, 0.0);
}
