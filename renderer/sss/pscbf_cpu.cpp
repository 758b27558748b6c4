#include "renderer/sss/pscbf_cpu.h"

#include "common/check.h"
#include "renderer/sss/extension_weights.h"

#include <algorithm>
#include <cmath>

namespace skinlab::renderer::sss {

namespace {
constexpr float kMinAxisScale = 0.05f; // kPscbfMinAxisScale of pscbf_blur.frag
float mix(float x, float y, float a) { return x * (1.0f - a) + y * a; }
glm::vec3 toVec3(const Rgb& rgb) { return glm::vec3(rgb[0], rgb[1], rgb[2]); }

// The foreshortening of the blur axis on the plane of view normal `n` seen along view ray `w` (pscbf_blur.frag).
float axisScaleOf(const glm::vec3& n, const glm::vec3& w, bool horizontal) {
    const float nw = std::abs(glm::dot(n, w));
    const float along = horizontal ? n.x : n.y;
    const float across = horizontal ? n.y * w.y : n.x * w.x;
    const float acrossRay = horizontal ? w.y : w.x;
    const float denominator =
        std::sqrt((across + n.z) * (across + n.z) + along * along * (1.0f + acrossRay * acrossRay));
    return std::max(denominator > 0.0f ? nw / denominator : 1.0f, kMinAxisScale);
}
} // namespace

std::vector<Rgb> pscbfPass(const PscbfCpuInputs& inputs, const std::vector<Rgb>& input,
                           const std::vector<Rgb>& unblurred, const KernelStage& stage, BlurAxis axis) {
    const SurfaceBuffers& surface = *inputs.surface;
    const BlurSettings& extensions = inputs.extensions;
    const int width = surface.width;
    const int height = surface.height;
    SKINLAB_CHECK_EQ(input.size(), size_t(width) * height);
    SKINLAB_CHECK_EQ(unblurred.size(), input.size());
    SKINLAB_CHECK(inputs.viewNormal.empty() || inputs.viewNormal.size() == input.size());
    const bool horizontal = axis == BlurAxis::Horizontal;
    const bool hasNormal = !inputs.viewNormal.empty();
    const float f = surface.focalLengthPixels;
    const std::array<float, 2> principal =
        surface.principalPoint.value_or(std::array<float, 2>{0.5f * float(width), 0.5f * float(height)});
    std::vector<Rgb> output(input.size());
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const size_t index = size_t(y) * width + x;
            const Rgb centre = input[index];
            const float centreMask = surface.mask[index];
            if (!(centreMask > 0.0f)) {
                output[index] = centre;
                continue;
            }
            const float centreDepth = surface.depth[index];
            const glm::vec3 w((principal[0] - (float(x) + 0.5f)) / f, (principal[1] - (float(y) + 0.5f)) / f, 1.0f);
            glm::vec3 n(0.0f, 0.0f, 1.0f);
            if (hasNormal) {
                const glm::vec3 normal = toVec3(inputs.viewNormal[index]);
                if (glm::dot(normal, normal) > 0.25f) n = glm::normalize(normal);
            }
            if (glm::dot(n, w) < 0.0f) n = -n;
            const float axisScale = hasNormal ? axisScaleOf(n, w, horizontal) : 1.0f;
            float pixelsPerMm = f / (surface.mmPerUnit * centreDepth) * axisScale;
            if (extensions.curvature != CurvatureStrategy::Off)
                pixelsPerMm *= curvatureWidthScale(
                    extensions.curvature,
                    normalisedCurvature(surface.curvature[index], surface.mmPerUnit, extensions.curvatureReferenceMm),
                    extensions.curvatureFloor);
            const float nw = glm::dot(n, w);
            const float nAxis = horizontal ? n.x : n.y;
            const bool planePrediction = hasNormal && nw > kMinAxisScale;
            Rgb inverseTwoSigmaSquared{};
            for (int c = 0; c < 3; ++c)
                inverseTwoSigmaSquared[c] = 1.0f / (2.0f * inputs.depthSigmaMm[c] * inputs.depthSigmaMm[c]);
            const bool weighsTaps = extensions.weighsTaps();
            const glm::vec3 labCentre = weighsTaps && extensions.labWeight > 0.0f
                                            ? linearRec709ToLab(extensionColour(surface, input, index, extensions))
                                            : glm::vec3(0.0f);
            const float auxCentre =
                weighsTaps && extensions.cbf ? extensionAuxiliary(surface, input, index, extensions) : 0.0f;
            const int along = horizontal ? x : y;
            const int lastTexel = (horizontal ? width : height) - 1;
            Rgb sum{0.0f, 0.0f, 0.0f};
            Rgb weightSum{0.0f, 0.0f, 0.0f};
            for (const auto& tap : stage.taps) {
                const float position = float(along) + static_cast<float>(tap.offsetMm) * pixelsPerMm;
                const float first = std::floor(position);
                const float fraction = position - first;
                for (int t = 0; t < 2; ++t) {
                    const float share = t == 0 ? 1.0f - fraction : fraction;
                    if (share <= 0.0f) continue;
                    const int k = std::clamp(int(first) + t, 0, lastTexel);
                    const size_t texel = horizontal ? size_t(y) * width + k : size_t(k) * width + x;
                    const float mask = surface.mask[texel];
                    if (!(mask > 0.0f)) continue;
                    Rgb weight{};
                    for (int c = 0; c < 3; ++c) weight[c] = static_cast<float>(tap.weight[c]) * (share * mask);
                    if (inputs.depthWeight) {
                        float expected = centreDepth;
                        if (planePrediction) {
                            const float denominator = nw - nAxis * float(k - along) / f;
                            if (denominator > kMinAxisScale * nw) expected = centreDepth * nw / denominator;
                        }
                        const float differenceMm = (surface.depth[texel] - expected) * surface.mmPerUnit;
                        for (int c = 0; c < 3; ++c)
                            weight[c] *= std::isnan(differenceMm)
                                             ? 0.0f
                                             : std::exp(-differenceMm * differenceMm * inverseTwoSigmaSquared[c]);
                    }
                    if (weighsTaps) {
                        float extension = 1.0f;
                        if (extensions.labWeight > 0.0f)
                            extension *= labWeight(
                                labCentre, linearRec709ToLab(extensionColour(surface, input, texel, extensions)),
                                extensions.labWeight);
                        if (extensions.cbf)
                            extension *= auxiliaryWeight(
                                auxCentre, extensionAuxiliary(surface, input, texel, extensions), extensions.cbfLambda);
                        for (int c = 0; c < 3; ++c) weight[c] *= extension;
                    }
                    for (int c = 0; c < 3; ++c) {
                        sum[c] += weight[c] * input[texel][c];
                        weightSum[c] += weight[c];
                    }
                }
            }
            Rgb blurred{};
            for (int c = 0; c < 3; ++c)
                blurred[c] = resolveWeightedSum(glm::vec3(sum[c]), weightSum[c], glm::vec3(centre[c])).x;
            for (int c = 0; c < 3; ++c) {
                if (horizontal) {
                    output[index][c] = mix(centre[c], blurred[c], centreMask);
                } else {
                    const float spike = static_cast<float>(1.0 - stage.accumulate[c]); // as PscbfMethod sets it
                    const float original = unblurred[index][c];
                    output[index][c] = mix(original, spike * original + (1.0f - spike) * blurred[c], centreMask);
                }
            }
        }
    return output;
}

std::vector<Rgb> applyPscbf(const PscbfCpuInputs& inputs, const std::vector<Rgb>& diffuse, const Kernel& kernel) {
    SKINLAB_CHECK(methodInfo(kernel.method).execution == Execution::Pscbf);
    SKINLAB_CHECK_EQ(kernel.stages.size(), 1u);
    const KernelStage& stage = kernel.stages[0];
    const std::vector<Rgb> horizontal = pscbfPass(inputs, diffuse, diffuse, stage, BlurAxis::Horizontal);
    return pscbfPass(inputs, horizontal, diffuse, stage, BlurAxis::Vertical);
}

} // namespace skinlab::renderer::sss
