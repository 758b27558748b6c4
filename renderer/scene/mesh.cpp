#include "renderer/scene/mesh.h"

#include <limits>

namespace skinlab::renderer {

// Axis-aligned bounds of the vertices that the index buffer actually references (unreferenced vertices, e.g.
// left over by a loader, must not move the framing of the named camera views). An empty model has zero bounds.
void Model::computeBounds() {
    if (indices.empty()) {
        boundsMin = glm::vec3(0.0f);
        boundsMax = glm::vec3(0.0f);
        return;
    }
    glm::vec3 lowest(std::numeric_limits<float>::max());
    glm::vec3 highest(std::numeric_limits<float>::lowest());
    for (std::uint32_t index : indices) {
        const glm::vec3& p = vertices.at(index).position;
        lowest = glm::min(lowest, p);
        highest = glm::max(highest, p);
    }
    boundsMin = lowest;
    boundsMax = highest;
}

} // namespace skinlab::renderer
