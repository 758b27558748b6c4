#pragma once
// An SSS method as one unit: its file under renderer/sss/methods/ holds its class (prepared once per parameter set on
// the CPU: its kernel and support radius) and the function that declares its row of the method table (MethodInfo,
// sss_params.h: name, executor — the one code path of the renderer its Execution names —, whether it is interactive,
// summary, the keys it reads and declares, its defaults). Every method — none, the tap-kernel methods, pscbf,
// reference, pathtraced, eevee — is registered by one line (method_table.cpp, or SKINLAB_REGISTER_METHOD below);
// docs/methods.md, "Adding a method", walks through adding one.
#include "renderer/sss/kernel.h"
#include "renderer/sss/sss_params.h"

#include <array>
#include <memory>
#include <string_view>
#include <vector>

namespace skinlab::renderer::sss {

class Method {
public:
    virtual ~Method() = default;
    // The taps of `params` (InputError for inconsistent parameters, e.g. an unreadable profile file). A method
    // without screen-space taps returns a kernel with no stages and says in `source` what computes it.
    virtual Kernel kernel(const SssParams& params) const = 0;
    // The support radius on the surface, mm (EXR attribute skinlab:sss_radius_mm; the metrics' band widths follow
    // it). Default: the kernel's (Kernel::supportRadiusMm).
    virtual double supportRadiusMm(const SssParams& params, const Kernel& kernel) const;
    // The 1-D marginal of the physical profile the method integrates against (`skinlab kernel`'s continuous
    // statistics, `skinlab tune`'s kernel curve); nullptr (the default) for a method without one.
    virtual std::unique_ptr<Marginal> profileMarginal(const SssParams& params) const;
};

// Object-space and Blender methods: the radius outside which every channel of the radial profile they use (or are
// matched to) keeps at most 0.1 % of its energy (radial_profile.h).
class RadialProfileSupport : public Method {
public:
    static constexpr double kCutoffTail = 1e-3;
    double supportRadiusMm(const SssParams& params, const Kernel& kernel) const override;
};

// The [sss] keys every screen-space blur reads besides its own: follow-surface and the thesis' extensions
// (docs/extensions.md). withBlurKeys appends them to a row's `keys`; a method's listing (methodKeys) gives them after
// its own keys.
inline constexpr std::array<std::string_view, 7> kBlurKeys{
    "follow_surface", "cbf", "cbf_lambda", "lab_weight", "extension_input", "curvature", "curvature_floor"};
std::vector<std::string_view> withBlurKeys(std::vector<std::string_view> keys);

// Registers the method whose row `declaration()` returns (a function returning MethodInfo) at start-up, after the
// built-in methods: the registration line of a method compiled outside the renderer library, e.g. in a test
// executable. A built-in method's registration line is its entry in method_table.cpp's list instead (a static
// library drops an object file nothing refers to, registration included).
#define SKINLAB_REGISTER_METHOD(declaration)                                                                           \
    [[maybe_unused]] static const ::skinlab::renderer::sss::SssMethod skinlabRegistered_##declaration =                \
        ::skinlab::renderer::sss::registerMethod(declaration())

// A method prepared for one parameter set: what the renderer runs.
struct PreparedMethod {
    SssParams params;
    const MethodInfo* info = nullptr;
    Kernel kernel;
    double supportRadiusMm = 0.0;
};

// The prepared method of `params`, built once per parameter set: the last few sets are kept (process-wide,
// thread-safe), so renders that repeat a set — a stimulus set's blocks, live tuning — reuse its kernel.
std::shared_ptr<const PreparedMethod> prepareMethod(const SssParams& params);

} // namespace skinlab::renderer::sss
