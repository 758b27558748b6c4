// sss.method = "box" (test only): equal weights over ±box_half_width_mm on the surface, with one key of its own — a
// method written as docs/methods.md, "Adding a method", says: this file is the whole method (its class, its own key
// bound to its typed parameters, and its row), and test_method_recipe.cpp's one SKINLAB_REGISTER_METHOD line
// registers it.
#include "renderer/sss/method.h"

namespace skinlab::renderer::sss {

namespace {
// Its own parameters; the initialisers are the keys' defaults.
struct BoxParams {
    double halfWidthMm = 2.0;
};

// Its own keys, bound to BoxParams.
const std::vector<BoundKey<BoxParams>>& boxKeys() {
    static const std::vector<BoundKey<BoxParams>> keys{
        boundKey({"box_half_width_mm", KeyType::Number, 0.1, 20.0, {}, "mm", "half width of the box"},
                 &BoxParams::halfWidthMm),
    };
    return keys;
}

class BoxMethod final : public Method {
public:
    Kernel kernel(const SssParams& params) const override {
        const double half = ownParams(params, boxKeys()).halfWidthMm;
        KernelStage stage;
        const int n = params.samples;
        for (int i = 0; i < n; ++i) {
            const double w = 1.0 / n;
            stage.taps.push_back({half * (2.0 * i / (n - 1) - 1.0), {w, w, w}});
        }
        stage.accumulate = {1.0, 1.0, 1.0};
        Kernel kernel;
        kernel.source = "box kernel (test)";
        kernel.stages.push_back(std::move(stage));
        return kernel;
    }
};
} // namespace

MethodInfo boxMethod() {
    return {{},
            "box",
            Execution::TapPasses,
            true,
            "test: equal weights over ±box_half_width_mm",
            {"samples", "follow_surface", "follow_surface_k"},
            ownKeys(boxKeys()),
            {},
            std::make_shared<BoxMethod>()};
}

} // namespace skinlab::renderer::sss
