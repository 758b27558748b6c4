#include "renderer/sss/method.h"

#include "renderer/sss/radial_profile.h"

#include <algorithm>
#include <deque>
#include <mutex>

namespace skinlab::renderer::sss {

double Method::supportRadiusMm(const SssParams&, const Kernel& kernel) const { return kernel.supportRadiusMm(); }

std::unique_ptr<Marginal> Method::profileMarginal(const SssParams&) const { return nullptr; }

std::vector<std::string_view> withBlurKeys(std::vector<std::string_view> keys) {
    keys.insert(keys.end(), kBlurKeys.begin(), kBlurKeys.end());
    return keys;
}

double RadialProfileSupport::supportRadiusMm(const SssParams& params, const Kernel&) const {
    return makeRadialProfile(params)->cutoffRadiusMm(kCutoffTail);
}

std::shared_ptr<const PreparedMethod> prepareMethod(const SssParams& params) {
    // A few entries: a render, its reference and a tuning session's A/B pair repeat at most a handful of sets.
    constexpr std::size_t kKept = 8;
    static std::mutex mutex;
    static std::deque<std::shared_ptr<const PreparedMethod>> kept;
    {
        const std::lock_guard lock(mutex);
        const auto found = std::find_if(kept.begin(), kept.end(), [&](const auto& p) { return p->params == params; });
        if (found != kept.end()) return *found;
    }
    // Built outside the lock (a Burley or file: kernel takes milliseconds); two threads may build the same set once
    // each, and both results are equal.
    auto prepared = std::make_shared<PreparedMethod>();
    prepared->params = params;
    prepared->info = &methodInfo(params.method);
    prepared->kernel = makeKernel(params);
    prepared->supportRadiusMm = prepared->info->model->supportRadiusMm(params, prepared->kernel);
    const std::lock_guard lock(mutex);
    kept.push_front(prepared);
    if (kept.size() > kKept) kept.pop_back();
    return prepared;
}

} // namespace skinlab::renderer::sss
