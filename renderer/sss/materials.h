#pragma once
// Named scattering materials (thesis Fig. 5.3) and how each becomes a diffusion profile.
//  - "skin": d'Eon's six-Gaussian profile; for Burley, d per channel matched to its second moment.
//  - skin1, skin2, marble, apple, ketchup, wholemilk: measured reduced scattering σs' and absorption σa (1/mm) of
//    Jensen, Marschner, Levoy & Hanrahan, "A Practical Model for Subsurface Light Transport", SIGGRAPH 2001,
//    Table 2 (the media of the published separable kernels), turned into Burley's d (docs/methods.md).
#include <array>
#include <string>
#include <vector>

namespace skinlab::renderer::sss {

struct MeasuredMedium {
    std::string name;
    std::array<double, 3> reducedScattering; // σs', 1/mm (R, G, B)
    std::array<double, 3> absorption;        // σa, 1/mm
};

// Names accepted by sss.material, "skin" first.
const std::vector<std::string>& materialNames();
// Jensen et al. 2001 media (not "skin"); nullptr for an unknown name.
const MeasuredMedium* findMeasuredMedium(const std::string& name);

// Burley's shape d (mm) per channel for a material name (must be one of materialNames()).
//  - measured media: diffuse mean free path ℓd = 1/σtr, σtr = √(3 σa σt'), σt' = σa + σs'; surface albedo
//    A = Rd(α') of the dipole (Jensen 2001 Eq. for total diffuse reflectance, η = 1.3); d = ℓd / s(A) with
//    Christensen & Burley's searchlight fit s = 1.85 − A + 7|A − 0.8|³;
//  - "skin": d = √(Σ w_i v_i / 7) (Burley's 1-D variance 7d² equal to d'Eon's Σ w_i v_i per channel).
std::array<double, 3> burleyShapeMm(const std::string& material);

// Total diffuse reflectance of the dipole for reduced albedo α' and relative index η (Jensen et al. 2001).
double dipoleDiffuseReflectance(double reducedAlbedo, double eta);

} // namespace skinlab::renderer::sss
