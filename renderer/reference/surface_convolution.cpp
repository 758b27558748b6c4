#include "renderer/reference/surface_convolution.h"

#include "common/check.h"
#include "renderer/reference/spatial_hash_grid.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <thread>

namespace skinlab::renderer::reference {

std::vector<glm::vec3> convolveSurface(const SurfaceSamples& samples, const std::vector<glm::vec3>& irradiance,
                                       const sss::RadialProfile& profile, const ConvolutionSettings& settings,
                                       const std::vector<std::uint32_t>* receivers, ConvolutionReport* report) {
    SKINLAB_CHECK_EQ(irradiance.size(), samples.size());
    const std::size_t count = samples.size();
    std::vector<glm::vec3> output(count);
    for (std::size_t i = 0; i < count; ++i) output[i] = irradiance[i] * samples.albedo[i];

    std::vector<std::uint32_t> skinSources;
    for (std::uint32_t i = 0; i < count; ++i)
        if (samples.skin[i] && samples.areaMm2[i] > 0.0f) skinSources.push_back(i);
    // Non-skin samples: sources of no light that still count in the normaliser (NonSkin::Absorbs).
    std::vector<std::uint32_t> absorbers;
    if (settings.nonSkin == NonSkin::Absorbs)
        for (std::uint32_t i = 0; i < count; ++i)
            if (!samples.skin[i] && samples.areaMm2[i] > 0.0f) absorbers.push_back(i);
    std::vector<std::uint32_t> targets;
    if (receivers) {
        for (const std::uint32_t i : *receivers)
            if (i < count && samples.skin[i]) targets.push_back(i);
    } else {
        for (std::uint32_t i = 0; i < count; ++i)
            if (samples.skin[i]) targets.push_back(i);
    }

    const double cutoff = profile.cutoffRadiusMm(settings.cutoffTail);
    const SpatialHashGrid grid(samples.positionMm, skinSources, static_cast<float>(cutoff));
    const SpatialHashGrid absorberGrid(samples.positionMm, absorbers, static_cast<float>(cutoff));

    // R_c(r) tabulated at kProfileTableSize + 1 equal steps of r over [0, r_c], linearly interpolated: one table
    // look-up per source instead of up to 18 exponentials (3 channels × 6 lobes). At 8 mm / 4096 = 2 µm per step
    // the narrowest d'Eon lobe (σ = 80 µm) spans 40 steps, so the interpolation error is below 1e-3 of its peak;
    // r = 0 (Burley's 1/r) is never looked up, sources closer than one step being at least 100× closer than any
    // tessellation places them.
    constexpr int kProfileTableSize = 4096;
    const double step = cutoff / kProfileTableSize;
    std::vector<std::array<float, 3>> table(kProfileTableSize + 2);
    for (int k = 0; k < kProfileTableSize + 2; ++k)
        for (int c = 0; c < 3; ++c)
            table[k][c] = static_cast<float>(profile.radial(c, std::max(k, 1) * step)); // r = 0 → first step
    const float inverseStep = static_cast<float>(1.0 / step);
    std::vector<std::size_t> sourceCounts(targets.size(), 0);

    const auto convolveOne = [&](std::size_t t) {
        const std::uint32_t p = targets[t];
        const glm::vec3 centre = samples.positionMm[p];
        const glm::vec3 normal = samples.normal[p];
        std::array<double, 3> weighted{0.0, 0.0, 0.0};
        std::array<double, 3> weightSum{0.0, 0.0, 0.0};
        std::size_t sources = 0;
        // Whether q is reached from p (ThroughTissue: through the body), and whether it faces p's way.
        const auto reached = [&](std::uint32_t q, bool& facing) {
            facing = true; // q lies on the receiver's side of the surface (counts in the normaliser)
            if (settings.transport == Transport::ThroughTissue && q != p) {
                // The chord p → q must run inside the body: it may not leave p's surface outwards, nor reach q
                // from outside, steeper than 10° (a flat or convex neighbour gives ≤ 0, a concave one a little
                // above 0; across an air gap — lips, a fold, a nostril — the chord leaves through p's surface). A source behind a thin part (its normal turned away) passes: that is through-light.
                const glm::vec3 chord = samples.positionMm[q] - centre;
                const float length = glm::length(chord);
                if (glm::dot(chord, normal) > kAirGapSine * length ||
                    glm::dot(chord, samples.normal[q]) < -kAirGapSine * length)
                    return false;
                facing = glm::dot(normal, samples.normal[q]) > 0.0f;
            }
            return true;
        };
        // K_c(p, q) for q ≠ p: the tabulated profile at the 3-D distance times q's area.
        const auto kernel = [&](std::uint32_t q, float distance, std::array<double, 3>& k) {
            const float position = distance * inverseStep;
            const int index = std::min(static_cast<int>(position), kProfileTableSize);
            const float fraction = position - static_cast<float>(index);
            for (int c = 0; c < 3; ++c)
                k[c] =
                    double(table[index][c] + fraction * (table[index + 1][c] - table[index][c])) * samples.areaMm2[q];
        };
        grid.forEachWithin(centre, static_cast<float>(cutoff), [&](std::uint32_t q) {
            bool facing = true;
            if (!reached(q, facing)) return;
            std::array<double, 3> k;
            float distance = 0.0f;
            if (q == p) {
                const double radius = std::sqrt(samples.areaMm2[p] / std::numbers::pi);
                for (int c = 0; c < 3; ++c) k[c] = profile.cumulative(c, radius);
            } else {
                distance = glm::length(samples.positionMm[q] - centre);
                kernel(q, distance, k);
            }
            const glm::vec3 value = irradiance[q] * samples.albedo[q];
            if (!facing) // the far side of a thin part: the through-light gain, growing with the distance
                for (int c = 0; c < 3; ++c)
                    k[c] *= settings.throughGrowthPerMm2[c] == 0.0
                                ? settings.throughGain[c]
                                : settings.throughGain[c] *
                                      std::exp(settings.throughGrowthPerMm2[c] * double(distance) * distance);
            for (int c = 0; c < 3; ++c) {
                weighted[c] += k[c] * value[c];
                if (facing) weightSum[c] += k[c];
            }
            ++sources;
        });
        // Non-skin neighbours on the receiver's side: the light the profile carries there leaves the skin (a path
        // tracer's walk ends at the medium's boundary), so they add to the normaliser and nothing to the light.
        absorberGrid.forEachWithin(centre, static_cast<float>(cutoff), [&](std::uint32_t q) {
            bool facing = true;
            if (q == p || !reached(q, facing) || !facing) return;
            std::array<double, 3> k;
            kernel(q, glm::length(samples.positionMm[q] - centre), k);
            // A neighbour closer than its own spacing (the vertex across a material boundary lies at distance 0)
            // stands for a disc of area A_q: its weight is at most the profile's mass over such a disc.
            const double disc = std::sqrt(samples.areaMm2[q] / std::numbers::pi);
            for (int c = 0; c < 3; ++c) weightSum[c] += std::min(k[c], profile.cumulative(c, disc));
        });
        glm::vec3 result = output[p]; // no weight at all (an isolated sample): keep E·α
        for (int c = 0; c < 3; ++c)
            if (weightSum[c] > 0.0) result[c] = static_cast<float>(weighted[c] / weightSum[c]);
        output[p] = result;
        sourceCounts[t] = sources;
    };

    unsigned threads = settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
    threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(1, targets.size() / 64)));
    // Each receiver is written by exactly one worker and reads only inputs: the result does not depend on the
    // number of threads or their timing.
    std::atomic<std::size_t> next{0};
    const auto worker = [&] {
        constexpr std::size_t chunk = 256;
        for (std::size_t begin = next.fetch_add(chunk); begin < targets.size(); begin = next.fetch_add(chunk))
            for (std::size_t t = begin; t < std::min(begin + chunk, targets.size()); ++t) convolveOne(t);
    };
    std::vector<std::thread> pool;
    for (unsigned i = 1; i < threads; ++i) pool.emplace_back(worker);
    worker();
    for (auto& thread : pool) thread.join();

    if (report) {
        report->cutoffRadiusMm = cutoff;
        for (int c = 0; c < 3; ++c) report->energyBeyondCutoff[c] = 1.0 - profile.cumulative(c, cutoff);
        report->receivers = targets.size();
        std::size_t total = 0;
        for (const std::size_t s : sourceCounts) total += s;
        report->meanSources = targets.empty() ? 0.0 : double(total) / double(targets.size());
    }
    return output;
}

} // namespace skinlab::renderer::reference
