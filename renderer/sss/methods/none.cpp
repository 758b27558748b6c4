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

MethodInfo noneMethod() {
    return {{}, "none", Execution::CopyThrough,        true, "no SSS: the diffuse buffer is copied through", {},
            {}, {},     std::make_shared<NoneMethod>()};
}

} // namespace skinlab::renderer::sss
