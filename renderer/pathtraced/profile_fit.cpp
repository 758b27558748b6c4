#include "renderer/pathtraced/profile_fit.h"

#include "common/error.h"
#include "common/files.h"
#include "renderer/output/display_output.h"
#include "renderer/pathtraced/blender_process.h"
#include "renderer/pathtraced/blender_scene.h"
#include "renderer/pathtraced/cycles_render.h"
#include "renderer/sss/gaussian_sum_profile.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace skinlab::renderer::pathtraced {

EdgeResponse measureEdgeResponse(const EdgeMeasurementSettings& s) {
    if (s.pixels < 16 || s.pixels % 2 != 0)
        throwInput("fit-profile", "pixels", std::to_string(s.pixels) + " must be even and at least 16");
    if (s.rows < 4)
        throwInput("fit-profile", "rows", std::to_string(s.rows) + " is below Blender's smallest image (4 rows)");
    const std::filesystem::path folder = makeWorkFolder("skinlab-profile");
    const nlohmann::json description = {{"settings",
                                         {{"width", s.pixels},
                                          {"height", s.rows},
                                          {"samples", s.samples},
                                          {"seed", s.seed},
                                          {"max_bounces", 8},
                                          // Each pixel the mean of E over its width (a box filter of one
                                          // pixel): ∫E sums pixel means exactly.
                                          {"pixel_filter", "box"},
                                          {"filter_width_px", 1.0},
                                          {"threads", s.threads}}},
                                        {"albedo", s.albedo},
                                        {"radius", {1.0, 1.0, 1.0}},
                                        {"radius_table", s.radiusTable},
                                        {"slab_size", 20.0 * s.halfLengthMm},
                                        {"strip_length", 2.0 * s.halfLengthMm},
                                        {"strip_centre", 0.0},
                                        {"output", "cycles.exr"},
                                        {"record", "cycles.json"}};
    writeFileAtomic(folder / "profile.json", description.dump(1));
    writeFileAtomic(folder / "cycles_scene.py", cyclesScript());
    runBlender(s.blender, folder / "cycles_scene.py", {"profile", (folder / "profile.json").string()}, folder,
               folder / "blender.log");
    int width = 0, height = 0;
    const std::filesystem::path exr = folder / "cycles.exr";
    const auto channels = readExrChannels(exr, width, height);
    if (width != s.pixels || height != s.rows)
        throw InputError(exr.string() + ": Cycles wrote " + std::to_string(width) + "x" + std::to_string(height) +
                         ", expected " + std::to_string(s.pixels) + "x" + std::to_string(s.rows));
    EdgeResponse response;
    const double pixelMm = 2.0 * s.halfLengthMm / s.pixels;
    const int half = s.pixels / 2;
    const char* names[] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        const std::string n = names[c];
        const auto& direct = channelEndingWith(channels, "DiffDir." + n, exr);
        const auto& indirect = channelEndingWith(channels, "DiffInd." + n, exr);
        const auto& color = channelEndingWith(channels, "DiffCol." + n, exr);
        std::vector<double> column(static_cast<std::size_t>(s.pixels), 0.0);
        for (int y = 0; y < s.rows; ++y)
            for (int x = 0; x < s.pixels; ++x) {
                const std::size_t p =
                    static_cast<std::size_t>(y) * static_cast<std::size_t>(s.pixels) + static_cast<std::size_t>(x);
                column[static_cast<std::size_t>(x)] += (direct[p] + indirect[p]) * color[p] / s.rows;
            }
        // Pixel half + k has its centre at (k + 0.5) · pixel; its mirror is half − 1 − k.
        double plateauSum = 0.0;
        std::vector<double> lit(static_cast<std::size_t>(half)), dark(static_cast<std::size_t>(half));
        for (int k = 0; k < half; ++k) {
            dark[static_cast<std::size_t>(k)] = column[static_cast<std::size_t>(half + k)];
            lit[static_cast<std::size_t>(k)] = column[static_cast<std::size_t>(half - 1 - k)];
            plateauSum += dark[static_cast<std::size_t>(k)] + lit[static_cast<std::size_t>(k)];
        }
        const double plateau = plateauSum / half;
        response.plateau[static_cast<std::size_t>(c)] = plateau;
        if (!(plateau > 0.0)) throw InputError(exr.string() + ": the lit slab is black in channel " + n);
        auto& values = response.value[static_cast<std::size_t>(c)];
        values.resize(static_cast<std::size_t>(half));
        for (int k = 0; k < half; ++k)
            values[static_cast<std::size_t>(k)] = dark[static_cast<std::size_t>(k)] / plateau;
    }
    for (int k = 0; k < half; ++k) response.xMm.push_back((k + 0.5) * pixelMm);
    const nlohmann::json record = readRecord(folder / "cycles.json");
    response.blenderVersion = record.value("blender_version", "");
    response.renderSeconds = record.value("render_seconds", 0.0);
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
    return response;
}

double eeveeEdgeResponseAt(double xMm, double radiusMm) {
    const double d = kEeveeBurleyDPerRadius * radiusMm;
    if (!(d > 0.0)) return xMm < 0.0 ? 1.0 : xMm > 0.0 ? 0.0 : 0.5;
    const double limit = kEeveeBurleyTruncation * d;
    if (xMm < 0.0) return 1.0 - eeveeEdgeResponseAt(-xMm, radiusMm);
    if (xMm >= limit) return 0.0;
    // ∫_x^L (e^{−t/d} + e^{−t/3d}) dt = d (e^{−x/d} − e^{−L/d}) + 3d (e^{−x/3d} − e^{−L/3d}); the whole kernel is
    // twice that from 0.
    auto tail = [&](double x) {
        return d * (std::exp(-x / d) - std::exp(-limit / d)) +
               3.0 * d * (std::exp(-x / (3.0 * d)) - std::exp(-limit / (3.0 * d)));
    };
    return tail(xMm) / (2.0 * tail(0.0));
}

EdgeResponse eeveeEdgeResponse() {
    EdgeResponse response;
    const int pixels = 4096;
    const double pixelMm = kEeveeBurleyTruncation * kEeveeBurleyDPerRadius / pixels;
    for (int k = 0; k < pixels; ++k) response.xMm.push_back((k + 0.5) * pixelMm);
    for (int c = 0; c < 3; ++c) {
        for (const double x : response.xMm)
            response.value[static_cast<std::size_t>(c)].push_back(eeveeEdgeResponseAt(x, 1.0));
        response.plateau[static_cast<std::size_t>(c)] = 1.0;
    }
    response.blenderVersion = "analytic";
    return response;
}

double deonEdgeResponse(int channel, double xMm) {
    double e = 0.0;
    for (const sss::GaussianLobe& lobe : sss::deonSkinLobes())
        e += lobe.weight[static_cast<std::size_t>(channel)] * 0.5 * std::erfc(xMm / std::sqrt(2.0 * lobe.varianceMm2));
    return e;
}

double scaledEdgeResponse(const EdgeResponse& response, int channel, double radiusMm, double xMm) {
    const auto& values = response.value[static_cast<std::size_t>(channel)];
    const auto& xs = response.xMm;
    const double u = xMm / radiusMm;
    if (u <= xs.front()) {
        // Between 0 (where E = ½ by symmetry) and the first pixel centre.
        const double t = u / xs.front();
        return 0.5 + t * (values.front() - 0.5);
    }
    if (u >= xs.back()) return 0.0;
    const double pixel = xs[1] - xs[0];
    const double position = (u - xs.front()) / pixel;
    const auto index = static_cast<std::size_t>(position);
    const double t = position - static_cast<double>(index);
    return values[index] * (1.0 - t) + values[std::min(index + 1, values.size() - 1)] * t;
}

namespace {
struct Errors {
    double rms = 0.0;
    double max = 0.0;
};
Errors fitErrors(const EdgeResponse& response, int channel, double radius, double range, double step) {
    Errors e;
    int count = 0;
    for (double x = step; x <= range + 1e-9; x += step) {
        const double d = scaledEdgeResponse(response, channel, radius, x) - deonEdgeResponse(channel, x);
        e.rms += d * d;
        e.max = std::max(e.max, std::abs(d));
        ++count;
    }
    e.rms = std::sqrt(e.rms / count);
    return e;
}
} // namespace

ProfileFit fitRadii(const EdgeResponse& response, const std::array<double, 3>& initialRadiusMm, double range,
                    double step) {
    ProfileFit fit;
    for (int c = 0; c < 3; ++c) {
        auto cost = [&](double logRadius) { return fitErrors(response, c, std::exp(logRadius), range, step).rms; };
        // Coarse scan over 0.01 … 50 mm, then golden-section search around the best cell.
        double bestLog = std::log(0.01), bestCost = cost(bestLog);
        const int cells = 120;
        const double low = std::log(0.01), high = std::log(50.0), cell = (high - low) / cells;
        for (int i = 1; i <= cells; ++i) {
            const double l = low + i * cell;
            const double v = cost(l);
            if (v < bestCost) bestCost = v, bestLog = l;
        }
        double a = bestLog - cell, b = bestLog + cell;
        const double g = (std::sqrt(5.0) - 1.0) / 2.0;
        double x1 = b - g * (b - a), x2 = a + g * (b - a);
        double f1 = cost(x1), f2 = cost(x2);
        for (int i = 0; i < 60; ++i) {
            if (f1 < f2) b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = cost(x1);
            else a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = cost(x2);
        }
        const double radius = std::exp(0.5 * (a + b));
        const Errors e = fitErrors(response, c, radius, range, step);
        fit.radiusMm[static_cast<std::size_t>(c)] = radius;
        fit.rmsError[static_cast<std::size_t>(c)] = e.rms;
        fit.maxError[static_cast<std::size_t>(c)] = e.max;
        fit.initialRmsError[static_cast<std::size_t>(c)] =
            fitErrors(response, c, initialRadiusMm[static_cast<std::size_t>(c)], range, step).rms;
    }
    return fit;
}

double deonEdgeIntegral(int channel) {
    double integral = 0.0;
    for (const sss::GaussianLobe& lobe : sss::deonSkinLobes())
        integral += lobe.weight[static_cast<std::size_t>(channel)] * std::sqrt(lobe.varianceMm2) /
                    std::sqrt(2.0 * 3.14159265358979323846);
    return integral;
}

double deonCrossing(int channel, double level) {
    double low = 0.0, high = 100.0; // E decreases from ½ at 0
    for (int i = 0; i < 100; ++i) {
        const double middle = 0.5 * (low + high);
        (deonEdgeResponse(channel, middle) > level ? low : high) = middle;
    }
    return 0.5 * (low + high);
}

double edgeIntegral(const EdgeResponse& response, int channel, double radiusMm) {
    const auto& values = response.value[static_cast<std::size_t>(channel)];
    const double pixel = response.xMm.size() > 1 ? response.xMm[1] - response.xMm[0] : 2.0 * response.xMm.front();
    double sum = 0.0;
    for (const double v : values) sum += v;
    return radiusMm * sum * pixel;
}

double edgeCrossing(const EdgeResponse& response, int channel, double radiusMm, double level) {
    const auto& values = response.value[static_cast<std::size_t>(channel)];
    const auto& xs = response.xMm;
    double previousX = 0.0, previousE = 0.5;
    for (std::size_t k = 0; k < values.size(); ++k) {
        if (values[k] <= level) {
            const double t = previousE == values[k] ? 0.0 : (previousE - level) / (previousE - values[k]);
            return radiusMm * (previousX + t * (xs[k] - previousX));
        }
        previousX = xs[k];
        previousE = values[k];
    }
    return radiusMm * xs.back();
}

ProfileMatch matchProfile(const EdgeResponse& response, const std::array<double, 3>& radiusMm, double range,
                          double step) {
    ProfileMatch match;
    match.radiusMm = radiusMm;
    for (int c = 0; c < 3; ++c) {
        const auto i = static_cast<std::size_t>(c);
        const Errors e = fitErrors(response, c, radiusMm[i], range, step);
        match.rmsError[i] = e.rms;
        match.maxError[i] = e.max;
        match.integralError[i] = edgeIntegral(response, c, radiusMm[i]) / deonEdgeIntegral(c) - 1.0;
        match.crossingError[i] = edgeCrossing(response, c, radiusMm[i], 0.1) / deonCrossing(c, 0.1) - 1.0;
    }
    return match;
}

std::vector<double> smoothRadii(const std::vector<double>& albedo, const std::vector<double>& radiusMm, int degree,
                                double* rmsLogResidual) {
    const std::size_t n = albedo.size(), m = static_cast<std::size_t>(degree) + 1;
    if (radiusMm.size() != n || n < m) throw InputError("smoothRadii: need at least degree + 1 albedos and radii");
    // Normal equations in t = albedo mapped onto [−1, 1] (well conditioned for the small degrees used).
    const double low = *std::min_element(albedo.begin(), albedo.end());
    const double high = *std::max_element(albedo.begin(), albedo.end());
    auto toT = [&](double a) { return high > low ? 2.0 * (a - low) / (high - low) - 1.0 : 0.0; };
    std::vector<std::vector<double>> a(m, std::vector<double>(m + 1, 0.0));
    for (std::size_t k = 0; k < n; ++k) {
        std::vector<double> power(m, 1.0);
        for (std::size_t i = 1; i < m; ++i) power[i] = power[i - 1] * toT(albedo[k]);
        for (std::size_t i = 0; i < m; ++i) {
            for (std::size_t j = 0; j < m; ++j) a[i][j] += power[i] * power[j];
            a[i][m] += power[i] * std::log(radiusMm[k]);
        }
    }
    for (std::size_t i = 0; i < m; ++i) { // Gauss-Jordan with partial pivoting
        std::size_t pivot = i;
        for (std::size_t r = i + 1; r < m; ++r)
            if (std::abs(a[r][i]) > std::abs(a[pivot][i])) pivot = r;
        std::swap(a[i], a[pivot]);
        if (a[i][i] == 0.0) throw InputError("smoothRadii: the albedos do not determine the polynomial");
        for (std::size_t r = 0; r < m; ++r) {
            if (r == i) continue;
            const double f = a[r][i] / a[i][i];
            for (std::size_t c = i; c <= m; ++c) a[r][c] -= f * a[i][c];
        }
    }
    std::vector<double> smoothed;
    double squares = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        double value = 0.0, power = 1.0;
        for (std::size_t i = 0; i < m; ++i) value += a[i][m] / a[i][i] * power, power *= toT(albedo[k]);
        squares += (std::log(radiusMm[k]) - value) * (std::log(radiusMm[k]) - value);
        smoothed.push_back(std::exp(value));
    }
    if (rmsLogResidual) *rmsLogResidual = std::sqrt(squares / static_cast<double>(n));
    return smoothed;
}

EdgeResponse readEdgeResponseCsv(const std::filesystem::path& path) {
    const std::string text = readFile(path);
    EdgeResponse response;
    std::size_t line = 0, start = 0;
    while (start < text.size()) {
        std::size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        const std::string row = text.substr(start, end - start);
        start = end + 1;
        if (line++ == 0 || row.empty()) continue; // the header
        std::array<double, 4> v{};
        if (std::sscanf(row.c_str(), "%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3]) != 4)
            throw InputError(path.string() + ":" + std::to_string(line) + ": expected x,E_R,E_G,E_B");
        response.xMm.push_back(v[0]);
        for (std::size_t c = 0; c < 3; ++c) response.value[c].push_back(v[c + 1]);
    }
    if (response.xMm.size() < 2) throw InputError(path.string() + ": fewer than two rows");
    return response;
}

void writeFitPlot(const std::filesystem::path& path, const EdgeResponse& response, const ProfileFit& fit,
                  double rangeMm) {
    const int width = 720, height = 480, left = 60, right = 20, top = 20, bottom = 40;
    std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width * height * 3), 255);
    auto plot = [&](int x, int y, std::array<std::uint8_t, 3> color) {
        if (x < 0 || y < 0 || x >= width || y >= height) return;
        std::uint8_t* p = &rgb[static_cast<std::size_t>((y * width + x) * 3)];
        p[0] = color[0], p[1] = color[1], p[2] = color[2];
    };
    const double logLow = std::log10(1e-4), logHigh = std::log10(0.5);
    auto toPixelX = [&](double x) {
        return left + static_cast<int>(std::lround(x / rangeMm * (width - left - right)));
    };
    auto toPixelY = [&](double e) {
        const double l = std::clamp(std::log10(std::max(e, 1e-6)), logLow, logHigh);
        return top + static_cast<int>(std::lround((logHigh - l) / (logHigh - logLow) * (height - top - bottom)));
    };
    // Axes, a grid line per mm and per decade.
    for (int mm = 0; mm <= static_cast<int>(rangeMm); ++mm)
        for (int y = top; y < height - bottom; ++y)
            plot(toPixelX(mm), y,
                 mm == 0 ? std::array<std::uint8_t, 3>{0, 0, 0} : std::array<std::uint8_t, 3>{220, 220, 220});
    for (int decade = -4; decade <= -1; ++decade)
        for (int x = left; x < width - right; ++x) plot(x, toPixelY(std::pow(10.0, decade)), {220, 220, 220});
    for (int x = left; x < width - right; ++x) plot(x, height - bottom, {0, 0, 0});
    const std::array<std::array<std::uint8_t, 3>, 3> colors{{{200, 30, 30}, {30, 150, 30}, {30, 60, 200}}};
    for (int c = 0; c < 3; ++c) {
        int previousMeasured = -1, previousDeon = -1;
        for (int px = left; px < width - right; ++px) {
            const double x = (px - left) * rangeMm / (width - left - right);
            const int measured =
                toPixelY(scaledEdgeResponse(response, c, fit.radiusMm[static_cast<std::size_t>(c)], x));
            const int deon = toPixelY(deonEdgeResponse(c, x));
            auto segment = [&](int from, int to, bool dashed) {
                if (dashed && ((px / 6) % 2 == 1)) return;
                if (from < 0) from = to;
                for (int y = std::min(from, to); y <= std::max(from, to); ++y)
                    for (int t = 0; t < 2; ++t) plot(px, y + t, colors[static_cast<std::size_t>(c)]);
            };
            segment(previousMeasured, measured, false);
            segment(previousDeon, deon, true);
            previousMeasured = measured;
            previousDeon = deon;
        }
    }
    writePng(path, width, height, rgb);
}

} // namespace skinlab::renderer::pathtraced
