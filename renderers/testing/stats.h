// Helpers for statistical tests of sampling routines: adaptive quadrature of densities, a regular grid of bins with
// expected counts integrated from a density, and Pearson's chi-square goodness-of-fit test (sparse bins merged, p-value
// from the regularized upper incomplete gamma function).
#ifndef TYNDALL_TEST_STATS_H
#define TYNDALL_TEST_STATS_H

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

namespace tyndall::test {

// ---------------------------------------------------------------------------------------------------------------------
// Quadrature

namespace detail {

// One step of adaptive Simpson on [a, b] with midpoint m; fa, fm, fb are f at a, m, b and `whole` the Simpson estimate
// over [a, b]. Refines until the halves agree to 15 * tolerance (Richardson), and always to at least 3 levels (8
// pieces) so that a narrow peak between the first nodes is not missed.
template <typename F>
double adaptiveSimpson(const F& f, double a, double m, double b, double fa, double fm, double fb, double whole,
                       double tolerance, double relativeTolerance, int depth) {
    const int minDepth = 3, maxDepth = 30;
    const double lm = 0.5 * (a + m), rm = 0.5 * (m + b);
    const double flm = f(lm), frm = f(rm);
    const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    const double delta = left + right - whole;
    const double allowed = 15.0 * std::max(tolerance, relativeTolerance * std::abs(left + right));
    if (depth >= maxDepth || (depth >= minDepth && std::abs(delta) <= allowed)) return left + right + delta / 15.0;
    return adaptiveSimpson(f, a, lm, m, fa, flm, fm, left, 0.5 * tolerance, relativeTolerance, depth + 1) +
           adaptiveSimpson(f, m, rm, b, fm, frm, fb, right, 0.5 * tolerance, relativeTolerance, depth + 1);
}

}  // namespace detail

// Integral of f over [a, b] (adaptive Simpson) to about `tolerance` absolute or `relativeTolerance` relative error,
// whichever is looser on each subinterval. The relative floor must stay above the integrand's own rounding noise,
// or the refinement never stops: 1e-7 suits integrands evaluated in float (the shared shader math); pass a smaller one
// for double integrands. f must be finite on [a, b]; split the integral at known kinks and peaks for best accuracy.
template <typename F>
double integrate(const F& f, double a, double b, double tolerance = 1e-10, double relativeTolerance = 1e-7) {
    if (a == b) return 0.0;
    const double m = 0.5 * (a + b);
    const double fa = f(a), fm = f(m), fb = f(b);
    const double whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    return detail::adaptiveSimpson(f, a, m, b, fa, fm, fb, whole, tolerance, relativeTolerance, 0);
}

// Integral of f(x, y) over [x0, x1] x [y0, y1], nested adaptive Simpson (y inside), tolerances as in integrate().
template <typename F>
double integrate2D(const F& f, double x0, double x1, double y0, double y1, double tolerance = 1e-10,
                   double relativeTolerance = 1e-7) {
    const double innerTolerance = tolerance / std::max(1e-3, std::abs(x1 - x0));
    const auto inner = [&](double x) {
        return integrate([&](double y) { return f(x, y); }, y0, y1, innerTolerance, relativeTolerance);
    };
    return integrate(inner, x0, x1, tolerance, relativeTolerance);
}

// ---------------------------------------------------------------------------------------------------------------------
// Binning

// A regular nx-by-ny grid of bins over [x0, x1] x [y0, y1], bin index = ix * ny + iy.
struct Grid2D {
    double x0, x1;
    int nx;
    double y0, y1;
    int ny;

    int size() const { return nx * ny; }

    // The bin holding (x, y), or -1 outside the grid. Points within `slack` (relative to the extent) outside are put in
    // the edge bin: float samplers land on the closed end of their range, or an ulp beyond it.
    int index(double x, double y, double slack = 1e-6) const {
        const int ix = cell(x, x0, x1, nx, slack), iy = cell(y, y0, y1, ny, slack);
        return ix < 0 || iy < 0 ? -1 : ix * ny + iy;
    }

    double xEdge(int i) const { return x0 + (x1 - x0) * i / nx; }
    double yEdge(int i) const { return y0 + (y1 - y0) * i / ny; }

    // sampleCount times the integral of `density` (a pdf in (x, y)) over each bin. The quadrature tolerances apply to
    // the probability of a bin; the defaults keep the expected counts of 1e6 samples exact to ~1e-6 relative, far below
    // their statistical fluctuation (>= 1e-3 relative for bins of fewer than 1e6 samples).
    template <typename F>
    std::vector<double> expectedCounts(const F& density, double sampleCount, double tolerance = 1e-10,
                                       double relativeTolerance = 1e-6) const {
        std::vector<double> expected(static_cast<size_t>(size()));
        for (int ix = 0; ix < nx; ++ix) {
            for (int iy = 0; iy < ny; ++iy) {
                const double probability = integrate2D(density, xEdge(ix), xEdge(ix + 1), yEdge(iy), yEdge(iy + 1),
                                                       tolerance, relativeTolerance);
                expected[static_cast<size_t>(ix * ny + iy)] = sampleCount * probability;
            }
        }
        return expected;
    }

private:
    static int cell(double v, double lo, double hi, int n, double slack) {
        const double s = (v - lo) / (hi - lo);
        if (!(s >= -slack && s <= 1.0 + slack)) return -1;  // also rejects NaN
        return std::clamp(static_cast<int>(std::floor(s * n)), 0, n - 1);
    }
};

// Sample counts per bin of a Grid2D. Samples outside the grid (beyond `slack`, see Grid2D::index) are counted apart:
// the tests expect none.
struct Histogram2D {
    explicit Histogram2D(const Grid2D& g, double s = 1e-6)
        : grid(g), slack(s), counts(static_cast<size_t>(g.size()), 0.0) {}

    void add(double x, double y) {
        const int bin = grid.index(x, y, slack);
        if (bin < 0) {
            ++outside;
        } else {
            counts[static_cast<size_t>(bin)] += 1.0;
        }
    }

    Grid2D grid;
    double slack;
    std::vector<double> counts;
    int outside = 0;
};

// ---------------------------------------------------------------------------------------------------------------------
// Incomplete gamma function and chi-square

// Q(a, x) = Gamma(a, x) / Gamma(a), the regularized upper incomplete gamma function, for a > 0, x >= 0. For x < a + 1
// the power series of P = 1 - Q converges fast (A&S 6.5.29: gamma(a, x) = x^a e^-x sum_n x^n / (a (a+1) ... (a+n)));
// beyond, the continued fraction of Gamma(a, x) (A&S 6.5.31), evaluated by the modified Lentz method.
inline double regularizedGammaQ(double a, double x) {
    if (x <= 0.0) return 1.0;
    const double logPrefactor = a * std::log(x) - x - std::lgamma(a);  // log(x^a e^-x / Gamma(a))
    const double epsilon = 1e-15;
    const int maxIterations = 100000;
    if (x < a + 1.0) {
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < maxIterations && std::abs(term) > std::abs(sum) * epsilon; ++n) {
            term *= x / (a + n);
            sum += term;
        }
        return std::clamp(1.0 - sum * std::exp(logPrefactor), 0.0, 1.0);
    }
    // Gamma(a, x) = x^a e^-x / (x + 1 - a - 1 (1 - a) / (x + 3 - a - 2 (2 - a) / (x + 5 - a - ...)))
    const double tiny = 1e-300;
    double b = x + 1.0 - a;
    double c = 1.0 / tiny, d = 1.0 / b, fraction = d;
    for (int n = 1; n < maxIterations; ++n) {
        const double an = -n * (n - a);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        const double step = c * d;
        fraction *= step;
        if (std::abs(step - 1.0) < epsilon) break;
    }
    return std::clamp(fraction * std::exp(logPrefactor), 0.0, 1.0);
}

// P(X >= statistic) for X chi-square distributed with `dof` degrees of freedom.
inline double chiSquarePValue(double statistic, int dof) {
    return regularizedGammaQ(0.5 * dof, 0.5 * statistic);
}

struct ChiSquareResult {
    double statistic = 0.0;
    int dof = 0;  // bins after merging, minus one
    double pValue = 1.0;
    int mergedBins = 0;   // bins with expected count < minExpected, pooled into one
    std::string failure;  // set when the samples cannot come from the expected distribution at all

    std::string describe() const {
        char text[200];
        std::snprintf(text, sizeof text, "chi2 = %.2f, dof = %d, p = %.3g (%d sparse bins pooled)", statistic, dof,
                      pValue, mergedBins);
        return failure.empty() ? std::string(text) : failure + "; " + text;
    }
};

// Pearson's chi-square test of observed counts against expected counts per bin. Bins expected to hold fewer than
// `minExpected` samples are pooled (smallest first) into one bin, which is merged into the smallest regular bin if it
// still holds too few, so that the statistic's chi-square approximation holds. Samples that fell in no bin at all are
// the caller's to count and check.
inline ChiSquareResult chiSquareTest(const std::vector<double>& observed, const std::vector<double>& expected,
                                     double minExpected = 5.0) {
    ChiSquareResult result;
    if (observed.size() != expected.size() || observed.empty()) {
        result.failure = "observed and expected counts differ in size";
        result.pValue = 0.0;
        return result;
    }
    std::vector<size_t> order(expected.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(), [&](size_t i, size_t j) { return expected[i] < expected[j]; });

    // A sample where the density integrates to (nearly) nothing is a failure no pooling should hide.
    for (size_t i : order) {
        if (expected[i] < 1e-9 && observed[i] > 0.0) {
            result.failure = std::to_string(static_cast<long long>(observed[i])) + " samples in bin " +
                             std::to_string(i) + " where none are expected";
            result.pValue = 0.0;
            return result;
        }
    }

    std::vector<double> binObserved, binExpected;
    double pooledObserved = 0.0, pooledExpected = 0.0;
    for (size_t i : order) {
        if (expected[i] < minExpected) {
            pooledObserved += observed[i];
            pooledExpected += expected[i];
            ++result.mergedBins;
        } else {
            binObserved.push_back(observed[i]);
            binExpected.push_back(expected[i]);
        }
    }
    if (pooledExpected > 0.0) {
        if (pooledExpected < minExpected && !binExpected.empty()) {
            binObserved.front() += pooledObserved;  // the smallest regular bin, by the sort
            binExpected.front() += pooledExpected;
        } else {
            binObserved.push_back(pooledObserved);
            binExpected.push_back(pooledExpected);
        }
    }
    for (size_t i = 0; i < binObserved.size(); ++i) {
        const double difference = binObserved[i] - binExpected[i];
        result.statistic += difference * difference / binExpected[i];
    }
    result.dof = static_cast<int>(binObserved.size()) - 1;
    if (result.dof < 1) {
        result.failure = "fewer than two bins after pooling: the test has no power";
        result.pValue = 0.0;
        return result;
    }
    result.pValue = chiSquarePValue(result.statistic, result.dof);
    return result;
}

}  // namespace tyndall::test

#endif  // TYNDALL_TEST_STATS_H
