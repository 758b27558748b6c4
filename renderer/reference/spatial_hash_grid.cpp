#include "renderer/reference/spatial_hash_grid.h"

#include "common/check.h"

#include <algorithm>
#include <cmath>

namespace skinlab::renderer::reference {

SpatialHashGrid::SpatialHashGrid(const std::vector<glm::vec3>& points, const std::vector<std::uint32_t>& members,
                                 float cellSizeMm)
    : points_(&points), cellSize_(cellSizeMm) {
    SKINLAB_CHECK_GT(cellSizeMm, 0.0f);
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
    keyed.reserve(members.size());
    for (const std::uint32_t index : members) keyed.emplace_back(key(cellOf(points[index])), index);
    std::sort(keyed.begin(), keyed.end());
    sorted_.reserve(keyed.size());
    for (std::size_t i = 0; i < keyed.size(); ++i) {
        sorted_.push_back(keyed[i].second);
        auto [it, inserted] = cells_.try_emplace(keyed[i].first, static_cast<std::uint32_t>(i), 0u);
        it->second.second = static_cast<std::uint32_t>(i + 1);
        (void)inserted;
    }
}

glm::ivec3 SpatialHashGrid::cellOf(const glm::vec3& p) const { return glm::ivec3(glm::floor(p / cellSize_)); }

std::uint64_t SpatialHashGrid::key(const glm::ivec3& cell) {
    // 21 bits per axis (±2^20 cells: ±1 km at 1 mm cells), offset to unsigned.
    constexpr std::int64_t offset = 1 << 20;
    constexpr std::uint64_t mask = (1u << 21) - 1;
    const auto part = [&](int v) { return static_cast<std::uint64_t>(v + offset) & mask; };
    return part(cell.x) | (part(cell.y) << 21) | (part(cell.z) << 42);
}

} // namespace skinlab::renderer::reference
