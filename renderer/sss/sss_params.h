#pragma once
// Typed parameters of the scene spec tables [sss] and [transmittance] (contracts.md §4), their strict reader and
// their JSON form (the "resolved" record stored in EXR metadata and manifests). Every key, unit and default is
// documented in docs/methods.md; the readers throw InputError naming file and key for bad values.
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace skinlab {
class SpecReader;
}

namespace skinlab::renderer::sss {

enum class SssMethod {
    None,         // diffuse copied through
    GaussianSum,  // Jimenez & Gutierrez 2010: six incremental Gaussian blurs, 12 passes
    Separable,    // Jimenez et al. 2015: two passes with the marginal of a physical profile
    Artistic,     // Jimenez's demo kernel (width, strength, falloff), two passes
    Pscbf,        // Mikkelsen 2010: pseudo-separable cross-bilateral filter, spike + one Gaussian per channel
    Reference,    // object-space SSS on the tessellated surface (the ground truth of the metrics)
    Pathtraced,   // Blender Cycles' random walk (renderer/pathtraced; the screen-space stage copies through)
};

// How a continuous 1-D kernel is discretised into taps (docs/methods.md, "Discretisation").
enum class TapPlacement {
    Quadratic,   // offsets R·t²/T² (dense near the centre), trapezoid weights (Jimenez's demo)
    Importance,  // equal-probability cells of the widest channel (Mikkelsen 2010), other channels re-weighted
};

std::string_view methodName(SssMethod method);
std::string_view placementName(TapPlacement placement);

struct SssParams {
    SssMethod method = SssMethod::None;
    // Taps per 1-D pass (odd, 3…101). gaussian-sum uses it for each of its 12 passes.
    int samples = 21;
    // Physical width of the blur in millimetres on the surface: a kernel offset of o profile-millimetres is placed
    // at o · width_mm / 3 mm on the surface. 3 is the profile's own physical scale (d'Eon, Burley and the tabulated
    // kernels are measured in mm). Same convention as the demo's sssWidth, which spans the kernel range ±3:
    // width_mm = sssWidth × mm_per_unit.
    double widthMm = 3.0;
    TapPlacement placement = TapPlacement::Quadratic;
    // Follow-surface correction (Jimenez): per tap s = saturate(k · |Δz| · mm_per_unit), colour = lerp(tap, centre,
    // s), with Δz the linear-depth difference centre−tap in world units, so k is in 1/mm: a depth step of 1/k mm
    // stops all light crossing it.
    bool followSurface = true;
    double followSurfaceK = 0.5;  // 1/mm
    // Profile of the separable method: "deon" (six Gaussians), "burley" (normalized diffusion) or "file:PATH"
    // (a tabulated .bn kernel, Jimenez et al. 2015 supplementary format).
    std::string profile = "deon";
    // Material of the profile: "skin" (d'Eon's table; for burley, d matched to its second moment) or one of the
    // measured media of Jensen et al. 2001 (skin1, skin2, marble, apple, ketchup, wholemilk; burley only).
    std::string material = "skin";
    // Artistic kernel (demo baseline): per-channel strength and falloff, each in [0, 1].
    std::array<double, 3> artisticStrength{0.48, 0.41, 0.28};
    std::array<double, 3> artisticFalloff{1.0, 0.37, 0.3};

    // --- artifact extensions (thesis §3.3; docs/extensions.md), each a switch on every screen-space method ---
    // E1: cross-bilateral weights exp(−λ |F_c − F_tap|) on Mikkelsen's auxiliary image (AOV aux.Y), combined
    // with the follow-surface correction, renormalised, falling back to the unblurred colour where they vanish.
    bool cbf = false;
    double cbfLambda = 10.0;  // λ, dimensionless (thesis code: 10)
    // E2: CIELAB weight exp(−β ΔE*ab) on the albedos of centre and tap; β in 1/ΔE, 0 = off.
    double labWeight = 0.0;
    // E3: curvature modulation of the kernel width from the curvature AOV (curvature.Y).
    std::string curvature = "off";  // off | increase | reduce | reduce-floor
    double curvatureFloor = 0.5;    // reduce-floor: width share kept on flat skin, [0, 1]
    // reference method: longest skin edge (mm) after tessellation; irradiance is sampled at the vertices.
    double referenceEdgeMm = 1.0;

    nlohmann::json toJson() const;
};

struct TransmittanceParams {
    bool enabled = false;
    // 0 = opaque, 1 = fully translucent: thickness is scaled by 8.25 (1 − translucency) / width (Jimenez et al.
    // 2010) before T(s) = Σ w_i exp(−s²/v_i) with d'Eon's weights (T(0) = 1 per channel).
    double translucency = 0.5;
    // transmittance × (1 + c) with c the normalised curvature: the thesis's option, which produces bright
    // artefacts at nostrils and other tight, thin features (documented as such).
    bool curvature = false;

    nlohmann::json toJson() const;
};

// Reads the [sss] table of a scene spec (through the scene's reader: `scene.table("sss")` is read and finished
// here). Defaults for absent keys; InputError naming file and key for bad ones.
SssParams readSssParams(const SpecReader& scene);
TransmittanceParams readTransmittanceParams(const SpecReader& scene);

// From the JSON form written by toJson() (e.g. SssStageSettings::sss); same validation as the TOML reader, errors
// name `source` as the file.
SssParams sssParamsFromJson(const nlohmann::json& sss, std::string_view source = "sss");
TransmittanceParams transmittanceParamsFromJson(const nlohmann::json& transmittance,
                                                std::string_view source = "transmittance");

} // namespace skinlab::renderer::sss
