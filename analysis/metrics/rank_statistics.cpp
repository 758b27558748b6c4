#include "analysis/metrics/rank_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace skinlab::metrics {
namespace {

constexpr double notANumber = std::numeric_limits<double>::quiet_NaN();

// The continued fraction of the regularized incomplete beta function (modified Lentz's method; Press et al.,
// Numerical Recipes, 3rd ed., § 6.4), converging for x < (a + 1)/(a + b + 2).
double betaContinuedFraction(double a, double b, double x) {
    constexpr double tiny = 1e-300;
    constexpr double epsilon = 1e-15;
    const double qab = a + b;
    const double qap = a + 1.0;
    const double qam = a - 1.0;
    double c = 1.0;
    double d = 1.0 - qab * x / qap;
    if (std::abs(d) < tiny) d = tiny;
    d = 1.0 / d;
    double h = d;
    for (int m = 1; m <= 1000; ++m) {
        const double m2 = 2.0 * m;
        double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if (std::abs(d) < tiny) d = tiny;
        c = 1.0 + aa / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        h *= d * c;
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if (std::abs(d) < tiny) d = tiny;
        c = 1.0 + aa / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        const double delta = d * c;
        h *= delta;
        if (std::abs(delta - 1.0) < epsilon) break;
    }
    return h;
}

// I_x(a, b), the regularized incomplete beta function.
double regularizedBeta(double a, double b, double x) {
    if (x <= 0.0) return 0.0;
    if (x >= 1.0) return 1.0;
    const double front =
        std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
    if (x < (a + 1.0) / (a + b + 2.0)) return front * betaContinuedFraction(a, b, x) / a;
    return 1.0 - front * betaContinuedFraction(b, a, 1.0 - x) / b;
}

} // namespace

double studentTCdf(double t, double degreesOfFreedom) {
    if (!(degreesOfFreedom > 0.0) || std::isnan(t)) return notANumber;
    if (std::isinf(t)) return t > 0.0 ? 1.0 : 0.0;
    // P(|T| > |t|) = I_{ν/(ν+t²)}(ν/2, 1/2).
    const double tail =
        0.5 * regularizedBeta(0.5 * degreesOfFreedom, 0.5, degreesOfFreedom / (degreesOfFreedom + t * t));
    return t >= 0.0 ? 1.0 - tail : tail;
}

double studentTQuantile(double probability, double degreesOfFreedom) {
    if (!(probability > 0.0 && probability < 1.0) || !(degreesOfFreedom > 0.0)) return notANumber;
    if (probability == 0.5) return 0.0;
    if (probability < 0.5) return -studentTQuantile(1.0 - probability, degreesOfFreedom);
    double low = 0.0;
    double high = 1.0;
    while (studentTCdf(high, degreesOfFreedom) < probability && high < 1e300) high *= 2.0;
    for (int iteration = 0; iteration < 200 && high - low > 1e-13 * high; ++iteration) {
        const double middle = 0.5 * (low + high);
        (studentTCdf(middle, degreesOfFreedom) < probability ? low : high) = middle;
    }
    return 0.5 * (low + high);
}

double sampleQuantile(std::vector<double> values, double probability) {
    std::erase_if(values, [](double v) { return !std::isfinite(v); });
    if (values.empty() || !(probability >= 0.0 && probability <= 1.0)) return notANumber;
    std::sort(values.begin(), values.end());
    const double h = static_cast<double>(values.size() - 1) * probability;
    const auto below = static_cast<std::size_t>(std::floor(h));
    const std::size_t above = std::min(below + 1, values.size() - 1);
    return values[below] + (h - static_cast<double>(below)) * (values[above] - values[below]);
}

std::array<double, 2> percentileInterval(std::vector<double> replicates, double level) {
    std::erase_if(replicates, [](double v) { return !std::isfinite(v); });
    if (replicates.size() < 2 || !(level > 0.0 && level < 1.0)) return {notANumber, notANumber};
    return {sampleQuantile(replicates, 0.5 * (1.0 - level)), sampleQuantile(replicates, 0.5 * (1.0 + level))};
}

double upperTukeyFence(const std::vector<double>& values) {
    const auto finite = std::count_if(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
    if (finite < 4) return notANumber;
    const double q1 = sampleQuantile(values, 0.25);
    const double q3 = sampleQuantile(values, 0.75);
    return q3 + 1.5 * (q3 - q1);
}

std::vector<std::size_t> smallestIndices(const std::vector<double>& values, std::size_t count) {
    std::vector<std::size_t> indices;
    for (std::size_t i = 0; i < values.size(); ++i)
        if (std::isfinite(values[i])) indices.push_back(i);
    std::stable_sort(indices.begin(), indices.end(),
                     [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
    if (indices.size() > count) indices.resize(count);
    return indices;
}

} // namespace skinlab::metrics
