#pragma once
// A uniform grid over 3-D points, hashed by integer cell coordinates, for radius queries of the object-space
// reference (every receiver visits the 27 cells around it; with the cell size equal to the query radius these
// contain every point within the radius).
#include <cstdint>
#include <glm/glm.hpp>
#include <unordered_map>
#include <vector>

namespace skinlab::renderer::reference {

class SpatialHashGrid {
public:
    // Indexes the points `members` (indices into `points`); cellSizeMm > 0.
    SpatialHashGrid(const std::vector<glm::vec3>& points, const std::vector<std::uint32_t>& members, float cellSizeMm);

    float cellSizeMm() const { return cellSize_; }

    // Calls visit(index) for every member within `radiusMm` (≤ cellSizeMm) of `centre`, in a fixed order (cells in
    // z, y, x order, members in ascending index within a cell): results are deterministic.
    template <class Visit>
    void forEachWithin(const glm::vec3& centre, float radiusMm, Visit&& visit) const {
        const glm::ivec3 cell = cellOf(centre);
        const float radiusSquared = radiusMm * radiusMm;
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const auto found = cells_.find(key(cell + glm::ivec3(dx, dy, dz)));
                    if (found == cells_.end()) continue;
                    for (std::uint32_t k = found->second.first; k < found->second.second; ++k) {
                        const std::uint32_t index = sorted_[k];
                        const glm::vec3 delta = (*points_)[index] - centre;
                        if (glm::dot(delta, delta) <= radiusSquared) visit(index);
                    }
                }
    }

private:
    glm::ivec3 cellOf(const glm::vec3& p) const;
    static std::uint64_t key(const glm::ivec3& cell);

    const std::vector<glm::vec3>* points_;
    float cellSize_;
    std::vector<std::uint32_t> sorted_; // members sorted by cell key, then index
    std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>> cells_; // key → [begin, end) in sorted_
};

} // namespace skinlab::renderer::reference
