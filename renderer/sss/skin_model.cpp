#include "renderer/sss/skin_model.h"

#include "common/check.h"
#include "common/error.h"
#include "renderer/sss/burley_profile.h"
#include "renderer/sss/materials.h"
#include "renderer/sss/sss_params.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <unordered_map>

namespace skinlab::renderer::sss {

namespace {

// CIE 1931 2° standard observer, 400–700 nm every 10 nm (CIE 015:2004, Table T.4).
constexpr std::array<std::array<double, 3>, kSkinSpectralSamples> kCie1931{{
    {0.014310, 0.000396, 0.067850}, {0.043510, 0.001210, 0.207400}, {0.134380, 0.004000, 0.645600},
    {0.283900, 0.011600, 1.385600}, {0.348280, 0.023000, 1.747060}, {0.336200, 0.038000, 1.772110},
    {0.290800, 0.060000, 1.669200}, {0.195360, 0.090980, 1.287640}, {0.095640, 0.139020, 0.812950},
    {0.032010, 0.208020, 0.465180}, {0.004900, 0.323000, 0.272000}, {0.009300, 0.503000, 0.158200},
    {0.063270, 0.710000, 0.078250}, {0.165500, 0.862000, 0.042160}, {0.290400, 0.954000, 0.020300},
    {0.433450, 0.994950, 0.008750}, {0.594500, 0.995000, 0.003900}, {0.762100, 0.952000, 0.002100},
    {0.916300, 0.870000, 0.001650}, {1.026300, 0.757000, 0.001100}, {1.062200, 0.631000, 0.000800},
    {1.002600, 0.503000, 0.000340}, {0.854450, 0.381000, 0.000190}, {0.642400, 0.265000, 0.000050},
    {0.447900, 0.175000, 0.000020}, {0.283500, 0.107000, 0.000000}, {0.164900, 0.061000, 0.000000},
    {0.087400, 0.032000, 0.000000}, {0.046770, 0.017000, 0.000000}, {0.022700, 0.008210, 0.000000},
    {0.011359, 0.004102, 0.000000},
}};

// CIE standard illuminant D65, relative spectral power, 400–700 nm every 10 nm (CIE 015:2004, Table T.1).
constexpr SkinSpectrum kD65{82.7549, 91.4860, 93.4318, 86.6823, 104.865, 117.008, 117.812, 114.861,
                            115.923, 108.811, 109.354, 107.802, 104.790, 107.689, 104.405, 104.046,
                            100.000, 96.3342, 95.7880, 88.6856, 90.0062, 89.5991, 87.6987, 83.2886,
                            83.6992, 80.0268, 80.2146, 82.2778, 78.2842, 69.7213, 71.6091};

// Molar extinction of oxy- and deoxy-haemoglobin (cm⁻¹/M), 400–700 nm every 10 nm: S. Prahl, "Optical Absorption
// of Hemoglobin", Oregon Medical Laser Center, 1999 (compiled from W. B. Gratzer and N. Kollias),
// https://omlc.org/spectra/hemoglobin/summary.html.
constexpr SkinSpectrum kOxyExtinction{266232,  466840,  480360,  246072,  102580,  62816,   44480, 33209.2,
                                      26629.2, 23684.4, 20932.8, 20035.2, 24202.4, 39956.8, 53236, 43016,
                                      32613.2, 44496,   50104,   14400.8, 3200,    1506,    942,   610,
                                      442,     368,     319.6,   294,     277.6,   276,     290};
constexpr SkinSpectrum kDeoxyExtinction{223296, 303956,  407560,  528600,  413280,  103292,  23388.8, 16156.4,
                                        14550,  16684,   20862,   25773.6, 31589.6, 39036.4, 46592,   53412,
                                        53788,  45072,   37020,   28324.4, 14677.2, 9443.6,  6509.6,  5148.8,
                                        4345.2, 3750.12, 3226.56, 2795.12, 2407.92, 2051.96, 1794.28};

// XYZ → linear sRGB (IEC 61966-2-1).
constexpr std::array<std::array<double, 3>, 3> kXyzToSrgb{{
    {3.2406, -1.5372, -0.4986},
    {-0.9689, 1.8758, 0.0415},
    {0.0557, -0.2040, 1.0570},
}};

constexpr double kOxygenSaturation = 0.75;         // γ, Donner & Jensen 2006
constexpr double kHaemoglobinInBloodGPerL = 150.0; // Prahl 1999
constexpr double kHaemoglobinMolarMass = 64500.0;  // g/mol, Prahl 1999

std::array<double, 3> toRgbUnbalanced(const SkinSpectrum& reflectance) {
    std::array<double, 3> xyz{};
    for (int i = 0; i < kSkinSpectralSamples; ++i)
        for (int k = 0; k < 3; ++k) xyz[k] += reflectance[i] * kD65[i] * kCie1931[i][k];
    std::array<double, 3> rgb{};
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) rgb[c] += kXyzToSrgb[c][k] * xyz[k];
    return rgb;
}

const std::array<double, 3>& whiteRgb() {
    static const std::array<double, 3> white = [] {
        SkinSpectrum ones;
        ones.fill(1.0);
        return toRgbUnbalanced(ones);
    }();
    return white;
}

// Each channel's spectral response: the channel's row of the XYZ → sRGB matrix applied to the CMFs under D65,
// negative lobes clipped (weights for averaging a per-wavelength quantity into a channel).
const std::array<SkinSpectrum, 3>& channelResponses() {
    static const std::array<SkinSpectrum, 3> responses = [] {
        std::array<SkinSpectrum, 3> r{};
        for (int i = 0; i < kSkinSpectralSamples; ++i)
            for (int c = 0; c < 3; ++c) {
                double v = 0.0;
                for (int k = 0; k < 3; ++k) v += kXyzToSrgb[c][k] * kCie1931[i][k];
                r[c][i] = std::max(0.0, v * kD65[i]);
            }
        return r;
    }();
    return responses;
}

double diffuseFresnelReflectance(double eta) { return -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta; }

double signedExp(double z, double sigmaTr) { return (z >= 0.0 ? 1.0 : -1.0) * std::exp(-sigmaTr * std::abs(z)); }

std::string formatNumber(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

void checkRange(std::string_view where, std::string_view key, double value, double low, double high) {
    if (!(value >= low && value <= high))
        throwInput(where, key,
                   formatNumber(value) + " is out of the skin model's range [" + formatNumber(low) + ", " +
                       formatNumber(high) + "]");
}

} // namespace

double skinWavelengthNm(int sample) { return kSkinFirstWavelengthNm + kSkinWavelengthStepNm * sample; }

const std::vector<SkinToneLevel>& skinToneLevels() {
    static const std::vector<SkinToneLevel> levels{
        {"I", 0.015}, {"II", 0.05}, {"III", 0.11}, {"IV", 0.16}, {"V", 0.27}, {"VI", 0.43},
    };
    return levels;
}

std::optional<SkinTone> skinToneForLevel(std::string_view name) {
    for (const auto& level : skinToneLevels())
        if (level.name == name) {
            SkinTone tone;
            tone.melanin = level.melanin;
            tone.level = std::string(name);
            return tone;
        }
    return std::nullopt;
}

double eumelaninAbsorption(double nm) { return 6.6e10 * std::pow(nm, -3.33); }
double pheomelaninAbsorption(double nm) { return 2.9e14 * std::pow(nm, -4.75); }
double baselineSkinAbsorption(double nm) { return 0.0244 + 8.53 * std::exp(-(nm - 154.0) / 66.2); }
double oxyHaemoglobinExtinction(int sample) { return kOxyExtinction.at(static_cast<std::size_t>(sample)); }
double deoxyHaemoglobinExtinction(int sample) { return kDeoxyExtinction.at(static_cast<std::size_t>(sample)); }
double oxyHaemoglobinAbsorption(int sample) {
    // σa (1/cm) = ln 10 · ε · c / M; /10 for 1/mm.
    return std::log(10.0) * oxyHaemoglobinExtinction(sample) * kHaemoglobinInBloodGPerL / kHaemoglobinMolarMass / 10.0;
}
double deoxyHaemoglobinAbsorption(int sample) {
    return std::log(10.0) * deoxyHaemoglobinExtinction(sample) * kHaemoglobinInBloodGPerL / kHaemoglobinMolarMass /
           10.0;
}
double epidermisReducedScattering(double nm) { return 14.74 * std::pow(nm, -0.22) + 2.2e11 * std::pow(nm, -4.0); }

LayerCoefficients epidermisCoefficients(const SkinTone& tone, int sample) {
    const double nm = skinWavelengthNm(sample);
    const double melanin =
        tone.melaninBlend * eumelaninAbsorption(nm) + (1.0 - tone.melaninBlend) * pheomelaninAbsorption(nm);
    return {tone.melanin * melanin + (1.0 - tone.melanin) * baselineSkinAbsorption(nm), epidermisReducedScattering(nm)};
}

LayerCoefficients dermisCoefficients(const SkinTone& tone, int sample) {
    const double nm = skinWavelengthNm(sample);
    const double blood = kOxygenSaturation * oxyHaemoglobinAbsorption(sample) +
                         (1.0 - kOxygenSaturation) * deoxyHaemoglobinAbsorption(sample);
    return {tone.haemoglobin * blood + (1.0 - tone.haemoglobin) * baselineSkinAbsorption(nm),
            0.5 * epidermisReducedScattering(nm)};
}

SlabTotals multipoleSlabTotals(const LayerCoefficients& layer, double d, double eta, int poles) {
    const double sigmaTPrime = layer.absorption + layer.reducedScattering;
    const double albedo = layer.reducedScattering / sigmaTPrime;
    const double sigmaTr = std::sqrt(3.0 * layer.absorption * sigmaTPrime);
    const double l = 1.0 / sigmaTPrime;
    const double diffusion = 1.0 / (3.0 * sigmaTPrime);
    const double fdr = diffuseFresnelReflectance(eta);
    const double zb = 2.0 * (1.0 + fdr) / (1.0 - fdr) * diffusion;
    // Donner & Jensen 2005, Eq. 8–9: pole pairs at z_r,i = 2i(d + 2z_b) + ℓ, z_v,i = 2i(d + 2z_b) − ℓ − 2z_b; the
    // area integral of each pole's term z(1 + σtr d_r) e^{−σtr d_r} / d_r³ is 2π sign(z) e^{−σtr |z|}.
    double reflectance = 0.0;
    double transmittance = 0.0;
    for (int i = -poles; i <= poles; ++i) {
        const double zr = 2.0 * i * (d + 2.0 * zb) + l;
        const double zv = 2.0 * i * (d + 2.0 * zb) - l - 2.0 * zb;
        reflectance += signedExp(zr, sigmaTr) - signedExp(zv, sigmaTr);
        transmittance += signedExp(d - zr, sigmaTr) - signedExp(d - zv, sigmaTr);
    }
    return {std::max(0.0, 0.5 * albedo * reflectance), std::max(0.0, 0.5 * albedo * transmittance)};
}

SkinSpectrum skinReflectanceSpectrum(const SkinTone& tone) {
    SkinSpectrum out{};
    for (int i = 0; i < kSkinSpectralSamples; ++i) {
        // The multipole places the same extrapolated boundary on both faces of a slab, so it cannot carry the
        // air–skin top (η = 1.4) and the index-matched epidermis–dermis bottom at once: both are taken as matched
        // (η = 1), and the surface's Fresnel reflection is left to the renderer's specular term (F0 = 0.028).
        const SlabTotals epidermis = multipoleSlabTotals(epidermisCoefficients(tone, i), kEpidermisThicknessMm, 1.0);
        const LayerCoefficients dermis = dermisCoefficients(tone, i);
        // The dermis under the epidermis: an index-matched boundary (η = 1).
        const double dermisReflectance =
            dipoleDiffuseReflectance(dermis.reducedScattering / (dermis.absorption + dermis.reducedScattering), 1.0);
        out[i] = epidermis.reflectance + epidermis.transmittance * epidermis.transmittance * dermisReflectance /
                                             (1.0 - epidermis.reflectance * dermisReflectance);
    }
    return out;
}

std::array<double, 3> reflectanceToLinearSrgb(const SkinSpectrum& reflectance) {
    std::array<double, 3> rgb = toRgbUnbalanced(reflectance);
    for (int c = 0; c < 3; ++c) rgb[c] = std::clamp(rgb[c] / whiteRgb()[c], 0.0, 1.0);
    return rgb;
}

double linearLuminance(const std::array<double, 3>& rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

void validateSkinTone(const SkinTone& tone, std::string_view where) {
    checkRange(where, "skin.melanin", tone.melanin, kMelaninMin, kMelaninMax);
    checkRange(where, "skin.haemoglobin", tone.haemoglobin, kHaemoglobinMin, kHaemoglobinMax);
    checkRange(where, "skin.melanin_blend", tone.melaninBlend, 0.0, 1.0);
}

std::vector<GaussianLobe> fitDeonLobesToBurley(const std::array<double, 3>& shapeMm) {
    const std::vector<GaussianLobe>& deon = deonSkinLobes();
    const std::size_t n = deon.size();
    std::vector<GaussianLobe> out = deon;
    for (int c = 0; c < 3; ++c) {
        const double d = shapeMm[c];
        const BurleyProfile burley({d, d, d}, "fit");
        // Samples of the radial CDF (the energy within r) on 0 < r ≤ 12 d; least squares with w ≥ 0 by projected
        // coordinate descent on the normal equations (six unknowns).
        constexpr int kSamples = 240;
        std::vector<std::vector<double>> basis(n, std::vector<double>(kSamples));
        std::vector<double> target(kSamples);
        for (int s = 0; s < kSamples; ++s) {
            const double r = 12.0 * d * (s + 0.5) / kSamples;
            target[s] = burley.radialCumulative(0, r);
            for (std::size_t k = 0; k < n; ++k) basis[k][s] = -std::expm1(-r * r / (2.0 * deon[k].varianceMm2));
        }
        std::vector<std::vector<double>> gram(n, std::vector<double>(n, 0.0));
        std::vector<double> rhs(n, 0.0);
        // One more equation, weighted like kMomentWeight samples: the second moment Σ w_k v_k equals Burley's 7 d²
        // (the width the Blender radii and the kernels' reach follow), so the tail lobes cannot run off.
        constexpr double kMomentWeight = 50.0;
        for (std::size_t a = 0; a < n; ++a) {
            for (int s = 0; s < kSamples; ++s) rhs[a] += basis[a][s] * target[s];
            rhs[a] += kMomentWeight * deon[a].varianceMm2 / (7.0 * d * d);
            for (std::size_t b = 0; b < n; ++b) {
                for (int s = 0; s < kSamples; ++s) gram[a][b] += basis[a][s] * basis[b][s];
                gram[a][b] += kMomentWeight * deon[a].varianceMm2 * deon[b].varianceMm2 / (49.0 * d * d * d * d);
            }
        }
        std::vector<double> w(n, 0.0);
        for (int iteration = 0; iteration < 2000; ++iteration)
            for (std::size_t a = 0; a < n; ++a) {
                double residual = rhs[a];
                for (std::size_t b = 0; b < n; ++b)
                    if (b != a) residual -= gram[a][b] * w[b];
                w[a] = std::max(0.0, residual / gram[a][a]);
            }
        double total = 0.0;
        for (double v : w) total += v;
        if (!(total > 0.0)) w.assign(n, 1.0 / static_cast<double>(n)), total = 1.0;
        for (std::size_t k = 0; k < n; ++k) out[k].weight[c] = w[k] / total;
    }
    return out;
}

SkinOptics skinOptics(const SkinTone& tone, std::string_view where) {
    validateSkinTone(tone, where);
    SkinOptics optics;
    optics.tone = tone;
    const SkinSpectrum reflectance = skinReflectanceSpectrum(tone);
    optics.albedo = reflectanceToLinearSrgb(reflectance);
    optics.luminance = linearLuminance(optics.albedo);
    const auto& responses = channelResponses();
    for (int c = 0; c < 3; ++c) {
        double weighted = 0.0;
        double total = 0.0;
        for (int i = 0; i < kSkinSpectralSamples; ++i) {
            const LayerCoefficients dermis = dermisCoefficients(tone, i);
            const double sigmaTr = std::sqrt(3.0 * dermis.absorption * (dermis.absorption + dermis.reducedScattering));
            const double weight = responses[c][i] * reflectance[i];
            weighted += weight / sigmaTr;
            total += weight;
        }
        optics.meanFreePathMm[c] = weighted / total;
        const double a = std::clamp(optics.albedo[c], 0.0, 1.0);
        const double s = 1.85 - a + 7.0 * std::pow(std::abs(a - 0.8), 3.0);
        optics.burleyShapeMm[c] = optics.meanFreePathMm[c] / s;
    }
    optics.lobes = fitDeonLobesToBurley(optics.burleyShapeMm);
    return optics;
}

void applySkinTone(const SkinOptics& optics, SssParams& params) {
    SKINLAB_CHECK_EQ(optics.lobes.size(), 6u);
    std::array<std::array<double, 3>, 6> weights{};
    for (std::size_t k = 0; k < 6; ++k) weights[k] = optics.lobes[k].weight;
    params.skinLobeWeights = weights;
    params.skinShapeMm = optics.burleyShapeMm;
}

std::vector<GaussianLobe> skinProfileLobes(const SssParams& params) {
    std::vector<GaussianLobe> lobes = deonSkinLobes();
    if (params.skinLobeWeights)
        for (std::size_t k = 0; k < lobes.size(); ++k) lobes[k].weight = (*params.skinLobeWeights)[k];
    return lobes;
}

std::array<double, 3> skinBurleyShapeMm(const SssParams& params) {
    if (params.material == "skin" && params.skinShapeMm) return *params.skinShapeMm;
    return burleyShapeMm(params.material);
}

std::array<double, 3> skinTransmittance(const SssParams& params, double thicknessMm) {
    std::array<double, 3> t{};
    for (const auto& lobe : skinProfileLobes(params))
        for (int c = 0; c < 3; ++c) t[c] += lobe.weight[c] * std::exp(-thicknessMm * thicknessMm / lobe.varianceMm2);
    return t;
}

std::array<double, 3> skinWidthRatio(const SssParams& params) {
    if (!params.skinShapeMm) return {1.0, 1.0, 1.0};
    const std::array<double, 3> deon = burleyShapeMm("skin"); // d'Eon's profile as Burley's d (same second moment)
    std::array<double, 3> ratio{};
    for (int c = 0; c < 3; ++c) ratio[c] = (*params.skinShapeMm)[c] / deon[c];
    return ratio;
}

PscbfProfile skinPscbfProfile(const SssParams& params, PscbfSigma reading) {
    PscbfProfile profile = mikkelsenSkinProfile(reading);
    if (!params.skinShapeMm) return profile;
    const std::array<double, 3> ratio = skinWidthRatio(params);
    for (int c = 0; c < 3; ++c) profile.varianceMm2[c] *= ratio[c] * ratio[c];
    profile.maxRadiusMm *= std::max({ratio[0], ratio[1], ratio[2]});
    return profile;
}

std::array<double, 3> skinArtisticFalloff(const SssParams& params, std::array<double, 3> falloff) {
    const std::array<double, 3> ratio = skinWidthRatio(params);
    for (int c = 0; c < 3; ++c) falloff[c] *= ratio[c];
    return falloff;
}

SkinToneTable::SkinToneTable(double melaninBlend, int melaninSteps, int haemoglobinSteps)
    : blend_(melaninBlend), melaninSteps_(melaninSteps), haemoglobinSteps_(haemoglobinSteps) {
    table_.resize(static_cast<std::size_t>(melaninSteps_ * haemoglobinSteps_));
    for (int m = 0; m < melaninSteps_; ++m)
        for (int h = 0; h < haemoglobinSteps_; ++h) {
            SkinTone tone;
            tone.melaninBlend = blend_;
            tone.melanin = kMelaninMin * std::pow(kMelaninMax / kMelaninMin, m / double(melaninSteps_ - 1));
            tone.haemoglobin =
                kHaemoglobinMin * std::pow(kHaemoglobinMax / kHaemoglobinMin, h / double(haemoglobinSteps_ - 1));
            table_[static_cast<std::size_t>(m * haemoglobinSteps_ + h)] =
                reflectanceToLinearSrgb(skinReflectanceSpectrum(tone));
        }
    logTable_.resize(table_.size());
    for (std::size_t i = 0; i < table_.size(); ++i)
        for (int c = 0; c < 3; ++c) logTable_[i][c] = std::log(std::max(table_[i][c], 1e-4));
}

namespace {
double gridCoordinate(double value, double low, double high, int steps) {
    return std::log(value / low) / std::log(high / low) * (steps - 1);
}
double gridValue(double coordinate, double low, double high, int steps) {
    return low * std::pow(high / low, coordinate / (steps - 1));
}
double logDistance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    double sum = 0.0;
    for (int c = 0; c < 3; ++c) {
        const double d = std::log(std::max(a[c], 1e-4)) - std::log(std::max(b[c], 1e-4));
        sum += d * d;
    }
    return sum;
}
} // namespace

std::array<double, 3> SkinToneTable::albedo(double melanin, double haemoglobin) const {
    const double mc =
        std::clamp(gridCoordinate(melanin, kMelaninMin, kMelaninMax, melaninSteps_), 0.0, double(melaninSteps_ - 1));
    const double hc = std::clamp(gridCoordinate(haemoglobin, kHaemoglobinMin, kHaemoglobinMax, haemoglobinSteps_), 0.0,
                                 double(haemoglobinSteps_ - 1));
    const int m0 = std::min(static_cast<int>(mc), melaninSteps_ - 2);
    const int h0 = std::min(static_cast<int>(hc), haemoglobinSteps_ - 2);
    const double fm = mc - m0, fh = hc - h0;
    std::array<double, 3> out{};
    const auto at = [&](int m, int h) { return table_[static_cast<std::size_t>(m * haemoglobinSteps_ + h)]; };
    for (int c = 0; c < 3; ++c)
        out[c] = (1 - fm) * ((1 - fh) * at(m0, h0)[c] + fh * at(m0, h0 + 1)[c]) +
                 fm * ((1 - fh) * at(m0 + 1, h0)[c] + fh * at(m0 + 1, h0 + 1)[c]);
    return out;
}

ToneEstimate SkinToneTable::invert(const std::array<double, 3>& rgb) const {
    int best = 0;
    double bestDistance = std::numeric_limits<double>::infinity();
    std::array<double, 3> logRgb{};
    for (int c = 0; c < 3; ++c) logRgb[c] = std::log(std::max(rgb[c], 1e-4));
    for (std::size_t i = 0; i < logTable_.size(); ++i) {
        double distance = 0.0;
        for (int c = 0; c < 3; ++c) distance += (logRgb[c] - logTable_[i][c]) * (logRgb[c] - logTable_[i][c]);
        if (distance < bestDistance) bestDistance = distance, best = static_cast<int>(i);
    }
    // Pattern search on the continuous grid coordinates.
    double mc = best / haemoglobinSteps_;
    double hc = best % haemoglobinSteps_;
    const auto cost = [&](double m, double h) {
        return logDistance(rgb, albedo(gridValue(m, kMelaninMin, kMelaninMax, melaninSteps_),
                                       gridValue(h, kHaemoglobinMin, kHaemoglobinMax, haemoglobinSteps_)));
    };
    double current = cost(mc, hc);
    for (double step = 0.5; step > 1e-3; step *= 0.5) {
        bool moved = true;
        while (moved) {
            moved = false;
            for (const auto& [dm, dh] : {std::pair{1.0, 0.0}, {-1.0, 0.0}, {0.0, 1.0}, {0.0, -1.0}}) {
                const double m = std::clamp(mc + dm * step, 0.0, double(melaninSteps_ - 1));
                const double h = std::clamp(hc + dh * step, 0.0, double(haemoglobinSteps_ - 1));
                const double c = cost(m, h);
                if (c < current) current = c, mc = m, hc = h, moved = true;
            }
        }
    }
    ToneEstimate estimate;
    estimate.melanin = gridValue(mc, kMelaninMin, kMelaninMax, melaninSteps_);
    estimate.haemoglobin = gridValue(hc, kHaemoglobinMin, kHaemoglobinMax, haemoglobinSteps_);
    const std::array<double, 3> model = albedo(estimate.melanin, estimate.haemoglobin);
    double difference = 0.0, magnitude = 0.0;
    for (int c = 0; c < 3; ++c) {
        difference += (model[c] - rgb[c]) * (model[c] - rgb[c]);
        magnitude += rgb[c] * rgb[c];
    }
    estimate.error = magnitude > 0.0 ? std::sqrt(difference / magnitude) : std::numeric_limits<double>::infinity();
    return estimate;
}

double retoneAlbedo(std::vector<float>& rgba, const SkinTone& tone, std::string_view where, std::string_view key) {
    validateSkinTone(tone, where);
    const SkinToneTable table(tone.melaninBlend);
    // Colours repeat (8-bit sources): one inversion per distinct colour, keyed by 10 bits per channel.
    struct Entry {
        ToneEstimate estimate;
        std::size_t count = 0;
        bool skin = false;
    };
    std::unordered_map<std::uint32_t, Entry> colours;
    const std::size_t texels = rgba.size() / 4;
    const auto keyOf = [](const float* p) {
        std::uint32_t k = 0;
        for (int c = 0; c < 3; ++c)
            k = (k << 10) | static_cast<std::uint32_t>(std::lround(std::clamp(p[c], 0.0f, 1.0f) * 1023.0f));
        return k;
    };
    const auto coloured = [](const float* p) { return p[0] > 0.0f || p[1] > 0.0f || p[2] > 0.0f; };
    // Skin: the model's match within the tolerance and a skin hue (red at least 10 % above green, green not below
    // blue), which keeps whites, greys and blue or green texels (eyes, background) out.
    const auto isSkin = [](const float* p, const ToneEstimate& estimate) {
        return estimate.error <= kToneInversionTolerance && p[0] >= 1.1f * p[1] && p[1] >= p[2];
    };
    std::size_t colouredCount = 0, invertible = 0;
    for (std::size_t t = 0; t < texels; ++t) {
        const float* p = &rgba[t * 4];
        if (!coloured(p)) continue;
        ++colouredCount;
        auto [it, inserted] = colours.try_emplace(keyOf(p));
        if (inserted) {
            it->second.estimate = table.invert({p[0], p[1], p[2]});
            it->second.skin = isSkin(p, it->second.estimate);
        }
        ++it->second.count;
        if (it->second.skin) ++invertible;
    }
    const double share = colouredCount > 0 ? static_cast<double>(invertible) / static_cast<double>(colouredCount) : 0.0;
    if (colouredCount == 0 || share < 0.5)
        throwInput(where, key,
                   "the skin model inverts only " + formatNumber(std::round(share * 1000.0) / 10.0) +
                       " % of the map's texels (at least 50 % must be skin colours to re-tone it)");
    // The map's own melanin level: the median over its invertible texels. Every texel's melanin is scaled by
    // target / median, so freckles and shading detail keep their melanin ratio to the rest of the skin.
    std::vector<std::pair<double, std::size_t>> melanins;
    for (const auto& [k, entry] : colours)
        if (entry.skin) melanins.emplace_back(entry.estimate.melanin, entry.count);
    std::sort(melanins.begin(), melanins.end());
    std::size_t seen = 0;
    double median = melanins.front().first;
    for (const auto& [m, count] : melanins) {
        seen += count;
        median = m;
        if (2 * seen >= invertible) break;
    }
    const double scale = tone.melanin / median;
    std::unordered_map<std::uint32_t, std::array<float, 3>> ratios;
    for (const auto& [k, entry] : colours) {
        if (!entry.skin) continue;
        const double melanin = std::clamp(entry.estimate.melanin * scale, kMelaninMin, kMelaninMax);
        const auto from = table.albedo(entry.estimate.melanin, entry.estimate.haemoglobin);
        const auto to = table.albedo(melanin, entry.estimate.haemoglobin);
        std::array<float, 3> ratio{};
        for (int c = 0; c < 3; ++c) ratio[c] = static_cast<float>(to[c] / std::max(from[c], 1e-6));
        ratios.emplace(k, ratio);
    }
    for (std::size_t t = 0; t < texels; ++t) {
        float* p = &rgba[t * 4];
        if (!coloured(p)) continue;
        const auto it = ratios.find(keyOf(p));
        if (it == ratios.end()) continue;
        for (int c = 0; c < 3; ++c) p[c] = std::clamp(p[c] * it->second[c], 0.0f, 1.0f);
    }
    return share;
}

} // namespace skinlab::renderer::sss
