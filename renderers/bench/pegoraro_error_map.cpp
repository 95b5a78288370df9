// The error map of the Pegoraro closed form (docs/pegoraro.md): for each total order and optical distance H, the
// largest relative error of the closed form against quadrature of Eq. 3 over random configurations, in double and in
// float, the largest ratio of actual error to the error bound (<= 1 means the bound holds), and how often the bound
// exceeds the fallback tolerance 1e-4 (those evaluations fall back to quadrature).
// A second table does the same for Henyey-Greenstein phase functions truncated to a number of Legendre terms, with an
// isotropic light or a spot (exponent 4): the phase functions of lookdev, whose monomial coefficients alternate. It
// compares the a priori error bound (pegoraroSeries alone) with the measured one (after pegoraroSeriesRefine), and
// their fallback rates at the tolerance 1e-4, with only the fallback decision applied to each.
//   tyndall_pegoraro_error_map [configurations per cell = 40]
#include "pegoraro/coefficients.h"
#include "pegoraro/test/closed_form_cases.h"

#include <algorithm>
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

    std::printf(
        "\n| g | terms | light | max rel. error (double) | max error / bound (a priori, measured) | "
        "median bound / error (a priori, measured) | falls back (a priori, measured) "
        "|\n|---|---|---|---|---|---|---|\n");
    for (double g : {0.5, 0.7, 0.9}) {
        for (int terms : {8, 12, 16, 20, 24, 28, 32}) {
            for (bool spot : {false, true}) {
                tyndall::PhaseFunction phase;
                phase.kind = tyndall::PhaseKind::HenyeyGreenstein;
                phase.g = g;
                tyndall::pegoraro::HgSettings hg;
                hg.terms = terms;
                const std::vector<double> hgPolynomial = tyndall::pegoraro::phasePolynomial(phase, hg).c;
                double worst = 0.0, ratioA = 0.0, ratioM = 0.0;
                std::vector<double> looseA, looseM;
                int fallbackA = 0, fallbackM = 0, counted = 0;
                for (int i = 0; i < perCell; ++i) {
                    Case c = randomCase(rng, 0, 1e-2, 20.0, 20.0);
                    c.phase = hgPolynomial;
                    c.lightPoly = spot ? std::vector<double>{1.0 / 16, 4.0 / 16, 6.0 / 16, 4.0 / 16, 1.0 / 16}
                                       : std::vector<double>{1.0};
                    const double expected = quadrature(c);
                    if (!(std::abs(expected) > 1e-30)) continue;
                    sh::PegoraroSeries_double s;
                    const sh::PegoraroPolynomial_double p = toPolynomialD(c.phase), l = toPolynomialD(c.lightPoly);
                    sh::pegoraroSeries(c.del, c.dc, p, l, s);
                    double boundA = 0.0, boundM = 0.0;
                    const double value = sh::pegoraroIntegral(s, c.H, c.ua, c.ub, boundA);
                    sh::pegoraroSeriesRefine(c.del, c.dc, p, l, s);
                    sh::pegoraroIntegral(s, c.H, c.ua, c.ub, boundM);
                    const double error = std::abs(value - expected);
                    const double floor = 1e-9 * std::abs(expected);
                    worst = std::max(worst, error / std::abs(expected));
                    ratioA = std::max(ratioA, std::max(0.0, error - floor) / std::max(boundA, 1e-300));
                    ratioM = std::max(ratioM, std::max(0.0, error - floor) / std::max(boundM, 1e-300));
                    looseA.push_back(boundA / std::max(error, floor));
                    looseM.push_back(boundM / std::max(error, floor));
                    fallbackA += boundA > 1e-4 * std::abs(value);
                    fallbackM += boundM > 1e-4 * std::abs(value);
                    ++counted;
                }
                std::sort(looseA.begin(), looseA.end());
                std::sort(looseM.begin(), looseM.end());
                const auto median = [](const std::vector<double>& v) { return v.empty() ? 0.0 : v[v.size() / 2]; };
                std::printf("| %g | %d | %s | %.1e | %.2g, %.2g | %.2g, %.2g | %d%%, %d%% |\n", g, terms,
                            spot ? "spot 4" : "isotropic", worst, ratioA, ratioM, median(looseA), median(looseM),
                            100 * fallbackA / std::max(counted, 1), 100 * fallbackM / std::max(counted, 1));
            }
        }
    }
    return 0;
}
