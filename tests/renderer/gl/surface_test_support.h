#pragma once
// Helpers of the surface-pass tests (transmittance, aux and curvature AOVs): the camera stored in an EXR, view-space
// positions from its linear depth, and the skin pixels away from every non-skin pixel.
#include "render_test_support.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <vector>

namespace skinlab::renderer::test {

struct ExrCamera {
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
};

inline ExrCamera exrCamera(const ExrImage& image) {
    const nlohmann::json camera = nlohmann::json::parse(image.strings.at("skinlab:camera"));
    ExrCamera result;
    for (int i = 0; i < 16; ++i) {
        result.view[i / 4][i % 4] = camera["view"][static_cast<std::size_t>(i)].get<float>();
        result.projection[i / 4][i % 4] = camera["projection"][static_cast<std::size_t>(i)].get<float>();
    }
    return result;
}

// View-space position of the surface seen through the centre of pixel (x, y) (rows top first), from depth.Z and
// the projection's focal terms (independent of the shader's route through the inverse projection).
inline glm::vec3 viewPositionAt(const ExrImage& image, const ExrCamera& camera, int x, int y) {
    const float ndcX = 2.0f * (static_cast<float>(x) + 0.5f) / static_cast<float>(image.width) - 1.0f;
    const float ndcY = 1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / static_cast<float>(image.height);
    const float depth = image.at("depth.Z", x, y);
    return {ndcX / camera.projection[0][0] * depth, ndcY / camera.projection[1][1] * depth, -depth};
}

// Pixels (x, y) whose mask is 1 everywhere within `margin` pixels (Chebyshev distance): away from silhouettes and
// material edges. "1": at least 0.999, the interpolated vertex skin flag is 1 only to float rounding.
inline std::vector<std::pair<int, int>> interiorSkinPixels(const ExrImage& image, int margin) {
    std::vector<std::pair<int, int>> pixels;
    for (int y = margin; y < image.height - margin; ++y)
        for (int x = margin; x < image.width - margin; ++x) {
            bool interior = true;
            for (int dy = -margin; dy <= margin && interior; ++dy)
                for (int dx = -margin; dx <= margin && interior; ++dx)
                    interior = image.at("mask.Y", x + dx, y + dy) >= 0.999f;
            if (interior) pixels.emplace_back(x, y);
        }
    return pixels;
}

} // namespace skinlab::renderer::test
