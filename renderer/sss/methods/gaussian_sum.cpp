// sss.method = "gaussian-sum" (Jimenez & Gutierrez 2010): d'Eon's six Gaussians as six incremental blurs. Stage i
// adds variance v_i − v_{i−1} (scaled to the surface), so the cascade's result after stage i is the input blurred by
// a Gaussian of variance v_i, and the output sums the stages with d'Eon's weights (kernel.h).
#include "renderer/sss/discretisation.h"
#include "renderer/sss/gaussian_sum_profile.h"
#include "renderer/sss/method.h"
#include "renderer/sss/skin_model.h"

namespace skinlab::renderer::sss {

namespace {
class GaussianSumMethod final : public Method {
public:
    Kernel kernel(const SssParams& params) const override {
        const double scale = profileScale(params.widthMm);
        Kernel kernel;
        double previous = 0.0;
        for (const auto& lobe : skinProfileLobes(params)) {
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
        return kernel;
    }
};
} // namespace

MethodInfo gaussianSumMethod() {
    return {{},
            "gaussian-sum",
            Execution::TapPasses,
            true,
            "Jimenez & Gutierrez 2010: d'Eon's six Gaussians as incremental separable blurs (12 passes)",
            withBlurKeys({"samples", "sampling", "follow_surface_k"}),
            {},
            {},
            std::make_shared<GaussianSumMethod>()};
}

} // namespace skinlab::renderer::sss
