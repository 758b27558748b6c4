// sss.method = "artistic": the kernel of Jimenez's separable SSS demo (per-channel strength and falloff,
// artistic_kernel.h), one stage run as a horizontal and a vertical pass.
#include "renderer/sss/artistic_kernel.h"
#include "renderer/sss/method.h"
#include "renderer/sss/skin_model.h"

namespace skinlab::renderer::sss {

namespace {
class ArtisticMethod final : public Method {
public:
    Kernel kernel(const SssParams& params) const override {
        KernelStage stage;
        // A [skin] tone widens each channel's falloff by its profile width over d'Eon's (skinArtisticFalloff).
        stage.taps = artisticTaps(params.samples, params.artisticStrength, skinArtisticFalloff(params));
        scaleOffsets(stage.taps, profileScale(params.widthMm));
        stage.accumulate = {1.0, 1.0, 1.0};
        Kernel kernel;
        kernel.source = "artistic kernel of Jimenez's demo (slice of d'Eon's red lobes 2-6)";
        kernel.stages.push_back(std::move(stage));
        return kernel;
    }
};
} // namespace

MethodInfo artisticMethod() {
    return {{},
            "artistic",
            Execution::TapPasses,
            true,
            "Jimenez's demo kernel (per-channel strength and falloff), two passes",
            withBlurKeys({"samples", "follow_surface_k", "artistic_strength", "artistic_falloff"}),
            {},
            {},
            std::make_shared<ArtisticMethod>()};
}

} // namespace skinlab::renderer::sss
