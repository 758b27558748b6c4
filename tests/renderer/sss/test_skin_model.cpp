// The biophysical skin model (renderer/sss/skin_model.h) against its published sources: the analytic absorption fits
// of Donner & Jensen 2006, Prahl's haemoglobin spectra (values and isosbestic points), the dipole of Jensen et al.
// 2001 as the multipole's limit, the trends Donner & Jensen report (melanin darkens most in the blue; blood draws
// its double dip at the Q bands), Jacques' melanosome fractions for the named levels, and the inversion of
// Jimenez et al. 2010.
#include "common/error.h"
#include "renderer/sss/burley_profile.h"
#include "renderer/sss/materials.h"
#include "renderer/sss/skin_model.h"

#include <cmath>
#include <gtest/gtest.h>
#include <string>

using namespace skinlab::renderer::sss;

namespace {
int sampleAt(double nm) { return static_cast<int>(std::lround((nm - kSkinFirstWavelengthNm) / kSkinWavelengthStepNm)); }
SkinTone tone(double melanin, double haemoglobin) {
    SkinTone t;
    t.melanin = melanin;
    t.haemoglobin = haemoglobin;
    return t;
}
} // namespace

TEST(SkinModel, AbsorptionFitsAreTheirPublishedCentimetreFormsInMillimetres) {
    // Jacques' forms in 1/cm (melanosome 6.6e11 λ^−3.33, baseline 0.244 + 85.3 e^{−(λ−154)/66.2}) are one tenth
    // of Donner & Jensen's 1/mm constants; pheomelanin 2.9e15 λ^−4.75 1/cm likewise.
    for (double nm : {400.0, 480.0, 550.0, 633.0, 700.0}) {
        EXPECT_NEAR(eumelaninAbsorption(nm), 6.6e11 * std::pow(nm, -3.33) / 10.0, 1e-9 * eumelaninAbsorption(nm));
        EXPECT_NEAR(pheomelaninAbsorption(nm), 2.9e15 * std::pow(nm, -4.75) / 10.0, 1e-9 * pheomelaninAbsorption(nm));
        EXPECT_NEAR(baselineSkinAbsorption(nm), (0.244 + 85.3 * std::exp(-(nm - 154.0) / 66.2)) / 10.0, 1e-12);
    }
    // Melanin absorbs more towards the blue: 400 nm over 700 nm is (7/4)^3.33 ≈ 6.4 for eumelanin.
    EXPECT_NEAR(eumelaninAbsorption(400.0) / eumelaninAbsorption(700.0), std::pow(1.75, 3.33), 1e-9);
}

TEST(SkinModel, EumelaninFollowsJacquesMelanosomeSpectrum) {
    // S. Jacques, "Melanosome absorption coefficient" (Oregon Medical Laser Center, 1998,
    // https://omlc.org/spectra/melanin/mua.html) approximates the skin melanosome's interior as
    // µa = 1.70·10¹² λ^−3.48 cm⁻¹, a fit independent of the 6.6·10¹¹ λ^−3.33 the model takes: over the visible range
    // the two agree within 5 % (the model's over Jacques': 0.954 at 400 nm, 1.000 at 550 nm, 1.037 at 700 nm).
    for (int i = 0; i < kSkinSpectralSamples; ++i) {
        const double nm = skinWavelengthNm(i);
        const double jacques = 1.70e12 * std::pow(nm, -3.48) / 10.0; // 1/mm
        EXPECT_NEAR(eumelaninAbsorption(nm) / jacques, 1.0, 0.05) << nm;
    }
}

TEST(SkinModel, MeasuredEpidermalAbsorptionAt694nmFallsInJacquesRanges) {
    // "Skin pigmentation characterized by visible reflectance measurements" (University of California, Irvine,
    // https://escholarship.org/uc/item/54d8m0g9) measured the epidermal melanin absorption at 694 nm: 300–1200 m⁻¹ for
    // Caucasian and Asian skin, about 2500 m⁻¹ for African skin. Through the model's melanin (eumelanin share 0.7) the
    // light range is a melanin fraction of 1.6–6.4 %, Jacques' light-skinned 1.3–6.3 % within 0.3 points; the African
    // mean is 13.3 %, inside the moderately pigmented 11–16 % and between levels III and V: the named levels V and VI
    // (27 %, 43 %, the upper half of Jacques' darkly pigmented range) absorb 2.0× and 3.2× that mean.
    const double blend = SkinTone{}.melaninBlend;
    const double perFraction =
        blend * eumelaninAbsorption(694.0) + (1.0 - blend) * pheomelaninAbsorption(694.0); // 1/mm at C_m = 1
    const auto fractionFor = [&](double perMetre) { return perMetre / 1000.0 / perFraction; };
    EXPECT_NEAR(fractionFor(300.0), 0.016, 0.001);
    EXPECT_NEAR(fractionFor(1200.0), 0.064, 0.001);
    EXPECT_GE(fractionFor(300.0), 0.013);          // Jacques' light-skinned range, lower end
    EXPECT_LE(fractionFor(1200.0), 0.063 + 0.003); // upper end
    const double african = fractionFor(2500.0);
    EXPECT_NEAR(african, 0.133, 0.002);
    EXPECT_GE(african, 0.11); // Jacques' moderately pigmented range
    EXPECT_LE(african, 0.16);
    EXPECT_GT(african, skinToneForLevel("III")->melanin);
    EXPECT_LT(african, skinToneForLevel("V")->melanin);
}

TEST(SkinModel, HaemoglobinSpectraMatchPrahlsTableAndIsosbesticPoints) {
    // Prahl (omlc.org/spectra/hemoglobin): 660 nm, the pulse-oximetry red line: HbO2 319.6, Hb 3226.56 cm⁻¹/M.
    EXPECT_DOUBLE_EQ(oxyHaemoglobinExtinction(sampleAt(660)), 319.6);
    EXPECT_DOUBLE_EQ(deoxyHaemoglobinExtinction(sampleAt(660)), 3226.56);
    // Prahl's tabulated values at more of the model's samples (the Soret band's shoulder, the green, the Q bands and
    // the trough between them, the red edge; the same compiled table, cm⁻¹/M): every sample is the published one.
    const struct {
        double nm, oxy, deoxy;
    } published[] = {{420, 480360, 407560}, {450, 62816, 103292},  {500, 20932.8, 20862},
                     {540, 53236, 46592},   {560, 32613.2, 53788}, {580, 50104, 37020},
                     {600, 3200, 14677.2},  {650, 368, 3750.12},   {700, 290, 1794.28}};
    for (const auto& row : published) {
        EXPECT_DOUBLE_EQ(oxyHaemoglobinExtinction(sampleAt(row.nm)), row.oxy) << row.nm;
        EXPECT_DOUBLE_EQ(deoxyHaemoglobinExtinction(sampleAt(row.nm)), row.deoxy) << row.nm;
    }
    // Whole blood: µa = ln 10 · ε · 150 g/L / 64 500 g/mol (1/cm) → 1/mm.
    EXPECT_NEAR(oxyHaemoglobinAbsorption(sampleAt(660)), std::log(10.0) * 319.6 * 150.0 / 64500.0 / 10.0, 1e-12);
    // The published isosbestic points 500, 529, 545, 570, 584 nm: oxy − deoxy changes sign in each 10 nm interval.
    for (double nm : {500.0, 520.0, 540.0, 570.0, 580.0}) {
        const int i = sampleAt(nm);
        const double before = oxyHaemoglobinExtinction(i) - deoxyHaemoglobinExtinction(i);
        const double after = oxyHaemoglobinExtinction(i + 1) - deoxyHaemoglobinExtinction(i + 1);
        EXPECT_LT(before * after, 0.0) << "no isosbestic crossing between " << nm << " and " << nm + 10 << " nm";
    }
    // Oxyhaemoglobin's Q bands (542 and 576 nm) around a trough at 560 nm; the Soret band peaks near 415 nm.
    EXPECT_GT(oxyHaemoglobinExtinction(sampleAt(540)), oxyHaemoglobinExtinction(sampleAt(560)));
    EXPECT_GT(oxyHaemoglobinExtinction(sampleAt(580)), oxyHaemoglobinExtinction(sampleAt(560)));
    EXPECT_GT(oxyHaemoglobinExtinction(sampleAt(420)), 100.0 * oxyHaemoglobinExtinction(sampleAt(650)));
}

TEST(SkinModel, MultipoleReducesToTheDipoleAndConservesEnergy) {
    // No image pairs beyond the first and a slab far thicker than the light reaches: Jensen et al. 2001's Rd.
    for (double eta : {1.0, 1.3, 1.4})
        for (double albedo : {0.5, 0.9, 0.99}) {
            const LayerCoefficients layer{1.0 - albedo, albedo};
            EXPECT_NEAR(multipoleSlabTotals(layer, 1000.0, eta, 0).reflectance, dipoleDiffuseReflectance(albedo, eta),
                        1e-12);
            EXPECT_NEAR(multipoleSlabTotals(layer, 1000.0, eta).reflectance, dipoleDiffuseReflectance(albedo, eta),
                        1e-9);
        }
    // A non-absorbing slab (σa → 0) returns all light as reflectance plus transmittance.
    for (double d : {1.0, 5.0}) {
        const SlabTotals totals = multipoleSlabTotals({1e-6, 2.0}, d, 1.0);
        EXPECT_NEAR(totals.reflectance + totals.transmittance, 1.0, 2e-3) << "d = " << d;
    }
    // The epidermis is thicker than one transport mean free path at every sample (the multipole's regime).
    for (int i = 0; i < kSkinSpectralSamples; ++i) {
        const LayerCoefficients epi = epidermisCoefficients(tone(kMelaninMax, 0.02), i);
        EXPECT_LT(1.0 / (epi.absorption + epi.reducedScattering), kEpidermisThicknessMm) << skinWavelengthNm(i);
    }
}

TEST(SkinModel, MelaninDarkensEveryWavelengthAndMostInTheBlue) {
    // Donner & Jensen 2006 (reflectance against C_m): more melanin lowers the whole spectrum, the short end most.
    const SkinSpectrum light = skinReflectanceSpectrum(tone(0.002, 0.02));
    const SkinSpectrum dark = skinReflectanceSpectrum(tone(0.2, 0.02));
    for (int i = 0; i < kSkinSpectralSamples; ++i) EXPECT_LT(dark[i], light[i]) << skinWavelengthNm(i);
    EXPECT_LT(dark[sampleAt(450)] / light[sampleAt(450)], dark[sampleAt(650)] / light[sampleAt(650)]);
    // Light skin reflects red most: the 650 nm reflectance exceeds the 450 nm one.
    EXPECT_GT(light[sampleAt(650)], light[sampleAt(450)]);
}

TEST(SkinModel, BloodDrawsTheDoubleDipAtTheQBands) {
    // Skin reflectance shows oxyhaemoglobin's "W" between 540 and 580 nm, deeper with more blood.
    const SkinSpectrum flushed = skinReflectanceSpectrum(tone(0.015, kHaemoglobinMax));
    EXPECT_LT(flushed[sampleAt(540)], flushed[sampleAt(560)]);
    EXPECT_LT(flushed[sampleAt(580)], flushed[sampleAt(560)]);
    const auto pale = skinOptics(tone(0.015, 0.002)).albedo;
    const auto red = skinOptics(tone(0.015, 0.08)).albedo;
    EXPECT_LT(red[1] / red[0], pale[1] / pale[0]); // blood takes green more than red
}

TEST(SkinModel, NamedLevelsSpanFitzpatrickWithinJacquesRangesAndThreefoldLuminance) {
    const auto& levels = skinToneLevels();
    ASSERT_EQ(levels.size(), 6u);
    // Jacques 1998: light 1.3–6.3 %, moderate 11–16 %, dark 18–43 %.
    const double low[6] = {0.013, 0.013, 0.11, 0.11, 0.18, 0.18};
    const double high[6] = {0.063, 0.063, 0.16, 0.16, 0.43, 0.43};
    double previousLuminance = 2.0;
    for (std::size_t i = 0; i < levels.size(); ++i) {
        EXPECT_GE(levels[i].melanin, low[i]) << levels[i].name;
        EXPECT_LE(levels[i].melanin, high[i]) << levels[i].name;
        const SkinOptics optics = skinOptics(*skinToneForLevel(levels[i].name));
        EXPECT_LT(optics.luminance, previousLuminance) << levels[i].name;
        previousLuminance = optics.luminance;
        EXPECT_GT(optics.albedo[0], optics.albedo[1]) << levels[i].name; // skin hue: R > G > B
        EXPECT_GT(optics.albedo[1], optics.albedo[2]) << levels[i].name;
    }
    const double lightest = skinOptics(*skinToneForLevel("I")).luminance;
    const double darkest = skinOptics(*skinToneForLevel("VI")).luminance;
    EXPECT_GE(lightest / darkest, 3.0);
    EXPECT_FALSE(skinToneForLevel("VII").has_value());
}

TEST(SkinModel, ProfileNarrowsWithMelaninAndRedReachesFarthest) {
    const SkinOptics light = skinOptics(*skinToneForLevel("I"));
    const SkinOptics dark = skinOptics(*skinToneForLevel("VI"));
    for (int c = 0; c < 3; ++c) EXPECT_LT(dark.burleyShapeMm[c], light.burleyShapeMm[c]) << c;
    for (const SkinOptics* o : {&light, &dark}) {
        EXPECT_GT(o->burleyShapeMm[0], o->burleyShapeMm[1]);
        EXPECT_GT(o->burleyShapeMm[1], o->burleyShapeMm[2]);
        // The refitted six Gaussians: weights ≥ 0, each channel sums to 1, and their radial CDF follows Burley's
        // at d, 3d and 6d: within 0.1 in red; green and blue are narrower than d'Eon's narrowest lobe (σ = 0.08 mm)
        // resolves, so there the fit misses part of Burley's central peak (within 0.2; docs/skin-tones.md). The
        // second moment is Burley's 7 d² (the fit's constraint), the width every method and Blender follow.
        const GaussianSumProfile gaussians(o->lobes, "refit");
        const BurleyProfile burley(o->burleyShapeMm, "burley");
        for (int c = 0; c < 3; ++c) {
            double sum = 0.0;
            for (const auto& lobe : o->lobes) {
                EXPECT_GE(lobe.weight[c], 0.0);
                sum += lobe.weight[c];
            }
            EXPECT_NEAR(sum, 1.0, 1e-12);
            double moment = 0.0;
            for (const auto& lobe : o->lobes) moment += lobe.weight[c] * lobe.varianceMm2;
            EXPECT_NEAR(std::sqrt(moment / 7.0) / o->burleyShapeMm[c], 1.0, 0.03) << "channel " << c;
            for (double k : {1.0, 3.0, 6.0}) {
                const double r = k * o->burleyShapeMm[c];
                double cdf = 0.0;
                for (const auto& lobe : o->lobes)
                    cdf += lobe.weight[c] * -std::expm1(-r * r / (2.0 * lobe.varianceMm2));
                EXPECT_NEAR(cdf, burley.radialCumulative(c, r), c == 0 ? 0.1 : 0.2)
                    << "channel " << c << " r = " << k << " d";
            }
        }
    }
}

TEST(SkinModel, OutOfRangeValuesNameTheirKey) {
    const auto message = [](const SkinTone& t) {
        try {
            skinOptics(t, "scene.toml");
        } catch (const skinlab::InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(message(tone(0.7, 0.02)), "scene.toml: skin.melanin: 0.7 is out of the skin model's range [0.001, 0.5]");
    EXPECT_EQ(message(tone(0.02, 0.0)),
              "scene.toml: skin.haemoglobin: 0 is out of the skin model's range [0.001, 0.1]");
    SkinTone blend = tone(0.02, 0.02);
    blend.melaninBlend = 1.5;
    EXPECT_NE(message(blend).find("skin.melanin_blend"), std::string::npos);
    SkinTone nan = tone(std::nan(""), 0.02);
    EXPECT_NE(message(nan).find("skin.melanin"), std::string::npos);
}

TEST(SkinModel, InversionRecoversTheLevelsAndRejectsNonSkinColours) {
    const SkinToneTable table;
    for (double m : {0.004, 0.03, 0.12, 0.35})
        for (double h : {0.003, 0.02, 0.07}) {
            const ToneEstimate estimate = table.invert(table.albedo(m, h));
            EXPECT_NEAR(estimate.melanin / m, 1.0, 0.02) << m << " " << h;
            // Haemoglobin shows through light skin only: under much melanin the dermis is barely seen.
            if (m <= 0.03) {
                EXPECT_NEAR(estimate.haemoglobin / h, 1.0, 0.05) << m << " " << h;
            }
            EXPECT_LT(estimate.error, 1e-3);
            // The table agrees with the model evaluated directly.
            const auto direct = skinOptics(tone(m, h)).albedo;
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(table.albedo(m, h)[c] / direct[c], 1.0, 0.03);
        }
    EXPECT_GT(table.invert({0.1, 0.3, 0.6}).error, kToneInversionTolerance); // blue
    EXPECT_GT(table.invert({0.2, 0.6, 0.2}).error, kToneInversionTolerance); // green
}

TEST(SkinModel, RetoningKeepsDetailAndMovesTheTone) {
    const SkinToneTable table;
    // A light map (level I melanin) with ±10 % "detail" and one blue texel (an eye) that cannot be inverted.
    const double lightMelanin = skinToneForLevel("I")->melanin;
    std::vector<float> rgba;
    const double factors[4] = {0.9, 1.0, 1.1, 1.0};
    for (double f : factors) {
        const auto a = table.albedo(lightMelanin, 0.02);
        rgba.insert(rgba.end(), {float(a[0] * f), float(a[1] * f), float(a[2] * f), 1.0f});
    }
    rgba.insert(rgba.end(), {0.1f, 0.3f, 0.6f, 1.0f});
    const std::vector<float> before = rgba;
    const SkinTone dark = *skinToneForLevel("V");
    const double share = retoneAlbedo(rgba, dark, "scene.toml", "skin.tone");
    EXPECT_NEAR(share, 0.8, 1e-9);
    const auto target = table.albedo(dark.melanin, 0.02);
    EXPECT_NEAR(rgba[4 + 1] / target[1], 1.0, 0.03); // the unmodified texel lands on the dark tone
    // Detail kept: darker texels stay darker and brighter ones brighter; their melanin ratio is kept, so on darker
    // skin the same ratio shows as more contrast (log contrast between 1× and 2.5× the original).
    for (int i : {0, 2}) {
        const double original = std::log(factors[i]);
        const double retoned = std::log(rgba[static_cast<std::size_t>(4 * i + 1)] / rgba[4 + 1]);
        EXPECT_GE(retoned / original, 1.0) << i;
        EXPECT_LE(retoned / original, 2.5) << i;
    }
    // The blue texel is kept as it was.
    for (int c = 0; c < 4; ++c) EXPECT_EQ(rgba[16 + c], before[16 + c]);
    // A map that is not skin is refused, naming the key.
    std::vector<float> blue{0.1f, 0.3f, 0.6f, 1.0f, 0.2f, 0.6f, 0.2f, 1.0f};
    try {
        retoneAlbedo(blue, dark, "scene.toml", "skin.tone");
        FAIL() << "no error";
    } catch (const skinlab::InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("scene.toml: skin.tone: the skin model inverts only 0 %", 0), 0u)
            << e.what();
    }
}
