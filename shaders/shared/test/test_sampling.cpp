// Tests of the sampling math shared by GLSL and C++: the chi-square helpers of stats.h themselves, the direction
// samplers and frames of shaders/shared/sampling.h, equiangular sampling (plain and shaped, shaped_equiangular.h) and
// spherical-triangle sampling, the jitter about a
// point light's image of singular_pixel.h, the GGX and Lambertian
// BSDFs of bsdf.h (normalisation, furnace tests, samplers), and the random numbers of rng.h (PCG32, Sobol nets).
#include "shared/bsdf.h"
#include "shared/phase.h"
#include "shared/rng.h"
#include "shared/sampling.h"
#include "shared/shaped_equiangular.h"
#include "shared/singular_pixel.h"

#include "stats.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace tyndall {
namespace {

namespace sh = tyndall::shader;

using glm::dvec3;

constexpr double kPi = std::numbers::pi;

// Every chi-square test below runs several configurations; each is tested at kFamilyAlpha / configurations
// (Bonferroni), so that a correct sampler fails a whole test with probability below kFamilyAlpha.
constexpr double kFamilyAlpha = 1e-3;

sh::vec2 nextVec2(sh::Pcg32& rng) {
    return sh::vec2(sh::pcg32NextFloat(rng), sh::pcg32NextFloat(rng));
}

// A unit direction from spherical coordinates about +z.
dvec3 fromSpherical(double cosTheta, double phi) {
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    return dvec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
}

// The azimuth of d about +z, in [0, 2 pi).
double azimuth(const dvec3& d) {
    const double phi = std::atan2(d.y, d.x);
    return phi < 0.0 ? phi + 2.0 * kPi : phi;
}

// ---------------------------------------------------------------------------------------------------------------------
// stats.h: the incomplete gamma function and the chi-square test

// Q(n, x) for integer n in closed form: e^-x sum_{k < n} x^k / k!.
double gammaQIntegerReference(int n, double x) {
    double term = 1.0, sum = 1.0;
    for (int k = 1; k < n; ++k) {
        term *= x / k;
        sum += term;
    }
    return std::exp(-x) * sum;
}

// Against closed forms (Q(1, x) = e^-x, Q(1/2, x) = erfc(sqrt(x)), Q(n, x) for integer n) on both sides of x = a + 1,
// where the implementation switches from the series to the continued fraction, and against tabulated chi-square
// critical values. Tolerance 1e-10 relative (1e-6 for the tables, given to 7 digits): both methods converge to ~1e-15.
TEST(SamplingStats, IncompleteGammaMatchesKnownValues) {
    for (double x : {0.0, 0.01, 0.5, 1.0, 2.5, 7.0, 30.0}) {
        SCOPED_TRACE(x);
        EXPECT_NEAR(test::regularizedGammaQ(1.0, x), std::exp(-x), 1e-10 * std::exp(-x));
        EXPECT_NEAR(test::regularizedGammaQ(0.5, x), std::erfc(std::sqrt(x)), 1e-10 * std::erfc(std::sqrt(x)));
    }
    for (int n : {2, 5, 25, 100}) {
        for (double scale : {0.3, 0.9, 1.0, 1.1, 1.5, 3.0}) {
            const double x = scale * n;
            SCOPED_TRACE(std::to_string(n) + ", " + std::to_string(x));
            const double reference = gammaQIntegerReference(n, x);
            EXPECT_NEAR(test::regularizedGammaQ(n, x), reference, 1e-10 * reference + 1e-300);
        }
    }
    EXPECT_NEAR(test::chiSquarePValue(3.841459, 1), 0.05, 1e-6);
    EXPECT_NEAR(test::chiSquarePValue(6.634897, 1), 0.01, 1e-6);
    EXPECT_NEAR(test::chiSquarePValue(18.307038, 10), 0.05, 1e-6);
    EXPECT_NEAR(test::chiSquarePValue(124.342113, 100), 0.05, 1e-6);
}

TEST(SamplingStats, ChiSquarePoolsSparseBinsAndRejectsImpossibleSamples) {
    // A perfect fit.
    test::ChiSquareResult fit = test::chiSquareTest({10, 20, 30, 40}, {10, 20, 30, 40});
    EXPECT_EQ(fit.statistic, 0.0);
    EXPECT_EQ(fit.dof, 3);
    EXPECT_NEAR(fit.pValue, 1.0, 1e-12);

    // Bins expected to hold 1, 2 and 3 samples pool into one bin of 6: (7 - 6)^2 / 6 + 0 + 0, 2 degrees of freedom.
    test::ChiSquareResult pooled = test::chiSquareTest({2, 2, 3, 50, 100}, {1, 2, 3, 50, 100});
    EXPECT_EQ(pooled.mergedBins, 3);
    EXPECT_EQ(pooled.dof, 2);
    EXPECT_NEAR(pooled.statistic, 1.0 / 6.0, 1e-12);

    // A pool still short of 5 joins the smallest regular bin: observed 1 + 9, expected 1 + 10, so (10 - 11)^2 / 11.
    test::ChiSquareResult joined = test::chiSquareTest({1, 9, 100}, {1, 10, 100});
    EXPECT_EQ(joined.dof, 1);
    EXPECT_NEAR(joined.statistic, 1.0 / 11.0, 1e-12);

    // A sample where nothing is expected fails outright, even if pooling would hide it.
    test::ChiSquareResult impossible = test::chiSquareTest({1, 50, 50}, {0, 50, 51});
    EXPECT_EQ(impossible.pValue, 0.0);
    EXPECT_FALSE(impossible.failure.empty());
}

// For samples that do follow the expected distribution, p-values are uniform on [0, 1]: 400 multinomial histograms
// (a third of the bins sparse, so pooling is exercised) must give about 40 p-values below 0.1. The count is binomial
// (400, 0.1), standard deviation 6; [16, 64] is +/- 4 standard deviations. Deterministic with the fixed seed.
TEST(SamplingStats, ChiSquarePValuesAreUniformUnderTheNullHypothesis) {
    std::vector<double> probabilities;
    for (int i = 0; i < 30; ++i)
        probabilities.push_back(i < 10 ? 0.002 : 1.0 + 0.1 * i);
    double sum = 0.0;
    for (double p : probabilities)
        sum += p;
    for (double& p : probabilities)
        p /= sum;

    const int sampleCount = 1000;
    std::vector<double> expected;
    for (double p : probabilities)
        expected.push_back(p * sampleCount);

    sh::Pcg32 rng = sh::pcg32Seed(5u, 6u);
    int small = 0;
    for (int trial = 0; trial < 400; ++trial) {
        std::vector<double> observed(probabilities.size(), 0.0);
        for (int i = 0; i < sampleCount; ++i) {
            double u = sh::pcg32NextFloat(rng);
            size_t bin = 0;
            while (bin + 1 < probabilities.size() && u >= probabilities[bin])
                u -= probabilities[bin++];
            observed[bin] += 1.0;
        }
        if (test::chiSquareTest(observed, expected).pValue < 0.1) ++small;
    }
    EXPECT_GE(small, 16);
    EXPECT_LE(small, 64);
}

// ---------------------------------------------------------------------------------------------------------------------
// Sphere and hemisphere sampling, frames

// Chi-square in (cos theta, phi), 20 x 10 bins, 1M samples (5000 per bin: a 3% error in the density is detected).
TEST(SamplingUniformSphere, MatchesPdf) {
    const int sampleCount = 1000000;
    test::Histogram2D histogram(test::Grid2D{-1.0, 1.0, 20, 0.0, 2.0 * kPi, 10});
    sh::Pcg32 rng = sh::pcg32Seed(11u, 0u);
    for (int i = 0; i < sampleCount; ++i) {
        const dvec3 d(sh::sampleUniformSphere(nextVec2(rng)));
        ASSERT_NEAR(glm::length(d), 1.0, 1e-6);
        histogram.add(d.z, azimuth(d));
    }
    EXPECT_EQ(histogram.outside, 0);
    const auto expected = histogram.grid.expectedCounts([](double, double) { return 1.0 / (4.0 * kPi); }, sampleCount);
    const test::ChiSquareResult chi2 = test::chiSquareTest(histogram.counts, expected);
    EXPECT_GT(chi2.pValue, kFamilyAlpha) << chi2.describe();
}

// As above, for the density cos(theta) / pi.
TEST(SamplingCosineHemisphere, MatchesPdf) {
    const int sampleCount = 1000000;
    test::Histogram2D histogram(test::Grid2D{0.0, 1.0, 20, 0.0, 2.0 * kPi, 10});
    sh::Pcg32 rng = sh::pcg32Seed(12u, 0u);
    for (int i = 0; i < sampleCount; ++i) {
        const dvec3 d(sh::sampleCosineHemisphere(nextVec2(rng)));
        ASSERT_NEAR(glm::length(d), 1.0, 1e-6);
        ASSERT_GE(d.z, 0.0);
        histogram.add(d.z, azimuth(d));
    }
    EXPECT_EQ(histogram.outside, 0);
    const auto expected =
        histogram.grid.expectedCounts([](double cosTheta, double) { return cosTheta / kPi; }, sampleCount);
    const test::ChiSquareResult chi2 = test::chiSquareTest(histogram.counts, expected);
    EXPECT_GT(chi2.pValue, kFamilyAlpha) << chi2.describe();
}

// buildFrame(n) gives t, b with (t, b, n) orthonormal and right-handed (t x b = n), for random n and for the normals
// where naive constructions break: the poles, n = (0, 0, -1) and normals just off it, and n.z = -0 (a sign flip).
// Tolerance 1e-5: a few float roundings on unit-length values.
TEST(SamplingBuildFrame, OrthonormalRightHanded) {
    std::vector<sh::vec3> normals = {{0, 0, 1},  {0, 0, -1},          {1, 0, 0},
                                     {0, -1, 0}, {0.6f, 0.8f, -0.0f}, {0.6f, -0.8f, 0.0f}};
    for (float epsilon : {1e-2f, 1e-4f, 1e-6f, 1e-8f, 1e-20f}) {
        normals.push_back(glm::normalize(sh::vec3(epsilon, epsilon, -1.0f)));
        normals.push_back(glm::normalize(sh::vec3(-epsilon, 0.5f * epsilon, -1.0f)));
        normals.push_back(glm::normalize(sh::vec3(epsilon, -epsilon, 1.0f)));
        normals.push_back(glm::normalize(sh::vec3(0.6f, 0.8f, -epsilon)));
    }
    sh::Pcg32 rng = sh::pcg32Seed(13u, 0u);
    for (int i = 0; i < 10000; ++i)
        normals.push_back(sh::sampleUniformSphere(nextVec2(rng)));
    for (const sh::vec3& n : normals) {
        sh::vec3 t, b;
        sh::buildFrame(n, t, b);
        SCOPED_TRACE(std::to_string(n.x) + ", " + std::to_string(n.y) + ", " + std::to_string(n.z));
        ASSERT_NEAR(glm::length(t), 1.0f, 1e-5f);
        ASSERT_NEAR(glm::length(b), 1.0f, 1e-5f);
        ASSERT_NEAR(glm::dot(t, b), 0.0f, 1e-5f);
        ASSERT_NEAR(glm::dot(t, n), 0.0f, 1e-5f);
        ASSERT_NEAR(glm::dot(b, n), 0.0f, 1e-5f);
        ASSERT_LT(glm::length(glm::cross(t, b) - n), 1e-5f);
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Equiangular sampling

struct EquiangularCase {
    std::string name;
    double t0, h;   // foot of the perpendicular and distance of the light from the ray
    double ta, tb;  // tb may be kInfinity
};

// A foot inside the interval, intervals entirely before and after the foot, a light close to the ray (a sharp peak),
// and unbounded intervals starting before and after the foot.
const std::vector<EquiangularCase> kEquiangularCases = {
    {"foot inside", 2.0, 0.5, 0.0, 5.0},
    {"interval before foot", 3.0, 0.4, 0.0, 1.0},
    {"interval after foot", 2.0, 0.3, 4.0, 9.0},
    {"light near the ray", 1.5, 0.05, 0.0, 4.0},
    {"unbounded, foot inside", 2.0, 0.5, 0.0, sh::kInfinity},
    {"unbounded, after foot", 1.0, 0.25, 3.0, sh::kInfinity},
};

// Sets up sampling along a general ray (not axis-aligned) whose foot point and light distance are the case's.
sh::Equiangular setUp(const EquiangularCase& c) {
    const sh::vec3 origin(0.3f, -0.2f, 0.1f);
    const sh::vec3 dir = glm::normalize(sh::vec3(1.0f, 0.5f, -0.2f));
    const sh::vec3 perpendicular = glm::normalize(glm::cross(dir, sh::vec3(0.0f, 0.0f, 1.0f)));
    const sh::vec3 light = origin + float(c.t0) * dir + float(c.h) * perpendicular;
    return sh::equiangularSetup(origin, dir, light, float(c.ta), float(c.tb));
}

bool unbounded(const EquiangularCase& c) {
    return c.tb >= sh::kInfinity;
}

// How far float arithmetic may put a sample outside the end x of the interval. The sampler maps an angle theta to
// t0 + h tan(theta); theta near +/- pi/2 is resolved to ~1.2e-7, and dt/dtheta = h (1 + ((t - t0) / h)^2), so the
// slack is 4 such steps, plus rounding of t itself (1e-6 relative).
double endSlack(const EquiangularCase& c, double x) {
    const double d = (x - c.t0) / c.h;
    return 4.8e-7 * c.h * (1.0 + d * d) + 1e-6 * (std::abs(x) + std::abs(c.t0));
}

// A bijection of [ta, inf) onto [0, 1), s = (t - ta) / (t - ta + L), with L the distance scale of the case, so that
// unbounded intervals can be binned and integrated: a density p(t) becomes p(t(s)) dt/ds, dt/ds = L / (1 - s)^2.
struct UnitMap {
    double ta, L;
    double s(double t) const { return (t - ta) / (t - ta + L); }
    double t(double s) const { return ta + L * s / (1.0 - s); }
    double dtds(double s) const { return L / ((1.0 - s) * (1.0 - s)); }
};

UnitMap unitMap(const EquiangularCase& c) {
    return {c.ta, std::abs(c.ta - c.t0) + c.h};
}

// The density of the binned variable: t itself, or s for unbounded intervals. The s-density tends to a finite limit
// at s = 1 (the pdf falls as 1 / t^2); the quadrature evaluates just short of it.
double binnedDensity(const EquiangularCase& c, const sh::Equiangular& e, double x) {
    if (!unbounded(c)) return sh::equiangularPdf(e, float(x));
    const UnitMap map = unitMap(c);
    const double s = std::min(x, 1.0 - 1e-9);
    return sh::equiangularPdf(e, float(map.t(s))) * map.dtds(s);
}

// Samples lie in [ta, tb] (up to endSlack), for random u and for the extreme inputs u = 0 and the largest floats
// below 1.
TEST(Equiangular, SamplesLieInInterval) {
    for (const EquiangularCase& c : kEquiangularCases) {
        SCOPED_TRACE(c.name);
        const sh::Equiangular e = setUp(c);
        std::vector<float> us = {0.0f, sh::kOneMinusEpsilon};
        for (int k = 1; k <= 64; ++k)
            us.push_back(1.0f - static_cast<float>(k) * 0x1p-24f);  // the 64 largest floats below 1
        sh::Pcg32 rng = sh::pcg32Seed(21u, 0u);
        for (int i = 0; i < 10000; ++i)
            us.push_back(sh::pcg32NextFloat(rng));
        for (float u : us) {
            float pdf = 0.0f;
            const float t = sh::equiangularSample(e, u, pdf);
            ASSERT_TRUE(std::isfinite(t)) << "u = " << u;
            ASSERT_GE(t, c.ta - endSlack(c, c.ta)) << "u = " << u;
            if (!unbounded(c)) {
                ASSERT_LE(t, c.tb + endSlack(c, c.tb)) << "u = " << u;
            }
            ASSERT_GT(pdf, 0.0f) << "u = " << u;
        }
    }
}

// Regression: float atan of a far end rounds to float(pi / 2), which lies above pi / 2 and whose tangent is -2.3e7, so
// with a far end (tb = kInfinity, or finite but 1e30 away) u near 1 used to return t ~2e7 before ta; and with a far
// start (the light 1e8 light distances ahead of ta) u = 0 returned t ~2e7 past tb. The ray runs along +x from the
// origin so that t0 and h are exact. Samples must lie in [ta, tb] up to endSlack (capped at 1% of |ta - t0| + h: far
// from the foot the angle cannot resolve t, but a wrap-around lands ~2e7 away).
TEST(Equiangular, FarEndsNeverWrapAround) {
    const std::vector<EquiangularCase> cases = {
        {"unbounded, 10 h after the foot", 0.0, 1.0, 10.0, sh::kInfinity},
        {"unbounded, 1000 h after the foot", 0.0, 1.0, 1000.0, sh::kInfinity},
        {"finite end 1e30 away", 0.0, 1.0, 10.0, 1e30},
        {"start 1e8 h before the foot", 1e8, 1.0, 0.0, 1e8 + 16.0},
    };
    for (const EquiangularCase& c : cases) {
        SCOPED_TRACE(c.name);
        const sh::vec3 light(float(c.t0), float(c.h), 0.0f);
        const sh::Equiangular e =
            sh::equiangularSetup(sh::vec3(0.0f), sh::vec3(1.0f, 0.0f, 0.0f), light, float(c.ta), float(c.tb));
        ASSERT_EQ(e.t0, float(c.t0));
        ASSERT_EQ(e.h, float(c.h));
        const double cap = 0.01 * (std::abs(c.ta - c.t0) + c.h);
        for (float u : {0.0f, 1e-7f, 0.5f, 1.0f - 0x1p-23f, sh::kOneMinusEpsilon}) {
            float pdf = 0.0f;
            const float t = sh::equiangularSample(e, u, pdf);
            EXPECT_GE(t, c.ta - std::min(cap, endSlack(c, c.ta))) << "u = " << u;
            EXPECT_LE(t, c.tb + std::min(cap, endSlack(c, c.tb))) << "u = " << u;
            EXPECT_GT(pdf, 0.0f) << "u = " << u;
        }
    }
}

// The pdf integrates to 1 over [ta, tb] (unbounded intervals through the bijection). Tolerance 1e-5: the float pdf
// has ~1e-7 relative error and the quadrature converges to 1e-7 relative; the integral is split at the foot point,
// where the density peaks.
TEST(Equiangular, PdfIntegratesToOne) {
    for (const EquiangularCase& c : kEquiangularCases) {
        SCOPED_TRACE(c.name);
        const sh::Equiangular e = setUp(c);
        const auto density = [&](double x) { return binnedDensity(c, e, x); };
        double total;
        if (unbounded(c)) {
            const UnitMap map = unitMap(c);
            const double sFoot = std::clamp(map.s(c.t0), 0.0, 1.0);
            total = test::integrate(density, 0.0, sFoot) + test::integrate(density, sFoot, 1.0);
        } else {
            const double foot = std::clamp(c.t0, c.ta, c.tb);
            total = test::integrate(density, c.ta, foot) + test::integrate(density, foot, c.tb);
        }
        EXPECT_NEAR(total, 1.0, 1e-5);
    }
}

// A sampler of t on one equiangular case and the density of the binned variable (t, or s for unbounded intervals).
struct CaseSampler {
    std::function<double(float)> sample;
    std::function<double(double)> density;
};

// Chi-square of sampled t (or s for unbounded intervals) in 50 bins, 1M samples per case, against the quadrature of
// the density over each bin. Samples up to 1e-4 of the range outside it are binned at the end (see endSlack; an ulp
// or so past the end is float rounding, not a wrong distribution).
void expectSamplingMatchesPdf(sh::uint seed, const std::function<CaseSampler(const EquiangularCase&)>& prepare) {
    const int sampleCount = 1000000;
    const double alpha = kFamilyAlpha / static_cast<double>(kEquiangularCases.size());
    for (size_t k = 0; k < kEquiangularCases.size(); ++k) {
        const EquiangularCase& c = kEquiangularCases[k];
        SCOPED_TRACE(c.name);
        const CaseSampler sampler = prepare(c);
        const UnitMap map = unitMap(c);
        const test::Grid2D grid =
            unbounded(c) ? test::Grid2D{0.0, 1.0, 50, 0.0, 1.0, 1} : test::Grid2D{c.ta, c.tb, 50, 0.0, 1.0, 1};
        test::Histogram2D histogram(grid, 1e-4);
        sh::Pcg32 rng = sh::pcg32Seed(seed, static_cast<sh::uint>(k));
        for (int i = 0; i < sampleCount; ++i) {
            const double t = sampler.sample(sh::pcg32NextFloat(rng));
            histogram.add(unbounded(c) ? map.s(t) : t, 0.5);
        }
        EXPECT_EQ(histogram.outside, 0);
        const auto expected =
            histogram.grid.expectedCounts([&](double x, double) { return sampler.density(x); }, sampleCount);
        const test::ChiSquareResult chi2 = test::chiSquareTest(histogram.counts, expected);
        EXPECT_GT(chi2.pValue, alpha) << chi2.describe();
    }
}

TEST(Equiangular, SamplingMatchesPdf) {
    expectSamplingMatchesPdf(22u, [](const EquiangularCase& c) {
        const sh::Equiangular e = setUp(c);
        return CaseSampler{[e](float u) {
                               float pdf = 0.0f;
                               return double(sh::equiangularSample(e, u, pdf));
                           },
                           [c, e](double x) { return binnedDensity(c, e, x); }};
    });
}

// A softened setup is the plain one about a light moved away from the ray to sqrt(h^2 + s^2): same foot, angles and
// density (the reference's area lights, softened by their size).
TEST(Equiangular, SoftenedIsEquiangularAboutAFartherLight) {
    for (const EquiangularCase& c : kEquiangularCases) {
        SCOPED_TRACE(c.name);
        const sh::vec3 origin(0.3f, -0.2f, 0.1f);
        const sh::vec3 dir = glm::normalize(sh::vec3(1.0f, 0.5f, -0.2f));
        const sh::vec3 perpendicular = glm::normalize(glm::cross(dir, sh::vec3(0.0f, 0.0f, 1.0f)));
        const float softening2 = 0.09f;
        const sh::vec3 light = origin + float(c.t0) * dir + float(c.h) * perpendicular;
        const sh::vec3 farther = origin + float(c.t0) * dir + float(std::sqrt(c.h * c.h + softening2)) * perpendicular;
        const sh::Equiangular soft =
            sh::equiangularSetupSoftened(origin, dir, light, float(c.ta), float(c.tb), softening2);
        const sh::Equiangular plain = sh::equiangularSetup(origin, dir, farther, float(c.ta), float(c.tb));
        EXPECT_NEAR(soft.t0, plain.t0, 1e-5f);
        EXPECT_NEAR(soft.h, plain.h, 1e-5f);
        EXPECT_NEAR(soft.thetaA, plain.thetaA, 1e-5f);
        EXPECT_NEAR(soft.thetaB, plain.thetaB, 1e-5f);
        EXPECT_NEAR(soft.h, std::sqrt(c.h * c.h + softening2), 1e-5);
    }
}

// The pdf returned with a sample equals equiangularPdf at it. Tolerance 1e-4 relative: t = t0 + d rounds d by an ulp
// of t, which moves the pdf by about ulp(t) / h (1e-5 here).
TEST(Equiangular, SampledPdfEqualsPdf) {
    for (const EquiangularCase& c : kEquiangularCases) {
        SCOPED_TRACE(c.name);
        const sh::Equiangular e = setUp(c);
        sh::Pcg32 rng = sh::pcg32Seed(23u, 0u);
        for (int i = 0; i < 2000; ++i) {
            float pdf = 0.0f;
            const float t = sh::equiangularSample(e, sh::pcg32NextFloat(rng), pdf);
            const float reference = sh::equiangularPdf(e, t);
            ASSERT_NEAR(pdf, reference, 1e-4f * reference) << "t = " << t;
        }
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Shaped equiangular sampling (shaped_equiangular.h)

// The single-scattering weight the reference shapes with, in closed form for a homogeneous fog: both transmittances
// and an HG lobe towards the light (the `fog-point` bench scene's sigma_t 0.3 and g 0.5).
double fogWeight(double t, double r, double mu) {
    sh::PhaseParams hg{};
    hg.kind = sh::kPhaseHenyeyGreenstein;
    hg.g = 0.5f;
    return std::exp(-0.3 * (t + r)) * double(sh::phaseEval(hg, float(mu)));
}

sh::ShapedEquiangular shapedSetUp(const EquiangularCase& c, double (*weight)(double, double, double)) {
    sh::ShapedEquiangular s{};
    s.e = setUp(c);
    sh::ShapedNodes n;
    sh::shapedNodeGeometry(s.e, n);
    for (int k = 0; k <= TY_SHAPED_BINS; ++k)
        s.w[k] = float(weight(n.t[k], n.r[k], n.mu[k]));
    sh::shapedFinish(s);
    return s;
}

double shapedBinnedDensity(const EquiangularCase& c, const sh::ShapedEquiangular& s, double x) {
    if (!unbounded(c)) return sh::shapedPdf(s, float(x));
    const UnitMap map = unitMap(c);
    const double u = std::min(x, 1.0 - 1e-9);
    return sh::shapedPdf(s, float(map.t(u))) * map.dtds(u);
}

// Node geometry: t, r and mu of each node describe the point at angle theta_k seen from the light.
TEST(ShapedEquiangular, NodesLieOnTheRayAtTheirAngles) {
    const EquiangularCase c = kEquiangularCases[0];
    const sh::Equiangular e = setUp(c);
    sh::ShapedNodes n;
    sh::shapedNodeGeometry(e, n);
    for (int k = 0; k <= TY_SHAPED_BINS; ++k) {
        const double theta = e.thetaA + (e.thetaB - e.thetaA) * k / TY_SHAPED_BINS;
        EXPECT_NEAR(n.t[k], c.t0 + c.h * std::tan(theta), 1e-5);
        EXPECT_NEAR(n.r[k], std::hypot(c.h, n.t[k] - c.t0), 1e-5);
        EXPECT_NEAR(n.mu[k], -(n.t[k] - c.t0) / n.r[k], 1e-6);  // the cosine between the ray and the light's direction
    }
}

// The pdf integrates to 1 (split at the foot and at every node, where the density has kinks). Tolerance 1e-5 as for
// the plain equiangular pdf.
TEST(ShapedEquiangular, PdfIntegratesToOne) {
    for (const EquiangularCase& c : kEquiangularCases) {
        SCOPED_TRACE(c.name);
        const sh::ShapedEquiangular s = shapedSetUp(c, fogWeight);
        const auto density = [&](double x) { return shapedBinnedDensity(c, s, x); };
        std::vector<double> cuts;
        const UnitMap map = unitMap(c);
        sh::ShapedNodes n;
        sh::shapedNodeGeometry(s.e, n);
        for (int k = 0; k <= TY_SHAPED_BINS; ++k)
            cuts.push_back(unbounded(c) ? std::clamp(map.s(n.t[k]), 0.0, 1.0) : std::clamp(double(n.t[k]), c.ta, c.tb));
        cuts.push_back(unbounded(c) ? std::clamp(map.s(c.t0), 0.0, 1.0) : std::clamp(c.t0, c.ta, c.tb));
        cuts.push_back(unbounded(c) ? 0.0 : c.ta);
        cuts.push_back(unbounded(c) ? 1.0 : c.tb);
        std::sort(cuts.begin(), cuts.end());
        double total = 0.0;
        for (size_t i = 0; i + 1 < cuts.size(); ++i)
            total += test::integrate(density, cuts[i], cuts[i + 1]);
        EXPECT_NEAR(total, 1.0, 1e-5);
    }
}

// Chi-square of sampled t (or s) in 50 bins, 1M samples per case, against the quadrature of shapedPdf.
TEST(ShapedEquiangular, SamplingMatchesPdf) {
    expectSamplingMatchesPdf(24u, [](const EquiangularCase& c) {
        const sh::ShapedEquiangular s = shapedSetUp(c, fogWeight);
        return CaseSampler{[s](float u) {
                               float pdf = 0.0f;
                               return double(sh::shapedSample(s, u, pdf));
                           },
                           [c, s](double x) { return shapedBinnedDensity(c, s, x); }};
    });
}

// The pdf returned with a sample equals shapedPdf at it (1e-4 relative, as for equiangular), for random u and the
// extreme inputs.
TEST(ShapedEquiangular, SampledPdfEqualsPdf) {
    for (const EquiangularCase& c : kEquiangularCases) {
        SCOPED_TRACE(c.name);
        const sh::ShapedEquiangular s = shapedSetUp(c, fogWeight);
        std::vector<float> us = {0.0f, sh::kOneMinusEpsilon, 0.5f};
        sh::Pcg32 rng = sh::pcg32Seed(25u, 0u);
        for (int i = 0; i < 2000; ++i)
            us.push_back(sh::pcg32NextFloat(rng));
        for (float u : us) {
            float pdf = 0.0f;
            const float t = sh::shapedSample(s, u, pdf);
            EXPECT_GE(t, c.ta - endSlack(c, c.ta));
            if (!unbounded(c)) {
                EXPECT_LE(t, c.tb + endSlack(c, c.tb));
            }
            const float reference = sh::shapedPdf(s, t);
            ASSERT_NEAR(pdf, reference, 1e-4f * reference) << "u = " << u << ", t = " << t;
        }
    }
}

// What the shaping is for: on the integrand it was built for (the weight over r^2) the estimate f / pdf is nearly
// constant, while equiangular's varies with both transmittances and the phase function. Measured as the relative
// standard deviation of f / pdf over 4096 stratified samples: the shaped one below 8 % and at least 10x below the
// plain one on every case (measured: 0.0-6.8 % against 1.9-126 %; the largest where an unbounded ray's weight falls
// off within the last bins).
TEST(ShapedEquiangular, CancelsTheWeightItWasBuiltFor) {
    for (const EquiangularCase& c : kEquiangularCases) {
        SCOPED_TRACE(c.name);
        const sh::ShapedEquiangular s = shapedSetUp(c, fogWeight);
        const auto f = [&](double t) {
            const double r = std::hypot(c.h, t - c.t0);
            return fogWeight(t, r, -(t - c.t0) / r) / (r * r);
        };
        const auto relativeDeviation = [&](bool shaped) {
            double sum = 0.0, sum2 = 0.0;
            const int n = 4096;
            for (int i = 0; i < n; ++i) {
                const float u = (float(i) + 0.5f) / float(n);
                float pdf = 0.0f;
                const float t = shaped ? sh::shapedSample(s, u, pdf) : sh::equiangularSample(s.e, u, pdf);
                const double value = f(t) / double(pdf);
                sum += value;
                sum2 += value * value;
            }
            const double mean = sum / n;
            return std::sqrt(std::max(0.0, sum2 / n - mean * mean)) / mean;
        };
        const double shaped = relativeDeviation(true), plain = relativeDeviation(false);
        EXPECT_LT(shaped, 0.08);
        EXPECT_LT(10.0 * shaped, plain) << "shaped " << shaped << ", equiangular " << plain;
    }
}

// Weights that are all zero (or not finite) leave the plain equiangular density, and a zero node is floored so that
// no part of the ray is left without samples.
TEST(ShapedEquiangular, DegenerateWeightsFallBackToEquiangular) {
    const EquiangularCase c = kEquiangularCases[0];
    for (double (*weight)(double, double, double) :
         {+[](double, double, double) { return 0.0; },
          +[](double, double, double) { return double(std::numeric_limits<float>::infinity()); }}) {
        const sh::ShapedEquiangular s = shapedSetUp(c, weight);
        for (double t = c.ta; t <= c.tb; t += 0.25)
            EXPECT_NEAR(sh::shapedPdf(s, float(t)), sh::equiangularPdf(s.e, float(t)),
                        1e-5 * sh::equiangularPdf(s.e, float(t)));
    }
    const sh::ShapedEquiangular spike =
        shapedSetUp(c, [](double t, double, double) { return std::abs(t - 2.0) < 0.1 ? 1.0 : 0.0; });
    for (double t = c.ta; t <= c.tb; t += 0.25)
        EXPECT_GT(sh::shapedPdf(spike, float(t)), 0.0f);
}

// ---------------------------------------------------------------------------------------------------------------------
// Spherical triangles

// A planar triangle seen from the origin; the spherical triangle is its projection on the unit sphere.
struct TriangleCase {
    std::string name;
    std::array<dvec3, 3> p;
    std::array<sh::vec3, 3> directions() const {
        return {sh::vec3(glm::normalize(p[0])), sh::vec3(glm::normalize(p[1])), sh::vec3(glm::normalize(p[2]))};
    }
};

const std::vector<TriangleCase> kTriangles = {
    {"small", {dvec3(0.1, 0.0, 8.0), dvec3(0.4, 0.1, 8.1), dvec3(0.2, 0.35, 7.9)}},
    {"medium", {dvec3(1.0, -0.5, 2.0), dvec3(-0.8, 0.3, 1.5), dvec3(0.2, 1.2, 1.8)}},
    {"obtuse", {dvec3(-1.5, 0.0, 1.0), dvec3(1.5, 0.0, 1.0), dvec3(0.0, 0.3, 1.0)}},
    {"large", {dvec3(1.0, 0.0, 0.05), dvec3(-0.5, 0.866, 0.05), dvec3(-0.5, -0.866, 0.05)}},
};

// Barycentric coordinates (b1, b2) of the ray from the origin along d on the triangle's plane (Moller-Trumbore); false
// if the ray runs parallel to the plane or meets it behind the origin.
bool rayPlaneBarycentrics(const dvec3& d, const std::array<dvec3, 3>& p, double& b1, double& b2) {
    const dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const dvec3 pvec = glm::cross(d, e2);
    const double det = glm::dot(e1, pvec);
    if (std::abs(det) < 1e-300) return false;
    const dvec3 tvec = -p[0];
    b1 = glm::dot(tvec, pvec) / det;
    const dvec3 qvec = glm::cross(tvec, e1);
    b2 = glm::dot(d, qvec) / det;
    return glm::dot(e2, qvec) / det > 0.0;
}

bool hitsTriangle(const dvec3& d, const std::array<dvec3, 3>& p, double slack = 0.0) {
    double b1 = 0.0, b2 = 0.0;
    return rayPlaneBarycentrics(d, p, b1, b2) && b1 >= -slack && b2 >= -slack && b1 + b2 <= 1.0 + slack;
}

// Solid angle by Girard's theorem (angle excess), in double: independent of the header's Van Oosterom-Strackee form.
double girardSolidAngle(const std::array<dvec3, 3>& p) {
    const dvec3 a = glm::normalize(p[0]), b = glm::normalize(p[1]), c = glm::normalize(p[2]);
    const auto angleAt = [](const dvec3& v, const dvec3& x, const dvec3& y) {
        const dvec3 tx = glm::normalize(x - glm::dot(x, v) * v), ty = glm::normalize(y - glm::dot(y, v) * v);
        return std::acos(std::clamp(glm::dot(tx, ty), -1.0, 1.0));
    };
    return angleAt(a, b, c) + angleAt(b, c, a) + angleAt(c, a, b) - kPi;
}

// Solid angle by Van Oosterom-Strackee in double, for the sub-triangles of the uniformity test.
double solidAngle(const dvec3& p0, const dvec3& p1, const dvec3& p2) {
    const dvec3 a = glm::normalize(p0), b = glm::normalize(p1), c = glm::normalize(p2);
    const double numerator = std::abs(glm::dot(a, glm::cross(b, c)));
    return 2.0 * std::atan2(numerator, 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a));
}

// ---------------------------------------------------------------------------------------------------------------------
// The pixel around a point light's image (singular_pixel.h)

// The integral of 1 / |x - p| over [x0, x1] x [y0, y1] in closed form: over a rectangle [0, a] x [0, b] with p at its
// corner it is a asinh(b / a) + b asinh(a / b), and any rectangle is a signed sum of four such, one per corner.
double inverseDistanceIntegral(const glm::dvec2& p, double x0, double x1, double y0, double y1) {
    const auto corner = [&](double x, double y) {
        const double a = std::abs(x - p.x), b = std::abs(y - p.y);
        const double value = (a > 0.0 && b > 0.0) ? a * std::asinh(b / a) + b * std::asinh(a / b) : 0.0;
        return (x < p.x ? -1.0 : 1.0) * (y < p.y ? -1.0 : 1.0) * value;
    };
    return corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0);
}

// Points in and around pixel (2, 5): inside, on an edge, at a corner, just outside, diagonally outside, 3 px away.
const std::vector<glm::vec2> kSingularPoints = {{2.31f, 5.72f}, {2.0f, 5.4f},  {3.0f, 6.0f},
                                                {3.2f, 5.5f},   {1.5f, 4.3f}, {5.8f, 3.9f}};

TEST(SingularPixel, MeasureIsTheIntegralOfOneOverDistance) {
    for (const glm::vec2& p : kSingularPoints) {
        const double exact = inverseDistanceIntegral(glm::dvec2(p), 2.0, 3.0, 5.0, 6.0);
        const float measure = sh::singularPixelMeasure(sh::singularPixelSetup(2, 5, p));
        EXPECT_NEAR(measure, exact, 2e-6 * exact) << p.x << ", " << p.y;
    }
}

// One accepted point about p (the first try with u, then independent numbers), as the reference jitters.
sh::vec3 singularJitter(int px, int py, const glm::vec2& p, sh::Pcg32& rng, int& tries) {
    const sh::SingularPixel pixel = sh::singularPixelSetup(px, py, p);
    const float measure = sh::singularPixelMeasure(pixel);
    for (tries = 1;; ++tries) {
        const glm::vec2 q = sh::singularPixelTry(pixel, nextVec2(rng));
        if (sh::singularPixelContains(pixel, q)) return sh::vec3(q, measure * glm::length(q - p));
    }
}

// The accepted points have the density 1 / (M |x - p|) over the pixel; the expected counts come from the closed form.
TEST(SingularPixel, AcceptedPointsHaveTheDensityOneOverDistance) {
    const int n = 200000;
    const double alpha = kFamilyAlpha / double(kSingularPoints.size());
    for (const glm::vec2& p : kSingularPoints) {
        SCOPED_TRACE(std::to_string(p.x) + ", " + std::to_string(p.y));
        sh::Pcg32 rng = sh::pcg32Seed(17u, 3u);
        test::Grid2D grid{2.0, 3.0, 12, 5.0, 6.0, 12};
        test::Histogram2D histogram(grid);
        long tries = 0;
        for (int i = 0; i < n; ++i) {
            int t = 0;
            const sh::vec3 x = singularJitter(2, 5, p, rng, t);
            tries += t;
            histogram.add(x.x, x.y);
        }
        EXPECT_EQ(histogram.outside, 0);
        const double measure = inverseDistanceIntegral(glm::dvec2(p), 2.0, 3.0, 5.0, 6.0);
        std::vector<double> expected;
        for (int ix = 0; ix < grid.nx; ++ix)
            for (int iy = 0; iy < grid.ny; ++iy)
                expected.push_back(n *
                                   inverseDistanceIntegral(glm::dvec2(p), grid.xEdge(ix), grid.xEdge(ix + 1),
                                                           grid.yEdge(iy), grid.yEdge(iy + 1)) /
                                   measure);
        const test::ChiSquareResult chi2 = test::chiSquareTest(histogram.counts, expected);
        EXPECT_GT(chi2.pValue, alpha) << chi2.describe();
        // Inside the closed pixel every try lands; outside, the acceptance is the pixel's share of the measure of the
        // triangles facing away from p.
        const bool inside = p.x >= 2.0f && p.x <= 3.0f && p.y >= 5.0f && p.y <= 6.0f;
        if (inside) EXPECT_EQ(tries, n);
        else EXPECT_GT(tries, n);
    }
}

// The weight makes f(x) w an unbiased estimate of the pixel's average of f; for f = 1 / |x - p| it is exact.
TEST(SingularPixel, WeightsEstimateThePixelAverage) {
    for (const glm::vec2& p : kSingularPoints) {
        SCOPED_TRACE(std::to_string(p.x) + ", " + std::to_string(p.y));
        const double measure = inverseDistanceIntegral(glm::dvec2(p), 2.0, 3.0, 5.0, 6.0);
        sh::Pcg32 rng = sh::pcg32Seed(5u, 9u);
        const int n = 100000;
        double sum = 0.0, sumSquares = 0.0;
        for (int i = 0; i < n; ++i) {
            int tries = 0;
            const sh::vec3 x = singularJitter(2, 5, p, rng, tries);
            const double r = glm::length(glm::dvec2(x.x, x.y) - glm::dvec2(p));
            ASSERT_NEAR(x.z / r, measure, 1e-4 * measure);  // 1 / |x - p|: every sample is the average itself
            // A smooth function: its average over the pixel is 1 + 2.5 + (6^3 - 5^3) / 3 / 10 = 6.5333...
            const double f = (1.0 + double(x.x) + double(x.y) * double(x.y) / 10.0) * double(x.z);
            sum += f;
            sumSquares += f * f;
        }
        const double mean = sum / n, sigma = std::sqrt((sumSquares / n - mean * mean) / n);
        EXPECT_NEAR(mean, 1.0 + 2.5 + (216.0 - 125.0) / 30.0, 5.0 * sigma);
    }
}

// sphericalTriangleSolidAngle against (1) Girard's theorem in double, tolerance 2e-6 + 1e-5 relative (float
// evaluation), and (2) a Monte Carlo estimate, 4 pi times the fraction of 2M uniform directions that hit the planar
// triangle, within 5 binomial standard errors (two-sided probability 6e-7 per triangle).
TEST(SphericalTriangle, SolidAngleMatchesGirardAndMonteCarlo) {
    const int sampleCount = 2000000;
    for (const TriangleCase& triangle : kTriangles) {
        SCOPED_TRACE(triangle.name);
        const auto [a, b, c] = triangle.directions();
        const double omega = sh::sphericalTriangleSolidAngle(a, b, c);
        const double girard = girardSolidAngle(triangle.p);
        EXPECT_NEAR(omega, girard, 2e-6 + 1e-5 * girard);

        sh::Pcg32 rng = sh::pcg32Seed(31u, 0u);
        int hits = 0;
        for (int i = 0; i < sampleCount; ++i)
            hits += hitsTriangle(dvec3(sh::sampleUniformSphere(nextVec2(rng))), triangle.p) ? 1 : 0;
        const double fraction = double(hits) / sampleCount;
        const double standardError = 4.0 * kPi * std::sqrt(fraction * (1.0 - fraction) / sampleCount);
        EXPECT_NEAR(omega, 4.0 * kPi * fraction, 5.0 * standardError) << hits << " hits";
    }
}

// Every sampled direction hits the triangle, and the solid angle returned matches sphericalTriangleSolidAngle.
// Slack in barycentric coordinates 1e-6 + 5e-7 / l^2, l the shortest edge's arc: Arvo's construction places C' on edge
// AC through q = cos(arc AC'), which float resolves to ~1e-7 absolute, i.e. to ~1e-7 / l^2 relative along the edge
// (1.3e-4 seen for the small triangle, l = 0.04; below 1e-6 for the others). The returned solid angle comes from the
// angle excess, which loses ~1e-7 absolute per angle: tolerance 2e-6 + 1e-5 relative.
TEST(SphericalTriangle, SamplesHitTheTriangle) {
    for (const TriangleCase& triangle : kTriangles) {
        SCOPED_TRACE(triangle.name);
        const auto [a, b, c] = triangle.directions();
        const double omega = sh::sphericalTriangleSolidAngle(a, b, c);
        double shortestArc = kPi;
        for (int k = 0; k < 3; ++k) {
            const double cosArc = glm::dot(glm::normalize(triangle.p[k]), glm::normalize(triangle.p[(k + 1) % 3]));
            shortestArc = std::min(shortestArc, std::acos(std::clamp(cosArc, -1.0, 1.0)));
        }
        const double slack = 1e-6 + 5e-7 / (shortestArc * shortestArc);
        std::vector<sh::vec2> us = {{0.0f, 0.0f},
                                    {sh::kOneMinusEpsilon, 0.0f},
                                    {0.0f, sh::kOneMinusEpsilon},
                                    {sh::kOneMinusEpsilon, sh::kOneMinusEpsilon},
                                    {0.5f, 0.5f}};
        sh::Pcg32 rng = sh::pcg32Seed(32u, 0u);
        for (int i = 0; i < 20000; ++i)
            us.push_back(nextVec2(rng));
        for (const sh::vec2& u : us) {
            float sampledSolidAngle = 0.0f;
            const dvec3 d(sh::sampleSphericalTriangle(a, b, c, u, sampledSolidAngle));
            ASSERT_NEAR(glm::length(d), 1.0, 1e-6);
            ASSERT_TRUE(hitsTriangle(d, triangle.p, slack)) << "u = " << u.x << ", " << u.y;
            ASSERT_NEAR(sampledSolidAngle, omega, 2e-6 + 1e-5 * omega);
        }
    }
}

// Uniformity over the solid angle: the planar triangle is cut into n^2 = 64 similar sub-triangles (a barycentric
// grid); each sample is binned by the sub-triangle its ray hits, and the expected count of a bin is N times the
// sub-triangle's solid angle over the whole. 100k samples, ~1500 per bin.
TEST(SphericalTriangle, SamplingIsUniformInSolidAngle) {
    const int n = 8, sampleCount = 100000;
    const double alpha = kFamilyAlpha / static_cast<double>(kTriangles.size());
    for (size_t k = 0; k < kTriangles.size(); ++k) {
        const TriangleCase& triangle = kTriangles[k];
        SCOPED_TRACE(triangle.name);
        const auto [a, b, c] = triangle.directions();
        const auto& p = triangle.p;
        const auto at = [&](double b1, double b2) { return p[0] + b1 * (p[1] - p[0]) + b2 * (p[2] - p[0]); };

        // Sub-triangle (i, j, upper) covers barycentric cell [i, i+1] x [j, j+1] / n, below or above its diagonal.
        std::vector<double> expected(size_t(2 * n * n), 0.0), observed(size_t(2 * n * n), 0.0);
        const auto bin = [](int i, int j, int upper) { return size_t(2 * (i * n + j) + upper); };
        double total = 0.0;
        for (int i = 0; i < n; ++i) {
            for (int j = 0; i + j < n; ++j) {
                const dvec3 p00 = at(double(i) / n, double(j) / n), p10 = at(double(i + 1) / n, double(j) / n);
                const dvec3 p01 = at(double(i) / n, double(j + 1) / n), p11 = at(double(i + 1) / n, double(j + 1) / n);
                expected[bin(i, j, 0)] = solidAngle(p00, p10, p01);
                if (i + j + 2 <= n) expected[bin(i, j, 1)] = solidAngle(p10, p11, p01);
                total += expected[bin(i, j, 0)] + expected[bin(i, j, 1)];
            }
        }
        for (double& e : expected)
            e *= sampleCount / total;

        sh::Pcg32 rng = sh::pcg32Seed(33u, static_cast<sh::uint>(k));
        for (int s = 0; s < sampleCount; ++s) {
            float ignored = 0.0f;
            const dvec3 d(sh::sampleSphericalTriangle(a, b, c, nextVec2(rng), ignored));
            double b1 = 0.0, b2 = 0.0;
            ASSERT_TRUE(rayPlaneBarycentrics(d, p, b1, b2));
            const int i = std::clamp(int(std::floor(b1 * n)), 0, n - 1);
            const int j = std::clamp(int(std::floor(b2 * n)), 0, n - 1 - i);
            const int upper = (b1 * n - i) + (b2 * n - j) > 1.0 && i + j + 2 <= n ? 1 : 0;
            observed[bin(i, j, upper)] += 1.0;
        }
        // Slots of the 2 n^2 array that are no sub-triangle expect nothing and receive nothing; drop them.
        std::vector<double> binObserved, binExpected;
        for (size_t q = 0; q < expected.size(); ++q) {
            if (expected[q] > 0.0) {
                binObserved.push_back(observed[q]);
                binExpected.push_back(expected[q]);
            }
        }
        ASSERT_EQ(binObserved.size(), size_t(n * n));
        const test::ChiSquareResult chi2 = test::chiSquareTest(binObserved, binExpected);
        EXPECT_GT(chi2.pValue, alpha) << chi2.describe();
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// BSDFs

sh::MaterialParams ggx(float alphaX, float alphaY) {
    sh::MaterialParams m{};
    m.kind = sh::kMaterialGgx;
    m.alphaX = alphaX;
    m.alphaY = alphaY;
    m.f0 = sh::vec3(1.0f);
    return m;
}

sh::MaterialParams diffuse() {
    sh::MaterialParams m{};
    m.kind = sh::kMaterialDiffuse;
    m.albedo = sh::vec3(1.0f);
    return m;
}

// Roughness pairs from near-specular to fully rough, isotropic and anisotropic both ways.
const std::vector<std::pair<float, float>> kAlphas = {{0.05f, 0.05f}, {0.2f, 0.2f},  {0.5f, 0.5f}, {1.0f, 1.0f},
                                                      {0.05f, 0.5f},  {0.5f, 0.05f}, {0.1f, 1.0f}, {1.0f, 0.3f}};

// View directions from normal incidence to 85 degrees, at azimuths off the anisotropy axes.
std::vector<dvec3> viewDirections() {
    std::vector<dvec3> directions;
    for (double degrees : {0.0, 30.0, 60.0, 85.0})
        directions.push_back(fromSpherical(std::cos(degrees * kPi / 180.0), 0.7));
    return directions;
}

// int over wi in { wi.z >= zMin } of f(wi) d omega, in (cos theta_i, phi_i) with phi_i centred on the mirror direction
// of wo and cos theta_i split at wo.z, so the peak of a glossy lobe sits on quadrature nodes.
template <typename F>
double integrateAroundMirror(const dvec3& wo, double zMin, const F& f) {
    const double phiMirror = azimuth(wo) + kPi;
    const auto integrand = [&](double mu, double phi) { return f(fromSpherical(mu, phi)); };
    const double split = std::clamp(wo.z, zMin, 1.0);
    double total = 0.0;
    for (auto [mu0, mu1] : {std::pair(zMin, split), std::pair(split, 1.0)})
        for (auto [phi0, phi1] : {std::pair(phiMirror - kPi, phiMirror), std::pair(phiMirror, phiMirror + kPi)})
            total += test::integrate2D(integrand, mu0, mu1, phi0, phi1, 1e-9);
    return total;
}

// int D(h) h.z d omega_h = 1 over the hemisphere (the microsurface's projected area is the macrosurface's), in
// (theta, phi) with phi split at the anisotropy axes where the lobe is sharpest. Tolerance 1e-4 relative: quadrature
// to 1e-7 relative of a float D.
TEST(Ggx, NormalDistributionIsNormalised) {
    for (const auto& alphas : kAlphas) {
        const float ax = alphas.first, ay = alphas.second;  // clang 14 cannot capture structured bindings
        SCOPED_TRACE(std::to_string(ax) + ", " + std::to_string(ay));
        const auto integrand = [&](double theta, double phi) {
            const sh::vec3 h(fromSpherical(std::cos(theta), phi));
            return double(sh::ggxD(h, ax, ay)) * std::cos(theta) * std::sin(theta);
        };
        double total = 0.0;
        for (int quadrant = 0; quadrant < 4; ++quadrant)
            total +=
                test::integrate2D(integrand, 0.0, 0.5 * kPi, quadrant * 0.5 * kPi, (quadrant + 1) * 0.5 * kPi, 1e-9);
        EXPECT_NEAR(total, 1.0, 1e-4);
    }
}

// The weak white furnace test (Heitz 2014): with F = 1 and masking only, int G1(wo) D(h) / (4 wo.z) d omega_i = 1 over
// the whole sphere of wi (h = normalize(wo + wi); D vanishes for wi.z < -wo.z). It holds only if Lambda matches D.
// Tolerance 1e-3: quadrature of a peaked float integrand (alpha = 0.05 at 85 degrees) to ~1e-6, with margin.
TEST(Ggx, WeakWhiteFurnace) {
    for (const auto& alphas : kAlphas) {
        const float ax = alphas.first, ay = alphas.second;  // clang 14 cannot capture structured bindings
        for (const dvec3& wo : viewDirections()) {
            SCOPED_TRACE(std::to_string(ax) + ", " + std::to_string(ay) + ", wo.z = " + std::to_string(wo.z));
            const sh::vec3 woF(wo);
            const double g1 = sh::ggxG1(woF, ax, ay);
            const double total = integrateAroundMirror(wo, -wo.z, [&](const dvec3& wi) {
                const dvec3 sum = wo + wi;
                if (glm::length(sum) < 1e-9) return 0.0;
                return g1 * sh::ggxD(sh::vec3(glm::normalize(sum)), ax, ay) / (4.0 * wo.z);
            });
            EXPECT_NEAR(total, 1.0, 1e-3);
        }
    }
}

// With F0 = 1 the full single-scattering model, E(wo) = int f(wo, wi) wi.z d omega_i over the upper hemisphere, loses
// energy (shadowing, and light reflected below the horizon) but never gains it: E <= 1 within the quadrature
// tolerance, 1e-4. Two magnitudes are known: smooth surfaces lose little away from grazing (E >= 0.99 for alpha = 0.05
// up to 60 degrees), and for alpha = 1 at normal incidence D = 1 / pi and G2 = 2 cos / (1 + cos), so
// E = int_0^1 mu / (1 + mu) dmu = 1 - ln 2 exactly (tolerance 1e-4).
TEST(Ggx, FullModelLosesEnergy) {
    for (const auto& alphas : kAlphas) {
        const float ax = alphas.first, ay = alphas.second;  // clang 14 cannot capture structured bindings
        const sh::MaterialParams m = ggx(ax, ay);
        for (const dvec3& wo : viewDirections()) {
            SCOPED_TRACE(std::to_string(ax) + ", " + std::to_string(ay) + ", wo.z = " + std::to_string(wo.z));
            const sh::vec3 woF(wo);
            const double albedo = integrateAroundMirror(
                wo, 0.0, [&](const dvec3& wi) { return double(sh::bsdfEval(m, woF, sh::vec3(wi)).x) * wi.z; });
            EXPECT_LE(albedo, 1.0 + 1e-4);
            if (std::max(ax, ay) <= 0.05f && wo.z >= 0.49) {
                EXPECT_GT(albedo, 0.99);
            }
            if (ax == 1.0f && ay == 1.0f && wo.z == 1.0) {
                EXPECT_NEAR(albedo, 1.0 - std::log(2.0), 1e-4);
            }
        }
    }
}

struct BsdfCase {
    std::string name;
    sh::MaterialParams material;
    dvec3 wo;
};

std::vector<BsdfCase> ggxSamplingCases() {
    std::vector<BsdfCase> cases;
    const std::vector<std::pair<float, float>> alphas = {{0.15f, 0.15f}, {0.6f, 0.6f}, {0.1f, 0.4f}, {0.7f, 0.2f}};
    for (auto [ax, ay] : alphas) {
        for (double degrees : {30.0, 75.0}) {
            const std::string name = "GGX " + std::to_string(ax) + ", " + std::to_string(ay) + " at " +
                                     std::to_string(int(degrees)) + " degrees";
            cases.push_back({name, ggx(ax, ay), fromSpherical(std::cos(degrees * kPi / 180.0), 0.7)});
        }
    }
    return cases;
}

// Chi-square of bsdfSample's wi against bsdfPdf: 16 x 16 bins in (cos theta_i, phi_i) over the upper hemisphere, plus
// one bin for the samples GGX sends below the horizon (expected: 1 minus the integral of bsdfPdf above it). 100k
// samples per case.
void expectBsdfSamplingMatchesPdf(const std::vector<BsdfCase>& cases) {
    const int sampleCount = 100000;
    const double alpha = kFamilyAlpha / static_cast<double>(cases.size());
    for (size_t k = 0; k < cases.size(); ++k) {
        const BsdfCase& c = cases[k];
        SCOPED_TRACE(c.name);
        const sh::vec3 wo(c.wo);
        test::Histogram2D histogram(test::Grid2D{0.0, 1.0, 16, 0.0, 2.0 * kPi, 16});
        double below = 0.0;
        sh::Pcg32 rng = sh::pcg32Seed(41u, static_cast<sh::uint>(k));
        for (int i = 0; i < sampleCount; ++i) {
            float pdf = 0.0f;
            const dvec3 wi(sh::bsdfSample(c.material, wo, nextVec2(rng), pdf));
            if (wi.z <= 0.0)
                below += 1.0;
            else
                histogram.add(wi.z, azimuth(wi));
        }
        EXPECT_EQ(histogram.outside, 0);
        std::vector<double> expected = histogram.grid.expectedCounts(
            [&](double mu, double phi) {
                return double(sh::bsdfPdf(c.material, wo, sh::vec3(fromSpherical(mu, phi))));
            },
            sampleCount);
        double upper = 0.0;
        for (double e : expected)
            upper += e;
        std::vector<double> observed = histogram.counts;
        observed.push_back(below);
        expected.push_back(std::max(0.0, sampleCount - upper));
        const test::ChiSquareResult chi2 = test::chiSquareTest(observed, expected);
        EXPECT_GT(chi2.pValue, alpha) << chi2.describe();
    }
}

TEST(Ggx, SamplingMatchesPdf) {
    expectBsdfSamplingMatchesPdf(ggxSamplingCases());
}

TEST(SamplingLambertian, MatchesPdf) {
    expectBsdfSamplingMatchesPdf({{"diffuse, normal view", diffuse(), dvec3(0, 0, 1)},
                                  {"diffuse, grazing view", diffuse(), fromSpherical(0.1, 2.0)}});
}

// The pdf bsdfSample returns is the density of the wi it returns: for GGX, the visible-normal density of the sampled
// half vector divided by 4 wo.h (recomputed here from the sampler's own h), zero below the horizon; for Lambertian,
// wi.z / pi. Tolerance 1e-3 relative: h = normalize(wo + wi) differs from the sampled h by float rounding, and D
// changes by ~4 |dh| / alpha^2 relative for alpha = 0.1.
TEST(Ggx, SampledPdfEqualsBsdfPdf) {
    std::vector<BsdfCase> cases = ggxSamplingCases();
    cases.push_back({"diffuse", diffuse(), fromSpherical(0.6, 1.0)});
    for (const BsdfCase& c : cases) {
        SCOPED_TRACE(c.name);
        const sh::vec3 wo(c.wo);
        sh::Pcg32 rng = sh::pcg32Seed(42u, 0u);
        for (int i = 0; i < 2000; ++i) {
            const sh::vec2 u = nextVec2(rng);
            float pdf = -1.0f;
            const sh::vec3 wi = sh::bsdfSample(c.material, wo, u, pdf);
            ASSERT_NEAR(glm::length(wi), 1.0f, 1e-5f);
            ASSERT_EQ(pdf, sh::bsdfPdf(c.material, wo, wi));
            if (wi.z <= 0.0f) {
                ASSERT_EQ(pdf, 0.0f);
                continue;
            }
            double reference = wi.z / kPi;
            if (c.material.kind == sh::kMaterialGgx) {
                const sh::vec3 h = sh::ggxSampleVisibleNormal(wo, c.material.alphaX, c.material.alphaY, u);
                reference =
                    sh::ggxVisibleNormalPdf(wo, h, c.material.alphaX, c.material.alphaY) / (4.0 * glm::dot(wo, h));
            }
            ASSERT_GT(pdf, 0.0f);
            ASSERT_NEAR(pdf, reference, 1e-3 * reference) << "u = " << u.x << ", " << u.y;
        }
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Random numbers

// PCG32 (XSH RR) on a native 64-bit state, written from its definition.
struct ReferencePcg32 {
    std::uint64_t state;
    std::uint32_t next() {
        const std::uint64_t old = state;
        state = old * 6364136223846793005ull + 1442695040888963407ull;
        const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rot = static_cast<std::uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }
};

// The two-uint PCG32 equals the 64-bit one, output and state, over 1000 steps from several states (including ones
// with the carry and rotation edge cases: all-zero, all-ones, high bits only).
TEST(RngPcg32, MatchesReference64Bit) {
    const std::vector<std::uint64_t> states = {
        0ull, ~0ull, 0x853c49e6748fea9bull, 0xffffffff00000000ull, 0x00000000ffffffffull, 0x8000000000000000ull};
    for (std::uint64_t initial : states) {
        SCOPED_TRACE(initial);
        ReferencePcg32 reference{initial};
        sh::Pcg32 rng{static_cast<sh::uint>(initial), static_cast<sh::uint>(initial >> 32u)};
        for (int i = 0; i < 1000; ++i) {
            ASSERT_EQ(sh::pcg32Next(rng), reference.next()) << "output " << i;
            ASSERT_EQ((std::uint64_t(rng.stateHi) << 32u) | rng.stateLo, reference.state) << "output " << i;
        }
    }
}

// uintToUnitFloat maps every uint into [0, 1), monotonically, and exactly onto k / 2^24: checked for every value of
// the top 24 bits (the only ones used), with the low bits all set.
TEST(RngPcg32, UnitFloatsLieInUnitInterval) {
    EXPECT_EQ(sh::uintToUnitFloat(0u), 0.0f);
    EXPECT_EQ(sh::uintToUnitFloat(0xffffffffu), sh::kOneMinusEpsilon);
    float previous = -1.0f;
    for (std::uint32_t k = 0; k < (1u << 24u); ++k) {
        const float f = sh::uintToUnitFloat((k << 8u) | 0xffu);
        if (!(f >= 0.0f && f < 1.0f && f > previous && f == float(k) * 0x1p-24f)) FAIL() << "k = " << k;
        previous = f;
    }
    sh::Pcg32 rng = sh::pcg32Seed(51u, 2u);
    for (int i = 0; i < 100000; ++i) {
        const float f = sh::pcg32NextFloat(rng);
        ASSERT_TRUE(f >= 0.0f && f < 1.0f);
    }
}

// The first Sobol points in index order. Dimension 0 is the van der Corput sequence (bit-reversed index); dimension 1
// XORs the direction numbers v_k of the index's set bits k, with v_0 = 1/2 and v_k = v_{k-1} ^ (v_{k-1} >> 1):
// v = 1/2, 3/4, 5/8 (0.101b), so index 3 -> 1/2 ^ 3/4 = 1/4, 4 -> 5/8, 5 -> 5/8 ^ 1/2 = 1/8, 6 -> 5/8 ^ 3/4 = 3/8,
// 7 -> 3/8 ^ 1/2 = 7/8.
TEST(Sobol, FirstPointsMatchKnownValues) {
    const std::array<double, 8> dim0 = {0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
    const std::array<double, 8> dim1 = {0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
    for (sh::uint i = 0; i < 8; ++i) {
        const sh::uvec2 s = sh::sobol2(i);
        EXPECT_EQ(s.x, static_cast<sh::uint>(dim0[i] * 4294967296.0)) << "index " << i;
        EXPECT_EQ(s.y, static_cast<sh::uint>(dim1[i] * 4294967296.0)) << "index " << i;
    }
}

// sobol2() computes dimension 1 by a subset-sum transform (Lucas' theorem); it must equal the XOR of the direction
// numbers of the index's set bits exactly, for every bit pattern: small indices, single bits, all ones, and random
// 32-bit indices (the shuffled indices sobolSample2D() passes have all 32 bits in play).
TEST(Sobol, Dimension1EqualsDirectionNumbers) {
    auto byDirectionNumbers = [](sh::uint index) {
        sh::uint y = 0u, v = 0x80000000u;
        for (sh::uint i = index; i != 0u; i >>= 1u) {
            if (i & 1u) y ^= v;
            v ^= v >> 1u;
        }
        return y;
    };
    std::vector<sh::uint> indices;
    for (sh::uint i = 0; i < 4096; ++i) indices.push_back(i);
    for (int b = 0; b < 32; ++b) indices.push_back(1u << b);
    indices.push_back(0xffffffffu);
    sh::Pcg32 rng = sh::pcg32Seed(7u, 3u);
    for (int k = 0; k < 100000; ++k) indices.push_back(sh::pcg32Next(rng));
    for (sh::uint i : indices) {
        ASSERT_EQ(sh::sobol2(i).y, byDirectionNumbers(i)) << "index " << i;
        ASSERT_EQ(sh::sobol2(i).x, glm::bitfieldReverse(i)) << "index " << i;
    }
}

// sobolSample2D() leaves out the bit reversals that cancel; it must equal the scramble written out in full.
TEST(Sobol, SampleEqualsFullScramble) {
    for (sh::uint pixelSeed : {0u, 5u, 0xdeadbeefu}) {
        for (sh::uint pair : {0u, 1u, 9u}) {
            const sh::uint seed = sh::hashCombine(pixelSeed, pair);
            for (sh::uint i = 0; i < 2048; ++i) {
                const sh::uvec2 s = sh::sobol2(sh::nestedUniformScramble(i, sh::hashCombine(seed, 0x6c8e9cf5u)));
                const sh::uint sx = sh::nestedUniformScramble(s.x, sh::hashCombine(seed, 0xa511e9b3u));
                const sh::uint sy = sh::nestedUniformScramble(s.y, sh::hashCombine(seed, 0x63d83595u));
                const sh::vec2 p = sh::sobolSample2D(pixelSeed, i, pair);
                ASSERT_EQ(p.x, std::min(sh::uintToUnitFloat(sx), sh::kOneMinusEpsilon)) << i;
                ASSERT_EQ(p.y, std::min(sh::uintToUnitFloat(sy), sh::kOneMinusEpsilon)) << i;
            }
        }
    }
}

// Empty if the points form a (0, m, 2)-net in base 2: for every k in 0..m, each of the 2^k x 2^(m-k) elementary
// intervals holds exactly one point; otherwise a description of the first failure.
std::string zeroTwoNetFailure(const std::vector<std::pair<double, double>>& points, int m) {
    if (points.size() != (size_t(1) << m)) return "wrong number of points";
    for (int k = 0; k <= m; ++k) {
        const int nx = 1 << k, ny = 1 << (m - k);
        std::vector<int> counts(size_t(nx * ny), 0);
        for (auto [x, y] : points) {
            if (!(x >= 0.0 && x < 1.0 && y >= 0.0 && y < 1.0)) return "point outside [0, 1)^2";
            ++counts[size_t(int(x * nx) * ny + int(y * ny))];
        }
        for (size_t q = 0; q < counts.size(); ++q)
            if (counts[q] != 1)
                return std::to_string(counts[q]) + " points in interval " + std::to_string(q) + " of the " +
                       std::to_string(nx) + " x " + std::to_string(ny) + " partition";
    }
    return "";
}

std::vector<std::pair<double, double>> sobolPoints(sh::uint pixelSeed, sh::uint pair, sh::uint first, sh::uint count) {
    std::vector<std::pair<double, double>> points;
    for (sh::uint i = first; i < first + count; ++i) {
        const sh::vec2 p = sh::sobolSample2D(pixelSeed, i, pair);
        points.emplace_back(p.x, p.y);
    }
    return points;
}

TEST(Sobol, UnscrambledPointsFormNets) {
    std::vector<std::pair<double, double>> points;
    for (sh::uint i = 0; i < 256; ++i) {
        const sh::uvec2 s = sh::sobol2(i);
        points.emplace_back(s.x * 0x1p-32, s.y * 0x1p-32);
    }
    EXPECT_EQ(zeroTwoNetFailure(points, 8), "");
}

// Scrambling keeps the (0, 2) property: for several pixels and dimension pairs, the first 256 points (and the first
// 64, and the aligned block 256..511) are (0, m, 2)-nets.
TEST(Sobol, ScrambledPointsFormZeroTwoNets) {
    for (sh::uint pixelSeed : {0u, 1u, 0xdeadbeefu, 123456789u}) {
        for (sh::uint pair : {0u, 1u, 2u, 7u}) {
            SCOPED_TRACE(std::to_string(pixelSeed) + ", pair " + std::to_string(pair));
            EXPECT_EQ(zeroTwoNetFailure(sobolPoints(pixelSeed, pair, 0, 256), 8), "");
            EXPECT_EQ(zeroTwoNetFailure(sobolPoints(pixelSeed, pair, 0, 64), 6), "");
            EXPECT_EQ(zeroTwoNetFailure(sobolPoints(pixelSeed, pair, 256, 256), 8), "");
        }
    }
}

// Different dimension pairs (and different pixels) get different point sets: at most a handful of the 256 points
// may coincide by chance (each has ~1e-7 probability at 24-bit resolution; we allow 2).
TEST(Sobol, PairsAndPixelsGetDifferentPoints) {
    const auto shared = [](const std::vector<std::pair<double, double>>& a,
                           const std::vector<std::pair<double, double>>& b) {
        const std::set<std::pair<double, double>> setA(a.begin(), a.end());
        int count = 0;
        for (const auto& p : b)
            count += setA.count(p) != 0 ? 1 : 0;
        return count;
    };
    const auto base = sobolPoints(7u, 0u, 0, 256);
    for (sh::uint pair = 1; pair < 8; ++pair)
        EXPECT_LE(shared(base, sobolPoints(7u, pair, 0, 256)), 2) << "pair " << pair;
    for (sh::uint pixel : {8u, 9u, 1000u})
        EXPECT_LE(shared(base, sobolPoints(pixel, 0u, 0, 256)), 2) << "pixel " << pixel;
}

}  // namespace
}  // namespace tyndall
