#include "renderer/sss/numerical_integration.h"

#include <cmath>

namespace skinlab::renderer::sss {

namespace {
double simpson(double fa, double fm, double fb, double a, double b) { return (b - a) / 6.0 * (fa + 4.0 * fm + fb); }

double adaptive(const std::function<double(double)>& f, double a, double b, double fa, double fm, double fb,
                double whole, double tolerance, int depth) {
    const double m = 0.5 * (a + b);
    const double lm = 0.5 * (a + m);
    const double rm = 0.5 * (m + b);
    const double flm = f(lm);
    const double frm = f(rm);
    const double left = simpson(fa, flm, fm, a, m);
    const double right = simpson(fm, frm, fb, m, b);
    const double delta = left + right - whole;
    // 15 = Richardson factor of Simpson's rule; depth 50 bounds the work near integrable singularities.
    if (depth <= 0 || std::abs(delta) <= 15.0 * tolerance) return left + right + delta / 15.0;
    return adaptive(f, a, m, fa, flm, fm, left, 0.5 * tolerance, depth - 1) +
           adaptive(f, m, b, fm, frm, fb, right, 0.5 * tolerance, depth - 1);
}
} // namespace

double integrate(const std::function<double(double)>& f, double a, double b, double tolerance) {
    if (b == a) return 0.0;
    // Start from 8 panels so that narrow features are not missed by the first Simpson estimate.
    constexpr int panels = 8;
    double sum = 0.0;
    const double h = (b - a) / panels;
    for (int i = 0; i < panels; ++i) {
        const double x0 = a + i * h;
        const double x1 = i + 1 == panels ? b : a + (i + 1) * h;
        const double fa = f(x0);
        const double fb = f(x1);
        const double fm = f(0.5 * (x0 + x1));
        sum += adaptive(f, x0, x1, fa, fm, fb, simpson(fa, fm, fb, x0, x1), tolerance / panels, 50);
    }
    return sum;
}

double integrateToInfinity(const std::function<double(double)>& f, double a, double scale, double tolerance) {
    double sum = 0.0;
    double start = a;
    double length = scale;
    // Pieces double in length; stop once a piece of at least 30 scale lengths adds less than the tolerance.
    for (int piece = 0; piece < 64; ++piece) {
        const double part = integrate(f, start, start + length, tolerance);
        sum += part;
        start += length;
        if (std::abs(part) < tolerance && length >= 30.0 * scale) break;
        length *= 2.0;
    }
    return sum;
}

} // namespace skinlab::renderer::sss
