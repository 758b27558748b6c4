#include "renderer/sss/kernel.h"

#include "common/error.h"
#include "renderer/sss/burley_profile.h"
#include "renderer/sss/gaussian_sum_profile.h"
#include "renderer/sss/materials.h"
#include "renderer/sss/method.h"
#include "renderer/sss/skin_model.h"
#include "renderer/sss/tabulated_kernel.h"

#include <algorithm>
#include <cmath>
#include <memory>

namespace skinlab::renderer::sss {

void scaleOffsets(std::vector<KernelTap>& taps, double scale) {
    for (auto& tap : taps) tap.offsetMm *= scale;
}

std::unique_ptr<Marginal> makeMarginal(const SssParams& params) {
    if (params.profile.rfind("file:", 0) == 0)
        return std::make_unique<TabulatedMarginal>(TabulatedMarginal::fromFile(params.profile.substr(5)));
    if (params.profile == "burley")
        return std::make_unique<BurleyProfile>(skinBurleyShapeMm(params),
                                               "Burley normalized diffusion, material " + params.material);
    if (params.profile == "deon") {
        if (params.material != "skin")
            throwInput("", "sss.material",
                       "'" + params.material + "' has no d'Eon profile (only 'skin'); use sss.profile = \"burley\"");
        return std::make_unique<GaussianSumProfile>(skinProfileLobes(params),
                                                    params.skinLobeWeights
                                                        ? "six-Gaussian profile of the [skin] tone (d'Eon's variances)"
                                                        : "d'Eon six-Gaussian skin profile");
    }
    throwInput("", "sss.profile", "'" + params.profile + "' is not one of: deon, burley, file:PATH");
}
Kernel makeKernel(const SssParams& params) {
    if (methodUsesKey(params.method, "samples") &&
        (params.samples < 3 || params.samples > 101 || params.samples % 2 == 0))
        throwInput("", "sss.samples", std::to_string(params.samples) + " is not an odd number of taps in [3, 101]");
    if (!(params.widthMm > 0.0)) throwInput("", "sss.width_mm", "must be positive");
    // The method's own class (its row of the method table, method_table.cpp) builds the taps.
    Kernel kernel = methodInfo(params.method).model->kernel(params);
    kernel.method = params.method;
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
