#pragma once
// Small models for the reference tests.
#include "renderer/scene/mesh.h"

namespace skinlab::renderer::reference::test_models {

// A square of side `sizeMm` in the plane z = 0 (1 unit = 1 mm), centred at the origin, facing +Z, made of two
// triangles, one skin material of albedo 1.
inline Model makeSquare(float sizeMm, bool skin = true) {
    Model model;
    const float h = 0.5f * sizeMm;
    for (const glm::vec2 corner : {glm::vec2(-h, -h), glm::vec2(h, -h), glm::vec2(h, h), glm::vec2(-h, h)}) {
        Vertex v;
        v.position = glm::vec3(corner, 0.0f);
        v.normal = glm::vec3(0.0f, 0.0f, 1.0f);
        v.uv = corner / sizeMm + glm::vec2(0.5f);
        model.vertices.push_back(v);
    }
    model.indices = {0, 1, 2, 0, 2, 3};
    model.parts.push_back({0, 6, 0});
    model.materials.push_back({"skin", glm::vec3(1.0f), skin, 0.6f, 1.0f});
    model.computeBounds();
    return model;
}

} // namespace skinlab::renderer::reference::test_models
