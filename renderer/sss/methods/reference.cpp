// sss.method = "reference": object-space SSS on the tessellated surface (Execution::ObjectSpace,
// renderer/gl/reference_method.h), the ground truth of the metrics. No screen-space taps; its support is the radial
// profile's.
#include "renderer/sss/methods/reference.h"

#include "renderer/sss/method.h"

namespace skinlab::renderer::sss {

namespace {
// Its own keys, bound to ReferenceParams.
const std::vector<BoundKey<ReferenceParams>>& referenceKeys() {
    static const std::vector<BoundKey<ReferenceParams>> keys{
        boundKey({"reference_edge_mm",
                  KeyType::Number,
                  0.05,
                  50.0,
                  {},
                  "mm",
                  "reference: longest skin edge after tessellation"},
                 &ReferenceParams::edgeMm),
        boundKey({"reference_through_gain",
                  KeyType::Vec3,
                  0.0,
                  100.0,
                  {},
                  "",
                  "reference: per-channel gain g on light through thin parts"},
                 &ReferenceParams::throughGain),
        boundKey({"reference_through_growth_per_mm2",
                  KeyType::Vec3,
                  -1.0,
                  0.1,
                  {},
                  "1/mm²",
                  "reference: growth of that gain with the distance d through the part, g exp(k d²), k at width_mm 3"},
                 &ReferenceParams::throughGrowthPerMm2),
        boundKey({"reference_non_skin",
                  KeyType::Choice,
                  0,
                  0,
                  {"absorbs", "returns"},
                  "",
                  "reference: light carried to non-skin neighbours leaves the skin or returns to the receiver"},
                 &ReferenceParams::nonSkin),
        boundKey({"reference_convexity_mm",
                  KeyType::Vec3,
                  -10.0,
                  10.0,
                  {},
                  "mm",
                  "reference: per-channel length L of the convex-surface gain 1 + L κ, L at width_mm 3"},
                 &ReferenceParams::convexityMm),
        boundKey({"reference_near_field",
                  KeyType::Choice,
                  0,
                  0,
                  {"vertex", "pixel"},
                  "",
                  "reference: the near field summed at the vertices or drawn at the pixels (sharp light edges)"},
                 &ReferenceParams::nearField),
    };
    return keys;
}

class ReferenceMethod final : public RadialProfileSupport {
public:
    Kernel kernel(const SssParams& params) const override {
        Kernel kernel;
        kernel.source = "object-space reference (" + makeMarginal(params)->description() + ", 3-D distances)";
        return kernel;
    }
    std::unique_ptr<Marginal> profileMarginal(const SssParams& params) const override { return makeMarginal(params); }
};
} // namespace

ReferenceParams referenceParams(const SssParams& params) { return ownParams(params, referenceKeys()); }

MethodInfo referenceMethod() {
    return {{},
            "reference",
            Execution::ObjectSpace,
            false,
            "object-space SSS on the tessellated surface (the ground truth of the metrics)",
            {"profile", "material"},
            ownKeys(referenceKeys()),
            {},
            std::make_shared<ReferenceMethod>()};
}

} // namespace skinlab::renderer::sss
