// The error map of the Pegoraro closed form (docs/pegoraro.md): for each total order and optical distance H, the
// largest relative error of the closed form against quadrature of Eq. 3 over random configurations, in double and in
// float, the largest ratio of actual error to the error bound (<= 1 means the bound holds), and how often the bound
// exceeds the fallback tolerance 1e-4 (those evaluations fall back to quadrature).
//   tyndall_pegoraro_error_map [configurations per cell = 40]
#include "pegoraro/test/closed_form_cases.h"

#include <cstdio>
#include <cstdlib>

using namespace tyndall::pegoraro::test;

int main(int argc, char** argv) {
    const int perCell = argc > 1 ? std::max(1, std::atoi(argv[1])) : 40;
    const int orders[] = {0, 1, 2, 4, 8, 12, 16, 24, 32};
    const double depths[] = {0.01, 0.1, 1.0, 5.0, 20.0, 40.0};
    std::printf(
        "| order | H | max rel. error (double) | max rel. error (float) | error / bound (double, float) | "
        "falls back (double, float) |\n|---|---|---|---|---|---|\n");
    sh::Pcg32 rng = sh::pcg32Seed(314u, 15u);
    for (int order : orders) {
        for (double H : depths) {
            double worstD = 0.0, worstF = 0.0, ratioD = 0.0, ratioF = 0.0;
            int fallbackD = 0, fallbackF = 0;
            for (int i = 0; i < perCell; ++i) {
                const Case c = randomCase(rng, order, H, H, 1e30);
                const double expected = quadrature(c);
                if (!(std::abs(expected) > 1e-30)) continue;  // underflows in float; irrelevant for pixels
                const ClosedFormResult d = closedFormDouble(c), f = closedFormFloat(c);
                const double errorD = std::abs(d.value - expected), errorF = std::abs(f.value - expected);
                worstD = std::max(worstD, errorD / std::abs(expected));
                worstF = std::max(worstF, errorF / std::abs(expected));
                // The quadrature's own error (~1e-10 relative) is removed from the ratios.
                const double floor = 1e-9 * std::abs(expected);
                ratioD = std::max(ratioD, std::max(0.0, errorD - floor) / std::max(d.errorBound, 1e-300));
                ratioF = std::max(ratioF, std::max(0.0, errorF - floor) / std::max(f.errorBound, 1e-300));
                fallbackD += d.errorBound > 1e-4 * std::abs(d.value);
                fallbackF += f.errorBound > 1e-4 * std::abs(f.value);
            }
            std::printf("| %d | %g | %.1e | %.1e | %.2g, %.2g | %d%%, %d%% |\n", order, H, worstD, worstF, ratioD,
                        ratioF, 100 * fallbackD / perCell, 100 * fallbackF / perCell);
        }
    }
    return 0;
}
