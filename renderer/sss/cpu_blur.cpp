#include "renderer/sss/cpu_blur.h"

#include "common/check.h"

#include <algorithm>
#include <cmath>

namespace skinlab::renderer::sss {

namespace {
float mix(float x, float y, float a) { return x * (1.0f - a) + y * a; }
glm::vec3 toVec3(const Rgb& rgb) { return glm::vec3(rgb[0], rgb[1], rgb[2]); }

} // namespace

std::vector<Rgb> blurPass(const SurfaceBuffers& surface, const std::vector<Rgb>& input, const KernelStage& stage,
                          BlurAxis axis, const BlurSettings& settings) {
    const int width = surface.width;
    const int height = surface.height;
    SKINLAB_CHECK_EQ(input.size(), size_t(width) * height);
    SKINLAB_CHECK(settings.labWeight <= 0.0f || surface.albedo.size() == input.size());
    SKINLAB_CHECK(!settings.cbf || surface.aux.size() == input.size());
    SKINLAB_CHECK(settings.curvature == CurvatureStrategy::Off || surface.curvature.size() == input.size());
    std::vector<Rgb> output(input.size());
    const bool horizontal = axis == BlurAxis::Horizontal;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const size_t index = size_t(y) * width + x;
            const Rgb centre = input[index];
            const float centreMask = surface.mask[index];
            if (centreMask <= 0.0f) {
                output[index] = centre;
                continue;
            }
            const float centreDepth = surface.depth[index];
            float pixelsPerMm = surface.focalLengthPixels / (surface.mmPerUnit * centreDepth);
            if (settings.curvature != CurvatureStrategy::Off)
                pixelsPerMm *= curvatureWidthScale(
                    settings.curvature,
                    normalisedCurvature(surface.curvature[index], surface.mmPerUnit, settings.curvatureReferenceMm),
                    settings.curvatureFloor);
            Rgb sum{0.0f, 0.0f, 0.0f};
            // E1/E2: the centre's CIELAB albedo and auxiliary value, and the per-channel weight sum.
            const bool weighsTaps = settings.weighsTaps();
            const glm::vec3 labCentre = weighsTaps && settings.labWeight > 0.0f
                                            ? linearRec709ToLab(extensionColour(surface, input, index, settings))
                                            : glm::vec3(0.0f);
            const float auxCentre =
                weighsTaps && settings.cbf ? extensionAuxiliary(surface, input, index, settings) : 0.0f;
            auto texelWeight = [&](size_t texel) {
                float weight = 1.0f;
                if (settings.labWeight > 0.0f)
                    weight *= labWeight(labCentre, linearRec709ToLab(extensionColour(surface, input, texel, settings)),
                                        settings.labWeight);
                if (settings.cbf)
                    weight *= auxiliaryWeight(auxCentre, extensionAuxiliary(surface, input, texel, settings),
                                              settings.cbfLambda);
                return weight;
            };
            Rgb weightSum{0.0f, 0.0f, 0.0f};
            const int along = horizontal ? x : y;
            const int length = horizontal ? width : height;
            auto texelIndex = [&](int j) {
                const int clamped = std::clamp(j, 0, length - 1);
                return horizontal ? size_t(y) * width + clamped : size_t(clamped) * width + x;
            };
            for (const auto& tap : stage.taps) {
                const float position = float(along) + static_cast<float>(tap.offsetMm) * pixelsPerMm;
                const float first = std::floor(position);
                const float fraction = position - first;
                const int j = static_cast<int>(first);
                const size_t texels[2] = {texelIndex(j), texelIndex(j + 1)};
                Rgb values[2];
                for (int t = 0; t < 2; ++t) {
                    const float texelMask = surface.mask[texels[t]];
                    float s = 1.0f - texelMask;
                    if (settings.followSurface && texelMask > 0.0f)
                        s = std::max(
                            s, std::clamp(settings.followSurfaceK * std::abs(centreDepth - surface.depth[texels[t]]) *
                                              surface.mmPerUnit,
                                          0.0f, 1.0f));
                    for (int c = 0; c < 3; ++c) values[t][c] = mix(input[texels[t]][c], centre[c], s);
                }
                if (!weighsTaps) {
                    for (int c = 0; c < 3; ++c)
                        sum[c] += static_cast<float>(tap.weight[c]) * mix(values[0][c], values[1][c], fraction);
                    continue;
                }
                const float share0 = (1.0f - fraction) * texelWeight(texels[0]);
                const float share1 = fraction * texelWeight(texels[1]);
                for (int c = 0; c < 3; ++c) {
                    const float weight0 = static_cast<float>(tap.weight[c]) * share0;
                    const float weight1 = static_cast<float>(tap.weight[c]) * share1;
                    sum[c] += weight0 * values[0][c] + weight1 * values[1][c];
                    weightSum[c] += weight0 + weight1;
                }
            }
            if (weighsTaps)
                for (int c = 0; c < 3; ++c)
                    sum[c] = resolveWeightedSum(glm::vec3(sum[c]), weightSum[c], glm::vec3(centre[c])).x;
            for (int c = 0; c < 3; ++c) output[index][c] = mix(centre[c], sum[c], centreMask);
        }
    }
    return output;
}

glm::vec3 extensionColour(const SurfaceBuffers& surface, const std::vector<Rgb>& input, std::size_t i,
                          const BlurSettings& settings) {
    return settings.input == ExtensionInput::Lit ? toVec3(input[i]) : toVec3(surface.albedo[i]);
}

float extensionAuxiliary(const SurfaceBuffers& surface, const std::vector<Rgb>& input, std::size_t i,
                         const BlurSettings& settings) {
    if (settings.input != ExtensionInput::Lit) return surface.aux[i];
    return litAuxiliaryValue(surface.aux[i], toVec3(surface.albedo[i]), toVec3(input[i]));
}

BlurSettings blurSettingsFromParams(const SssParams& params) {
    BlurSettings settings;
    settings.followSurface = params.followSurface;
    settings.followSurfaceK = static_cast<float>(params.followSurfaceK);
    settings.cbf = params.cbf;
    settings.cbfLambda = static_cast<float>(params.cbfLambda);
    settings.labWeight = static_cast<float>(params.labWeight);
    settings.input = extensionInputFromName(params.extensionInput, "sss");
    settings.curvature = curvatureStrategyFromName(params.curvature, "sss");
    settings.curvatureFloor = static_cast<float>(params.curvatureFloor);
    settings.curvatureReferenceMm = static_cast<float>(params.curvatureReferenceMm);
    return settings;
}

std::vector<Rgb> applyKernel(const SurfaceBuffers& surface, const std::vector<Rgb>& diffuse, const Kernel& kernel,
                             const BlurSettings& settings) {
    if (kernel.stages.empty()) return diffuse;
    std::vector<Rgb> current = diffuse;
    std::vector<Rgb> output(diffuse.size(), Rgb{0.0f, 0.0f, 0.0f});
    for (const auto& stage : kernel.stages) {
        current = blurPass(surface, blurPass(surface, current, stage, BlurAxis::Horizontal, settings), stage,
                           BlurAxis::Vertical, settings);
        for (size_t i = 0; i < output.size(); ++i)
            for (int c = 0; c < 3; ++c) output[i][c] += static_cast<float>(stage.accumulate[c]) * current[i][c];
    }
    return output;
}

} // namespace skinlab::renderer::sss
