#pragma once
// A biophysical skin model: melanin and haemoglobin levels → spectral diffuse reflectance → linear sRGB albedo and
// the per-channel diffusion profile every SSS method reads (docs/skin-tones.md).
//
// After Donner & Jensen, "A Spectral BSSRDF for Shading Human Skin", EGSR 2006: two layers, an epidermis of
// 0.25 mm holding melanin (volume fraction C_m, eumelanin share β_m) over a dermis holding blood (volume fraction
// C_h, oxygen saturation γ = 0.75), each with the skin baseline absorption in the rest of its volume:
//   σa_epi  = C_m (β_m σa_eu + (1 − β_m) σa_pheo) + (1 − C_m) σa_base
//   σa_derm = C_h (γ σa_oxy + (1 − γ) σa_deoxy) + (1 − C_h) σa_base
// with the published analytic fits (λ in nm, 1/mm): σa_eu = 6.6·10¹⁰ λ^−3.33, σa_pheo = 2.9·10¹⁴ λ^−4.75,
// σa_base = 0.0244 + 8.53 e^{−(λ−154)/66.2}, and the haemoglobin spectra of S. Prahl's compilation (molar
// extinction ε, cm⁻¹/M, 150 g/L haemoglobin in blood, 64 500 g/mol: σa = ln 10 · ε · 150 / 64 500 cm⁻¹). Reduced
// scattering σs'_epi = 14.74 λ^−0.22 + 2.2·10¹¹ λ^−4 (1/mm), σs'_derm = σs'_epi / 2.
//
// Light transport: the epidermis is a finite slab under the multipole model of Donner & Jensen, "Light Diffusion in
// Multi-Layered Translucent Materials", SIGGRAPH 2005 (total reflectance and transmittance in closed form), the
// dermis a semi-infinite dipole (Jensen et al. 2001), both with index-matched boundaries (the surface's Fresnel
// reflection is the renderer's specular term); the two are added at zero spatial frequency,
// R = R₁ + T₁² R₂ / (1 − R₁ R₂) (Donner & Jensen 2005, Eq. 11–12 at frequency 0). The spectrum is integrated with
// the CIE 1931 2° colour-matching functions under CIE D65 (10 nm, 400–700 nm) into linear sRGB, white-balanced so
// that a perfect white reflector maps to (1, 1, 1).
//
// Profile: per channel Burley's shape d = ℓd / s(A) (Christensen & Burley 2015) from the dermis' diffuse mean free
// path ℓd = 1/σtr (averaged over the channel's spectral response, weighted by the reflected light) and the channel
// albedo A; d'Eon's six Gaussian variances with weights refitted (non-negative least squares) to that Burley
// profile give the sum-of-Gaussians form the Gaussian methods, transmittance and reference read.
//
// Re-toning (after Jimenez et al., "A Practical Appearance Model for Dynamic Facial Color", SIGGRAPH Asia 2010): a
// table (C_m, C_h) → albedo, inverted per colour by nearest match and refined; a texel's melanin is scaled to the
// new tone and the texel multiplied by albedo(C_m', C_h) / albedo(C_m, C_h), so what the model does not explain
// (pores, stubble, shading baked into the map) is kept.
#include "renderer/sss/gaussian_sum_profile.h"
#include "renderer/sss/pscbf_kernel.h"

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::renderer::sss {

// Wavelength samples of the model: 400, 410, …, 700 nm.
constexpr int kSkinSpectralSamples = 31;
constexpr double kSkinFirstWavelengthNm = 400.0;
constexpr double kSkinWavelengthStepNm = 10.0;
using SkinSpectrum = std::array<double, kSkinSpectralSamples>;
double skinWavelengthNm(int sample);

// Ranges accepted for the model's parameters (inclusive). Melanin: 0.1 % (albinism-like) to 50 %, the upper end of
// Jacques' darkly pigmented range (18–43 % melanosome volume fraction) with margin; haemoglobin: 0.1 % to 10 % of
// the dermis' volume (this project's range, pale to flushed skin); blend: a share in [0, 1].
constexpr double kMelaninMin = 0.001;
constexpr double kMelaninMax = 0.5;
constexpr double kHaemoglobinMin = 0.001;
constexpr double kHaemoglobinMax = 0.1;

struct SkinTone {
    double melanin = 0.02;     // C_m, epidermal melanin volume fraction
    double melaninBlend = 0.7; // β_m, eumelanin share of the melanin (the rest pheomelanin)
    double haemoglobin = 0.02; // C_h, dermal blood volume fraction
    std::string level;         // named level ("I" … "VI") it came from; empty when given by value
};

// Named levels spanning Fitzpatrick I–VI: melanin fractions placed in S. Jacques' published melanosome volume
// fractions of the epidermis ("Skin Optics", Oregon Medical Laser Center News, 1998): light-skinned adults 1.3–6.3 %
// (I, II), moderately pigmented 11–16 % (III, IV), darkly pigmented 18–43 % (V, VI). The haemoglobin and blend of
// every level are the defaults of SkinTone.
struct SkinToneLevel {
    std::string_view name;
    double melanin;
};
const std::vector<SkinToneLevel>& skinToneLevels();
// The level's tone; nullopt for an unknown name.
std::optional<SkinTone> skinToneForLevel(std::string_view name);

// --- spectral coefficients (1/mm) -----------------------------------------------------------------------------
double eumelaninAbsorption(double wavelengthNm);
double pheomelaninAbsorption(double wavelengthNm);
double baselineSkinAbsorption(double wavelengthNm);
// Haemoglobin of whole blood (150 g/L) at one of the model's samples, from Prahl's molar extinction.
double oxyHaemoglobinAbsorption(int sample);
double deoxyHaemoglobinAbsorption(int sample);
// Prahl's molar extinction (cm⁻¹/M) at one of the model's samples.
double oxyHaemoglobinExtinction(int sample);
double deoxyHaemoglobinExtinction(int sample);
double epidermisReducedScattering(double wavelengthNm);

struct LayerCoefficients {
    double absorption;        // σa, 1/mm
    double reducedScattering; // σs', 1/mm
};
LayerCoefficients epidermisCoefficients(const SkinTone& tone, int sample);
LayerCoefficients dermisCoefficients(const SkinTone& tone, int sample);

// --- transport -------------------------------------------------------------------------------------------------
constexpr double kEpidermisThicknessMm = 0.25;
struct SlabTotals {
    double reflectance;
    double transmittance;
};
// Multipole totals of a slab (Donner & Jensen 2005) of thickness d (mm); `poles` dipole pairs on each side.
SlabTotals multipoleSlabTotals(const LayerCoefficients& layer, double thicknessMm, double eta, int poles = 10);
// Spectral diffuse reflectance of the two-layer skin.
SkinSpectrum skinReflectanceSpectrum(const SkinTone& tone);

// --- colour ----------------------------------------------------------------------------------------------------
// Linear sRGB of a reflectance spectrum under D65, white-balanced (a flat spectrum of 1 → (1, 1, 1)).
std::array<double, 3> reflectanceToLinearSrgb(const SkinSpectrum& reflectance);
// Relative luminance (Rec. 709 weights) of a linear sRGB colour.
double linearLuminance(const std::array<double, 3>& rgb);

// Everything the renderer takes from a tone.
struct SkinOptics {
    SkinTone tone;
    std::array<double, 3> albedo{};         // linear sRGB diffuse albedo
    double luminance = 0.0;                 // of the albedo
    std::array<double, 3> meanFreePathMm{}; // ℓd per channel (dermis)
    std::array<double, 3> burleyShapeMm{};  // d per channel
    std::vector<GaussianLobe> lobes;        // d'Eon's variances, weights refitted to the Burley profile
};
// Throws InputError naming `where` and the key of a value out of range (skin.melanin, skin.haemoglobin,
// skin.melanin_blend).
SkinOptics skinOptics(const SkinTone& tone, std::string_view where = "");
// Checks the tone's ranges (the same errors as skinOptics).
void validateSkinTone(const SkinTone& tone, std::string_view where = "");

// Non-negative weights on d'Eon's six variances fitting a Burley profile of shape d (mm) per channel, each channel
// normalised to sum 1 (least squares on the radial CDF, the energy within r, over 0…12 d, with Burley's second
// moment 7 d² as one more, heavily weighted equation).
std::vector<GaussianLobe> fitDeonLobesToBurley(const std::array<double, 3>& shapeMm);

// --- what the methods read ----------------------------------------------------------------------------------------
struct SssParams;
// Writes the tone's refitted weights and Burley shape into the [sss] record (SssParams::skinLobeWeights, skinShapeMm).
void applySkinTone(const SkinOptics& optics, SssParams& params);
// The six lobes of material "skin": the tone's refit when the scene has [skin], else d'Eon's (deonSkinLobes()).
std::vector<GaussianLobe> skinProfileLobes(const SssParams& params);
// Burley's d (mm) for a material: the tone's for "skin" when the scene has [skin], else burleyShapeMm(material).
std::array<double, 3> skinBurleyShapeMm(const SssParams& params);
// Transmittance T(s) = Σ w_i exp(−s²/v_i) with the lobes of skinProfileLobes (T(0) = 1 per channel).
std::array<double, 3> skinTransmittance(const SssParams& params, double thicknessMm);
// Per-channel ratio of the tone's Burley d to d'Eon's profile as Burley's d (burleyShapeMm("skin"), the same second
// moment); (1, 1, 1) without [skin]. The Blender radii (fitted to d'Eon's profile) scale by it.
std::array<double, 3> skinWidthRatio(const SssParams& params);

// pscbf's profile (Mikkelsen 2010, Table 1, read as `reading`: sss.pscbf_sigma) with each channel's Gaussian widened
// by skinWidthRatio (variance × ratio²) and the filter disc r_max by the largest ratio; Mikkelsen's own without [skin].
PscbfProfile skinPscbfProfile(const SssParams& params, PscbfSigma reading);
// The artistic kernel's per-channel falloff `falloff` (sss.artistic_falloff, a width multiplier of its profile) times
// skinWidthRatio; `falloff` as it is without [skin].
std::array<double, 3> skinArtisticFalloff(const SssParams& params, std::array<double, 3> falloff);

// --- inversion and re-toning (Jimenez et al. 2010) ------------------------------------------------------------------
struct ToneEstimate {
    double melanin;
    double haemoglobin;
    double error; // relative RGB distance between the colour and the model's albedo at the estimate
};
class SkinToneTable {
public:
    // Melanin and haemoglobin on logarithmic grids spanning the model's ranges; blend fixed.
    explicit SkinToneTable(double melaninBlend = SkinTone{}.melaninBlend, int melaninSteps = 48,
                           int haemoglobinSteps = 24);
    std::array<double, 3> albedo(double melanin, double haemoglobin) const; // bilinear in the log grid
    // Nearest table entry in log RGB, refined on the log grid by bilinear interpolation.
    ToneEstimate invert(const std::array<double, 3>& linearRgb) const;

private:
    double blend_;
    int melaninSteps_, haemoglobinSteps_;
    std::vector<std::array<double, 3>> table_;    // melanin-major
    std::vector<std::array<double, 3>> logTable_; // its logarithms (the nearest-entry search)
};

// Relative error above which a colour counts as not skin (not invertible): 0.35 (35 % of the colour's magnitude).
// Scanned skin is more saturated than the model reaches (the scanned head's typical texel is 5–20 % away); what the
// model does not explain is kept by the re-toning's ratio.
constexpr double kToneInversionTolerance = 0.35;

// Re-tones a linear RGBA float image in place (4 floats per texel): per texel, estimate (C_m, C_h); scale C_m by
// tone.melanin / (the median C_m of the map's invertible texels), so the map's typical skin lands on the tone and
// freckles keep their melanin ratio; multiply the texel by albedo(C_m', C_h) / albedo(C_m, C_h). Texels that are not
// skin (error above the tolerance, or not a skin hue: red < 1.1 × green or green < blue; eyes, whites) are kept. Returns the share of texels re-toned; throws InputError naming
// `where` and `key` when fewer than half of the texels with any colour can be inverted (the map is not skin).
double retoneAlbedo(std::vector<float>& rgba, const SkinTone& tone, std::string_view where, std::string_view key);

} // namespace skinlab::renderer::sss
