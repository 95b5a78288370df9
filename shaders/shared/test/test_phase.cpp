// Tests of the phase functions in shaders/shared/phase.h: normalisation and mean cosine against quadrature, chi-square
// tests of every sampler against the evaluated density, the sampler's pdf against phaseEval, and the Legendre series
// (CDF, expansion of a known polynomial).
#include "shared/phase.h"
#include "shared/rng.h"
#include "tyndall/core/scene.h"

#include "stats.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <numbers>
#include <string>
#include <vector>

namespace tyndall {
namespace {

namespace sh = tyndall::shader;

constexpr double kPi = std::numbers::pi;

// Every chi-square test below runs several configurations; each is tested at kFamilyAlpha / configurations
// (Bonferroni), so that a correct sampler fails a whole test with probability below kFamilyAlpha.
constexpr double kFamilyAlpha = 1e-3;

// ---------------------------------------------------------------------------------------------------------------------
// Phase functions under test

struct NamedPhase {
    std::string name;
    sh::PhaseParams params;
    double meanCosine;  // analytic <mu>
};

sh::PhaseParams makePhase(int kind) {
    sh::PhaseParams p{};
    p.kind = kind;
    p.terms = 1;
    p.legendre[0] = 1.0f;
    return p;
}

NamedPhase isotropic() {
    return {"isotropic", makePhase(sh::kPhaseIsotropic), 0.0};
}

NamedPhase henyeyGreenstein(float g) {
    sh::PhaseParams p = makePhase(sh::kPhaseHenyeyGreenstein);
    p.g = g;
    return {"HG g=" + std::to_string(g), p, g};
}

NamedPhase isoHgMix(float a, float g) {
    sh::PhaseParams p = makePhase(sh::kPhaseIsoHgMix);
    p.a = a;
    p.g = g;
    return {"mix a=" + std::to_string(a) + " g=" + std::to_string(g), p, double(a) * double(g)};
}

NamedPhase rayleigh() {
    return {"Rayleigh", makePhase(sh::kPhaseRayleigh), 0.0};
}

NamedPhase eddington(float b) {
    sh::PhaseParams p = makePhase(sh::kPhaseEddington);
    p.b = b;
    return {"Eddington b=" + std::to_string(b), p, b / 3.0};
}

NamedPhase legendre(const std::string& name, const std::vector<double>& coefficients) {
    sh::PhaseParams p = makePhase(sh::kPhaseLegendre);
    p.terms = static_cast<int>(coefficients.size());
    for (size_t n = 0; n < coefficients.size(); ++n)
        p.legendre[n] = static_cast<float>(coefficients[n]);
    return {"Legendre " + name, p, coefficients.size() > 1 ? coefficients[1] / 3.0 : 0.0};
}

// P_n(mu) in double, by Bonnet's recurrence.
double legendreP(int n, double mu) {
    double previous = 1.0, current = mu;
    if (n == 0) return previous;
    for (int k = 1; k < n; ++k) {
        const double next = ((2 * k + 1) * mu * current - k * previous) / (k + 1);
        previous = current;
        current = next;
    }
    return current;
}

// The "hazy Mie" phase function of Nishita et al., 4 pi p(mu) = 0.5 + 4.5 ((1 + mu) / 2)^8: a degree-8 polynomial.
double hazyMie4Pi(double mu) {
    return 0.5 + 4.5 * std::pow(0.5 * (1.0 + mu), 8.0);
}

// Its Legendre coefficients, a_n = (2n + 1) / 2 * int_{-1}^{1} f P_n dmu (exact with 9 terms: f has degree 8).
std::vector<double> hazyMieCoefficients() {
    std::vector<double> a(9);
    for (int n = 0; n < 9; ++n)
        a[size_t(n)] =
            0.5 * (2 * n + 1) *
            test::integrate([n](double mu) { return hazyMie4Pi(mu) * legendreP(n, mu); }, -1.0, 1.0, 1e-14, 1e-14);
    return a;
}

// Coefficients chosen so that the series 0.75 (1 + mu + mu^2) + 0.25 mu^3 is non-negative: its derivative,
// 0.75 (1 + mu)^2, is >= 0, and its value at mu = -1 is 0.5 (checked by Legendre.TestSeriesAreNonNegative).
const std::vector<double> kSmoothLegendre = {1.0, 0.9, 0.5, 0.1};

std::vector<NamedPhase> hgPhases() {
    std::vector<NamedPhase> phases;
    for (float g : {-0.9f, -0.3f, 0.0005f, 0.5f, 0.95f})
        phases.push_back(henyeyGreenstein(g));
    return phases;
}

std::vector<NamedPhase> mixPhases() {
    std::vector<NamedPhase> phases;
    for (float a : {0.0f, 0.3f, 1.0f})
        phases.push_back(isoHgMix(a, 0.7f));
    return phases;
}

std::vector<NamedPhase> eddingtonPhases() {
    std::vector<NamedPhase> phases;
    for (float b : {-1.0f, -0.4f, 0.0f, 0.8f, 1.0f})
        phases.push_back(eddington(b));
    return phases;
}

std::vector<NamedPhase> legendrePhases() {
    return {legendre("{1, 0.9, 0.5, 0.1}", kSmoothLegendre), legendre("hazy Mie", hazyMieCoefficients())};
}

// The Mie presets: mean cosine (n + 1) / (n + 2) - 1/2 of the half-weight lobe ((1 + mu) / 2)^n.
std::vector<NamedPhase> miePhases() {
    return {{"hazy Mie", makePhase(sh::kPhaseHazyMie), 9.0 / 10.0 - 0.5},
            {"murky Mie", makePhase(sh::kPhaseMurkyMie), 33.0 / 34.0 - 0.5}};
}

std::vector<NamedPhase> allPhases() {
    std::vector<NamedPhase> phases = {isotropic(), rayleigh()};
    for (const auto& family : {hgPhases(), mixPhases(), eddingtonPhases(), legendrePhases(), miePhases()})
        phases.insert(phases.end(), family.begin(), family.end());
    return phases;
}

double eval(const sh::PhaseParams& p, double mu) {
    return sh::phaseEval(p, static_cast<float>(mu));
}

// 2 pi int_{-1}^{1} p(mu) f(mu) dmu, to ~1e-7 relative (the float noise of phaseEval bounds the quadrature), far below
// the test tolerances. HG peaks sit on the ends of the interval, where adaptive Simpson starts.
template <typename F>
double sphereIntegral(const sh::PhaseParams& p, const F& f) {
    return 2.0 * kPi * test::integrate([&](double mu) { return eval(p, mu) * f(mu); }, -1.0, 1.0, 1e-10);
}

// ---------------------------------------------------------------------------------------------------------------------
// Sampling helpers

// A unit vector away from the axes, so that the sampler's frame around it is a general one.
const glm::dvec3 kIncident = glm::normalize(glm::dvec3(0.36, -0.48, 0.8) + glm::dvec3(0.1, 0.05, -0.2));

// An orthonormal frame around w built independently of sampling.h's buildFrame (Gram-Schmidt against the axis w is
// least aligned with), for measuring the azimuth of sampled directions.
void referenceFrame(const glm::dvec3& w, glm::dvec3& t, glm::dvec3& b) {
    const glm::dvec3 axis = std::abs(w.x) < 0.5 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    t = glm::normalize(axis - glm::dot(axis, w) * w);
    b = glm::cross(w, t);
}

// Chi-square test of phaseSample: directions binned by mu = dot(w, sampled) (50 bins) and by the azimuth around w
// (4 bins); the expected count of a bin is N times the integral of phaseEval over it (the solid angle element is
// dmu dphi). 1M samples put 5000 per bin on average, so a 3% error in the density is detected; sparse bins (HG
// g = 0.95 backwards) are pooled.
void expectPhaseSamplingMatchesPdf(const std::vector<NamedPhase>& phases, int sampleCount = 1000000) {
    const double alpha = kFamilyAlpha / static_cast<double>(phases.size());
    const test::Grid2D grid{-1.0, 1.0, 50, 0.0, 2.0 * kPi, 4};
    glm::dvec3 t, b;
    referenceFrame(kIncident, t, b);
    for (size_t k = 0; k < phases.size(); ++k) {
        const NamedPhase& phase = phases[k];
        SCOPED_TRACE(phase.name);
        sh::Pcg32 rng = sh::pcg32Seed(1234u, static_cast<sh::uint>(k));
        test::Histogram2D histogram(grid);
        for (int i = 0; i < sampleCount; ++i) {
            const sh::vec2 u(sh::pcg32NextFloat(rng), sh::pcg32NextFloat(rng));
            float pdf = 0.0f;
            const glm::dvec3 d(sh::phaseSample(phase.params, sh::vec3(kIncident), u, pdf));
            double phi = std::atan2(glm::dot(d, b), glm::dot(d, t));
            if (phi < 0.0) phi += 2.0 * kPi;
            histogram.add(glm::dot(d, kIncident), phi);
        }
        EXPECT_EQ(histogram.outside, 0);
        const std::vector<double> expected =
            grid.expectedCounts([&](double mu, double) { return eval(phase.params, mu); }, sampleCount);
        const test::ChiSquareResult chi2 = test::chiSquareTest(histogram.counts, expected);
        EXPECT_GT(chi2.pValue, alpha) << chi2.describe();
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Every kind: normalisation, mean cosine, pdf of samples

// Tolerance 1e-4 relative: quadrature error is ~1e-7 and float evaluation of phaseEval ~1e-6 relative, so a real
// normalisation error (a missing factor, a wrong constant) is far above it.
TEST(PhaseFunction, IntegratesToOne) {
    for (const NamedPhase& phase : allPhases()) {
        SCOPED_TRACE(phase.name);
        EXPECT_NEAR(sphereIntegral(phase.params, [](double) { return 1.0; }), 1.0, 1e-4);
    }
}

// Tolerance 1e-4 absolute (the mean cosine lies in [-1, 1]; zero for isotropic and Rayleigh): as above.
TEST(PhaseFunction, MeanCosineMatchesAnalytic) {
    for (const NamedPhase& phase : allPhases()) {
        SCOPED_TRACE(phase.name);
        EXPECT_NEAR(sphereIntegral(phase.params, [](double mu) { return mu; }), phase.meanCosine, 1e-4);
    }
}

// phaseSample returns the pdf of the direction it returns: phaseEval at that direction's cosine to the incident one.
// Building the direction from mu in float moves its cosine by a few ulps, so the pdf must lie between phaseEval at
// mu -/+ 1e-5 (widened by 1e-5 relative for float evaluation); HG g = 0.95 changes by 1% over that interval near
// mu = 1, a wrong pdf (another lobe, a missing factor) by far more.
TEST(PhaseFunction, SampledPdfEqualsEval) {
    const double delta = 1e-5;
    for (const NamedPhase& phase : allPhases()) {
        SCOPED_TRACE(phase.name);
        sh::Pcg32 rng = sh::pcg32Seed(77u, 3u);
        for (int i = 0; i < 2000; ++i) {
            const sh::vec2 u(sh::pcg32NextFloat(rng), sh::pcg32NextFloat(rng));
            float pdf = 0.0f;
            const glm::dvec3 d(sh::phaseSample(phase.params, sh::vec3(kIncident), u, pdf));
            const double mu = glm::dot(d, kIncident);
            const double p0 = eval(phase.params, std::max(-1.0, mu - delta));
            const double p1 = eval(phase.params, std::min(1.0, mu + delta));
            ASSERT_TRUE(std::isfinite(pdf) && pdf > 0.0f) << "u = " << u.x << ", " << u.y;
            ASSERT_GE(pdf, std::min(p0, p1) * (1.0 - 1e-5)) << "mu = " << mu;
            ASSERT_LE(pdf, std::max(p0, p1) * (1.0 + 1e-5)) << "mu = " << mu;
            ASSERT_NEAR(glm::length(d), 1.0, 1e-6);
        }
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Chi-square test of each sampler

TEST(PhaseIsotropic, SamplingMatchesPdf) {
    expectPhaseSamplingMatchesPdf({isotropic()});
}
TEST(HenyeyGreenstein, SamplingMatchesPdf) {
    expectPhaseSamplingMatchesPdf(hgPhases());
}
TEST(PhaseIsoHgMix, SamplingMatchesPdf) {
    expectPhaseSamplingMatchesPdf(mixPhases());
}
TEST(Rayleigh, SamplingMatchesPdf) {
    expectPhaseSamplingMatchesPdf({rayleigh()});
}
TEST(Eddington, SamplingMatchesPdf) {
    expectPhaseSamplingMatchesPdf(eddingtonPhases());
}
// 300k samples: the Legendre sampler bisects its CDF (24 evaluations per sample).
TEST(MiePresets, SamplingMatchesPdf) {
    expectPhaseSamplingMatchesPdf(miePhases());
}
// The presets are the polynomials they are named after.
TEST(MiePresets, EvaluateTheirPolynomials) {
    for (double mu = -1.0; mu <= 1.0; mu += 0.01) {
        EXPECT_NEAR(eval(makePhase(sh::kPhaseHazyMie), mu), hazyMie4Pi(mu) / (4.0 * kPi), 1e-6 * hazyMie4Pi(mu));
        const double murky = 0.5 + 16.5 * std::pow(0.5 * (1.0 + mu), 32.0);
        EXPECT_NEAR(eval(makePhase(sh::kPhaseMurkyMie), mu), murky / (4.0 * kPi), 1e-6 * murky);
    }
}
TEST(Legendre, SamplingMatchesPdf) {
    expectPhaseSamplingMatchesPdf(legendrePhases(), 300000);
}

// ---------------------------------------------------------------------------------------------------------------------
// Legendre series

// phaseEval clamps a negative series to zero, which would break normalisation silently: the test series must not need
// it. Checked on a dense grid (the series are low-degree polynomials with minima far above zero).
TEST(Legendre, TestSeriesAreNonNegative) {
    for (const NamedPhase& phase : legendrePhases()) {
        SCOPED_TRACE(phase.name);
        for (int i = 0; i <= 2000; ++i) {
            const float mu = -1.0f + 2.0f * static_cast<float>(i) / 2000.0f;
            EXPECT_GT(sh::legendreSeries(phase.params, mu), 0.0f) << "mu = " << mu;
        }
    }
}

// The hazy Mie expansion has a_0 = 1 (it is normalised) and reproduces the polynomial: checks legendreSeries's
// recurrence on 9 terms. Tolerance 1e-5 relative: float recurrence on values up to 5.
TEST(Legendre, HazyMieExpansionMatchesPolynomial) {
    const std::vector<double> a = hazyMieCoefficients();
    EXPECT_NEAR(a[0], 1.0, 1e-12);
    const sh::PhaseParams p = legendre("hazy Mie", a).params;
    for (int i = 0; i <= 200; ++i) {
        const double mu = -1.0 + 2.0 * i / 200.0;
        EXPECT_NEAR(sh::legendreSeries(p, float(mu)), hazyMie4Pi(mu), 1e-5 * hazyMie4Pi(mu)) << "mu = " << mu;
    }
}

// legendreCdf is 0 at -1, 1 at 1, non-decreasing, and equals the quadrature of (1/2) sum a_n P_n. Tolerance 2e-6
// absolute: float evaluation of a value in [0, 1] after a short recurrence.
TEST(Legendre, CdfIsMonotoneFromZeroToOne) {
    for (const NamedPhase& phase : legendrePhases()) {
        SCOPED_TRACE(phase.name);
        const sh::PhaseParams& p = phase.params;
        EXPECT_NEAR(sh::legendreCdf(p, -1.0f), 0.0f, 2e-6);
        EXPECT_NEAR(sh::legendreCdf(p, 1.0f), 1.0f, 2e-6);
        float previous = sh::legendreCdf(p, -1.0f);
        for (int i = 1; i <= 4000; ++i) {
            const float mu = -1.0f + 2.0f * static_cast<float>(i) / 4000.0f;
            const float cdf = sh::legendreCdf(p, mu);
            ASSERT_GE(cdf, previous) << "mu = " << mu;
            previous = cdf;
        }
        for (double mu : {-0.9, -0.5, 0.0, 0.3, 0.7, 0.95}) {
            const double reference =
                test::integrate([&](double m) { return 0.5 * sh::legendreSeries(p, float(m)); }, -1.0, mu, 1e-12);
            EXPECT_NEAR(sh::legendreCdf(p, float(mu)), reference, 2e-6) << "mu = " << mu;
        }
    }
}

// legendreToMonomial against the explicit sum of Eq. 13 (Pegoraro (003)):
//   P_n(mu) = 2^-n sum_{j <= n/2} (-1)^j (2n - 2j)! / (j! (n - j)! (n - 2j)!) mu^(n - 2j),
// evaluated in long double, for each P_n alone and for a random combination of 25 terms.
TEST(Legendre, MonomialCoefficientsMatchEquation13) {
    auto factorial = [](int n) {
        long double f = 1.0L;
        for (int i = 2; i <= n; ++i)
            f *= i;
        return f;
    };
    const int terms = 25;
    std::vector<long double> expected(terms, 0.0L);
    std::vector<double> a(terms);
    sh::Pcg32 rng = sh::pcg32Seed(5u, 9u);
    for (int n = 0; n < terms; ++n) {
        a[size_t(n)] = 2.0 * double(sh::pcg32NextFloat(rng)) - 1.0;
        std::vector<double> single(size_t(n) + 1, 0.0);
        single[size_t(n)] = 1.0;
        const std::vector<double> c = legendreToMonomial(single);
        for (int j = 0; 2 * j <= n; ++j) {
            const long double cj = (j % 2 ? -1.0L : 1.0L) * factorial(2 * n - 2 * j) /
                                   (std::pow(2.0L, n) * factorial(j) * factorial(n - j) * factorial(n - 2 * j));
            EXPECT_NEAR(c[size_t(n - 2 * j)], double(cj), 1e-12 * std::max(1.0, std::abs(double(cj))))
                << "P_" << n << ", mu^" << n - 2 * j;
            expected[size_t(n - 2 * j)] += a[size_t(n)] * cj;
        }
        for (int k = n - 1; k >= 0; k -= 2)
            EXPECT_EQ(c[size_t(k)], 0.0) << "P_" << n << ", mu^" << k;
    }
    const std::vector<double> c = legendreToMonomial(a);
    for (int k = 0; k < terms; ++k)
        EXPECT_NEAR(c[size_t(k)], double(expected[size_t(k)]),
                    1e-9 * std::max(1.0, std::abs(double(expected[size_t(k)]))));
}

}  // namespace
}  // namespace tyndall
