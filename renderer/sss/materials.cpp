#include "renderer/sss/materials.h"

#include "common/check.h"
#include "renderer/sss/gaussian_sum_profile.h"

#include <cmath>

namespace skinlab::renderer::sss {

namespace {
const std::vector<MeasuredMedium>& measuredMedia() {
    // Jensen et al. 2001, Table 2: σs' and σa in 1/mm for R, G, B.
    static const std::vector<MeasuredMedium> media{
        {"skin1", {0.74, 0.88, 1.01}, {0.032, 0.17, 0.48}},
        {"skin2", {1.09, 1.59, 1.79}, {0.013, 0.070, 0.145}},
        {"marble", {2.19, 2.62, 3.00}, {0.0021, 0.0041, 0.0071}},
        {"apple", {2.29, 2.39, 1.97}, {0.0030, 0.0034, 0.046}},
        {"ketchup", {0.18, 0.07, 0.03}, {0.061, 0.97, 1.45}},
        {"wholemilk", {2.55, 3.21, 3.77}, {0.0011, 0.0024, 0.014}},
    };
    return media;
}
constexpr double kRelativeIndex = 1.3; // η used by Jensen et al. 2001 for all their media
} // namespace

const std::vector<std::string>& materialNames() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n{"skin"};
        for (const auto& m : measuredMedia()) n.push_back(m.name);
        return n;
    }();
    return names;
}

const MeasuredMedium* findMeasuredMedium(const std::string& name) {
    for (const auto& m : measuredMedia())
        if (m.name == name) return &m;
    return nullptr;
}

double dipoleDiffuseReflectance(double reducedAlbedo, double eta) {
    // Diffuse Fresnel reflectance fit (Egan & Hilgeman 1973, as used by Jensen 2001) and boundary term A.
    const double fdr = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    const double boundary = (1.0 + fdr) / (1.0 - fdr);
    const double root = std::sqrt(3.0 * (1.0 - reducedAlbedo));
    return 0.5 * reducedAlbedo * (1.0 + std::exp(-4.0 / 3.0 * boundary * root)) * std::exp(-root);
}

std::array<double, 3> burleyShapeMm(const std::string& material) {
    std::array<double, 3> d{};
    if (material == "skin") {
        GaussianSumProfile deon(deonSkinLobes(), "d'Eon skin");
        for (int c = 0; c < 3; ++c) d[c] = std::sqrt(deon.secondMoment(c) / 7.0);
        return d;
    }
    const MeasuredMedium* medium = findMeasuredMedium(material);
    SKINLAB_CHECK(medium != nullptr);
    for (int c = 0; c < 3; ++c) {
        const double sigmaA = medium->absorption[c];
        const double sigmaTPrime = sigmaA + medium->reducedScattering[c];
        const double albedo = medium->reducedScattering[c] / sigmaTPrime;
        const double sigmaTr = std::sqrt(3.0 * sigmaA * sigmaTPrime);
        const double diffuseMeanFreePath = 1.0 / sigmaTr;
        const double surfaceAlbedo = dipoleDiffuseReflectance(albedo, kRelativeIndex);
        const double s = 1.85 - surfaceAlbedo + 7.0 * std::pow(std::abs(surfaceAlbedo - 0.8), 3.0);
        d[c] = diffuseMeanFreePath / s;
    }
    return d;
}

} // namespace skinlab::renderer::sss
