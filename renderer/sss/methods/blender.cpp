// sss.method = "pathtraced" (Blender Cycles' random walk) and "eevee" (Blender EEVEE's screen-space
// Christensen–Burley SSS): rendered by Blender (renderer/pathtraced; Execution::Cycles / Eevee), so no screen-space
// taps here. Their radii are matched to d'Eon's profile (docs/pathtraced.md): their support is that profile's, as the
// object-space reference declares.
#include "renderer/sss/method.h"

#include <string>
#include <utility>

namespace skinlab::renderer::sss {

namespace {
class BlenderMethod final : public RadialProfileSupport {
public:
    explicit BlenderMethod(std::string source) : source_(std::move(source)) {}
    Kernel kernel(const SssParams&) const override {
        Kernel kernel;
        kernel.source = source_;
        return kernel;
    }

private:
    std::string source_;
};
} // namespace

MethodInfo pathtracedMethod() {
    return {{},
            "pathtraced",
            Execution::Cycles,
            false,
            "Blender Cycles' random-walk SSS ([pathtraced] table)",
            {},
            {},
            {},
            std::make_shared<BlenderMethod>("path-traced (Blender Cycles, random walk)")};
}

MethodInfo eeveeMethod() {
    return {{},
            "eevee",
            Execution::Eevee,
            false,
            "Blender EEVEE's screen-space SSS ([eevee] table)",
            {},
            {},
            {},
            std::make_shared<BlenderMethod>("Blender EEVEE (screen-space Christensen-Burley)")};
}

} // namespace skinlab::renderer::sss
