// Phase functions and light distributions as polynomials in their cosines (Sec. 3.2 of the Pegoraro paper (003)):
// the input of the closed form. Exact for every phase function of the scene model except Henyey-Greenstein, which is
// truncated to a chosen number of terms of its Legendre (Eq. 11-13, Table 2) or Taylor (Eq. 14-16) expansion; the
// truncation error is measured against the true function and reported.
#pragma once

#include "tyndall/core/scene.h"

#include <vector>

namespace tyndall::pegoraro {

enum class HgExpansion { Legendre, Taylor };

inline constexpr int kMaxHgTerms = 32;

struct HgSettings {
    int terms = 8;  // number of polynomial terms (order + 1), [1, kMaxHgTerms]
    // > 0: the number of terms is instead the fewest whose L1 truncation error (PhasePolynomial::l1Error) is at most
    // this; 0: `terms`.
    double tolerance = 0.0;
    HgExpansion expansion = HgExpansion::Legendre;
    double taylorCentre = 0.0;  // mu_0 of the Taylor expansion (Eq. 15), in (-1, 1)
};

struct PhasePolynomial {
    std::vector<double> c;  // Phi_c(mu) = sum_k c[k] mu^k, normalised phase function (1 / sr)
    bool exact = true;      // false when a Henyey-Greenstein lobe was truncated
    // Truncation error against the true phase function, over mu in [-1, 1] (zero when exact):
    double l1Error = 0.0;      // 2 pi int |Phi_c - Phi| dmu: the fraction of the scattered energy misplaced
    double maxRelError = 0.0;  // max |Phi_c - Phi| / Phi
    double minimum = 0.0;      // min Phi_c: negative when the truncated series has negative lobes
};

// Legendre coefficients a_n = (2n + 1) g^n of Henyey-Greenstein, n < terms (Table 2).
std::vector<double> hgLegendre(double g, int terms);
// Polynomial coefficients of Henyey-Greenstein's Taylor expansion about mu0 truncated to `terms` terms: Eq. 14 gives
// the derivatives, Eq. 16 the coefficients in powers of mu.
std::vector<double> hgTaylor(double g, int terms, double mu0);

// Throws InputError (field hgTolerance) when hg.tolerance > 0 is not reached within kMaxHgTerms terms.
PhasePolynomial phasePolynomial(const PhaseFunction& phase, const HgSettings& hg);

}  // namespace tyndall::pegoraro
