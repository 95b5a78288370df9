// S by the boundary form (shaders/shared/ltsd_boundary.h, issue 32's accurate S) against the exact integral of the
// phase function over random polygons, beside the paper's Eq. 21 with the shipped HG table. The reference is
// ltsdPhasePolygonIntegral (adaptive Gauss-Kronrod per edge in double, itself checked against the 2-D quadrature to
// 1e-9 in tools/fit-tables/test); the polygons are 0.01-2 sr, anywhere, on either pole, across the horizon and beside
// the peak (test::sAccuracyPolygons).
#include "polygon_quadrature.h"
#include "shared/ltsd_boundary.h"
#include "tyndall/tables/ltsd_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace tyndall {
namespace {

namespace sh = tyndall::shader;

struct Errors {
    double weighted = 0.0;  // sum |S - exact| / sum exact
    double maxRel = 0.0;    // over the polygons whose exact value exceeds 1e-3
};

template <typename F>
Errors errorsOf(const LtsdPhase& phase, const std::vector<test::TestPolygon>& polygons, const F& s) {
    double sumErr = 0.0, sumExact = 0.0;
    Errors e;
    for (const test::TestPolygon& p : polygons) {
        const double exact = ltsdPhasePolygonIntegral(phase, p.vertices);
        const double err = std::abs(s(test::toShaderPolygon(p)) - exact);
        sumErr += err;
        sumExact += exact;
        if (exact > 1e-3) e.maxRel = std::max(e.maxRel, err / exact);
    }
    e.weighted = sumErr / sumExact;
    return e;
}

// The targets: weighted relative error <= 2e-3 for every g in [-0.95, 0.95] and every polygon above 1e-3
// within 1 %. Measured (3 nodes per edge, 360 polygons): weighted <= 1.8e-5, max 4.4e-4 up to |g| = 0.95, 9e-4 at
// 0.99; the rule is held at 4e-5 (x2) so that a regression fails. The paper's S is held near its own measured error
// (weighted 4-12 %, max 64-97 %: bounds 0.13 and 1.0), and the accurate one must beat it by 100x.
TEST(LtsdBoundaryS, MeetsTheAccuracyTargetsForEveryG) {
    const std::vector<test::TestPolygon> polygons = test::sAccuracyPolygons(32u, 60);
    const LtsdTable table = loadLtsdTable(ltsdTablePath("hg"), "hg");
    std::printf("%6s %12s %12s %12s %12s\n", "g", "accurate", "max rel", "paper", "max rel");
    for (double g : {-0.99, -0.95, -0.9, -0.7, -0.5, -0.2, 0.0, 0.2, 0.5, 0.7, 0.9, 0.95, 0.99}) {
        const LtsdPhase phase{"hg", g};
        const Errors accurate = errorsOf(phase, polygons, [&](const sh::SphericalPolygon& p) {
            return double(sh::ltsdLobeIntegral(p, sh::kLtsdLobeHg, float(g)));
        });
        const Errors paper =
            errorsOf(phase, polygons, [&](const sh::SphericalPolygon& p) { return table.integral(p, g); });
        std::printf("%6.2f %12.3e %12.3e %12.3e %12.3e\n", g, accurate.weighted, accurate.maxRel, paper.weighted,
                    paper.maxRel);
        EXPECT_LE(accurate.weighted, 2e-3) << g;
        EXPECT_LE(accurate.maxRel, 1e-2) << g;
        EXPECT_LE(accurate.weighted, 4e-5) << g;
        EXPECT_LE(paper.weighted, 0.13) << g;
        EXPECT_LE(paper.maxRel, 1.0) << g;
        EXPECT_LT(100.0 * accurate.weighted, paper.weighted) << g;
    }
}

// The other lobes (Rayleigh's mu^2, the Mie presets' ((1 + mu) / 2)^n) and the HG-isotropic mix, with the exact
// isotropic part: ltsdAccuratePhaseIntegral is the whole phase function. Measured: weighted <= 8e-5, max <= 8.6e-4.
TEST(LtsdBoundaryS, IntegratesEveryPhaseTypeWithALobe) {
    const std::vector<test::TestPolygon> polygons = test::sAccuracyPolygons(33u, 30);
    struct Case {
        LtsdPhase phase;
        int lobe;
        double lobeWeight;
    };
    const Case cases[] = {{{"rayleigh"}, sh::kLtsdLobeRayleigh, 0.25},
                          {{"hazy-mie"}, sh::kLtsdLobeMie8, 0.5},
                          {{"murky-mie"}, sh::kLtsdLobeMie32, 0.5},
                          {{"mix", 0.8, 0.6}, sh::kLtsdLobeHg, 0.6},
                          {{"mix", -0.9, 0.3}, sh::kLtsdLobeHg, 0.3}};
    for (const Case& c : cases) {
        const Errors e = errorsOf(c.phase, polygons, [&](const sh::SphericalPolygon& p) {
            return double(sh::ltsdAccuratePhaseIntegral(p, c.lobe, float(c.phase.g), float(c.lobeWeight),
                                                        float(1.0 - c.lobeWeight), 0.0f));
        });
        EXPECT_LE(e.weighted, 2e-3) << c.phase.type << " " << c.phase.g;
        EXPECT_LE(e.maxRel, 1e-2) << c.phase.type << " " << c.phase.g;
    }
}

// Tiny polygons (1e-4 .. 1e-3 sr) in HG's tail, where S is 1e-7: the edge spans are formed without cancelling, so the
// float result keeps its relative accuracy (an earlier form, tau1 - tau0, was 10 % off here).
TEST(LtsdBoundaryS, TinyPolygonsInTheTailKeepTheirRelativeAccuracy) {
    for (const test::TestPolygon& p : test::randomTestPolygons(5u, 6)) {
        if (std::string(p.kind) != "tiny") continue;
        for (double g : {-0.9, 0.5, 0.95}) {
            const double exact = ltsdPhasePolygonIntegral(LtsdPhase{"hg", g}, p.vertices);
            const double s = sh::ltsdLobeIntegral(test::toShaderPolygon(p), sh::kLtsdLobeHg, float(g));
            EXPECT_NEAR(s, exact, 1e-2 * exact) << g;
        }
    }
}

// The CPU entry point (`tables eval`'s sMethods.accurate) for every type with an LTSD form, and the refusal of one
// without.
TEST(LtsdBoundaryS, TheLibrarysEntryPointCoversEveryPhaseType) {
    const std::vector<LtsdPhase> phases = {{"hg", -0.6},      {"hg", 0.9},  {"isotropic"}, {"eddington", 0, 1, 0.7},
                                           {"mix", 0.7, 0.4}, {"rayleigh"}, {"hazy-mie"},  {"murky-mie"}};
    for (const LtsdPhase& phase : phases) {
        for (const test::TestPolygon& p : test::sAccuracyPolygons(34u, 4)) {
            const double exact = ltsdPhasePolygonIntegral(phase, p.vertices);
            EXPECT_NEAR(ltsdAccuratePhaseIntegral(phase, test::toShaderPolygon(p)), exact, 1e-2 * exact + 1e-6)
                << phase.type << " " << p.kind;
        }
    }
    EXPECT_THROW(
        ltsdAccuratePhaseIntegral(LtsdPhase{"legendre"}, test::toShaderPolygon(test::sAccuracyPolygons(1u, 1)[0])),
        std::exception);
}

}  // namespace
}  // namespace tyndall
