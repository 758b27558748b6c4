#pragma once
// Typed parameters of the scene spec tables [sss] and [transmittance], their strict reader and
// their JSON form (the "resolved" record stored in EXR metadata and manifests). Every key, unit and default is
// documented in docs/methods.md; the readers throw InputError naming file and key for bad values.
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace skinlab {
class SpecReader;
}

namespace skinlab::renderer::sss {

// A method's identifier: its row's position in the method table, assigned when the method is registered
// (method_table.cpp). There are no enumerators: code finds a method by name (findMethod, methodId) and asks its row
// and its class (method.h) what it needs: adding a method adds its registration line and nothing else to any list.
// SssMethod{} is "none".
enum class SssMethod : int {};

// How the renderer runs a method: each value is one code path of the renderer, shared by every method that names it,
// so a method whose kernel is a set of 1-D taps (TapPasses) needs no renderer code of its own.
enum class Execution {
    CopyThrough, // the diffuse buffer copied through (none)
    TapPasses,   // the method's Kernel through the shared 1-D blur passes (renderer/gl/sss_kernel_method.h) and
                 // their CPU mirror (cpu_blur.h): gaussian-sum, separable, artistic
    Pscbf,       // Mikkelsen's own two passes (renderer/gl/pscbf_method.h) on the method's one broad stage
    ObjectSpace, // on the tessellated surface (renderer/gl/reference_method.h)
    Cycles,      // Blender Cycles (renderer/pathtraced); the screen-space stage copies through
    Eevee,       // Blender EEVEE (renderer/pathtraced), likewise
};
std::string_view executionName(Execution execution); // "copy-through", "tap-passes", ...

// How a continuous 1-D kernel is discretised into taps (docs/methods.md, "Discretisation").
enum class TapPlacement {
    Quadratic,  // offsets R·t²/T² (dense near the centre), trapezoid weights (Jimenez's demo)
    Importance, // equal-probability cells of the widest channel (Mikkelsen 2010), other channels re-weighted
};

std::string_view methodName(SssMethod method);
std::string_view placementName(TapPlacement placement);

// The declaration of one key of [sss] or [transmittance]: name, type, range or choices, unit, one-line doc. The
// reader takes type, range and choices from here, `skinlab methods --json`, `skinlab tune` and the docs' tables show
// them, so none of them disagree. The default is the value of a default-constructed SssParams / TransmittanceParams
// (with the method row's overrides, MethodInfo::defaults).
enum class KeyType { Boolean, Integer, Number, Choice, Vec3, String };
std::string_view keyTypeName(KeyType type); // "boolean", "integer", "number", "choice", "vec3", "string"

struct KeyInfo {
    std::string_view name; // key within its table ("width_mm")
    KeyType type;
    double min = 0.0; // Integer, Number, Vec3 (each element): the accepted range, inclusive
    double max = 0.0;
    std::vector<std::string> choices; // Choice: the accepted values
    std::string_view unit;            // "mm", "1/mm", "" (dimensionless)
    std::string_view doc;             // one line
};

// Profile millimetres → surface millimetres. Every profile is tabulated at a width of 3 mm; sss.width_mm is where
// its kernel edge (±3 profile-mm) lands on the surface (the demo's kernel edge lies at 2 · sssWidth world units,
// widthMmFromDemoSssWidth in width_conventions.h), so a profile distance o lies at o · profileScale(width_mm) on the surface. The
// screen-space kernels, the object-space reference, pscbf's depth sigmas, the kernel views and the Blender radii
// all scale by it.
constexpr double kProfileWidthMm = 3.0;
constexpr double profileScale(double widthMm) { return widthMm / kProfileWidthMm; }

// The typed values of the [sss] table. Which fields the chosen method reads is given by its row of the method
// table (methodTable()): the reader accepts only those keys, and toJson() writes only those.
struct SssParams {
    SssMethod method{}; // "none"
    // Taps per 1-D pass (odd, 3…101). gaussian-sum uses it for each of its 12 passes. Default 21; for pscbf 13,
    // the paper's count (kDefaultSamples, kDefaultPscbfSamples; the reader picks by method when the key is absent).
    static constexpr int kDefaultSamples = 21;
    static constexpr int kDefaultPscbfSamples = 13;
    int samples = kDefaultSamples;
    // Physical width of the blur in millimetres on the surface: a kernel offset of o profile-millimetres is placed
    // at o · width_mm / 3 mm on the surface. 3 is the profile's own physical scale (d'Eon, Burley and the tabulated
    // kernels are measured in mm). Jimenez's demo places its kernel edge (±3) at 2 · sssWidth world units, so
    // width_mm = 2 × sssWidth × mm_per_unit (widthMmFromDemoSssWidth, width_conventions.h).
    double widthMm = 3.0;
    TapPlacement placement = TapPlacement::Quadratic;
    // Follow-surface correction (Jimenez): per tap s = saturate(k · |Δz| · mm_per_unit), colour = lerp(tap, centre,
    // s), with Δz the linear-depth difference centre−tap in world units, so k is in 1/mm: a depth step of 1/k mm
    // stops all light crossing it.
    bool followSurface = true;
    double followSurfaceK = 0.5; // 1/mm
    // Profile of the separable and reference methods: "deon" (six Gaussians), "burley" (normalized diffusion) or
    // "file:PATH" (a tabulated .bn kernel, Jimenez et al. 2015 supplementary format).
    std::string profile = "deon";
    // Material of the profile: "skin" (d'Eon's table; for burley, d matched to its second moment) or one of the
    // measured media of Jensen et al. 2001 (skin1, skin2, marble, apple, ketchup, wholemilk; burley only).
    std::string material = "skin";
    // --- artifact extensions (thesis §3.3; docs/extensions.md), each a switch on every screen-space method ---
    // E1: cross-bilateral weights exp(−λ |F_c − F_tap|) on Mikkelsen's auxiliary image (AOV aux.Y), combined
    // with the follow-surface correction, renormalised, falling back to the unblurred colour where they vanish.
    bool cbf = false;
    double cbfLambda = 10.0; // λ, dimensionless (thesis code: 10)
    // E2: CIELAB weight exp(−β ΔE*ab) on the albedos of centre and tap; β in 1/ΔE, 0 = off.
    double labWeight = 0.0;
    // E1/E2 input: "albedo" (the albedo AOV; every method in the thesis code's later revision) or "lit" (the colour
    // each pass blurs; the thesis text, Eq. 3.13, and every method of its code as submitted).
    std::string extensionInput = "albedo";
    // E3: curvature modulation of the kernel width from the curvature AOV (curvature.Y).
    std::string curvature = "off"; // off | increase | reduce | reduce-floor
    double curvatureFloor = 0.5;   // reduce-floor: width share kept on flat skin, [0, 1]
    // How the curvature AOV is measured: "normal" (3-D normal curvature, ≈ 1/radius) or "screen" (the thesis'
    // screen-space measure from the per-pixel change of the view normal; grows at silhouettes).
    std::string curvatureMeasure = "normal";
    // Radius (mm) at or below which a surface counts as fully curved: c = saturate(κ · curvature_reference_mm).
    // The thesis gives no such scale; 20 mm is the radius of the tightest broad facial features (nose tip, ear
    // rims, lips), so those reach c = 1 while cheeks and forehead (60–100 mm) stay at c = 0.2–0.33.
    double curvatureReferenceMm = 20.0;
    // Values of the keys a method declares in its own file (MethodInfo::ownKeys), by key; absent: the declared
    // default. The method reads them typed through its own parameter struct (ownParams below, e.g. artisticParams in
    // renderer/sss/methods/artistic.h).
    nlohmann::json own = nlohmann::json::object();
    // The scene's skin tone ([skin], renderer/sss/skin_model.h), set by the scene reader, not an [sss] key: the
    // six-Gaussian weights refitted to the tone (by lobe, d'Eon's variances) and its Burley shape d (mm per channel),
    // which every profile of material "skin" reads instead of d'Eon's light-skin table (skinProfileLobes,
    // skinBurleyShapeMm in skin_model.h). Empty: d'Eon's.
    std::optional<std::array<std::array<double, 3>, 6>> skinLobeWeights;
    std::optional<std::array<double, 3>> skinShapeMm;

    // The resolved record: the method and the keys it reads (its row of the method table), nothing else.
    nlohmann::json toJson() const;
    bool operator==(const SssParams&) const = default;
};

struct TransmittanceParams {
    bool enabled = false;
    // 0 = opaque, 1 = fully translucent: thickness is scaled by 8.25 (1 − translucency) / sssWidth (Jimenez et al.
    // 2010; transmittanceScalePerUnit below) before T(s) = Σ w_i exp(−s²/v_i) with d'Eon's weights (T(0) = 1 per channel).
    double translucency = 0.5;
    // Curvature modulation, the thesis's option, which produces bright artefacts at nostrils and other tight, thin
    // features (documented as such). curvatureForm "scale": transmittance × (1 + c), c the normalised curvature
    // capped at 1; "thesis": the profile widened inside the exponent as the thesis' main-pass shader does,
    // s / (1 + 2c) (its sssWidth × (1 + 2κ)), c uncapped, from the thesis' screen-space curvature.
    bool curvature = false;
    std::string curvatureForm = "scale";

    nlohmann::json toJson() const;
    bool operator==(const TransmittanceParams&) const = default;
};

// A key declaration bound to where its value lives: the reader, toJson() and the defaults go through get/set, so a
// key is named once, in its table.
template <class Params>
struct BoundKey : KeyInfo {
    std::function<nlohmann::json(const Params&)> get;
    std::function<void(Params&, const nlohmann::json&)> set;
};
using SssKey = BoundKey<SssParams>;
using TransmittanceKey = BoundKey<TransmittanceParams>;

// A key bound to a field of Params (enumerations through their JSON names).
template <class Params, class T>
BoundKey<Params> boundKey(KeyInfo info, T Params::*field) {
    return {std::move(info), [field](const Params& p) { return nlohmann::json(p.*field); },
            [field](Params& p, const nlohmann::json& value) { p.*field = value.get<T>(); }};
}
// A key a method declares in its own row: its value lives in SssParams::own, `fallback` when absent.
SssKey ownKey(KeyInfo info, nlohmann::json fallback);

// A method's own keys bound to the fields of its own parameter struct `Own` (ArtisticParams, ReferenceParams, ...;
// declared in the method's file with boundKey, the struct's initialisers being the defaults): the row's declarations
// (MethodInfo::ownKeys) and the typed read of a parameter set, so the method and its executor read its keys as typed
// fields, as the shared keys are read from SssParams.
template <class Own>
std::vector<SssKey> ownKeys(const std::vector<BoundKey<Own>>& keys) {
    std::vector<SssKey> declared;
    for (const BoundKey<Own>& key : keys) declared.push_back(ownKey(key, key.get(Own{})));
    return declared;
}
template <class Own>
Own ownParams(const SssParams& params, const std::vector<BoundKey<Own>>& keys) {
    Own own;
    for (const BoundKey<Own>& key : keys) {
        const auto value = params.own.find(std::string(key.name));
        if (value != params.own.end()) key.set(own, *value);
    }
    return own;
}

class Method;

// The method table: one row per SSS method, declared by the method's own file (renderer/sss/methods/, method.h); the
// single list the CLI (`skinlab methods`), the scene reader, the stimulus specs, `skinlab kernel`, `skinlab tune`,
// the renderer, the benchmarks and the tests that cover "every method" iterate (docs/methods.md, "Adding a method").
// `keys` are the shared [sss] keys (sssKeyTable()) the method reads besides the keys every method reads
// (kCommonSssKeys), `ownKeys` the keys only it reads, declared in its file; any other [sss] key given with the method
// is an error naming the key and the method.
struct MethodInfo {
    SssMethod method;      // assigned from the row's position
    std::string_view name; // sss.method value
    Execution execution;   // how the renderer runs it
    // Whether live tuning renders it as a slider moves (Renderer::renderDisplay, in milliseconds to a second);
    // otherwise `skinlab tune` runs it as a background render.
    bool interactive;
    std::string_view summary;
    std::vector<std::string_view> keys;
    std::vector<SssKey> ownKeys;
    // Defaults that differ for this method (pscbf: samples = 13, the paper's count).
    std::vector<std::pair<std::string_view, nlohmann::json>> defaults;
    // Prepares the method from typed parameters: its kernel (taps, or the source of a method without taps) and its
    // support radius (renderer/sss/method.h).
    std::shared_ptr<const Method> model;

    // Runs in the screen-space SSS stage on the frame's buffers (a 1-D tap kernel: TapPasses or Pscbf).
    bool screenSpace() const { return execution == Execution::TapPasses || execution == Execution::Pscbf; }
    // Its kernel runs through the shared 1-D blur passes (and the CPU mirror, renderer/sss/cpu_blur.h).
    bool blurPasses() const { return execution == Execution::TapPasses; }
};

// [sss] keys every method reads: the main pass's transmittance scale (width_mm), the curvature AOV's measure and
// the curvature scale shared by the extensions and the transmittance.
inline constexpr std::array<std::string_view, 4> kCommonSssKeys{"method", "width_mm", "curvature_measure",
                                                                "curvature_reference_mm"};

// Every method, in table order (the built-ins in the order of their registration lines, then the ones registered
// outside the renderer library).
const std::vector<MethodInfo>& methodTable();
const MethodInfo& methodInfo(SssMethod method);
// nullptr when `name` names no method.
const MethodInfo* findMethod(std::string_view name);
// The identifier of the method `name` (a check fails for a name that is no method: for code and tests that name a
// method they know; a spec's value goes through the reader).
SssMethod methodId(std::string_view name);
// Adds a method's row after the built-in ones and returns its identifier: what SKINLAB_REGISTER_METHOD does for a
// method compiled outside the renderer library (method.h). Throws RuntimeError for a name already taken, a row
// without a class or a key another row declares.
SssMethod registerMethod(MethodInfo row);
// Every method name, in table order (for choices and help texts).
std::vector<std::string> methodNames();
// The screen-space methods' names (those the SSS stage runs as tap kernels), in table order.
std::vector<std::string> screenSpaceMethodNames();
// The methods whose kernels run through the shared blur passes (and the CPU mirror, renderer/sss/cpu_blur.h).
std::vector<std::string> blurPassMethodNames();
// Every [sss] key of any method.
std::vector<std::string_view> allSssKeys();
// The [sss] keys `method` reads besides "method": the common ones, its shared ones, its own.
std::vector<std::string_view> methodKeys(SssMethod method);
// Whether `method` reads [sss] key `key` (a common key or one of its own).
bool methodUsesKey(SssMethod method, std::string_view key);
// "not a parameter of method 'separable' (its keys: ...)": the message of the error for a key `method` does not read.
std::string notAParameterMessage(SssMethod method);

// Every shared [sss] key, in reading order; every [transmittance] key.
const std::vector<SssKey>& sssKeyTable();
const std::vector<TransmittanceKey>& transmittanceKeyTable();
// The declaration of an [sss] key (shared, or a row's own) / a [transmittance] key (a check fails for an undeclared
// name).
const SssKey& sssKey(std::string_view name);
const TransmittanceKey& transmittanceKey(std::string_view name);
// The default of every key `method` reads (the reader's defaults: pscbf's samples is 13, the others' 21).
nlohmann::json sssKeyDefaults(SssMethod method);
nlohmann::json transmittanceKeyDefaults();
// A declaration as JSON: {"name", "type", "min", "max", "choices", "unit", "doc"} (range and choices where they apply).
nlohmann::json keyInfoJson(const KeyInfo& key);

NLOHMANN_JSON_SERIALIZE_ENUM(TapPlacement,
                             {{TapPlacement::Quadratic, "quadratic"}, {TapPlacement::Importance, "importance"}})
// A method as its name (sss.method); reading an unknown name throws InputError.
void to_json(nlohmann::json& out, SssMethod method);
void from_json(const nlohmann::json& in, SssMethod& method);

// Transmittance thickness scale, per world unit of thickness: the demo's 8.25 (1 − translucency) / sssWidth with
// sssWidth = width_mm / (2 · mm_per_unit), i.e. mm_per_unit · 16.5 (1 − translucency) / width_mm. The scaled
// thickness s goes into T(s) = Σ w_i exp(−s²/v_i) (v_i in mm²).
double transmittanceScalePerUnit(double translucency, double widthMm, double mmPerUnit);

// Reads the [sss] table of a scene spec (through the scene's reader: `scene.table("sss")` is read and finished
// here). Defaults for absent keys; InputError naming file and key for bad ones, and for a key the chosen method
// does not read ("sss.artistic_falloff: is not a parameter of method 'separable' (its keys: ...)").
SssParams readSssParams(const SpecReader& scene);
TransmittanceParams readTransmittanceParams(const SpecReader& scene);

// From the JSON form written by toJson() (e.g. SssStageSettings::sss); same validation as the TOML reader, errors
// name `source` as the file.
SssParams sssParamsFromJson(const nlohmann::json& sss, std::string_view source = "sss");
TransmittanceParams transmittanceParamsFromJson(const nlohmann::json& transmittance,
                                                std::string_view source = "transmittance");

} // namespace skinlab::renderer::sss
