// sss.method = "reference": object-space SSS on the tessellated surface (Execution::ObjectSpace,
// renderer/gl/reference_method.h), the ground truth of the metrics. No screen-space taps; its support is the radial
// profile's.
#include "renderer/sss/method.h"

namespace skinlab::renderer::sss {

namespace {
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

MethodInfo referenceMethod() {
    return {{},
            "reference",
            Execution::ObjectSpace,
            false,
            "object-space SSS on the tessellated surface (the ground truth of the metrics)",
            {"profile", "material", "reference_edge_mm", "reference_through_gain", "reference_through_growth_per_mm2",
             "reference_non_skin", "reference_convexity_mm", "reference_near_field"},
            {},
            {},
            std::make_shared<ReferenceMethod>()};
}

} // namespace skinlab::renderer::sss
