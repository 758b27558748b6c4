#pragma once
// An SSS method as an object: prepared once per parameter set on the CPU (its kernel and support radius), run by the
// renderer through the one code path its row's Execution names (sss_params.h). Every method — none, the tap-kernel
// methods, pscbf, reference, pathtraced, eevee — is one class behind a row of the method table (method_table.cpp);
// docs/methods.md, "Adding a method", walks through adding one.
#include "renderer/sss/kernel.h"
#include "renderer/sss/sss_params.h"

#include <memory>

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
};

// Object-space and Blender methods: the radius outside which every channel of the radial profile they use (or are
// matched to) keeps at most 0.1 % of its energy (radial_profile.h).
class RadialProfileSupport : public Method {
public:
    static constexpr double kCutoffTail = 1e-3;
    double supportRadiusMm(const SssParams& params, const Kernel& kernel) const override;
};

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
