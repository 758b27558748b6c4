#include "renderer/sss/sss_params.h"

#include "common/check.h"
#include "common/error.h"
#include "common/json_toml.h"
#include "common/spec.h"
#include "renderer/sss/materials.h"
#include "renderer/sss/tabulated_kernel.h"

#include <algorithm>

namespace skinlab::renderer::sss {

namespace {
// The screen-space blur methods' shared keys: follow-surface and the thesis' extensions (docs/extensions.md).
#define SKINLAB_BLUR_KEYS                                                                                              \
    "follow_surface", "cbf", "cbf_lambda", "lab_weight", "extension_input", "curvature", "curvature_floor"

const std::vector<MethodInfo> kMethods{
    {SssMethod::None, "none", false, false, "no SSS: the diffuse buffer is copied through", {}},
    {SssMethod::GaussianSum,
     "gaussian-sum",
     true,
     true,
     "Jimenez & Gutierrez 2010: d'Eon's six Gaussians as incremental separable blurs (12 passes)",
     {"samples", "sampling", "follow_surface_k", SKINLAB_BLUR_KEYS}},
    {SssMethod::Separable,
     "separable",
     true,
     true,
     "Jimenez et al. 2015: two passes with the marginal of a physical profile (d'Eon, Burley or a file)",
     {"samples", "sampling", "follow_surface_k", "profile", "material", SKINLAB_BLUR_KEYS}},
    {SssMethod::Artistic,
     "artistic",
     true,
     true,
     "Jimenez's demo kernel (per-channel strength and falloff), two passes",
     {"samples", "follow_surface_k", "artistic_strength", "artistic_falloff", SKINLAB_BLUR_KEYS}},
    {SssMethod::Pscbf,
     "pscbf",
     true,
     false,
     "Mikkelsen 2010: pseudo-separable cross-bilateral filter, spike + one Gaussian per channel",
     {"samples", "pscbf_sigma", SKINLAB_BLUR_KEYS}},
    {SssMethod::Reference,
     "reference",
     false,
     false,
     "object-space SSS on the tessellated surface (the ground truth of the metrics)",
     {"profile", "material", "reference_edge_mm", "reference_through_gain"}},
    {SssMethod::Pathtraced, "pathtraced", false, false, "Blender Cycles' random-walk SSS ([pathtraced] table)", {}},
    {SssMethod::Eevee, "eevee", false, false, "Blender EEVEE's screen-space SSS ([eevee] table)", {}},
};
#undef SKINLAB_BLUR_KEYS

// Shorthands for the reader: the declared range / choices of a key.
double lowest(std::string_view key) { return sssKey(key).min; }
double highest(std::string_view key) { return sssKey(key).max; }
const std::vector<std::string>& choicesOf(std::string_view key) { return sssKey(key).choices; }

SssParams readSssTable(const SpecReader& sss) {
    SssParams p;
    p.method = findMethod(sss.choice("method", "none", choicesOf("method")))->method;
    // A key of another method would be ignored silently: refuse it, naming the key and the method.
    for (const std::string_view key : allSssKeys())
        if (sss.has(key) && !methodUsesKey(p.method, key)) sss.fail(key, notAParameterMessage(p.method));
    if (p.method == SssMethod::Pscbf) p.samples = SssParams::kDefaultPscbfSamples;
    p.samples = static_cast<int>(sss.integer("samples", p.samples, static_cast<std::int64_t>(lowest("samples")),
                                             static_cast<std::int64_t>(highest("samples"))));
    if (p.samples % 2 == 0)
        sss.fail("samples",
                 std::to_string(p.samples) + " is even; a symmetric kernel needs an odd number of taps (3…101)");
    p.widthMm = sss.number("width_mm", p.widthMm, lowest("width_mm"), highest("width_mm"));
    p.placement = sss.choice("sampling", "quadratic", choicesOf("sampling")) == "importance" ? TapPlacement::Importance
                                                                                             : TapPlacement::Quadratic;
    p.followSurface = sss.boolean("follow_surface", p.followSurface);
    p.followSurfaceK =
        sss.number("follow_surface_k", p.followSurfaceK, lowest("follow_surface_k"), highest("follow_surface_k"));
    p.profile = sss.string("profile", p.profile);
    p.material = sss.choice("material", p.material, choicesOf("material"));
    if (p.profile.rfind("file:", 0) == 0) {
        if (p.profile.size() == 5) sss.fail("profile", "'file:' needs a path, e.g. file:/path/Skin1_PreInt_DISCSEP.bn");
        try {
            readTabulatedKernel(p.profile.substr(5));
        } catch (const InputError& e) {
            sss.fail("profile", e.what());
        }
    } else if (p.profile != "deon" && p.profile != "burley") {
        sss.fail("profile", "'" + p.profile + "' is not one of: deon, burley, file:PATH");
    }
    if (p.profile == "deon" && p.material != "skin")
        sss.fail("material", "'" + p.material + "' has no d'Eon profile (only 'skin'); use sss.profile = \"burley\"");
    p.artisticStrength =
        sss.vec3("artistic_strength", p.artisticStrength, lowest("artistic_strength"), highest("artistic_strength"));
    p.artisticFalloff =
        sss.vec3("artistic_falloff", p.artisticFalloff, lowest("artistic_falloff"), highest("artistic_falloff"));
    p.cbf = sss.boolean("cbf", p.cbf);
    p.cbfLambda = sss.number("cbf_lambda", p.cbfLambda, lowest("cbf_lambda"), highest("cbf_lambda"));
    p.labWeight = sss.number("lab_weight", p.labWeight, lowest("lab_weight"), highest("lab_weight"));
    p.extensionInput = sss.choice("extension_input", p.extensionInput, choicesOf("extension_input"));
    p.curvature = sss.choice("curvature", p.curvature, choicesOf("curvature"));
    p.curvatureFloor =
        sss.number("curvature_floor", p.curvatureFloor, lowest("curvature_floor"), highest("curvature_floor"));
    p.curvatureMeasure = sss.choice("curvature_measure", p.curvatureMeasure, choicesOf("curvature_measure"));
    p.curvatureReferenceMm = sss.number("curvature_reference_mm", p.curvatureReferenceMm,
                                        lowest("curvature_reference_mm"), highest("curvature_reference_mm"));
    p.pscbfSigma = sss.choice("pscbf_sigma", "variance", choicesOf("pscbf_sigma")) == "std-dev" ? PscbfSigma::StdDev
                                                                                                : PscbfSigma::Variance;
    p.referenceEdgeMm =
        sss.number("reference_edge_mm", p.referenceEdgeMm, lowest("reference_edge_mm"), highest("reference_edge_mm"));
    p.referenceThroughGain = sss.vec3("reference_through_gain", p.referenceThroughGain,
                                      lowest("reference_through_gain"), highest("reference_through_gain"));
    return p;
}

TransmittanceParams readTransmittanceTable(const SpecReader& t) {
    TransmittanceParams p;
    p.enabled = t.boolean("enabled", p.enabled);
    p.translucency = t.number("translucency", p.translucency, transmittanceKey("translucency").min,
                              transmittanceKey("translucency").max);
    p.curvature = t.boolean("curvature", p.curvature);
    p.curvatureForm = t.choice("curvature_form", p.curvatureForm, transmittanceKey("curvature_form").choices);
    return p;
}
} // namespace

const std::vector<KeyInfo>& sssKeyTable() {
    // Built on first use (the choices call methodNames() and materialNames()).
    static const std::vector<KeyInfo> table{
        {"method", KeyType::Choice, 0, 0, methodNames(), "", "the SSS method (skinlab methods)"},
        {"samples", KeyType::Integer, 3, 101, {}, "taps", "taps per 1-D pass (odd)"},
        {"width_mm", KeyType::Number, 0.01, 100.0, {}, "mm", "physical width of the blur on the surface"},
        {"sampling", KeyType::Choice, 0, 0, {"quadratic", "importance"}, "", "how the kernel is discretised into taps"},
        {"follow_surface", KeyType::Boolean, 0, 0, {}, "", "Jimenez's follow-surface correction on depth steps"},
        {"follow_surface_k",
         KeyType::Number,
         0.0,
         1000.0,
         {},
         "1/mm",
         "follow-surface strength: 1/k mm of depth stops a tap"},
        {"profile", KeyType::String, 0, 0, {}, "", "diffusion profile: deon, burley or file:PATH (a .bn kernel)"},
        {"material", KeyType::Choice, 0, 0, materialNames(), "",
         "material of the profile (burley: Jensen et al. 2001 media)"},
        {"artistic_strength", KeyType::Vec3, 0.0, 1.0, {}, "", "artistic kernel: per-channel strength (R, G, B)"},
        {"artistic_falloff", KeyType::Vec3, 0.0, 1.0, {}, "", "artistic kernel: per-channel falloff (R, G, B)"},
        {"cbf", KeyType::Boolean, 0, 0, {}, "", "E1: cross-bilateral weights on the auxiliary image"},
        {"cbf_lambda", KeyType::Number, 0.0, 1000.0, {}, "", "E1: lambda of exp(-lambda |F_c - F_tap|)"},
        {"lab_weight",
         KeyType::Number,
         0.0,
         100.0,
         {},
         "1/ΔE",
         "E2: beta of the CIELAB weight exp(-beta ΔE*ab); 0 = off"},
        {"extension_input",
         KeyType::Choice,
         0,
         0,
         {"albedo", "lit"},
         "",
         "E1/E2 input: the albedo AOV or the lit colour"},
        {"curvature",
         KeyType::Choice,
         0,
         0,
         {"off", "increase", "reduce", "reduce-floor"},
         "",
         "E3: curvature modulation of the kernel width"},
        {"curvature_floor", KeyType::Number, 0.0, 1.0, {}, "", "E3 reduce-floor: width share kept on flat skin"},
        {"curvature_measure",
         KeyType::Choice,
         0,
         0,
         {"normal", "screen"},
         "",
         "curvature AOV: 3-D normal curvature or the screen-space measure"},
        {"curvature_reference_mm",
         KeyType::Number,
         0.1,
         1000.0,
         {},
         "mm",
         "radius at or below which a surface counts as fully curved"},
        {"pscbf_sigma",
         KeyType::Choice,
         0,
         0,
         {"variance", "std-dev"},
         "",
         "pscbf: how Mikkelsen's Table 1 values are read"},
        {"reference_edge_mm", KeyType::Number, 0.05, 50.0, {}, "mm", "reference: longest skin edge after tessellation"},
        {"reference_through_gain",
         KeyType::Vec3,
         0.0,
         100.0,
         {},
         "",
         "reference: per-channel gain on light through thin parts"},
    };
    return table;
}

const std::vector<KeyInfo>& transmittanceKeyTable() {
    static const std::vector<KeyInfo> table{
        {"enabled", KeyType::Boolean, 0, 0, {}, "", "light through thin parts (Jimenez et al. 2010)"},
        {"translucency", KeyType::Number, 0.0, 1.0, {}, "", "0 = opaque, 1 = fully translucent"},
        {"curvature", KeyType::Boolean, 0, 0, {}, "", "curvature modulation of the transmittance (the thesis' option)"},
        {"curvature_form",
         KeyType::Choice,
         0,
         0,
         {"scale", "thesis"},
         "",
         "scale: × (1 + c); thesis: profile widened by 1 + 2c"},
    };
    return table;
}

namespace {
const KeyInfo& findKey(const std::vector<KeyInfo>& table, std::string_view name) {
    const auto found = std::find_if(table.begin(), table.end(), [&](const KeyInfo& key) { return key.name == name; });
    SKINLAB_CHECK(found != table.end()); // every key the reader reads is declared
    return *found;
}
} // namespace

const KeyInfo& sssKey(std::string_view name) { return findKey(sssKeyTable(), name); }
const KeyInfo& transmittanceKey(std::string_view name) { return findKey(transmittanceKeyTable(), name); }

std::string_view keyTypeName(KeyType type) {
    switch (type) {
    case KeyType::Boolean: return "boolean";
    case KeyType::Integer: return "integer";
    case KeyType::Number: return "number";
    case KeyType::Choice: return "choice";
    case KeyType::Vec3: return "vec3";
    case KeyType::String: return "string";
    }
    return "string";
}

nlohmann::json sssKeyDefaults(SssMethod method) {
    SssParams defaults;
    defaults.method = method;
    if (method == SssMethod::Pscbf) defaults.samples = SssParams::kDefaultPscbfSamples;
    return defaults.toJson();
}

nlohmann::json transmittanceKeyDefaults() { return TransmittanceParams{}.toJson(); }

nlohmann::json keyInfoJson(const KeyInfo& key) {
    nlohmann::json out = {{"name", key.name}, {"type", keyTypeName(key.type)}, {"unit", key.unit}, {"doc", key.doc}};
    if (key.type == KeyType::Integer || key.type == KeyType::Number || key.type == KeyType::Vec3) {
        out["min"] = key.min;
        out["max"] = key.max;
    }
    if (key.type == KeyType::Choice) out["choices"] = key.choices;
    return out;
}

const std::vector<MethodInfo>& methodTable() { return kMethods; }

const MethodInfo& methodInfo(SssMethod method) {
    for (const MethodInfo& info : kMethods)
        if (info.method == method) return info;
    return kMethods.front();
}

const MethodInfo* findMethod(std::string_view name) {
    for (const MethodInfo& info : kMethods)
        if (info.name == name) return &info;
    return nullptr;
}

std::vector<std::string> methodNames() {
    std::vector<std::string> names;
    for (const MethodInfo& info : kMethods) names.emplace_back(info.name);
    return names;
}

std::vector<std::string> screenSpaceMethodNames() {
    std::vector<std::string> names;
    for (const MethodInfo& info : kMethods)
        if (info.screenSpace) names.emplace_back(info.name);
    return names;
}

std::vector<std::string> blurPassMethodNames() {
    std::vector<std::string> names;
    for (const MethodInfo& info : kMethods)
        if (info.blurPasses) names.emplace_back(info.name);
    return names;
}

std::vector<std::string_view> allSssKeys() {
    std::vector<std::string_view> keys(kCommonSssKeys.begin(), kCommonSssKeys.end());
    for (const MethodInfo& info : kMethods)
        for (const std::string_view key : info.keys)
            if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
    return keys;
}

bool methodUsesKey(SssMethod method, std::string_view key) {
    const auto& own = methodInfo(method).keys;
    return std::find(kCommonSssKeys.begin(), kCommonSssKeys.end(), key) != kCommonSssKeys.end() ||
           std::find(own.begin(), own.end(), key) != own.end();
}

std::string notAParameterMessage(SssMethod method) {
    std::string keys;
    for (const std::string_view k : kCommonSssKeys)
        if (k != "method") keys += (keys.empty() ? "" : ", ") + std::string(k);
    for (const std::string_view k : methodInfo(method).keys) keys += ", " + std::string(k);
    return "not a parameter of method '" + std::string(methodName(method)) + "' (its keys: " + keys + ")";
}

std::string_view methodName(SssMethod method) { return methodInfo(method).name; }

std::string_view pscbfSigmaName(PscbfSigma reading) { return reading == PscbfSigma::StdDev ? "std-dev" : "variance"; }

std::string_view placementName(TapPlacement placement) {
    return placement == TapPlacement::Importance ? "importance" : "quadratic";
}

nlohmann::json SssParams::toJson() const {
    const nlohmann::json all = {{"method", std::string(methodName(method))},
                                {"samples", samples},
                                {"width_mm", widthMm},
                                {"sampling", std::string(placementName(placement))},
                                {"follow_surface", followSurface},
                                {"follow_surface_k", followSurfaceK},
                                {"profile", profile},
                                {"material", material},
                                {"artistic_strength", artisticStrength},
                                {"artistic_falloff", artisticFalloff},
                                {"cbf", cbf},
                                {"cbf_lambda", cbfLambda},
                                {"lab_weight", labWeight},
                                {"extension_input", extensionInput},
                                {"curvature", curvature},
                                {"curvature_floor", curvatureFloor},
                                {"curvature_measure", curvatureMeasure},
                                {"curvature_reference_mm", curvatureReferenceMm},
                                {"pscbf_sigma", std::string(pscbfSigmaName(pscbfSigma))},
                                {"reference_edge_mm", referenceEdgeMm},
                                {"reference_through_gain", referenceThroughGain}};
    nlohmann::json own = nlohmann::json::object();
    for (const auto& [key, value] : all.items())
        if (methodUsesKey(method, key)) own[key] = value;
    return own;
}

nlohmann::json TransmittanceParams::toJson() const {
    return {{"enabled", enabled},
            {"translucency", translucency},
            {"curvature", curvature},
            {"curvature_form", curvatureForm}};
}

SssParams readSssParams(const SpecReader& scene) {
    const SpecReader sss = scene.table("sss");
    SssParams p = readSssTable(sss);
    sss.finish();
    return p;
}

TransmittanceParams readTransmittanceParams(const SpecReader& scene) {
    const SpecReader t = scene.table("transmittance");
    TransmittanceParams p = readTransmittanceTable(t);
    t.finish();
    return p;
}

SssParams sssParamsFromJson(const nlohmann::json& sss, std::string_view source) {
    return readSssParams(SpecReader(jsonAsTomlTable(sss, source, "sss"), std::string(source)));
}

TransmittanceParams transmittanceParamsFromJson(const nlohmann::json& transmittance, std::string_view source) {
    return readTransmittanceParams(
        SpecReader(jsonAsTomlTable(transmittance, source, "transmittance"), std::string(source)));
}

double widthMmFromDemoSssWidth(double sssWidth, double mmPerUnit) { return 2.0 * sssWidth * mmPerUnit; }

double transmittanceScalePerUnit(double translucency, double widthMm, double mmPerUnit) {
    const double demoSssWidth = widthMm / (2.0 * mmPerUnit); // world units
    return 8.25 * (1.0 - translucency) / demoSssWidth;
}

} // namespace skinlab::renderer::sss
