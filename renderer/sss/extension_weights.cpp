#include "renderer/sss/extension_weights.h"

#include "common/error.h"

#include <algorithm>
#include <cmath>

namespace skinlab::renderer::sss {

namespace {
// CIE 15:2004 Lab companding: f(t) = t^(1/3) above (6/29)³, the linear segment below.
float labCompand(float t) {
    constexpr float delta = 6.0f / 29.0f;
    constexpr float deltaCubed = delta * delta * delta;
    return t > deltaCubed ? std::cbrt(t) : t / (3.0f * delta * delta) + 4.0f / 29.0f;
}

const std::vector<std::string> kCurvatureNames{"off", "increase", "reduce", "reduce-floor"};
} // namespace

glm::vec3 linearRec709ToXyz(const glm::vec3& rgb) {
    // IEC 61966-2-1 (sRGB) primaries, D65 white; rows sum to the white point (0.95047, 1, 1.08883).
    return {0.4124564f * rgb.r + 0.3575761f * rgb.g + 0.1804375f * rgb.b,
            0.2126729f * rgb.r + 0.7151522f * rgb.g + 0.0721750f * rgb.b,
            0.0193339f * rgb.r + 0.1191920f * rgb.g + 0.9503041f * rgb.b};
}

glm::vec3 xyzToLab(const glm::vec3& xyz) {
    const float fx = labCompand(xyz.x / 0.95047f);
    const float fy = labCompand(xyz.y / 1.0f);
    const float fz = labCompand(xyz.z / 1.08883f);
    return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

glm::vec3 linearRec709ToLab(const glm::vec3& rgb) { return xyzToLab(linearRec709ToXyz(rgb)); }

float labWeight(const glm::vec3& labCentre, const glm::vec3& labTap, float beta) {
    return std::exp(-beta * glm::length(labCentre - labTap));
}

float auxiliaryValue(const glm::vec3& viewPosition, const glm::vec3& viewNormal) {
    const float distance = glm::length(viewPosition);
    if (!(distance > 0.0f)) return 1.0f; // the eye itself: both angles 0
    const glm::vec3 toViewer = -viewPosition / distance;
    const float cosViewAxis = std::max(toViewer.z, 0.0f); // cos φ_i: view axis is −Z, ray direction −toViewer
    const float cosNormal = std::max(glm::dot(viewNormal, toViewer), kAuxiliaryMinCosine); // cos φ_j
    return cosViewAxis / cosNormal;
}

float auxiliaryValue(const glm::vec3& viewPosition, const glm::vec3& viewNormal, float albedoGrey) {
    return auxiliaryValue(viewPosition, viewNormal) * albedoGrey;
}

float auxiliaryWeight(float auxiliaryCentre, float auxiliaryTap, float lambda) {
    return std::exp(-lambda * std::abs(auxiliaryCentre - auxiliaryTap));
}

glm::vec3 resolveWeightedSum(const glm::vec3& weightedSum, float weightSum, const glm::vec3& centre) {
    return weightSum < kMinimumWeightSum ? centre : weightedSum / weightSum;
}

std::string_view curvatureStrategyName(CurvatureStrategy strategy) {
    switch (strategy) {
    case CurvatureStrategy::Off: return "off";
    case CurvatureStrategy::Increase: return "increase";
    case CurvatureStrategy::Reduce: return "reduce";
    case CurvatureStrategy::ReduceFloor: return "reduce-floor";
    }
    return "off";
}

const std::vector<std::string>& curvatureStrategyNames() { return kCurvatureNames; }

std::string_view extensionInputName(ExtensionInput input) { return input == ExtensionInput::Lit ? "lit" : "albedo"; }

ExtensionInput extensionInputFromName(std::string_view name, std::string_view source) {
    if (name == "albedo") return ExtensionInput::Albedo;
    if (name == "lit") return ExtensionInput::Lit;
    throwInput(source, "extension_input", "'" + std::string(name) + "' is not one of: albedo, lit");
}

float litAuxiliaryValue(float storedAux, const glm::vec3& albedo, const glm::vec3& lit) {
    const float albedoGrey = (albedo.r + albedo.g + albedo.b) / 3.0f;
    const float litGrey = (lit.r + lit.g + lit.b) / 3.0f;
    return albedoGrey > 1e-6f ? storedAux / albedoGrey * litGrey : 0.0f;
}

CurvatureStrategy curvatureStrategyFromName(std::string_view name, std::string_view source) {
    if (name == "off") return CurvatureStrategy::Off;
    if (name == "increase") return CurvatureStrategy::Increase;
    if (name == "reduce") return CurvatureStrategy::Reduce;
    if (name == "reduce-floor") return CurvatureStrategy::ReduceFloor;
    throwInput(source, "sss.curvature",
               "'" + std::string(name) + "' is not one of: off, increase, reduce, reduce-floor");
}

float normalisedCurvature(float curvaturePerUnit, float mmPerUnit, float referenceRadiusMm) {
    const float curvaturePerMm = std::max(curvaturePerUnit, 0.0f) / mmPerUnit;
    return std::clamp(curvaturePerMm * referenceRadiusMm, 0.0f, 1.0f);
}

float curvatureWidthScale(CurvatureStrategy strategy, float normalisedCurvature, float floor) {
    const float c = std::clamp(normalisedCurvature, 0.0f, 1.0f);
    switch (strategy) {
    case CurvatureStrategy::Off: return 1.0f;
    case CurvatureStrategy::Increase: return 1.0f + c;
    case CurvatureStrategy::Reduce: return c;
    case CurvatureStrategy::ReduceFloor: {
        const float f = std::clamp(floor, 0.0f, 1.0f);
        return f + (1.0f - f) * c;
    }
    }
    return 1.0f;
}

float transmittanceCurvatureScale(float normalisedCurvature) {
    return 1.0f + std::clamp(normalisedCurvature, 0.0f, 1.0f);
}

} // namespace skinlab::renderer::sss
