#include "renderer/sss/cpu_blur.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace skinlab::renderer::sss {

namespace {
float mix(float x, float y, float a) { return x * (1.0f - a) + y * a; }

} // namespace

std::vector<Rgb> blurPass(const SurfaceBuffers& surface, const std::vector<Rgb>& input, const KernelStage& stage,
                          BlurAxis axis, const BlurSettings& settings) {
    const int width = surface.width;
    const int height = surface.height;
    assert(input.size() == size_t(width) * height);
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
            const float pixelsPerMm = surface.focalLengthPixels / (surface.mmPerUnit * centreDepth);
            Rgb sum{0.0f, 0.0f, 0.0f};
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
                        s = std::max(s, std::clamp(settings.followSurfaceK *
                                                       std::abs(centreDepth - surface.depth[texels[t]]) *
                                                       surface.mmPerUnit,
                                                   0.0f, 1.0f));
                    for (int c = 0; c < 3; ++c) values[t][c] = mix(input[texels[t]][c], centre[c], s);
                }
                for (int c = 0; c < 3; ++c)
                    sum[c] += static_cast<float>(tap.weight[c]) * mix(values[0][c], values[1][c], fraction);
            }
            for (int c = 0; c < 3; ++c) output[index][c] = mix(centre[c], sum[c], centreMask);
        }
    }
    return output;
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
