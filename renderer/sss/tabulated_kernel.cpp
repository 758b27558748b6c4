#include "renderer/sss/tabulated_kernel.h"

#include "common/error.h"
#include "common/files.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace skinlab::renderer::sss {

namespace {
float readFloat(const std::string& bytes, size_t index) {
    // The format is little-endian, as is every platform skinlab builds on (x86-64, aarch64).
    float v;
    std::memcpy(&v, bytes.data() + 4 * index, 4);
    return v;
}
} // namespace

std::vector<TabulatedRow> readTabulatedKernel(const std::filesystem::path& path) {
    const std::string where = path.string();
    if (!std::filesystem::is_regular_file(path)) throwInput(where, "", "kernel file not found");
    const std::string bytes = readFile(path);
    if (bytes.size() < 4) throwInput(where, "", "truncated: " + std::to_string(bytes.size()) + " bytes, no header");
    const float header = readFloat(bytes, 0);
    if (!std::isfinite(header) || header <= 0.0f || header != std::floor(header) || header > 1e8f)
        throwInput(where, "", "not a .bn kernel: header " + std::to_string(header) + " is not a positive count");
    const auto count = static_cast<size_t>(header);
    if (count % 4 != 0)
        throwInput(where, "", "not a .bn kernel: " + std::to_string(count) + " floats is not a multiple of 4");
    const size_t available = (bytes.size() - 4) / 4;
    if (available < count || (bytes.size() - 4) % 4 != 0)
        throwInput(where, "",
                   "truncated: header says " + std::to_string(count) + " floats, file holds " +
                       std::to_string(available));
    if (available > count)
        throwInput(where, "",
                   "not a .bn kernel: " + std::to_string(available - count) + " floats after the " +
                       std::to_string(count) + " the header announces");
    const size_t rowCount = count / 4;
    if (rowCount < 3) throwInput(where, "", "not a .bn kernel: " + std::to_string(rowCount) + " rows (need ≥ 3)");

    std::vector<TabulatedRow> rows(rowCount);
    for (size_t j = 0; j < rowCount; ++j) {
        for (int c = 0; c < 3; ++c) {
            const float w = readFloat(bytes, 1 + 4 * j + c);
            if (!std::isfinite(w) || w < 0.0f)
                throwInput(where, "",
                           "row " + std::to_string(j) + ": weight " + std::to_string(w) +
                               " is not a finite non-negative number");
            rows[j].weight[c] = w;
        }
        const float x = readFloat(bytes, 1 + 4 * j + 3);
        if (!std::isfinite(x)) throwInput(where, "", "row " + std::to_string(j) + ": offset is not finite");
        rows[j].offsetMm = x;
    }
    // Uniform spacing, relative tolerance 1e-3: the published offsets are float32 multiples of a step.
    const double spacing = (rows.back().offsetMm - rows.front().offsetMm) / double(rowCount - 1);
    if (!(spacing > 0.0)) throwInput(where, "", "offsets are not increasing");
    for (size_t j = 1; j < rowCount; ++j) {
        const double step = rows[j].offsetMm - rows[j - 1].offsetMm;
        if (std::abs(step - spacing) > 1e-3 * spacing + 1e-6)
            throwInput(where, "", "row " + std::to_string(j) + ": offsets are not uniformly spaced");
    }
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (const auto& row : rows) sum += row.weight[c];
        if (!(sum > 0.0)) throwInput(where, "", "channel " + std::to_string(c) + " has no weight");
    }
    return rows;
}

TabulatedMarginal::TabulatedMarginal(std::vector<TabulatedRow> rows, std::string description)
    : rows_(std::move(rows)), description_(std::move(description)) {
    std::array<double, 3> total{0, 0, 0};
    for (const auto& row : rows_)
        for (int c = 0; c < 3; ++c) total[c] += row.weight[c];
    for (auto& row : rows_)
        for (int c = 0; c < 3; ++c) row.weight[c] /= total[c];
    spacing_ = (rows_.back().offsetMm - rows_.front().offsetMm) / double(rows_.size() - 1);
    start_ = rows_.front().offsetMm - 0.5 * spacing_;
    cumulativeBefore_.resize(rows_.size() + 1);
    cumulativeBefore_[0] = {0, 0, 0};
    for (size_t j = 0; j < rows_.size(); ++j)
        for (int c = 0; c < 3; ++c) cumulativeBefore_[j + 1][c] = cumulativeBefore_[j][c] + rows_[j].weight[c];
}

TabulatedMarginal TabulatedMarginal::fromFile(const std::filesystem::path& path) {
    return TabulatedMarginal(readTabulatedKernel(path), "tabulated kernel " + path.filename().string());
}

double TabulatedMarginal::density(int channel, double xMm) const {
    const double cell = (xMm - start_) / spacing_;
    if (cell < 0.0 || cell >= double(rows_.size())) return 0.0;
    return rows_[static_cast<size_t>(cell)].weight[channel] / spacing_;
}

double TabulatedMarginal::cumulative(int channel, double xMm) const {
    const double cell = (xMm - start_) / spacing_;
    if (cell <= 0.0) return 0.0;
    if (cell >= double(rows_.size())) return 1.0;
    const auto j = static_cast<size_t>(cell);
    return cumulativeBefore_[j][channel] + (cell - double(j)) * rows_[j].weight[channel];
}

double TabulatedMarginal::secondMoment(int channel) const {
    // Piecewise-constant density: each cell adds w (x_j² + Δx²/12).
    double sum = 0.0;
    for (const auto& row : rows_)
        sum += row.weight[channel] * (row.offsetMm * row.offsetMm + spacing_ * spacing_ / 12.0);
    return sum;
}

double TabulatedMarginal::searchRadiusMm() const {
    return std::max(std::abs(start_), std::abs(rows_.back().offsetMm + 0.5 * spacing_));
}

} // namespace skinlab::renderer::sss
