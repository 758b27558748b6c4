// sss.method = "pscbf" (Mikkelsen 2010): the broad Gaussian part as one stage whose accumulate weights are
// 1 − spike; the spike (the unblurred centre) is added by its own passes (Execution::Pscbf,
// renderer/gl/pscbf_method.h). Offsets scale with width_mm / 3 like every profile.
#include "renderer/sss/methods/pscbf.h"

#include "renderer/sss/method.h"
#include "renderer/sss/skin_model.h"

namespace skinlab::renderer::sss {

namespace {
// Its own key, bound to PscbfParams.
const std::vector<BoundKey<PscbfParams>>& pscbfKeys() {
    static const std::vector<BoundKey<PscbfParams>> keys{
        boundKey({"pscbf_sigma",
                  KeyType::Choice,
                  0,
                  0,
                  {"variance", "std-dev"},
                  "",
                  "pscbf: how Mikkelsen's Table 1 values are read"},
                 &PscbfParams::sigma),
    };
    return keys;
}

class PscbfMethod final : public Method {
public:
    Kernel kernel(const SssParams& params) const override {
        const double scale = profileScale(params.widthMm);
        // Mikkelsen's, widened by a [skin] tone
        const PscbfProfile profile = skinPscbfProfile(params, pscbfParams(params).sigma);
        KernelStage stage = makePscbfKernel(profile, params.samples).broadStage();
        scaleOffsets(stage.taps, scale);
        Kernel kernel;
        kernel.source = "Mikkelsen 2010 pseudo-separable cross-bilateral filter (spike + one Gaussian per channel)";
        // Its filter reaches the disc r_max that bounds it, while its taps sit at cell medians inside it.
        kernel.declaredSupportMm = profile.maxRadiusMm * scale;
        kernel.stages.push_back(std::move(stage));
        return kernel;
    }
};
} // namespace

PscbfParams pscbfParams(const SssParams& params) { return ownParams(params, pscbfKeys()); }

MethodInfo pscbfMethod() {
    return {{},
            "pscbf",
            Execution::Pscbf,
            true,
            "Mikkelsen 2010: pseudo-separable cross-bilateral filter, spike + one Gaussian per channel",
            withBlurKeys({"samples"}),
            ownKeys(pscbfKeys()),
            {{"samples", SssParams::kDefaultPscbfSamples}},
            std::make_shared<PscbfMethod>()};
}

} // namespace skinlab::renderer::sss
