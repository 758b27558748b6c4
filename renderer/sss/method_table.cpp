// The method table (sss_params.h, MethodInfo): one row per SSS method, constructing its class (method.h). A method is
// its class in renderer/sss/methods/ plus its row here (docs/methods.md, "Adding a method").
#include "common/check.h"
#include "common/error.h"
#include "renderer/sss/method.h"

#include <algorithm>

namespace skinlab::renderer::sss {

// Each method's class, in its own file under renderer/sss/methods/.
std::shared_ptr<const Method> makeNoneMethod();
std::shared_ptr<const Method> makeGaussianSumMethod();
std::shared_ptr<const Method> makeSeparableMethod();
std::shared_ptr<const Method> makeArtisticMethod();
std::shared_ptr<const Method> makePscbfMethod();
std::shared_ptr<const Method> makeReferenceMethod();
std::shared_ptr<const Method> makePathtracedMethod();
std::shared_ptr<const Method> makeEeveeMethod();

// Defined in sss_params.cpp: adds a registered method's name to the sss.method choices.
void addMethodChoice(std::string_view name);

namespace {
// The screen-space blur methods' shared keys: follow-surface and the thesis' extensions (docs/extensions.md).
#define SKINLAB_BLUR_KEYS                                                                                              \
    "follow_surface", "cbf", "cbf_lambda", "lab_weight", "extension_input", "curvature", "curvature_floor"

// The rows, built-ins in SssMethod order (the identifiers are the positions).
std::vector<MethodInfo> builtInRows() {
    std::vector<MethodInfo> rows{
        {SssMethod::None,
         "none",
         Execution::CopyThrough,
         "no SSS: the diffuse buffer is copied through",
         {},
         {},
         {},
         makeNoneMethod()},
        {SssMethod::GaussianSum,
         "gaussian-sum",
         Execution::TapPasses,
         "Jimenez & Gutierrez 2010: d'Eon's six Gaussians as incremental separable blurs (12 passes)",
         {"samples", "sampling", "follow_surface_k", SKINLAB_BLUR_KEYS},
         {},
         {},
         makeGaussianSumMethod()},
        {SssMethod::Separable,
         "separable",
         Execution::TapPasses,
         "Jimenez et al. 2015: two passes with the marginal of a physical profile (d'Eon, Burley or a file)",
         {"samples", "sampling", "follow_surface_k", "profile", "material", SKINLAB_BLUR_KEYS},
         {},
         {},
         makeSeparableMethod()},
        {SssMethod::Artistic,
         "artistic",
         Execution::TapPasses,
         "Jimenez's demo kernel (per-channel strength and falloff), two passes",
         {"samples", "follow_surface_k", "artistic_strength", "artistic_falloff", SKINLAB_BLUR_KEYS},
         {},
         {},
         makeArtisticMethod()},
        {SssMethod::Pscbf,
         "pscbf",
         Execution::Pscbf,
         "Mikkelsen 2010: pseudo-separable cross-bilateral filter, spike + one Gaussian per channel",
         {"samples", "pscbf_sigma", SKINLAB_BLUR_KEYS},
         {},
         {{"samples", SssParams::kDefaultPscbfSamples}},
         makePscbfMethod()},
        {SssMethod::Reference,
         "reference",
         Execution::ObjectSpace,
         "object-space SSS on the tessellated surface (the ground truth of the metrics)",
         {"profile", "material", "reference_edge_mm", "reference_through_gain", "reference_through_growth_per_mm2",
          "reference_non_skin", "reference_convexity_mm", "reference_near_field"},
         {},
         {},
         makeReferenceMethod()},
        {SssMethod::Pathtraced,
         "pathtraced",
         Execution::Cycles,
         "Blender Cycles' random-walk SSS ([pathtraced] table)",
         {},
         {},
         {},
         makePathtracedMethod()},
        {SssMethod::Eevee,
         "eevee",
         Execution::Eevee,
         "Blender EEVEE's screen-space SSS ([eevee] table)",
         {},
         {},
         {},
         makeEeveeMethod()},
    };
    for (std::size_t i = 0; i < rows.size(); ++i) SKINLAB_CHECK(static_cast<std::size_t>(rows[i].method) == i);
    return rows;
}
#undef SKINLAB_BLUR_KEYS

std::vector<MethodInfo>& rows() {
    static std::vector<MethodInfo> table = builtInRows();
    return table;
}
} // namespace

const std::vector<MethodInfo>& methodTable() { return rows(); }

const MethodInfo& methodInfo(SssMethod method) {
    const auto index = static_cast<std::size_t>(method);
    SKINLAB_CHECK(index < rows().size());
    return rows()[index];
}

const MethodInfo* findMethod(std::string_view name) {
    for (const MethodInfo& info : rows())
        if (info.name == name) return &info;
    return nullptr;
}

SssMethod registerMethod(MethodInfo row) {
    if (findMethod(row.name)) throw RuntimeError("method table: '" + std::string(row.name) + "' is taken");
    if (!row.model) throw RuntimeError("method table: '" + std::string(row.name) + "' has no class");
    for (const SssKey& key : row.ownKeys)
        for (const std::string_view taken : allSssKeys())
            if (key.name == taken)
                throw RuntimeError("method table: '" + std::string(row.name) + "' declares key '" +
                                   std::string(key.name) + "', which another row declares");
    row.method = static_cast<SssMethod>(rows().size());
    rows().push_back(std::move(row));
    addMethodChoice(rows().back().name);
    return rows().back().method;
}

std::vector<std::string> methodNames() {
    std::vector<std::string> names;
    for (const MethodInfo& info : rows()) names.emplace_back(info.name);
    return names;
}

std::vector<std::string> screenSpaceMethodNames() {
    std::vector<std::string> names;
    for (const MethodInfo& info : rows())
        if (info.screenSpace()) names.emplace_back(info.name);
    return names;
}

std::vector<std::string> blurPassMethodNames() {
    std::vector<std::string> names;
    for (const MethodInfo& info : rows())
        if (info.blurPasses()) names.emplace_back(info.name);
    return names;
}

std::vector<std::string_view> allSssKeys() {
    std::vector<std::string_view> keys(kCommonSssKeys.begin(), kCommonSssKeys.end());
    const auto add = [&](std::string_view key) {
        if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
    };
    for (const MethodInfo& info : rows()) {
        for (const std::string_view key : info.keys) add(key);
        for (const SssKey& key : info.ownKeys) add(key.name);
    }
    return keys;
}

bool methodUsesKey(SssMethod method, std::string_view key) {
    const MethodInfo& info = methodInfo(method);
    return std::find(kCommonSssKeys.begin(), kCommonSssKeys.end(), key) != kCommonSssKeys.end() ||
           std::find(info.keys.begin(), info.keys.end(), key) != info.keys.end() ||
           std::any_of(info.ownKeys.begin(), info.ownKeys.end(), [&](const SssKey& own) { return own.name == key; });
}

std::vector<std::string_view> methodKeys(SssMethod method) {
    std::vector<std::string_view> keys;
    for (const std::string_view k : kCommonSssKeys)
        if (k != "method") keys.push_back(k);
    const MethodInfo& info = methodInfo(method);
    keys.insert(keys.end(), info.keys.begin(), info.keys.end());
    for (const SssKey& k : info.ownKeys) keys.push_back(k.name);
    return keys;
}

std::string notAParameterMessage(SssMethod method) {
    std::string keys;
    for (const std::string_view k : methodKeys(method)) keys += (keys.empty() ? "" : ", ") + std::string(k);
    return "not a parameter of method '" + std::string(methodName(method)) + "' (its keys: " + keys + ")";
}

std::string_view methodName(SssMethod method) { return methodInfo(method).name; }

std::string_view executionName(Execution execution) {
    switch (execution) {
    case Execution::CopyThrough: return "copy-through";
    case Execution::TapPasses: return "tap-passes";
    case Execution::Pscbf: return "pscbf";
    case Execution::ObjectSpace: return "object-space";
    case Execution::Cycles: return "cycles";
    case Execution::Eevee: return "eevee";
    }
    return "copy-through";
}

void to_json(nlohmann::json& out, SssMethod method) { out = std::string(methodName(method)); }

void from_json(const nlohmann::json& in, SssMethod& method) {
    const MethodInfo* info = in.is_string() ? findMethod(in.get<std::string>()) : nullptr;
    if (!info) throwInput("", "sss.method", in.dump() + " is not one of the methods (skinlab methods)");
    method = info->method;
}

} // namespace skinlab::renderer::sss
