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
};
} // namespace

std::shared_ptr<const Method> makeReferenceMethod() { return std::make_shared<ReferenceMethod>(); }

} // namespace skinlab::renderer::sss
