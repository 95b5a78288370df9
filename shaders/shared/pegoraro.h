// The closed-form air-light integral of Pegoraro, Schott and Parker (EGSR 2010, ../shared/papers/003): single
// scattering along a ray from a point light in an infinite homogeneous medium, for phase functions and light
// distributions that are polynomials in their cosines. Shared by the GPU (GLSL compute) and the CPU (C++), in float and
// in double from one source: pegoraro_impl.h is included once per precision.
//
// The derivation, with the paper's garbled formulas written again, is in docs/pegoraro.md. In short, for a ray
// x -> pe + x ve and a light at pl with the foot of the perpendicular at xh and distance h (Eq. 4-7):
//   Lm = (sigma_s / h) * I,   I = int_{ua}^{ub} e^{-H (u + sqrt(1 + u^2) - ua)} Phi_c(mu(u)) I_c(s(u)) du / (1 + u^2)
// with H = sigma_t h, u = (x - xh) / h, mu = -u / sqrt(1 + u^2) and s = (dc + del u) / sqrt(1 + u^2). With
// v = u + sqrt(1 + u^2) the integrand is rational in v times e^{-H v} (Eq. 6, 20); its partial fractions at the poles
// +-i reduce it to the integrals of e^{-H v} / (v - i)^j, which are e^{-H v} (v - i)^{1-j} E_j(H (v - i)) (Eq. 29-30
// rewritten with the generalised exponential integral E_j instead of Ei and explicit alternating sums).
//
// Functions, for both precisions (TY_R = float or double):
//   pegoraroSeries      Eq. 17-21: the rational series of Phi_c * I_c in v, as partial-fraction coefficients B_j;
//   pegoraroSeriesRefine  a measured (not a priori) bound on the rounding error of the B_j, where the a priori one
//                       would send the evaluation to the fallback;
//   pegoraroIntegral    Eq. 22, 29, 30: I over [ua, ub] from the B_j, with a running error bound;
//   pegoraroQuadrature  adaptive Simpson quadrature of the same I in the angle theta = atan(u): the fallback.
// In GLSL the double versions exist only when the includer defines TY_ENABLE_DOUBLE (they need shaderFloat64).
#ifndef TY_SHARED_PEGORARO_H
#define TY_SHARED_PEGORARO_H

#include "compat.h"
#include "complex.h"
#include "constants.h"
#include "expint.h"

// The largest number of terms N = N_phi + N_I - 1 of the product Phi_c * I_c (its order plus one). A shader may lower
// it before including this header, which shortens its arrays.
#ifndef TY_PEGORARO_MAX_TERMS
#define TY_PEGORARO_MAX_TERMS 40
#endif

TY_BEGIN

TY_CONST int kPegoraroMaxTerms = TY_PEGORARO_MAX_TERMS;
// Coefficients of the numerator polynomial P(v), of degree 2N - 2.
TY_CONST int kPegoraroMaxDegree = 2 * TY_PEGORARO_MAX_TERMS - 2;
// Adaptive Simpson: stack depth, and the most panels it evaluates before it gives up.
TY_CONST int kPegoraroQuadratureDepth = 40;
TY_CONST int kPegoraroQuadratureMaxPanels = 20000;
// The error estimate of pegoraroIntegral, calibrated against quadrature on the CPU (docs/pegoraro.md, "Error
// estimate"): the relative error of the exponential integrals and their recurrence, in units of roundoff (expint.h's
// float versions are good to ~1e-6 on the CPU, about 17 units; on lavapipe, whose float log and atan are less
// accurate, ~6e-6, about 100 units, above this allowance), and the weight of the coefficient magnitudes (the worst
// measured ratio of actual to estimated error on the CPU is 0.63 with these).
TY_CONST float kPegoraroExpintUlps = 64.0f;
TY_CONST float kPegoraroCoefficientWeight = 0.5f;
// pegoraroSeriesRefine: the factor on the measured rounding error of each b_j (the difference of two computations
// whose errors are nearly independent: it can come out smaller than either error, which this allows for; with the
// coefficient weight above and pegoraroIntegral's factor 4 the bound counts 16 times the difference), and a floor of a
// few units of roundoff of |b_j|.
TY_CONST float kPegoraroRefineWeight = 8.0f;
TY_CONST float kPegoraroRefineFloor = 4.0f;

TY_END

#define TY_R float
#define TY_R2 vec2
#define TY_R_EPSILON 5.9604645e-8f  // 2^-24, the unit roundoff of float
#include "pegoraro_impl.h"
#undef TY_R
#undef TY_R2
#undef TY_R_EPSILON

#ifdef TY_HAS_DOUBLE
#define TY_R double
#define TY_R2 dvec2
#define TY_R_EPSILON 1.1102230246251565e-16f  // 2^-53 (a float literal: exactly representable)
#include "pegoraro_impl.h"
#undef TY_R
#undef TY_R2
#undef TY_R_EPSILON
#endif

#endif  // TY_SHARED_PEGORARO_H
