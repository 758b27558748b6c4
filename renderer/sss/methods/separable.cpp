// sss.method = "separable" (Jimenez et al. 2015): one stage of taps from the 1-D marginal of a physical profile
// (d'Eon, Burley or a tabulated .bn kernel), run as a horizontal and a vertical pass.
#include "renderer/sss/discretisation.h"
#include "renderer/sss/method.h"

namespace skinlab::renderer::sss {

namespace {
class SeparableMethod final : public Method {
public:
    Kernel kernel(const SssParams& params) const override {
        const auto marginal = makeMarginal(params);
        KernelStage stage;
        stage.taps = discretise(*marginal, params.samples, params.placement);
        scaleOffsets(stage.taps, profileScale(params.widthMm));
        stage.accumulate = {1.0, 1.0, 1.0};
        Kernel kernel;
        kernel.source =
            marginal->description() + " (marginal, " + std::string(placementName(params.placement)) + " placement)";
        kernel.stages.push_back(std::move(stage));
        return kernel;
    }
    std::unique_ptr<Marginal> profileMarginal(const SssParams& params) const override { return makeMarginal(params); }
};
} // namespace

MethodInfo separableMethod() {
    return {{},
            "separable",
            Execution::TapPasses,
            true,
            "Jimenez et al. 2015: two passes with the marginal of a physical profile (d'Eon, Burley or a file)",
            withBlurKeys({"samples", "sampling", "follow_surface_k", "profile", "material"}),
            {},
            {},
            std::make_shared<SeparableMethod>()};
}

} // namespace skinlab::renderer::sss
