#include "renderer/sss/kernel.h"

#include "common/error.h"
#include "renderer/sss/artistic_kernel.h"
#include "renderer/sss/burley_profile.h"
#include "renderer/sss/discretisation.h"
#include "renderer/sss/gaussian_sum_profile.h"
#include "renderer/sss/materials.h"
#include "renderer/sss/pscbf_kernel.h"
#include "renderer/sss/tabulated_kernel.h"

#include <algorithm>
#include <cmath>
#include <memory>

namespace skinlab::renderer::sss {

namespace {
double widthScale(const SssParams& params) { return profileScale(params.widthMm); }

void scaleOffsets(std::vector<KernelTap>& taps, double scale) {
    for (auto& tap : taps) tap.offsetMm *= scale;
}

} // namespace

std::unique_ptr<Marginal> makeMarginal(const SssParams& params) {
    if (params.profile.rfind("file:", 0) == 0)
        return std::make_unique<TabulatedMarginal>(TabulatedMarginal::fromFile(params.profile.substr(5)));
    if (params.profile == "burley")
        return std::make_unique<BurleyProfile>(burleyShapeMm(params.material),
                                               "Burley normalized diffusion, material " + params.material);
    if (params.profile == "deon") {
        if (params.material != "skin")
            throwInput("", "sss.material",
                       "'" + params.material + "' has no d'Eon profile (only 'skin'); use sss.profile = \"burley\"");
        return std::make_unique<GaussianSumProfile>(deonSkinLobes(), "d'Eon six-Gaussian skin profile");
    }
    throwInput("", "sss.profile", "'" + params.profile + "' is not one of: deon, burley, file:PATH");
}
Kernel makeKernel(const SssParams& params) {
    if (params.method != SssMethod::None && (params.samples < 3 || params.samples > 101 || params.samples % 2 == 0))
        throwInput("", "sss.samples", std::to_string(params.samples) + " is not an odd number of taps in [3, 101]");
    if (!(params.widthMm > 0.0)) throwInput("", "sss.width_mm", "must be positive");
    Kernel kernel;
    kernel.method = params.method;
    const double scale = widthScale(params);
    switch (params.method) {
    case SssMethod::None: kernel.source = "none"; break;
    case SssMethod::Pathtraced:
        // Rendered by Blender Cycles (renderer/pathtraced): no screen-space taps.
        kernel.source = "path-traced (Blender Cycles, random walk)";
        break;
    case SssMethod::Eevee:
        // Rendered by Blender EEVEE (renderer/pathtraced): its own screen-space kernel, not skinlab's taps.
        kernel.source = "Blender EEVEE (screen-space Christensen-Burley)";
        break;
    case SssMethod::Reference:
        // Computed on the surface (renderer/reference), not with screen-space taps.
        kernel.source = "object-space reference (" + makeMarginal(params)->description() + ", 3-D distances)";
        break;
    case SssMethod::Pscbf: {
        // Mikkelsen 2010: the broad Gaussian part as one stage whose accumulate weights are 1 − spike; the spike
        // (the unblurred centre) is added by the pass. Offsets scale with width_mm / 3 like every profile.
        const PscbfProfile& profile = mikkelsenSkinProfile(params.pscbfSigma);
        KernelStage stage = makePscbfKernel(profile, params.samples).broadStage();
        scaleOffsets(stage.taps, scale);
        kernel.source = "Mikkelsen 2010 pseudo-separable cross-bilateral filter (spike + one Gaussian per channel)";
        kernel.declaredSupportMm = profile.maxRadiusMm * scale;
        kernel.stages.push_back(std::move(stage));
        break;
    }
    case SssMethod::Separable: {
        const auto marginal = makeMarginal(params);
        KernelStage stage;
        stage.taps = discretise(*marginal, params.samples, params.placement);
        scaleOffsets(stage.taps, scale);
        stage.accumulate = {1.0, 1.0, 1.0};
        kernel.source =
            marginal->description() + " (marginal, " + std::string(placementName(params.placement)) + " placement)";
        kernel.stages.push_back(std::move(stage));
        break;
    }
    case SssMethod::Artistic: {
        KernelStage stage;
        stage.taps = artisticTaps(params.samples, params.artisticStrength, params.artisticFalloff);
        scaleOffsets(stage.taps, scale);
        stage.accumulate = {1.0, 1.0, 1.0};
        kernel.source = "artistic kernel of Jimenez's demo (slice of d'Eon's red lobes 2-6)";
        kernel.stages.push_back(std::move(stage));
        break;
    }
    case SssMethod::GaussianSum: {
        // Six incremental Gaussian blurs: stage i adds variance v_i − v_{i−1} (scaled to the surface), so the
        // cascade's result after stage i is the input blurred by a Gaussian of variance v_i.
        double previous = 0.0;
        for (const auto& lobe : deonSkinLobes()) {
            const double variance = lobe.varianceMm2 * scale * scale;
            KernelStage stage;
            stage.varianceMm2 = variance - previous;
            previous = variance;
            GaussianSumProfile gaussian({{stage.varianceMm2, {1.0, 1.0, 1.0}}}, "gaussian");
            stage.taps = discretise(gaussian, params.samples, params.placement);
            stage.accumulate = lobe.weight;
            kernel.stages.push_back(std::move(stage));
        }
        kernel.source = "d'Eon six-Gaussian skin profile (incremental Gaussian blurs, " +
                        std::string(placementName(params.placement)) + " placement)";
        break;
    }
    }
    return kernel;
}

double Kernel::supportRadiusMm() const {
    if (declaredSupportMm > 0.0) return declaredSupportMm;
    // Cascaded stages (gaussian-sum) blur the previous stage's result: their reaches combine as a root sum of
    // squares, exact for Gaussians truncated at the same number of standard deviations (variances add).
    double reachSquared = 0.0;
    double support = 0.0;
    for (const auto& stage : stages) {
        double stageReach = 0.0;
        for (const auto& tap : stage.taps) stageReach = std::max(stageReach, std::abs(tap.offsetMm));
        reachSquared += stageReach * stageReach;
        support = std::max(support, std::sqrt(reachSquared));
    }
    return support;
}

nlohmann::json Kernel::toJson() const {
    nlohmann::json out;
    out["method"] = std::string(methodName(method));
    out["source"] = source;
    out["support_radius_mm"] = supportRadiusMm();
    out["stages"] = nlohmann::json::array();
    for (const auto& stage : stages) {
        nlohmann::json s;
        s["accumulate"] = stage.accumulate;
        if (stage.varianceMm2 > 0.0) s["variance_mm2"] = stage.varianceMm2;
        s["taps"] = nlohmann::json::array();
        for (const auto& tap : stage.taps) s["taps"].push_back({{"offset_mm", tap.offsetMm}, {"weight", tap.weight}});
        out["stages"].push_back(std::move(s));
    }
    return out;
}

KernelStatistics tapStatistics(const std::vector<KernelTap>& taps, double beyondMm) {
    KernelStatistics stats{};
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0, moment = 0.0, beyond = 0.0;
        for (const auto& tap : taps) {
            sum += tap.weight[c];
            moment += tap.weight[c] * tap.offsetMm * tap.offsetMm;
            if (std::abs(tap.offsetMm) > beyondMm) beyond += tap.weight[c];
        }
        stats.rmsWidthMm[c] = std::sqrt(moment / sum);
        stats.energyBeyond[c] = beyond / sum;
    }
    return stats;
}

} // namespace skinlab::renderer::sss
