#include "renderer/reference/surface_convolution.h"

#include "common/check.h"
#include "renderer/reference/spatial_hash_grid.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <thread>

namespace skinlab::renderer::reference {

namespace {

// R_c(r) tabulated at kSteps + 1 equal steps of r over [0, r_c], linearly interpolated: one table look-up per source
// instead of up to 18 exponentials (3 channels × 6 lobes). At 8 mm / 4096 = 2 µm per step the narrowest d'Eon lobe
// (σ = 80 µm) spans 40 steps, so the interpolation error is below 1e-3 of its peak; r = 0 (Burley's 1/r) is never
// looked up, sources closer than one step being at least 100× closer than any tessellation places them.
class ProfileTable {
public:
    ProfileTable(const sss::RadialProfile& profile, double cutoff) : table_(kSteps + 2) {
        const double step = cutoff / kSteps;
        for (int k = 0; k < kSteps + 2; ++k)
            for (int c = 0; c < 3; ++c)
                table_[k][c] = static_cast<float>(profile.radial(c, std::max(k, 1) * step)); // r = 0 → first step
        inverseStep_ = static_cast<float>(1.0 / step);
    }
    // R_c(distance) · area for the three channels.
    void weights(float distance, float area, std::array<double, 3>& k) const {
        const float position = distance * inverseStep_;
        const int index = std::min(static_cast<int>(position), kSteps);
        const float fraction = position - static_cast<float>(index);
        for (int c = 0; c < 3; ++c)
            k[c] = double(table_[index][c] + fraction * (table_[index + 1][c] - table_[index][c])) * area;
    }

private:
    static constexpr int kSteps = 4096;
    std::vector<std::array<float, 3>> table_;
    float inverseStep_ = 0.0f;
};

// Everything one receiver's sum reads: the samples, the grids of skin sources and of absorbers, the table.
struct Convolution {
    const SurfaceSamples& samples;
    const std::vector<glm::vec3>& irradiance;
    const sss::RadialProfile& profile;
    const ConvolutionSettings& settings;
    double cutoff;
    const SpatialHashGrid& sources;
    const SpatialHashGrid& absorbers;
    const ProfileTable& table;

    // Whether q is reached from p (ThroughTissue: through the body), and whether it faces p's way.
    bool reached(std::uint32_t p, std::uint32_t q, bool& facing) const {
        facing = true; // q lies on the receiver's side of the surface (counts in the normaliser)
        if (settings.transport != Transport::ThroughTissue || q == p) return true;
        // The chord p → q must run inside the body: it may not leave p's surface outwards, nor reach q from
        // outside, steeper than 10° (a flat or convex neighbour gives ≤ 0, a concave one a little above 0; across
        // an air gap — lips, a fold, a nostril — the chord leaves through p's surface). A source behind a thin
        // part (its normal turned away) passes: that is through-light.
        const glm::vec3 chord = samples.positionMm[q] - samples.positionMm[p];
        const float length = glm::length(chord);
        if (glm::dot(chord, samples.normal[p]) > kAirGapSine * length ||
            glm::dot(chord, samples.normal[q]) < -kAirGapSine * length)
            return false;
        facing = glm::dot(samples.normal[p], samples.normal[q]) > -0.5f;
        return true;
    }

    // The convolved E·α at receiver p (its own E·α when nothing weighs), and the number of sources summed. With
    // `share`, the receiver's own term is left out of the result and its weight (after normalising and the gain)
    // written there (convolveSurface's ownShare).
    glm::vec3 at(std::uint32_t p, glm::vec3 own, std::size_t& sourceCount, glm::vec3* share = nullptr) const {
        const glm::vec3 centre = samples.positionMm[p];
        const glm::vec3 normal = samples.normal[p];
        std::array<double, 3> weighted{0.0, 0.0, 0.0};
        std::array<double, 3> weightSum{0.0, 0.0, 0.0};
        double curvatureSum = 0.0, curvatureWeight = 0.0; // the kernel-weighted curvature at p (convexityMm)
        double farWeight = 0.0;                           // the kernel weight of a thin part's far side
        std::array<double, 3> self{0.0, 0.0, 0.0};        // Σ_near K_c(p, q) · E_c α_c: the near field (ownShare)
        std::array<double, 3> selfWeight{0.0, 0.0, 0.0};  // Σ_near K_c(p, q)
        std::size_t count = 0;
        sources.forEachWithin(centre, static_cast<float>(cutoff), [&](std::uint32_t q) {
            bool facing = true;
            if (!reached(p, q, facing)) return;
            std::array<double, 3> k;
            float distance = 0.0f;
            if (q == p) {
                const double radius = std::sqrt(samples.areaMm2[p] / std::numbers::pi);
                for (int c = 0; c < 3; ++c) k[c] = profile.cumulative(c, radius);
            } else {
                distance = glm::length(samples.positionMm[q] - centre);
                table.weights(distance, samples.areaMm2[q], k);
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
            if (share && facing && (q == p || distance < settings.nearFieldMm))
                for (int c = 0; c < 3; ++c) {
                    self[c] += k[c] * value[c];
                    selfWeight[c] += k[c];
                }
            if (!facing) farWeight += (k[0] + k[1] + k[2]) / 3.0;
            if (facing && q != p && distance > 0.0f) {
                const double mean = (k[0] + k[1] + k[2]) / 3.0;
                curvatureSum += mean * glm::dot(normal - samples.normal[q], centre - samples.positionMm[q]) /
                                (double(distance) * distance);
                curvatureWeight += mean;
            }
            ++count;
        });
        // Non-skin neighbours on the receiver's side: the light the profile carries there leaves the skin (a path
        // tracer's walk ends at the medium's boundary), so they add to the normaliser and nothing to the light. A
        // neighbour closer than its own spacing (the vertex across a material boundary lies at distance 0) stands
        // for a disc of area A_q: its weight is at most the profile's mass over such a disc.
        absorbers.forEachWithin(centre, static_cast<float>(cutoff), [&](std::uint32_t q) {
            bool facing = true;
            if (q == p || !reached(p, q, facing) || !facing) return;
            std::array<double, 3> k;
            table.weights(glm::length(samples.positionMm[q] - centre), samples.areaMm2[q], k);
            const double disc = std::sqrt(samples.areaMm2[q] / std::numbers::pi);
            for (int c = 0; c < 3; ++c) weightSum[c] += std::min(k[c], profile.cumulative(c, disc));
        });
        sourceCount = count;
        // The gain is a first-order model of a body thick against the profile: where the kernel reaches a thin
        // part's far side (whose light the through-light gain already carries), it fades out, gone once that side
        // holds 5 % of the weight.
        const double farShare = farWeight / std::max(farWeight + curvatureWeight, 1e-30);
        // Curvatures tighter than 1 / convexityRadiusMinMm (a rounded rim, a nostril's edge: parts thin against
        // the profile) count as that radius: the first-order model does not extrapolate there.
        const double bound = 1.0 / settings.convexityRadiusMinMm;
        const double curvature = curvatureWeight > 0.0 ? std::clamp(curvatureSum / curvatureWeight, -bound, bound) *
                                                             std::max(0.0, 1.0 - 20.0 * farShare)
                                                       : 0.0;
        glm::vec3 result = own; // no weight at all (an isolated sample): keep E·α
        if (share) {
            *share = glm::vec3(1.0f);
            result = glm::vec3(0.0f);
        }
        for (int c = 0; c < 3; ++c)
            if (weightSum[c] > 0.0) {
                const double gain = std::max(0.0, 1.0 + settings.convexityMm[c] * curvature) / weightSum[c];
                if (share) {
                    result[c] = static_cast<float>((weighted[c] - self[c]) * gain);
                    (*share)[c] = static_cast<float>(selfWeight[c] * gain);
                } else {
                    result[c] = static_cast<float>(weighted[c] * gain);
                }
            }
        return result;
    }
};

std::vector<std::uint32_t> samplesWhere(const SurfaceSamples& samples, bool skin) {
    std::vector<std::uint32_t> found;
    for (std::uint32_t i = 0; i < samples.size(); ++i)
        if (bool(samples.skin[i]) == skin && samples.areaMm2[i] > 0.0f) found.push_back(i);
    return found;
}

} // namespace

std::vector<glm::vec3> convolveSurface(const SurfaceSamples& samples, const std::vector<glm::vec3>& irradiance,
                                       const sss::RadialProfile& profile, const ConvolutionSettings& settings,
                                       const std::vector<std::uint32_t>* receivers, ConvolutionReport* report,
                                       std::vector<glm::vec3>* ownShare) {
    SKINLAB_CHECK_EQ(irradiance.size(), samples.size());
    const std::size_t count = samples.size();
    std::vector<glm::vec3> output(count);
    if (ownShare) {
        ownShare->assign(count, glm::vec3(1.0f)); // not convolved: all of E·α is the sample's own
        std::fill(output.begin(), output.end(), glm::vec3(0.0f));
    } else {
        for (std::size_t i = 0; i < count; ++i) output[i] = irradiance[i] * samples.albedo[i];
    }

    std::vector<std::uint32_t> targets;
    if (receivers) {
        for (const std::uint32_t i : *receivers)
            if (i < count && samples.skin[i]) targets.push_back(i);
    } else {
        for (std::uint32_t i = 0; i < count; ++i)
            if (samples.skin[i]) targets.push_back(i);
    }

    const double cutoff = profile.cutoffRadiusMm(settings.cutoffTail);
    const SpatialHashGrid sources(samples.positionMm, samplesWhere(samples, true), static_cast<float>(cutoff));
    // Non-skin samples: sources of no light that still count in the normaliser (NonSkin::Absorbs).
    const SpatialHashGrid absorbers(samples.positionMm,
                                    settings.nonSkin == NonSkin::Absorbs ? samplesWhere(samples, false)
                                                                         : std::vector<std::uint32_t>{},
                                    static_cast<float>(cutoff));
    const ProfileTable table(profile, cutoff);
    const Convolution convolution{samples, irradiance, profile, settings, cutoff, sources, absorbers, table};
    std::vector<std::size_t> sourceCounts(targets.size(), 0);

    unsigned threads = settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
    threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(1, targets.size() / 64)));
    // Each receiver is written by exactly one worker and reads only inputs: the result does not depend on the
    // number of threads or their timing.
    std::atomic<std::size_t> next{0};
    const auto worker = [&] {
        constexpr std::size_t chunk = 256;
        for (std::size_t begin = next.fetch_add(chunk); begin < targets.size(); begin = next.fetch_add(chunk))
            for (std::size_t t = begin; t < std::min(begin + chunk, targets.size()); ++t)
                output[targets[t]] = convolution.at(targets[t], irradiance[targets[t]] * samples.albedo[targets[t]],
                                                    sourceCounts[t], ownShare ? &(*ownShare)[targets[t]] : nullptr);
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
