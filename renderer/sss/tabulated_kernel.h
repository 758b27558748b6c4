#pragma once
// External tabulated 1-D kernels in the published ".bn" format of Jimenez et al., "Separable Subsurface
// Scattering", CGF 2015 (supplementary material; the thesis loaded exactly these): little-endian float32 F, then F
// float32 values as F/4 rows (r, g, b, x) — per-channel weight and tap offset x in mm, uniform and symmetric.
// The files are data the user points to (sss.profile = "file:PATH"); none is copied into this repository.
#include "renderer/sss/marginal.h"

#include <array>
#include <filesystem>
#include <vector>

namespace skinlab::renderer::sss {

struct TabulatedRow {
    std::array<double, 3> weight; // per channel
    double offsetMm;
};

// Reads a .bn file. InputError naming the file for a missing, truncated or malformed file (count not a multiple of
// 4, size not matching the count, non-finite or negative weights, offsets not uniformly increasing).
std::vector<TabulatedRow> readTabulatedKernel(const std::filesystem::path& path);

// The rows as a piecewise-constant density: row j covers [x_j − Δx/2, x_j + Δx/2] with density w_j / Δx;
// each channel is normalised to sum 1.
class TabulatedMarginal final : public Marginal {
public:
    TabulatedMarginal(std::vector<TabulatedRow> rows, std::string description);
    static TabulatedMarginal fromFile(const std::filesystem::path& path);

    const std::vector<TabulatedRow>& rows() const { return rows_; }

    std::string description() const override { return description_; }
    double density(int channel, double xMm) const override;
    double cumulative(int channel, double xMm) const override;
    double secondMoment(int channel) const override;
    double searchRadiusMm() const override;

private:
    std::vector<TabulatedRow> rows_;
    std::vector<std::array<double, 3>> cumulativeBefore_; // Σ of weights of rows before j
    double spacing_ = 0.0;
    double start_ = 0.0; // left edge of row 0's cell
    std::string description_;
};

} // namespace skinlab::renderer::sss
