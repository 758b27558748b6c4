// sss.method = "artistic": the kernel of Jimenez's separable SSS demo (per-channel strength and falloff,
// artistic_kernel.h), one stage run as a horizontal and a vertical pass.
#include "renderer/sss/methods/artistic.h"

#include "renderer/sss/artistic_kernel.h"
#include "renderer/sss/method.h"
#include "renderer/sss/skin_model.h"

namespace skinlab::renderer::sss {

namespace {
// Its own keys, bound to ArtisticParams.
const std::vector<BoundKey<ArtisticParams>>& artisticKeys() {
    static const std::vector<BoundKey<ArtisticParams>> keys{
        boundKey(
            {"artistic_strength", KeyType::Vec3, 0.0, 1.0, {}, "", "artistic kernel: per-channel strength (R, G, B)"},
            &ArtisticParams::strength),
        boundKey(
            {"artistic_falloff", KeyType::Vec3, 0.0, 1.0, {}, "", "artistic kernel: per-channel falloff (R, G, B)"},
            &ArtisticParams::falloff),
    };
    return keys;
}

class ArtisticMethod final : public Method {
public:
    Kernel kernel(const SssParams& params) const override {
        const ArtisticParams artistic = artisticParams(params);
        KernelStage stage;
        // A [skin] tone widens each channel's falloff by its profile width over d'Eon's (skinArtisticFalloff).
        stage.taps = artisticTaps(params.samples, artistic.strength, skinArtisticFalloff(params, artistic.falloff));
        scaleOffsets(stage.taps, profileScale(params.widthMm));
        stage.accumulate = {1.0, 1.0, 1.0};
        Kernel kernel;
        kernel.source = "artistic kernel of Jimenez's demo (slice of d'Eon's red lobes 2-6)";
        kernel.stages.push_back(std::move(stage));
        return kernel;
    }
};
} // namespace

ArtisticParams artisticParams(const SssParams& params) { return ownParams(params, artisticKeys()); }

MethodInfo artisticMethod() {
    return {{},
            "artistic",
            Execution::TapPasses,
            true,
            "Jimenez's demo kernel (per-channel strength and falloff), two passes",
            withBlurKeys({"samples", "follow_surface_k"}),
            ownKeys(artisticKeys()),
            {},
            std::make_shared<ArtisticMethod>()};
}

} // namespace skinlab::renderer::sss
