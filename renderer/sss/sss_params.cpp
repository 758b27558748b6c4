#include "renderer/sss/sss_params.h"

#include "common/check.h"
#include "common/error.h"
#include "common/json_toml.h"
#include "common/spec.h"
#include "renderer/sss/materials.h"
#include "renderer/sss/tabulated_kernel.h"

#include <algorithm>
#include <cstdlib>

namespace skinlab::renderer::sss {

namespace {
// Reads one declared key with its declared type, range or choices; absent: the value `p` holds (the default).
template <class Params>
void readKey(const SpecReader& r, const BoundKey<Params>& key, Params& p) {
    const nlohmann::json current = key.get(p);
    switch (key.type) {
    case KeyType::Boolean: key.set(p, r.boolean(key.name, current.get<bool>())); return;
    case KeyType::Integer:
        key.set(p, r.integer(key.name, current.get<std::int64_t>(), static_cast<std::int64_t>(key.min),
                             static_cast<std::int64_t>(key.max)));
        return;
    case KeyType::Number: key.set(p, r.number(key.name, current.get<double>(), key.min, key.max)); return;
    case KeyType::Choice: key.set(p, r.choice(key.name, current.get<std::string>(), key.choices)); return;
    case KeyType::Vec3: key.set(p, r.vec3(key.name, current.get<std::array<double, 3>>(), key.min, key.max)); return;
    case KeyType::String: key.set(p, r.string(key.name, current.get<std::string>())); return;
    }
}

// The defaults of `method`: a default-constructed SssParams with the row's overrides.
SssParams defaultsOf(SssMethod method) {
    SssParams p;
    p.method = method;
    for (const auto& [name, value] : methodInfo(method).defaults) sssKey(name).set(p, value);
    return p;
}

// Checks across keys that the declarations cannot state: an odd tap count, a readable profile, a material the
// profile has.
void checkSssParams(const SpecReader& sss, const SssParams& p) {
    if (methodUsesKey(p.method, "samples") && p.samples % 2 == 0)
        sss.fail("samples",
                 std::to_string(p.samples) + " is even; a symmetric kernel needs an odd number of taps (3…101)");
    if (!methodUsesKey(p.method, "profile")) return;
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
}

SssParams readSssTable(const SpecReader& sss) {
    const SssMethod method =
        findMethod(sss.choice("method", std::string(methodName(SssMethod{})), methodNames()))->method;
    // A key of another method would be ignored silently: refuse it, naming the key and the method.
    for (const std::string_view key : allSssKeys())
        if (sss.has(key) && !methodUsesKey(method, key)) sss.fail(key, notAParameterMessage(method));
    SssParams p = defaultsOf(method);
    // The method's keys in declaration order (shared keys, then its own).
    for (const SssKey& key : sssKeyTable())
        if (key.name != "method" && methodUsesKey(method, key.name)) readKey(sss, key, p);
    for (const SssKey& key : methodInfo(method).ownKeys) readKey(sss, key, p);
    checkSssParams(sss, p);
    return p;
}

TransmittanceParams readTransmittanceTable(const SpecReader& t) {
    TransmittanceParams p;
    for (const TransmittanceKey& key : transmittanceKeyTable()) readKey(t, key, p);
    return p;
}
} // namespace

namespace {
// The declarations of the shared [sss] keys (name, type, range, unit, doc, field), those several methods read, in
// reading order, in two groups: the method and its kernel, the extensions and curvature. A key only one method reads
// is declared in that method's file (renderer/sss/methods/, MethodInfo::ownKeys).
std::vector<SssKey> kernelSssKeys() {
    return {
        boundKey({"method", KeyType::Choice, 0, 0, methodNames(), "", "the SSS method (skinlab methods)"},
                 &SssParams::method),
        boundKey({"samples", KeyType::Integer, 3, 101, {}, "taps", "taps per 1-D pass (odd)"}, &SssParams::samples),
        boundKey({"width_mm", KeyType::Number, 0.01, 100.0, {}, "mm", "physical width of the blur on the surface"},
                 &SssParams::widthMm),
        boundKey({"sampling",
                  KeyType::Choice,
                  0,
                  0,
                  {"quadratic", "importance"},
                  "",
                  "how the kernel is discretised into taps"},
                 &SssParams::placement),
        boundKey(
            {"follow_surface", KeyType::Boolean, 0, 0, {}, "", "Jimenez's follow-surface correction on depth steps"},
            &SssParams::followSurface),
        boundKey({"follow_surface_k",
                  KeyType::Number,
                  0.0,
                  1000.0,
                  {},
                  "1/mm",
                  "follow-surface strength: 1/k mm of depth stops a tap"},
                 &SssParams::followSurfaceK),
        boundKey(
            {"profile", KeyType::String, 0, 0, {}, "", "diffusion profile: deon, burley or file:PATH (a .bn kernel)"},
            &SssParams::profile),
        boundKey({"material", KeyType::Choice, 0, 0, materialNames(), "",
                  "material of the profile (burley: Jensen et al. 2001 media)"},
                 &SssParams::material),
    };
}

std::vector<SssKey> extensionSssKeys() {
    return {
        boundKey({"cbf", KeyType::Boolean, 0, 0, {}, "", "E1: cross-bilateral weights on the auxiliary image"},
                 &SssParams::cbf),
        boundKey({"cbf_lambda", KeyType::Number, 0.0, 1000.0, {}, "", "E1: lambda of exp(-lambda |F_c - F_tap|)"},
                 &SssParams::cbfLambda),
        boundKey({"lab_weight",
                  KeyType::Number,
                  0.0,
                  100.0,
                  {},
                  "1/ΔE",
                  "E2: beta of the CIELAB weight exp(-beta ΔE*ab); 0 = off"},
                 &SssParams::labWeight),
        boundKey({"extension_input",
                  KeyType::Choice,
                  0,
                  0,
                  {"albedo", "lit"},
                  "",
                  "E1/E2 input: the albedo AOV or the lit colour"},
                 &SssParams::extensionInput),
        boundKey({"curvature",
                  KeyType::Choice,
                  0,
                  0,
                  {"off", "increase", "reduce", "reduce-floor"},
                  "",
                  "E3: curvature modulation of the kernel width"},
                 &SssParams::curvature),
        boundKey(
            {"curvature_floor", KeyType::Number, 0.0, 1.0, {}, "", "E3 reduce-floor: width share kept on flat skin"},
            &SssParams::curvatureFloor),
        boundKey({"curvature_measure",
                  KeyType::Choice,
                  0,
                  0,
                  {"normal", "screen"},
                  "",
                  "curvature AOV: 3-D normal curvature or the screen-space measure"},
                 &SssParams::curvatureMeasure),
        boundKey({"curvature_reference_mm",
                  KeyType::Number,
                  0.1,
                  1000.0,
                  {},
                  "mm",
                  "radius at or below which a surface counts as fully curved"},
                 &SssParams::curvatureReferenceMm),
    };
}

std::vector<SssKey>& sharedSssKeys() {
    // Built on first use (the choices call methodNames() and materialNames()).
    static std::vector<SssKey> table = [] {
        std::vector<SssKey> keys = kernelSssKeys();
        std::vector<SssKey> extensions = extensionSssKeys();
        keys.insert(keys.end(), std::make_move_iterator(extensions.begin()), std::make_move_iterator(extensions.end()));
        return keys;
    }();
    return table;
}
} // namespace

const std::vector<SssKey>& sssKeyTable() { return sharedSssKeys(); }

void addMethodChoice(std::string_view name) {
    std::vector<std::string>& choices = sharedSssKeys().front().choices;
    if (std::find(choices.begin(), choices.end(), name) == choices.end()) choices.emplace_back(name);
}

SssKey ownKey(KeyInfo info, nlohmann::json fallback) {
    const std::string name(info.name);
    return {std::move(info),
            [name, fallback](const SssParams& p) { return p.own.contains(name) ? p.own.at(name) : fallback; },
            [name](SssParams& p, const nlohmann::json& value) { p.own[name] = value; }};
}

const std::vector<TransmittanceKey>& transmittanceKeyTable() {
    static const std::vector<TransmittanceKey> table{
        boundKey({"enabled", KeyType::Boolean, 0, 0, {}, "", "light through thin parts (Jimenez et al. 2010)"},
                 &TransmittanceParams::enabled),
        boundKey({"translucency", KeyType::Number, 0.0, 1.0, {}, "", "0 = opaque, 1 = fully translucent"},
                 &TransmittanceParams::translucency),
        boundKey({"curvature",
                  KeyType::Boolean,
                  0,
                  0,
                  {},
                  "",
                  "curvature modulation of the transmittance (the thesis' option)"},
                 &TransmittanceParams::curvature),
        boundKey({"curvature_form",
                  KeyType::Choice,
                  0,
                  0,
                  {"scale", "thesis"},
                  "",
                  "scale: × (1 + c); thesis: profile widened by 1 + 2c"},
                 &TransmittanceParams::curvatureForm),
    };
    return table;
}

namespace {
template <class Key>
const Key* findKey(const std::vector<Key>& table, std::string_view name) {
    const auto found = std::find_if(table.begin(), table.end(), [&](const Key& key) { return key.name == name; });
    return found == table.end() ? nullptr : &*found;
}
} // namespace

const SssKey& sssKey(std::string_view name) {
    if (const SssKey* shared = findKey(sssKeyTable(), name)) return *shared;
    for (const MethodInfo& info : methodTable())
        if (const SssKey* own = findKey(info.ownKeys, name)) return *own;
    SKINLAB_CHECK(false); // every key the reader reads is declared
    std::abort();
}

const TransmittanceKey& transmittanceKey(std::string_view name) {
    const TransmittanceKey* key = findKey(transmittanceKeyTable(), name);
    SKINLAB_CHECK(key != nullptr);
    return *key;
}

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

nlohmann::json sssKeyDefaults(SssMethod method) { return defaultsOf(method).toJson(); }

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

std::string_view placementName(TapPlacement placement) {
    return placement == TapPlacement::Importance ? "importance" : "quadratic";
}

nlohmann::json SssParams::toJson() const {
    nlohmann::json out = nlohmann::json::object();
    for (const SssKey& key : sssKeyTable())
        if (methodUsesKey(method, key.name)) out[std::string(key.name)] = key.get(*this);
    for (const SssKey& key : methodInfo(method).ownKeys) out[std::string(key.name)] = key.get(*this);
    return out;
}

nlohmann::json TransmittanceParams::toJson() const {
    nlohmann::json out = nlohmann::json::object();
    for (const TransmittanceKey& key : transmittanceKeyTable()) out[std::string(key.name)] = key.get(*this);
    return out;
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

double transmittanceScalePerUnit(double translucency, double widthMm, double mmPerUnit) {
    const double demoSssWidth = widthMm / (2.0 * mmPerUnit); // world units
    return 8.25 * (1.0 - translucency) / demoSssWidth;
}

} // namespace skinlab::renderer::sss
