// S of Eq. 21 without a fit: the integral of a rotationally symmetric phase function over a spherical polygon by the
// boundary form (Green's theorem in (phi, mu)), one short 1-D integral per edge with a fixed Gauss rule in a variable
// that follows the phase function's peak. Shared by GLSL and C++ (`tyndall tables eval`'s
// sMethods.accurate, and the LTSD technique with sMethod = accurate, its default).
// Derivation and measured accuracy: docs/tables.md, "S by the boundary form".
//
// Frame: as shared/ltsd.h (omega_o = +z, mu = -z). With e the lobe's peak direction (-z; +z for HG with g < 0),
// mu = e.w, G(mu) the lobe's CDF normalised to G(1) = 1 and H(mu) = (G(mu) - (1 + mu) / 2) / (1 - mu^2), the integral
// of the lobe over a counter-clockwise polygon P is
//     I(P) = Omega(P) / (4 pi) - 1 / (2 pi) sum_edges (n_i . e) int_0^theta_i H(mu_i(t)) dt,
// with n_i the unit normal of edge i's great circle and t the arc length along it: the isotropic (1 + mu) / 2 takes
// the pole's singularity, so H is bounded and no pole term remains. Along the great circle mu = rho cos(s), s = t - t*;
// the substitution s = 2 atan(c tan(tau)) spreads the nodes over the peak's width, so that 3 Gauss-Legendre
// nodes per edge suffice for every g.
#ifndef TY_SHARED_LTSD_BOUNDARY_H
#define TY_SHARED_LTSD_BOUNDARY_H

#include "compat.h"
#include "constants.h"
#include "ltsd.h"

TY_BEGIN

// The lobes the boundary form integrates (the part of a phase function beyond isotropic + linear, docs/tables.md
// "Other phase functions"), each normalised over the sphere.
TY_CONST int kLtsdLobeNone = 0;
TY_CONST int kLtsdLobeHg = 1;        // HG(g)
TY_CONST int kLtsdLobeRayleigh = 2;  // 3 mu^2 / (4 pi)
TY_CONST int kLtsdLobeMie8 = 3;      // 9 ((1 + mu) / 2)^8 / (4 pi)
TY_CONST int kLtsdLobeMie32 = 4;     // 33 ((1 + mu) / 2)^32 / (4 pi)

// The Gauss-Legendre rule on [-1, 1] per edge: 3 nodes (0 with weight 8/9, +-sqrt(3/5) with 5/9). Three suffice
// (docs/tables.md: weighted error ~1e-5 at |g| = 0.95 against the target 2e-3; two give 5e-4, four and six only what
// float leaves, 3e-6 and 5e-7).
TY_CONST float kLtsdGaussX = 0.7745966692414834f;
TY_CONST float kLtsdGaussOuterWeight = 0.5555555555555556f;
TY_CONST float kLtsdGaussCentreWeight = 0.8888888888888889f;

// The peak's width in 1 - mu: HG's 1 / r^2 structure has r^2 = (1 - g)^2 + 2 g (1 - mu), i.e. kappa = (1 - g)^2 /
// (2 g); a lobe ((1 + mu) / 2)^n falls by e at 1 - mu = 2 / n. Returned as (kappa numerator, 2 g) so that g = 0 needs
// no division: kappa = x / y. Rayleigh's lobe has no peak: y = 0 (c = 1, the nodes uniform in s).
TY_FUNC vec2 ltsdLobeWidth(int lobe, float g) {
    if (lobe == kLtsdLobeHg) return vec2((1.0f - g) * (1.0f - g), 2.0f * g);
    if (lobe == kLtsdLobeMie8) return vec2(2.0f / 8.0f, 1.0f);
    if (lobe == kLtsdLobeMie32) return vec2(2.0f / 32.0f, 1.0f);
    return vec2(1.0f, 0.0f);
}

// H(mu) = (G(mu) - (1 + mu) / 2) / (1 - mu^2) of the lobe, from d = 1 - mu (exact near the peak, where 1 - mu would
// cancel). g >= 0 (the caller mirrors HG's g < 0). Derivation of each form: docs/tables.md.
TY_FUNC float ltsdLobeH(int lobe, float g, float d) {
    if (lobe == kLtsdLobeHg) {
        // r = |g e - w| = sqrt(1 + g^2 - 2 g mu): H = -g (r + 2) / (r ((1 + r)^2 - g^2)).
        float r = sqrt((1.0f - g) * (1.0f - g) + 2.0f * g * d);
        return -g * (r + 2.0f) / (r * ((1.0f + r) * (1.0f + r) - g * g));
    }
    if (lobe == kLtsdLobeRayleigh) return -0.5f * (1.0f - d);  // G = (mu^3 + 1) / 2: H = -mu / 2
    // G = x^(n + 1), x = (1 + mu) / 2: H = -(1 - x^n) / (4 (1 - x)), 1 - x = d / 2; a short series where it cancels.
    float n = lobe == kLtsdLobeMie8 ? 8.0f : 32.0f;
    float y = 0.5f * d;
    if (n * y < 1e-2f) return -0.25f * n * (1.0f - 0.5f * (n - 1.0f) * y + (n - 1.0f) * (n - 2.0f) / 6.0f * y * y);
    return -0.25f * (1.0f - pow(1.0f - y, n)) / y;
}

// The integrand of one node at tau: H(mu) ds/dtau, with cos and sin of tau squared (the sum is even in tau's sign
// and period pi). 1 - mu = (1 - rho) + rho (1 - cos s), 1 - cos s = 2 c^2 sin^2 tau / D, ds = 2 c / D dtau.
TY_FUNC float ltsdBoundaryNode(float cos2, float sin2, float cc, float rho, float oneMinusRho, int lobe, float g) {
    float s2 = cc * cc * sin2;
    float denominator = cos2 + s2;
    float d = oneMinusRho + 2.0f * rho * s2 / denominator;
    return ltsdLobeH(lobe, g, d) * (2.0f * cc / denominator);
}

// The edge a -> b's term: (n . e) int_0^theta H(mu(t)) dt, e = (0, 0, ez). a, b unit.
TY_FUNC float ltsdBoundaryEdge(TY_IN(vec3) a, TY_IN(vec3) b, float ez, int lobe, float g, TY_IN(vec2) width) {
    vec3 c = cross(a, b);
    float sl = length(c);
    if (!(sl > 0.0f)) return 0.0f;
    vec3 n = c / sl;
    float ne = n.z * ez;
    if (ne == 0.0f) return 0.0f;
    // mu(t) = (e.a) cos t + (e.u) sin t = rho cos(s), s = t - t*, u = n x a: at a, rho cos s0 = e.a, rho sin s0 = -e.u.
    vec3 u = cross(n, a);
    float ea = a.z * ez, eu = u.z * ez;
    float rho = sqrt(max(0.0f, 1.0f - ne * ne));
    float oneMinusRho = ne * ne / (1.0f + rho);
    // c^2 = (kappa + 1 - rho) / (kappa + 1 + rho): 1 - rho cos s + kappa is then proportional to (1 + (w / c)^2) /
    // (1 + w^2), w = tan(s / 2), and H's 1 / r^2 is flat in tau = atan(w / c).
    float cc = sqrt((width.x + width.y * oneMinusRho) / (width.x + width.y * (1.0f + rho)));
    // tau(s) = atan2(sin(s / 2), c cos(s / 2)) from the half angles, which the geometry gives without trigonometry,
    // each up to a common sign (tau up to pi, which the nodes' squares ignore): s0 / 2 from (sin s0, 1 + cos s0) or
    // (1 - cos s0, sin s0), whichever is larger; theta / 2 from |a - b| / 2 and |a + b| / 2; s1 = s0 + theta.
    vec2 half0 = ea >= 0.0f ? vec2(-eu, rho + ea) : vec2(rho - ea, -eu);
    float half0Length = length(half0);
    half0 = half0Length > 0.0f ? half0 / half0Length : vec2(0.0f, 1.0f);  // rho = 0: mu is 0 all along, s arbitrary
    float sinHalfTheta = 0.5f * length(a - b), cosHalfTheta = 0.5f * length(a + b);
    float sin0 = half0.x, cos0 = half0.y;
    float sin1 = sin0 * cosHalfTheta + cos0 * sinHalfTheta, cos1 = cos0 * cosHalfTheta - sin0 * sinHalfTheta;
    // The span tau1 - tau0 by one atan2 of the two angles' difference, whose sine is c sin(theta / 2) exactly: a short
    // edge's span is not the difference of two O(1) angles, which would leave an absolute error of ~1e-7 per edge
    // (10 % of a 1e-4 sr polygon in HG's tail). tau is monotonic over |s| < 2 pi, so the span is in [0, pi].
    float tau0 = atan(sin0, cc * cos0);
    float span = atan(cc * sinHalfTheta, cc * cc * cos0 * cos1 + sin0 * sin1);
    float halfSpan = 0.5f * span, centre = tau0 + halfSpan;
    // The nodes centre and centre +- x halfSpan by the angle sums: two sin/cos pairs for three nodes.
    float cosC = cos(centre), sinC = sin(centre);
    float cosH = cos(kLtsdGaussX * halfSpan), sinH = sin(kLtsdGaussX * halfSpan);
    float cosM = cosC * cosH + sinC * sinH, sinM = sinC * cosH - cosC * sinH;  // centre - x halfSpan
    float cosP = cosC * cosH - sinC * sinH, sinP = sinC * cosH + cosC * sinH;  // centre + x halfSpan
    float sum = kLtsdGaussCentreWeight * ltsdBoundaryNode(cosC * cosC, sinC * sinC, cc, rho, oneMinusRho, lobe, g) +
                kLtsdGaussOuterWeight * (ltsdBoundaryNode(cosM * cosM, sinM * sinM, cc, rho, oneMinusRho, lobe, g) +
                                         ltsdBoundaryNode(cosP * cosP, sinP * sinP, cc, rho, oneMinusRho, lobe, g));
    return ne * sum * halfSpan;
}

// The lobe's integral over P (any orientation; a convex polygon inside an open hemisphere, as for ltsdS), g its HG
// asymmetry (ignored by the others).
TY_FUNC float ltsdLobeIntegral(TY_IN(SphericalPolygon) p, int lobe, float g) {
    float signedOmega = ltsdSignedSolidAngle(p);
    float ez = g < 0.0f && lobe == kLtsdLobeHg ? 1.0f : -1.0f;
    float ga = abs(g);
    vec2 width = ltsdLobeWidth(lobe, ga);
    float boundary = 0.0f;
    for (int i = 0; i < kLtsdLoopVertices; ++i) {
        if (i < p.count)
            boundary += ltsdBoundaryEdge(normalize(p.v[i]), normalize(ltsdNextVertex(p, i)), ez, lobe, ga, width);
    }
    float orientation = signedOmega < 0.0f ? -1.0f : 1.0f;
    return max(0.0f, orientation * (signedOmega * kInvFourPi - boundary * (0.5f * kInvPi)));
}

// The phase function's integral over P by the boundary form: the lobe (weight lobeWeight) plus the exact isotropic and
// linear part of ltsdLinearPhaseIntegral.
TY_FUNC float ltsdAccuratePhaseIntegral(TY_IN(SphericalPolygon) p, int lobe, float g, float lobeWeight, float isotropic,
                                        float linear) {
    float s = 0.0f;
    if (lobe != kLtsdLobeNone && lobeWeight != 0.0f) s += lobeWeight * ltsdLobeIntegral(p, lobe, g);
    if (isotropic != 0.0f || linear != 0.0f) s += ltsdLinearPhaseIntegral(p, isotropic, linear);
    return s;
}

TY_END

#endif  // TY_SHARED_LTSD_BOUNDARY_H
