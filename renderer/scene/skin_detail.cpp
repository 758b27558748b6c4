#include "renderer/scene/skin_detail.h"

#include "common/error.h"
#include "renderer/scene/builtin_geometry.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <thread>
#include <vector>

namespace skinlab::renderer {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Integer hash (a multiply-xorshift finaliser): the same lattice point always gives the same value.
std::uint32_t hash(int x, int y, int z, std::uint32_t seed) {
    std::uint32_t h = seed * 0x9e3779b9u;
    h ^= static_cast<std::uint32_t>(x) * 0x8da6b343u;
    h ^= static_cast<std::uint32_t>(y) * 0xd8163841u;
    h ^= static_cast<std::uint32_t>(z) * 0xcb1ab31fu;
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

// Uniform in [0, 1) from a hash and a stream index.
float unit(std::uint32_t h, std::uint32_t stream) {
    return static_cast<float>(hash(static_cast<int>(h), static_cast<int>(stream), 0, 17u) >> 8) / 16777216.0f;
}

float smoothStep(float edge0, float edge1, float x) {
    const float t = std::clamp((x - edge0) / (edge1 - edge0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

float gaussian(float value, float centre, float sigma) {
    const float d = (value - centre) / sigma;
    return std::exp(-0.5f * d * d);
}

// Value noise in [-1, 1]: hashed lattice values, quintic interpolation (C2 across cells).
float valueNoise(const glm::vec3& p, std::uint32_t seed) {
    const glm::vec3 cell = glm::floor(p);
    const glm::vec3 f = p - cell;
    const glm::vec3 w = f * f * f * (f * (f * 6.0f - 15.0f) + 10.0f);
    const int x = static_cast<int>(cell.x), y = static_cast<int>(cell.y), z = static_cast<int>(cell.z);
    const auto at = [&](int dx, int dy, int dz) {
        return static_cast<float>(hash(x + dx, y + dy, z + dz, seed) >> 8) / 8388608.0f - 1.0f;
    };
    const float x00 = at(0, 0, 0) + w.x * (at(1, 0, 0) - at(0, 0, 0));
    const float x10 = at(0, 1, 0) + w.x * (at(1, 1, 0) - at(0, 1, 0));
    const float x01 = at(0, 0, 1) + w.x * (at(1, 0, 1) - at(0, 0, 1));
    const float x11 = at(0, 1, 1) + w.x * (at(1, 1, 1) - at(0, 1, 1));
    const float y0 = x00 + w.y * (x10 - x00);
    const float y1 = x01 + w.y * (x11 - x01);
    return y0 + w.z * (y1 - y0);
}

// Sum of octaves, halving amplitude and doubling frequency; roughly in [-1, 1].
float fractalNoise(const glm::vec3& p, int octaves, std::uint32_t seed) {
    float sum = 0.0f, amplitude = 0.5f, norm = 0.0f;
    glm::vec3 q = p;
    for (int o = 0; o < octaves; ++o) {
        sum += amplitude * valueNoise(q, seed + static_cast<std::uint32_t>(o));
        norm += amplitude;
        amplitude *= 0.5f;
        q = q * 2.03f + glm::vec3(17.1f, 3.7f, 9.2f);
    }
    return sum / norm;
}

// Cellular dimples: one feature per cubic cell of `cellMm` (present with probability `presence`), radius between
// minRadius and maxRadius (≤ cellMm / 2, so only the 2 × 2 × 2 block of cells nearest p can reach it). Returns the
// largest profile (1 − (d/r)²)² in [0, 1].
float cellular(const glm::vec3& p, float cellMm, float presence, float minRadius, float maxRadius, std::uint32_t seed) {
    const glm::vec3 q = p / cellMm;
    const glm::vec3 base = glm::floor(q);
    const glm::vec3 f = q - base;
    const int start[3] = {static_cast<int>(base.x) - (f.x < 0.5f ? 1 : 0),
                          static_cast<int>(base.y) - (f.y < 0.5f ? 1 : 0),
                          static_cast<int>(base.z) - (f.z < 0.5f ? 1 : 0)};
    float best = 0.0f;
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                const int cx = start[0] + dx, cy = start[1] + dy, cz = start[2] + dz;
                const std::uint32_t h = hash(cx, cy, cz, seed);
                if (unit(h, 0) >= presence) continue;
                const glm::vec3 centre =
                    (glm::vec3(static_cast<float>(cx), static_cast<float>(cy), static_cast<float>(cz)) +
                     glm::vec3(unit(h, 1), unit(h, 2), unit(h, 3))) *
                    cellMm;
                const float radius = minRadius + (maxRadius - minRadius) * unit(h, 4);
                const float d2 = glm::dot(p - centre, p - centre) / (radius * radius);
                if (d2 >= 1.0f) continue;
                best = std::max(best, (1.0f - d2) * (1.0f - d2));
            }
    return best;
}

// Distance from point p to the segment ab (2-D).
float segmentDistance(const glm::vec2& p, const glm::vec2& a, const glm::vec2& b) {
    const glm::vec2 ab = b - a;
    const float t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
    return glm::length(p - (a + t * ab));
}

// Groove profile across a line at distance d (mm) with half width w: 1 on the line.
float groove(float d, float w) { return std::exp(-(d / w) * (d / w)); }

struct TexelDetail {
    float height = 0.0f;    // mm, outwards
    glm::vec3 albedo{1.0f}; // linear multiplier
};

// How much a point belongs to the face (front of the head).
float frontOf(const glm::vec3& p) {
    const glm::vec3 d = glm::normalize(p / glm::vec3(76.0f, 116.0f, 97.0f));
    return smoothStep(0.35f, 0.75f, d.z);
}

TexelDetail detailAt(const glm::vec3& p) {
    TexelDetail out;
    const float front = frontOf(p);
    const float ax = std::abs(p.x);

    // --- height: pores --------------------------------------------------------------------------------------
    // Deeper and denser on the nose and cheeks than elsewhere.
    const float nose = gaussian(p.x, 0.0f, 10.0f) * gaussian(p.y, -24.0f, 12.0f) * front;
    const float cheeks = gaussian(ax, 44.0f, 16.0f) * gaussian(p.y, -22.0f, 16.0f) * front;
    const float poreRegion = 1.0f + 0.8f * std::min(1.0f, nose + cheeks);
    const float pore = cellular(p, 1.3f, 0.55f + 0.25f * std::min(1.0f, nose + cheeks), 0.28f, 0.45f, 101u);
    out.height -= 0.08f * poreRegion * pore;

    // --- height: fine criss-cross micro-relief --------------------------------------------------------------
    {
        static const glm::vec3 d1 = glm::normalize(glm::vec3(0.8f, 1.0f, 0.35f));
        static const glm::vec3 d2 = glm::normalize(glm::vec3(-0.8f, 1.0f, 0.35f));
        const float amplitude = 0.03f * (0.6f + 0.4f * valueNoise(p / 6.0f, 202u));
        for (const auto& [direction, seed] : {std::pair{d1, 203u}, std::pair{d2, 204u}}) {
            const float phase = glm::dot(p, direction) / 1.6f + 0.7f * valueNoise(p / 3.5f, seed);
            const float c = std::max(0.0f, std::cos(2.0f * kPi * phase));
            out.height -= amplitude * c * c * c * c;
        }
    }

    // --- height: expression wrinkles ------------------------------------------------------------------------
    // Forehead: four wavy horizontal creases between the brows and the hairline.
    {
        const float wave = 2.0f * valueNoise(glm::vec3(p.x / 18.0f, 0.0f, 7.3f), 301u);
        const float y = p.y + wave;
        float creases = 0.0f;
        for (int k = 0; k < 4; ++k)
            creases +=
                (1.0f - 0.15f * static_cast<float>(k)) * groove(y - (44.0f + 9.0f * static_cast<float>(k)), 0.6f);
        out.height -= 0.10f * creases * smoothStep(50.0f, 28.0f, ax) * front;
    }
    // Crow's feet: lines fanning out from the outer eye corners.
    {
        const float dx = ax - 46.0f, dy = p.y - 3.0f;
        const float r = std::sqrt(dx * dx + dy * dy);
        const float theta = std::atan2(dy, dx);
        const float spacing = 14.0f * kPi / 180.0f;
        const float jitter = 0.25f * spacing * valueNoise(glm::vec3(r / 4.0f, p.x > 0 ? 1.0f : 5.0f, 0.5f), 302u);
        const float offset = theta + jitter - spacing * std::round((theta + jitter) / spacing);
        const float lines = groove(r * std::abs(offset), 0.45f) * smoothStep(3.0f, 6.0f, r) *
                            smoothStep(18.0f, 11.0f, r) *
                            smoothStep(65.0f * kPi / 180.0f, 45.0f * kPi / 180.0f, std::abs(theta));
        out.height -= 0.09f * lines * smoothStep(0.2f, 0.5f, front + 0.2f);
    }
    // Nasolabial folds: from the nose wings to beside the mouth corners.
    {
        const float d = segmentDistance(glm::vec2(ax, p.y), glm::vec2(17.0f, -36.0f), glm::vec2(31.0f, -74.0f));
        out.height -= 0.25f * groove(d, 1.6f) * front;
    }
    // Lips: fine vertical lines.
    const float lipX = p.x / 24.0f;
    const float lipY = (p.y + 66.0f) / 12.0f;
    const float lips = p.z > 40.0f ? smoothStep(1.0f, 0.8f, std::sqrt(lipX * lipX + lipY * lipY)) : 0.0f;
    float lipLines = 0.0f;
    if (lips > 0.0f) {
        const float c = std::max(0.0f, std::cos(2.0f * kPi * (p.x / 1.1f + 0.5f * valueNoise(p / 2.0f, 303u))));
        lipLines = lips * c * c * c * c;
        out.height -= 0.03f * lipLines;
    }
    // Gentle unevenness everywhere.
    out.height += 0.04f * fractalNoise(p / 3.0f, 2, 304u);

    // --- albedo ---------------------------------------------------------------------------------------------
    const float mottle = fractalNoise(p / 10.0f, 3, 401u);
    const float fine = fractalNoise(p / 3.0f, 2, 402u);
    glm::vec3 albedo(1.0f + 0.08f * mottle + 0.05f * fine);
    albedo *= glm::vec3(1.0f + 0.04f * mottle, 1.0f - 0.04f * mottle, 1.0f - 0.05f * mottle);
    // Flush of the cheeks and the nose.
    const float flush = std::min(1.0f, gaussian(ax, 44.0f, 14.0f) * gaussian(p.y, -20.0f, 13.0f) +
                                           0.8f * gaussian(p.x, 0.0f, 9.0f) * gaussian(p.y, -28.0f, 9.0f)) *
                        front;
    albedo *= glm::mix(glm::vec3(1.0f), glm::vec3(1.04f, 0.88f, 0.90f), 0.8f * flush);
    // Sparse spots (freckles, small naevi).
    const float spot = cellular(p, 5.0f, 0.2f, 0.4f, 0.9f, 403u);
    albedo *= glm::mix(glm::vec3(1.0f), glm::vec3(0.80f, 0.70f, 0.64f), 0.7f * smoothStep(0.0f, 0.5f, spot));
    // Pores are slightly darker.
    albedo *= glm::vec3(1.0f) - glm::vec3(0.10f, 0.14f, 0.14f) * pore;
    // Lip lines.
    albedo *= 1.0f - 0.08f * lipLines;
    // Brow hairs: strokes along the brows inside the brow region of the vertex colours (builtin_geometry.cpp).
    if (p.z > 40.0f) {
        const float x = ax;
        const float arcY = 19.0f + 4.0f * std::sin(kPi * std::clamp((x - 12.0f) / 40.0f, 0.0f, 1.0f));
        const float brow =
            smoothStep(5.5f, 3.0f, std::abs(p.y - arcY)) * smoothStep(9.0f, 14.0f, x) * smoothStep(55.0f, 48.0f, x);
        if (brow > 0.0f) {
            const glm::vec2 across = glm::normalize(glm::vec2(1.0f, -0.35f));
            const float phase = glm::dot(glm::vec2(x, p.y), across) / 0.7f + 1.2f * valueNoise(p / 2.0f, 404u);
            const float c = std::max(0.0f, std::cos(2.0f * kPi * phase));
            albedo *= 1.0f - 0.45f * brow * c * c * c;
        }
    }
    out.albedo = albedo;
    return out;
}

// Runs body(row) for rows [0, rows) on up to hardware_concurrency threads.
void forRows(int rows, const std::function<void(int)>& body) {
    const int threads = std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, 16);
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            for (int row = t; row < rows; row += threads) body(row);
        });
    for (std::thread& thread : pool) thread.join();
}

} // namespace

SkinDetailMaps makeHeadSkinDetail(int width, int height) {
    if (width < 4 || height < 4) throw InputError("builtin:head: skin detail maps need at least 4 × 4 texels");
    const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    std::vector<glm::vec3> points(count);
    std::vector<float> heights(count);
    SkinDetailMaps maps;
    maps.albedo.width = maps.normal.width = width;
    maps.albedo.height = maps.normal.height = height;
    maps.albedo.pixels.assign(count * 4, 1.0f);
    maps.normal.pixels.assign(count * 4, 1.0f);

    forRows(height, [&](int y) {
        const float v = (static_cast<float>(y) + 0.5f) / static_cast<float>(height);
        for (int x = 0; x < width; ++x) {
            const std::size_t i =
                static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
            const float u = (static_cast<float>(x) + 0.5f) / static_cast<float>(width);
            points[i] = headSurfaceAt(u, v);
            if (y == 0) {
                heights[i] = 0.0f; // row 0: flat, albedo 1 (the eyes sample it)
                continue;
            }
            const TexelDetail detail = detailAt(points[i]);
            heights[i] = detail.height;
            float* a = &maps.albedo.pixels[i * 4];
            a[0] = detail.albedo.r;
            a[1] = detail.albedo.g;
            a[2] = detail.albedo.b;
        }
    });
    forRows(height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const std::size_t i =
                static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
            float* n = &maps.normal.pixels[i * 4];
            glm::vec3 normal(0.0f, 0.0f, 1.0f);
            if (y > 0) {
                // u wraps (the chart is closed around the head); v is one-sided at the last row.
                const auto at = [&](int xx, int yy) {
                    return static_cast<std::size_t>(yy) * static_cast<std::size_t>(width) +
                           static_cast<std::size_t>((xx + width) % width);
                };
                const std::size_t left = at(x - 1, y), right = at(x + 1, y);
                const std::size_t up = at(x, y - 1), down = at(x, std::min(y + 1, height - 1));
                const float du = glm::length(points[right] - points[left]);
                const float dv = glm::length(points[down] - points[up]);
                const float slopeU = du > 1e-4f ? (heights[right] - heights[left]) / du : 0.0f;
                // Row 1 borders the flat row 0 (0.3 mm around the vertex): no slope along v there.
                const float slopeV = y == 1 ? 0.0f : dv > 1e-4f ? (heights[down] - heights[up]) / dv : 0.0f;
                // Tangent frame of computeTangents: x along ∂P/∂u, y along −∂P/∂v.
                normal = glm::normalize(glm::vec3(-slopeU, slopeV, 1.0f));
            }
            n[0] = 0.5f + 0.5f * normal.x;
            n[1] = 0.5f + 0.5f * normal.y;
            n[2] = 0.5f + 0.5f * normal.z;
        }
    });
    return maps;
}

} // namespace skinlab::renderer
