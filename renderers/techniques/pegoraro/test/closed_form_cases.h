// Random configurations of the air-light integral for the Pegoraro tests and the error map: a ray, a point light with
// an axis, a positive polynomial phase function and light distribution, and an extinction coefficient. The expected
// value comes from adaptive quadrature of Eq. 3 in the ray parameter x, computed from the 3-D geometry alone, so that
// it checks the closed form's change of variables (Eq. 4-7) too.
#pragma once

#include "shared/pegoraro.h"
#include "shared/rng.h"

#include "stats.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace tyndall::pegoraro::test {

namespace sh = tyndall::shader;

struct Case {
    glm::dvec3 origin, dir, light, axis;
    double ta = 0.0, tb = 1.0;  // tb = +inf: the ray never ends
    double sigmaT = 1.0;
    std::vector<double> phase, lightPoly;  // monomial coefficients in the cosines
    // Derived (Eq. 4-7):
    double h = 0.0, xh = 0.0, del = 0.0, dc = 0.0, ua = 0.0, ub = 0.0, H = 0.0;
};

inline double horner(const std::vector<double>& c, double x) {
    double s = 0.0;
    for (auto it = c.rbegin(); it != c.rend(); ++it)
        s = s * x + *it;
    return s;
}

inline void derive(Case& c) {
    c.xh = glm::dot(c.light - c.origin, c.dir);
    const glm::dvec3 foot = c.origin + c.xh * c.dir;
    c.h = glm::length(foot - c.light);
    c.del = glm::dot(c.dir, c.axis);
    c.dc = glm::dot(foot - c.light, c.axis) / c.h;
    c.ua = (c.ta - c.xh) / c.h;
    c.ub = std::isinf(c.tb) ? double(sh::kInfinity) : (c.tb - c.xh) / c.h;
    c.H = c.sigmaT * c.h;
}

// A polynomial of `terms` terms that is >= 0.1 on [-1, 1]: random coefficients in [-1, 1] and c_0 above their sum.
inline std::vector<double> positivePolynomial(sh::Pcg32& rng, int terms) {
    std::vector<double> c(static_cast<std::size_t>(terms));
    double sum = 0.0;
    for (int k = 1; k < terms; ++k) {
        c[std::size_t(k)] = 2.0 * double(sh::pcg32NextFloat(rng)) - 1.0;
        sum += std::abs(c[std::size_t(k)]);
    }
    c[0] = sum + 0.1 + double(sh::pcg32NextFloat(rng));
    return c;
}

inline glm::dvec3 randomUnit(sh::Pcg32& rng) {
    const double z = 2.0 * double(sh::pcg32NextFloat(rng)) - 1.0;
    const double phi = 2.0 * 3.14159265358979323846 * double(sh::pcg32NextFloat(rng));
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// A random case of total order `order` (N = order + 1 terms) with H = sigma_t h in [Hmin, Hmax] (log-uniform); finite
// segments keep sigma_t (tb - ta) <= maxDepth.
inline Case randomCase(sh::Pcg32& rng, int order, double Hmin, double Hmax, double maxDepth) {
    Case c;
    const auto u = [&] { return double(sh::pcg32NextFloat(rng)); };
    c.origin = glm::dvec3(4.0 * u() - 2.0, 4.0 * u() - 2.0, 4.0 * u() - 2.0);
    c.dir = randomUnit(rng);
    c.light = glm::dvec3(4.0 * u() - 2.0, 4.0 * u() - 2.0, 4.0 * u() - 2.0);
    c.axis = randomUnit(rng);
    const int phaseOrder = int(u() * (order + 1)) % (order + 1);
    c.phase = positivePolynomial(rng, phaseOrder + 1);
    c.lightPoly = positivePolynomial(rng, order - phaseOrder + 1);
    c.ta = u() < 0.3 ? 0.0 : 2.0 * u();
    c.tb = u() < 0.3 ? std::numeric_limits<double>::infinity() : c.ta + 0.01 + 5.0 * u();
    derive(c);
    c.H = Hmin * std::pow(Hmax / Hmin, u());
    c.sigmaT = c.H / c.h;
    if (!std::isinf(c.tb) && c.sigmaT * (c.tb - c.ta) > maxDepth) c.tb = c.ta + maxDepth / c.sigmaT;
    derive(c);
    return c;
}

// h times Eq. 3's integral: int_{ta}^{tb} e^(-sigma_t (x - ta)) e^(-sigma_t d(x)) Phi(mu) I(s) / d(x)^2 dx * h, with
// mu the cosine between the light's travel and the direction back to the camera, s the cosine to the light's axis.
inline double quadrature(const Case& c) {
    const auto f = [&](double x) {
        const glm::dvec3 p = c.origin + x * c.dir;
        const glm::dvec3 fromLight = p - c.light;
        const double d = glm::length(fromLight);
        const glm::dvec3 w = fromLight / d;
        const double mu = glm::dot(w, -c.dir);
        const double s = glm::dot(w, c.axis);
        return std::exp(-c.sigmaT * (x - c.ta + d)) * horner(c.phase, mu) * horner(c.lightPoly, s) / (d * d);
    };
    // Past this point the tail is below 1e-20 of the peak contribution.
    double end = c.tb;
    if (std::isinf(end)) end = std::max(c.ta, c.xh) + std::max(50.0 / c.sigmaT, 1e4 * c.h);
    // Split at the foot of the perpendicular and a few widths h around it, where the integrand peaks.
    std::vector<double> cuts = {c.ta, end};
    for (double k : {-30.0, -3.0, -1.0, 0.0, 1.0, 3.0, 30.0}) {
        const double x = c.xh + k * c.h;
        if (x > c.ta && x < end) cuts.push_back(x);
    }
    std::sort(cuts.begin(), cuts.end());
    double sum = 0.0;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
        sum += tyndall::test::integrate(f, cuts[i], cuts[i + 1], 0.0, 1e-12);
    return sum * c.h;
}

inline sh::PegoraroPolynomial_double toPolynomialD(const std::vector<double>& c) {
    sh::PegoraroPolynomial_double p{};
    p.terms = int(c.size());
    for (std::size_t k = 0; k < c.size(); ++k)
        p.c[k] = c[k];
    return p;
}

inline sh::PegoraroPolynomial_float toPolynomialF(const std::vector<double>& c) {
    sh::PegoraroPolynomial_float p{};
    p.terms = int(c.size());
    for (std::size_t k = 0; k < c.size(); ++k)
        p.c[k] = float(c[k]);
    return p;
}

struct ClosedFormResult {
    double value = 0.0;
    double errorBound = 0.0;
};

inline ClosedFormResult closedFormDouble(const Case& c) {
    sh::PegoraroSeries_double s;
    sh::pegoraroSeries(c.del, c.dc, toPolynomialD(c.phase), toPolynomialD(c.lightPoly), s);
    ClosedFormResult r;
    r.value = sh::pegoraroIntegral(s, c.H, c.ua, c.ub, r.errorBound);
    return r;
}

inline ClosedFormResult closedFormFloat(const Case& c) {
    sh::PegoraroSeries_float s;
    sh::pegoraroSeries(float(c.del), float(c.dc), toPolynomialF(c.phase), toPolynomialF(c.lightPoly), s);
    float bound = 0.0f;
    ClosedFormResult r;
    r.value = sh::pegoraroIntegral(s, float(c.H), float(c.ua), float(c.ub), bound);
    r.errorBound = bound;
    return r;
}

}  // namespace tyndall::pegoraro::test
