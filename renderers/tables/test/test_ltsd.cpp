// Tests of the LTSD math shared by GLSL and C++ (shaders/shared/ltsd.h): the polygon integrals of the clamped and the
// inverse clamped cosine against quadrature, the inverse clamped cosine's sampler, the normalisation of transformed
// distributions and the M^-1 convention of Eq. 7, the horizon split of Eq. 21, and the table fetch of Eq. 24.
#include "polygon_quadrature.h"
#include "shared/ltsd.h"
#include "shared/rng.h"
#include "stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace tyndall {
namespace {

namespace sh = tyndall::shader;
using glm::dvec3;
constexpr double kPi = std::numbers::pi;

sh::LtsdEntry entryFrom(const glm::mat3& m, int source, float amplitude = 1.0f) {
    sh::LtsdEntry e{};
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) e.m[3 * c + r] = m[c][r];
    e.amplitude = amplitude;
    e.source = source;
    return e;
}

// Matrices of the kinds a fit produces (diag(m, m, 1)) and general ones with det > 0 (shear, rotation about z, an
// anisotropic scale), to check Eq. 7's convention beyond the symmetric case.
std::vector<glm::mat3> testMatrices() {
    return {glm::mat3(1.0f),
            glm::mat3(glm::vec3(0.2f, 0, 0), glm::vec3(0, 0.2f, 0), glm::vec3(0, 0, 1)),
            glm::mat3(glm::vec3(3.0f, 0, 0), glm::vec3(0, 3.0f, 0), glm::vec3(0, 0, 1)),
            glm::mat3(glm::vec3(0.5f, 0.1f, 0), glm::vec3(-0.2f, 0.8f, 0), glm::vec3(0.3f, -0.1f, 1.0f))};
}

// ---------------------------------------------------------------------------------------------------------------------
// Polygon integrals against quadrature

// The clamped cosine, the solid angle and the inverse clamped cosine over random polygons of every kind (including
// those straddling the horizon, whose part below it must be clipped), against adaptive quadrature of z / pi, 1 and
// (1 - z) / pi over the polygon clipped in double. The issue asks for 1e-6 on the clamped cosine; float edge sums over
// up to 9 edges hold it (each term's rounding is ~1e-7 of at most pi / 2 pi). The solid angle's float fan loses a few
// 1e-7 relative per triangle, so the inverse clamped cosine, Omega / pi - E, is held to 3e-6.
TEST(LtsdPolygon, ClampedCosineMatchesQuadrature) {
    int checked = 0;
    for (const test::TestPolygon& p : test::randomTestPolygons(17u, 4)) {
        const sh::SphericalPolygon s = test::toShaderPolygon(p);
        const double cosine = test::integrateOverHalf(p.vertices, 1.0, [](const dvec3& w) { return w.z / kPi; }, 1e-12, 1e-10);
        const double solidAngle = test::integrateOverPolygon(p.centre, p.vertices, [](const dvec3&) { return 1.0; });
        const double inverse =
            test::integrateOverHalf(p.vertices, 1.0, [](const dvec3& w) { return (1.0 - w.z) / kPi; }, 1e-12, 1e-10);
        EXPECT_NEAR(sh::ltsdClampedCosineIntegral(s), cosine, 1e-6) << p.kind;
        EXPECT_NEAR(sh::ltsdSolidAngle(s), solidAngle, 1e-6 * std::max(1.0, solidAngle)) << p.kind;
        EXPECT_NEAR(sh::ltsdInverseClampedCosineIntegral(s), inverse, 3e-6) << p.kind;
        // Vertex order does not matter.
        sh::SphericalPolygon reversed = s;
        for (int i = 0; i < s.count; ++i) reversed.v[i] = s.v[s.count - 1 - i];
        EXPECT_NEAR(sh::ltsdClampedCosineIntegral(reversed), cosine, 1e-6) << p.kind;
        ++checked;
    }
    EXPECT_EQ(checked, 24);
}

// The whole upper hemisphere as a polygon (a square on the horizon, vertices at z = 0, and one above): E = 1, the
// inverse clamped cosine's total is 1, and a polygon entirely below the horizon gives 0.
TEST(LtsdPolygon, HemisphereTotals) {
    sh::SphericalPolygon below{};
    below.count = 3;
    below.v[0] = sh::vec3(1, 0, -0.2f), below.v[1] = sh::vec3(0, 1, -0.2f), below.v[2] = sh::vec3(0, 0, -1);
    EXPECT_EQ(sh::ltsdClampedCosineIntegral(below), 0.0f);
    EXPECT_EQ(sh::ltsdInverseClampedCosineIntegral(below), 0.0f);
    // Four octant triangles of the upper hemisphere.
    double e = 0.0, inv = 0.0, omega = 0.0;
    const sh::vec3 axes[4] = {sh::vec3(1, 0, 0), sh::vec3(0, 1, 0), sh::vec3(-1, 0, 0), sh::vec3(0, -1, 0)};
    for (int i = 0; i < 4; ++i) {
        sh::SphericalPolygon t{};
        t.count = 3;
        t.v[0] = axes[i], t.v[1] = axes[(i + 1) % 4], t.v[2] = sh::vec3(0, 0, 1);
        e += sh::ltsdClampedCosineIntegral(t);
        inv += sh::ltsdInverseClampedCosineIntegral(t);
        omega += sh::ltsdSolidAngle(t);
    }
    EXPECT_NEAR(e, 1.0, 1e-6);
    EXPECT_NEAR(inv, 1.0, 1e-6);
    EXPECT_NEAR(omega, 2.0 * kPi, 1e-5);
}

// ---------------------------------------------------------------------------------------------------------------------
// The inverse clamped cosine's sampler and density

// Chi-square in (z, phi), 20 x 10 bins, 1M samples, against the density (1 - z) / pi; and the density integrates to 1
// over the hemisphere.
TEST(LtsdInverseClampedCosine, SamplerMatchesPdf) {
    const int sampleCount = 1000000;
    test::Histogram2D histogram(test::Grid2D{0.0, 1.0, 20, 0.0, 2.0 * kPi, 10});
    sh::Pcg32 rng = sh::pcg32Seed(31u, 0u);
    for (int i = 0; i < sampleCount; ++i) {
        const dvec3 d(sh::ltsdSampleInverseClampedCosine(sh::vec2(sh::pcg32NextFloat(rng), sh::pcg32NextFloat(rng))));
        ASSERT_NEAR(glm::length(d), 1.0, 1e-6);
        double phi = std::atan2(d.y, d.x);
        if (phi < 0.0) phi += 2.0 * kPi;
        histogram.add(d.z, phi);
    }
    EXPECT_EQ(histogram.outside, 0);
    const auto pdf = [](double z, double) { return double(sh::ltsdSourceEval(sh::kLtsdSourceInverseClampedCosine, float(z))); };
    const auto expected = histogram.grid.expectedCounts(pdf, sampleCount);
    const test::ChiSquareResult chi2 = test::chiSquareTest(histogram.counts, expected);
    EXPECT_GT(chi2.pValue, 1e-3) << chi2.describe();
    const double total = test::integrate([&](double z) { return 2.0 * kPi * pdf(z, 0.0); }, 0.0, 1.0);
    EXPECT_NEAR(total, 1.0, 1e-6);
}

// ---------------------------------------------------------------------------------------------------------------------
// Transformed distributions

// Each transformed source integrates to 1 over the sphere (Eq. 6's Jacobian), for both sources and every test matrix.
// Quadrature in (z, phi) with the peak's axis M e_z refined by the adaptive rule; tolerance 1e-4 for the sharpest
// (m = 0.2, a lobe 25 times narrower than the source), evaluated in float.
TEST(LtsdTransformed, IntegratesToOne) {
    for (int source : {sh::kLtsdSourceClampedCosine, sh::kLtsdSourceInverseClampedCosine}) {
        for (const glm::mat3& m : testMatrices()) {
            const sh::LtsdEntry e = entryFrom(m, source);
            const auto f = [&](double z, double phi) {
                return double(sh::ltsdEval(e, sh::vec3(test::unitFromAngles(z, phi))));
            };
            const double total = test::integrate2D(f, -1.0, 1.0, 0.0, 2.0 * kPi, 1e-8, 1e-6);
            EXPECT_NEAR(total, 1.0, 1e-4) << "source " << source << " m00 " << m[0][0];
        }
    }
}

// Eq. 7 with P_o = M^-1 P: the polygon integral from the transformed polygon equals quadrature of the transformed
// density over the polygon. This fails if the vertices were transformed by M instead of M^-1.
TEST(LtsdTransformed, PolygonIntegralMatchesQuadratureOfDensity) {
    for (int source : {sh::kLtsdSourceClampedCosine, sh::kLtsdSourceInverseClampedCosine}) {
        for (const glm::mat3& m : testMatrices()) {
            const sh::LtsdEntry e = entryFrom(m, source);
            for (const test::TestPolygon& p : test::randomTestPolygons(23u, 1)) {
                // The density is evaluated in float: tolerances above its rounding noise, or the refinement never ends.
                const auto density = [&](const dvec3& w) { return double(sh::ltsdEval(e, sh::vec3(w))); };
                const double exact = test::integrateOverHalf(p.vertices, 1.0, density, 1e-8, 1e-6);
                EXPECT_NEAR(sh::ltsdPolygonIntegral(e, test::toShaderPolygon(p)), exact, 2e-5 + 1e-4 * exact)
                    << p.kind << " source " << source << " m00 " << m[0][0];
            }
        }
    }
}

// Eq. 21's horizon split: S with an upper and a lower entry equals quadrature of a_u D_u above the horizon plus a_l D_l
// (mirrored, M_l = diag(1, 1, -1) T) below it, over polygons that straddle it.
TEST(LtsdS, HorizonSplitMatchesQuadrature) {
    const sh::LtsdEntry upper = entryFrom(testMatrices()[1], sh::kLtsdSourceClampedCosine, 0.7f);
    const sh::LtsdEntry lower = entryFrom(testMatrices()[2], sh::kLtsdSourceInverseClampedCosine, 0.3f);
    const auto density = [&](const dvec3& w) {
        if (w.z >= 0.0) return 0.7 * double(sh::ltsdEval(upper, sh::vec3(w)));
        return 0.3 * double(sh::ltsdEval(lower, sh::vec3(float(w.x), float(w.y), float(-w.z))));
    };
    for (const test::TestPolygon& p : test::randomTestPolygons(29u, 2)) {
        const double exact = test::integrateOverHalf(p.vertices, 1.0, density, 1e-8, 1e-6) +
                             test::integrateOverHalf(p.vertices, -1.0, density, 1e-8, 1e-6);
        EXPECT_NEAR(sh::ltsdS(test::toShaderPolygon(p), upper, lower), exact, 2e-5 + 1e-4 * exact) << p.kind;
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Table fetch (Eq. 24)

TEST(LtsdFetch, PicksTheHalvesOfEquation24AndClamps) {
    const int n = 128;
    const float gMax = 0.99f;
    // g < 0: M_u from T_1, M_l from T_2(|g|); g >= 0: M_u from T_2, M_l from T_1(-g); g = 0 exactly: T_2(0) and T_1(0).
    EXPECT_LT(sh::ltsdFetchUpper(-0.5f, n, gMax).i0, n);
    EXPECT_GE(sh::ltsdFetchLower(-0.5f, n, gMax).i0, n);
    EXPECT_GE(sh::ltsdFetchUpper(0.5f, n, gMax).i0, n);
    EXPECT_LT(sh::ltsdFetchLower(0.5f, n, gMax).i0, n);
    const sh::LtsdFetch u0 = sh::ltsdFetchUpper(0.0f, n, gMax), l0 = sh::ltsdFetchLower(0.0f, n, gMax);
    EXPECT_EQ(u0.i0, n);
    EXPECT_FLOAT_EQ(u0.w, 0.0f);
    EXPECT_EQ(l0.i1, n - 1);
    EXPECT_FLOAT_EQ(l0.w, 1.0f);
    // Entry k of T_2 sits at g = gMax k / (n - 1); the lower fetch at -g finds the same coordinate in T_1 mirrored.
    const float g = gMax * 37.0f / float(n - 1);
    const sh::LtsdFetch a = sh::ltsdFetchUpper(g, n, gMax);
    EXPECT_EQ(a.i0 + (a.w > 0.5f ? 1 : 0), n + 37);
    // Clamped at the ends: beyond gMax the last entry, weight 1.
    const sh::LtsdFetch end = sh::ltsdFetchUpper(0.999f, n, gMax);
    EXPECT_EQ(end.i1, 2 * n - 1);
    EXPECT_FLOAT_EQ(end.w, 1.0f);
    const sh::LtsdFetch start = sh::ltsdFetchUpper(-1.0f, n, gMax);
    EXPECT_EQ(start.i0, 0);
    EXPECT_FLOAT_EQ(start.w, 0.0f);
}

}  // namespace
}  // namespace tyndall
