// sss.method = "none": the diffuse buffer copied through (Execution::CopyThrough).
#include "renderer/sss/method.h"

namespace skinlab::renderer::sss {

namespace {
class NoneMethod final : public Method {
public:
    Kernel kernel(const SssParams&) const override {
        Kernel kernel;
        kernel.source = "none";
        return kernel;
    }
};
} // namespace

std::shared_ptr<const Method> makeNoneMethod() { return std::make_shared<NoneMethod>(); }

} // namespace skinlab::renderer::sss
