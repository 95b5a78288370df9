#include "pegoraro/coefficients.h"

#include "tyndall/core/error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace tyndall::pegoraro {

namespace {

constexpr double kInvFourPi = 0.25 / std::numbers::pi;

double henyeyGreenstein(double g, double mu) {
    const double d = 1.0 + g * g - 2.0 * g * mu;
    return kInvFourPi * (1.0 - g * g) / (d * std::sqrt(d));
}

double evaluate(const std::vector<double>& c, double mu) {
    double sum = 0.0;
    for (auto it = c.rbegin(); it != c.rend(); ++it)
        sum = sum * mu + *it;
    return sum;
}

// 2^-n sum_k C(n, k) mu^k = ((1 + mu) / 2)^n.
std::vector<double> halfCosinePower(int n) {
    std::vector<double> c(std::size_t(n) + 1);
    c[0] = std::ldexp(1.0, -n);
    for (int k = 0; k < n; ++k)
        c[std::size_t(k) + 1] = c[std::size_t(k)] * (n - k) / (k + 1);
    return c;
}

// The Mie presets: (1/2 + w ((1 + mu) / 2)^n) / (4 pi).
std::vector<double> miePreset(int n, double w) {
    std::vector<double> c = halfCosinePower(n);
    for (double& x : c)
        x *= w * kInvFourPi;
    c[0] += 0.5 * kInvFourPi;
    return c;
}

// The truncated HG lobe as a phase function (with 1 / (4 pi)).
std::vector<double> hgPolynomial(double g, const HgSettings& hg) {
    if (hg.expansion == HgExpansion::Legendre) {
        std::vector<double> c = legendreToMonomial(hgLegendre(g, hg.terms));
        for (double& x : c)
            x *= kInvFourPi;
        return c;
    }
    return hgTaylor(g, hg.terms, hg.taylorCentre);
}

}  // namespace

std::vector<double> hgLegendre(double g, int terms) {
    std::vector<double> a(std::size_t(std::max(terms, 0)));
    double gn = 1.0;
    for (int n = 0; n < terms; ++n, gn *= g)
        a[std::size_t(n)] = (2.0 * n + 1.0) * gn;
    return a;
}

std::vector<double> hgTaylor(double g, int terms, double mu0) {
    TY_CHECK(terms >= 1 && std::abs(mu0) < 1.0, "a Taylor expansion needs at least one term and |mu0| < 1");
    // Eq. 14, re-derived (docs/pegoraro.md): d^n/dmu^n HG(mu) = (1 - g^2) / (4 pi) (g / 2)^n (2n + 1)! / n!
    //   * (1 + g^2 - 2 g mu)^(-3/2 - n). Kept divided by n! (a Taylor coefficient t_n = HG^(n)(mu0) / n!):
    //   t_(n+1) / t_n = g (2n + 3) / ((n + 1) (1 + g^2 - 2 g mu0)).
    const double d = 1.0 + g * g - 2.0 * g * mu0;
    std::vector<double> t(static_cast<std::size_t>(terms));
    t[0] = henyeyGreenstein(g, mu0);
    for (int n = 0; n + 1 < terms; ++n)
        t[std::size_t(n) + 1] = t[std::size_t(n)] * g * (2.0 * n + 3.0) / ((n + 1.0) * d);
    // Eq. 16: sum_k t_k (mu - mu0)^k expanded in powers of mu (binomial theorem).
    std::vector<double> c(std::size_t(terms), 0.0);
    for (int k = 0; k < terms; ++k) {
        double binomial = 1.0;  // C(k, j)
        for (int j = 0; j <= k; ++j) {
            c[std::size_t(j)] += t[std::size_t(k)] * binomial * std::pow(-mu0, k - j);
            binomial = binomial * (k - j) / (j + 1);
        }
    }
    return c;
}

namespace {

// The phase polynomial with `terms` terms of the Henyey-Greenstein expansion, its truncation measured against the
// true function.
PhasePolynomial phasePolynomialWithTerms(const PhaseFunction& phase, const HgSettings& hg, int terms) {
    TY_CHECK(terms >= 1 && terms <= kMaxHgTerms, "the Henyey-Greenstein truncation takes 1 to 32 terms");
    PhasePolynomial p;
    switch (phase.kind) {
        case PhaseKind::Isotropic:
            p.c = {kInvFourPi};
            break;
        case PhaseKind::Eddington:
            p.c = {kInvFourPi, phase.b * kInvFourPi};
            break;
        case PhaseKind::Rayleigh:
            p.c = {3.0 / (16.0 * std::numbers::pi), 0.0, 3.0 / (16.0 * std::numbers::pi)};
            break;
        case PhaseKind::Legendre:
            p.c = legendreToMonomial(phase.legendre);
            for (double& x : p.c)
                x *= kInvFourPi;
            break;
        case PhaseKind::HazyMie:
            p.c = miePreset(8, 4.5);
            break;
        case PhaseKind::MurkyMie:
            p.c = miePreset(32, 16.5);
            break;
        case PhaseKind::HenyeyGreenstein:
        case PhaseKind::IsoHgMix: {
            const double weight = phase.kind == PhaseKind::IsoHgMix ? phase.a : 1.0;
            HgSettings truncated = hg;
            truncated.terms = terms;
            p.c = hgPolynomial(phase.g, truncated);
            for (double& x : p.c)
                x *= weight;
            p.c[0] += (1.0 - weight) * kInvFourPi;
            p.exact = phase.g == 0.0;
            break;
        }
    }
    // Measure the truncation against the true function on a fine grid (composite Simpson for the L1 error).
    if (!p.exact) {
        const double weight = phase.kind == PhaseKind::IsoHgMix ? phase.a : 1.0;
        auto truth = [&](double mu) { return (1.0 - weight) * kInvFourPi + weight * henyeyGreenstein(phase.g, mu); };
        const int intervals = 8192;
        double l1 = 0.0, maxRel = 0.0, minimum = evaluate(p.c, -1.0);
        for (int i = 0; i <= intervals; ++i) {
            const double mu = -1.0 + 2.0 * i / intervals;
            const double approx = evaluate(p.c, mu), exact = truth(mu);
            const double w = (i == 0 || i == intervals) ? 1.0 : (i % 2 ? 4.0 : 2.0);
            l1 += w * std::abs(approx - exact);
            maxRel = std::max(maxRel, std::abs(approx - exact) / exact);
            minimum = std::min(minimum, approx);
        }
        p.l1Error = 2.0 * std::numbers::pi * l1 * (2.0 / intervals) / 3.0;
        p.maxRelError = maxRel;
        p.minimum = minimum;
    } else {
        p.minimum = 0.0;
    }
    return p;
}

}  // namespace

PhasePolynomial phasePolynomial(const PhaseFunction& phase, const HgSettings& hg) {
    const bool truncated =
        (phase.kind == PhaseKind::HenyeyGreenstein || phase.kind == PhaseKind::IsoHgMix) && phase.g != 0.0;
    if (!truncated || !(hg.tolerance > 0.0)) return phasePolynomialWithTerms(phase, hg, hg.terms);
    // hgTolerance: the fewest terms whose L1 truncation error meets it (the error falls with the order, but not
    // always monotonically for the Taylor expansion, so every order is tried from the lowest).
    PhasePolynomial p;
    for (int terms = 1; terms <= kMaxHgTerms; ++terms) {
        p = phasePolynomialWithTerms(phase, hg, terms);
        if (p.l1Error <= hg.tolerance) return p;
    }
    char text[256];
    std::snprintf(text, sizeof(text),
                  "hgTolerance = %g is not reached within %d terms for g = %g (%d terms leave an L1 error of %.3g); "
                  "allowed: hgTolerance >= %.3g for this phase function, or 0 to use hgTerms",
                  hg.tolerance, kMaxHgTerms, phase.g, kMaxHgTerms, p.l1Error, p.l1Error);
    throw InputError(InputLocation{"", 0, 0, "hgTolerance"}, text);
}

}  // namespace tyndall::pegoraro
