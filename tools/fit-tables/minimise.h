// A one-dimensional minimiser shared by the LTSD and LTC fitters: deterministic (a fixed scan, then a fixed number of
// golden-section steps), so that tables re-fit bit for bit.
#pragma once

namespace tyndall::tables {

inline constexpr double kGoldenFraction = 0.61803398874989484820;  // (sqrt 5 - 1) / 2

// Minimises f over y in [lo, hi]: a scan with the given step, then golden-section search around the best point.
template <typename F>
double minimise1D(const F& f, double lo, double hi, double step) {
    double best = lo, bestValue = f(lo);
    for (double y = lo + step; y <= hi + 1e-12; y += step) {
        const double v = f(y);
        if (v < bestValue) best = y, bestValue = v;
    }
    double a = best - step, b = best + step;
    double c = b - kGoldenFraction * (b - a), d = a + kGoldenFraction * (b - a);
    double fc = f(c), fd = f(d);
    for (int i = 0; i < 60; ++i) {
        if (fc < fd) {
            b = d, d = c, fd = fc;
            c = b - kGoldenFraction * (b - a);
            fc = f(c);
        } else {
            a = c, c = d, fc = fd;
            d = a + kGoldenFraction * (b - a);
            fd = f(d);
        }
    }
    const double y = 0.5 * (a + b);
    return f(y) <= bestValue ? y : best;
}

}  // namespace tyndall::tables
