// The artifact extensions of the thesis (§3.3) for any screen-space SSS pass, one pixel at a time.
// Mirrors renderer/sss/extension_weights.h function by function (same names, same float arithmetic); tests compare
// the two. docs/extensions.md describes each function and how a blur pass combines them:
//
//   vec3 labCentre = linearRec709ToLab(albedoCentre);            // E2, once per pixel
//   float auxCentre = auxiliaryValue(viewPosition, viewNormal);  // E1, or read from the aux.Y AOV
//   for each tap i:
//       float w = kernelWeight_i;
//       w *= labWeight(labCentre, linearRec709ToLab(albedoTap), beta);      // sss.lab_weight = beta (0: off)
//       w *= auxiliaryWeight(auxCentre, auxTap, lambda);                   // sss.cbf (lambda = 10)
//       sum += w * tapColour; weightSum += w;
//   colour = resolveWeightedSum(sum, weightSum, centreColour);            // no black dots where all taps fail
//   width *= curvatureWidthScale(strategy, normalisedCurvature(kappa, mmPerUnit, kCurvatureReferenceRadiusMm), floor);

// --- E2: CIELAB (D65) from linear Rec.709 ---------------------------------------------------------------------
vec3 linearRec709ToXyz(vec3 rgb) {
    return vec3(0.4124564 * rgb.r + 0.3575761 * rgb.g + 0.1804375 * rgb.b,
                0.2126729 * rgb.r + 0.7151522 * rgb.g + 0.0721750 * rgb.b,
                0.0193339 * rgb.r + 0.1191920 * rgb.g + 0.9503041 * rgb.b);
}

// CIE 15:2004: t^(1/3) above (6/29)^3, the linear segment below.
float labCompand(float t) {
    const float delta = 6.0 / 29.0;
    return t > delta * delta * delta ? pow(t, 1.0 / 3.0) : t / (3.0 * delta * delta) + 4.0 / 29.0;
}

vec3 xyzToLab(vec3 xyz) {
    float fx = labCompand(xyz.x / 0.95047);
    float fy = labCompand(xyz.y / 1.0);
    float fz = labCompand(xyz.z / 1.08883);
    return vec3(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz));
}

vec3 linearRec709ToLab(vec3 rgb) { return xyzToLab(linearRec709ToXyz(rgb)); }

// exp(-beta * DeltaE*ab); beta = 0.09 (separable methods) or 0.5 (sum of Gaussians) in the thesis; 0: weight 1.
float labWeight(vec3 labCentre, vec3 labTap, float beta) { return exp(-beta * length(labCentre - labTap)); }

// --- E1: Mikkelsen's auxiliary image, distance-invariant ------------------------------------------------------
const float kAuxiliaryMinCosine = 0.05;  // bounds F at grazing angles to 20

// F = cos(phi_i) / cos(phi_j): viewPosition in view space (camera at the origin looking down -Z), unit viewNormal.
float auxiliaryValue(vec3 viewPosition, vec3 viewNormal) {
    float distance = length(viewPosition);
    if (!(distance > 0.0)) return 1.0;
    vec3 toViewer = -viewPosition / distance;
    float cosViewAxis = max(toViewer.z, 0.0);
    float cosNormal = max(dot(viewNormal, toViewer), kAuxiliaryMinCosine);
    return cosViewAxis / cosNormal;
}

// The thesis code's albedo-grey-modulated F (an overload, as in C++).
float auxiliaryValue(vec3 viewPosition, vec3 viewNormal, float albedoGrey) {
    return auxiliaryValue(viewPosition, viewNormal) * albedoGrey;
}

float auxiliaryWeight(float auxiliaryCentre, float auxiliaryTap, float lambda) {
    return exp(-lambda * abs(auxiliaryCentre - auxiliaryTap));
}

const float kMinimumWeightSum = 1e-4;

vec3 resolveWeightedSum(vec3 weightedSum, float weightSum, vec3 centre) {
    return weightSum < kMinimumWeightSum ? centre : weightedSum / weightSum;
}

// --- E3: curvature --------------------------------------------------------------------------------------------
const int kCurvatureOff = 0;
const int kCurvatureIncrease = 1;
const int kCurvatureReduce = 2;
const int kCurvatureReduceFloor = 3;
const float kCurvatureReferenceRadiusMm = 20.0;

float normalisedCurvature(float curvaturePerUnit, float mmPerUnit, float referenceRadiusMm) {
    float curvaturePerMm = max(curvaturePerUnit, 0.0) / mmPerUnit;
    return clamp(curvaturePerMm * referenceRadiusMm, 0.0, 1.0);
}

float curvatureWidthScale(int strategy, float normalised, float floorValue) {
    float c = clamp(normalised, 0.0, 1.0);
    if (strategy == kCurvatureIncrease) return 1.0 + c;
    if (strategy == kCurvatureReduce) return c;
    if (strategy == kCurvatureReduceFloor) {
        float f = clamp(floorValue, 0.0, 1.0);
        return f + (1.0 - f) * c;
    }
    return 1.0;
}

float transmittanceCurvatureScale(float normalised) { return 1.0 + clamp(normalised, 0.0, 1.0); }
