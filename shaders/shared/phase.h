// Phase functions shared by GLSL and C++: evaluation, importance sampling and pdf.
//
// Convention (docs/conventions.md): mu = cos(theta) is the cosine between the direction light travels before and after
// the scattering event; mu = +1 is forward scattering and g > 0 favours it. For a camera ray with direction d and a
// light seen in direction l from the scattering point, mu = dot(d, l).
// Every sampler here draws exactly from its phase function, so its pdf equals phaseEval.
#ifndef TY_SHARED_PHASE_H
#define TY_SHARED_PHASE_H

#include "compat.h"
#include "constants.h"
#include "sampling.h"

TY_BEGIN

TY_CONST int kPhaseIsotropic = 0;
TY_CONST int kPhaseHenyeyGreenstein = 1;
TY_CONST int kPhaseIsoHgMix = 2;
TY_CONST int kPhaseRayleigh = 3;
TY_CONST int kPhaseEddington = 4;
TY_CONST int kPhaseLegendre = 5;
TY_CONST int kPhaseHazyMie =
    6;  // 4 pi p = 1/2 + 9/2 ((1 + mu) / 2)^8   (Nishita et al. 1987; Pegoraro (003), Sec. 3.2)
TY_CONST int kPhaseMurkyMie = 7;  // 4 pi p = 1/2 + 33/2 ((1 + mu) / 2)^32
TY_CONST int kMaxLegendreTerms = 32;

// A phase function as plain data (std430-compatible: 4-byte members only).
struct PhaseParams {
    int kind;                           // one of kPhase*
    float g;                            // HG and mix: asymmetry in (-1, 1)
    float a;                            // mix: weight of the HG lobe in [0, 1]
    float b;                            // Eddington: (1 + b mu) / (4 pi), b in [-1, 1]
    int terms;                          // Legendre: number of coefficients in use
    float legendre[kMaxLegendreTerms];  // Legendre: a_0 = 1, a_1, ...
};

TY_FUNC float henyeyGreenstein(float mu, float g) {
    float denom = 1.0f + g * g - 2.0f * g * mu;
    return kInvFourPi * (1.0f - g * g) / (denom * sqrt(denom));
}

// Sum_{n < terms} a_n P_n(mu) by the three-term recurrence (n+1) P_{n+1} = (2n+1) mu P_n - n P_{n-1}.
TY_FUNC float legendreSeries(TY_IN(PhaseParams) p, float mu) {
    float pPrev = 1.0f;  // P_0
    float pCur = mu;     // P_1
    float sum = p.legendre[0];
    if (p.terms > 1) sum += p.legendre[1] * mu;
    for (int n = 1; n + 1 < p.terms; ++n) {
        float pNext = (float(2 * n + 1) * mu * pCur - float(n) * pPrev) / float(n + 1);
        pPrev = pCur;
        pCur = pNext;
        sum += p.legendre[n + 1] * pCur;
    }
    return sum;
}

// Integral of the Legendre series' pdf in mu, (1/2) sum a_n P_n, from -1 to mu: a CDF in [0, 1].
// Uses int_{-1}^{mu} P_n = (P_{n+1}(mu) - P_{n-1}(mu)) / (2n + 1) for n >= 1.
TY_FUNC float legendreCdf(TY_IN(PhaseParams) p, float mu) {
    float pPrev = 1.0f;  // P_{n-1}
    float pCur = mu;     // P_n
    float integral = p.legendre[0] * (mu + 1.0f);
    for (int n = 1; n < p.terms; ++n) {
        float pNext = (float(2 * n + 1) * mu * pCur - float(n) * pPrev) / float(n + 1);
        integral += p.legendre[n] * (pNext - pPrev) / float(2 * n + 1);
        pPrev = pCur;
        pCur = pNext;
    }
    return clamp(0.5f * integral, 0.0f, 1.0f);
}

// The hazy and murky Mie presets are half isotropic and half the lobe ((1 + mu) / 2)^n, normalised: the lobe integrates
// to 4 pi / (n + 1) over the sphere, so its weight is (n + 1) / 2 for half the energy.
TY_FUNC int mieLobeExponent(int kind) {
    return kind == kPhaseHazyMie ? 8 : 32;
}

TY_FUNC float mieLobe(int n, float mu) {
    return 0.5f * float(n + 1) * pow(max(0.0f, 0.5f * (1.0f + mu)), float(n));
}

// mu with density proportional to ((1 + mu) / 2)^n: the CDF is ((1 + mu) / 2)^(n+1).
TY_FUNC float sampleMieLobeMu(int n, float u) {
    return clamp(2.0f * pow(u, 1.0f / float(n + 1)) - 1.0f, -1.0f, 1.0f);
}

// A shader whose phase function is known when it is compiled may define TY_PHASE_KIND (one of kPhase*): the other
// kinds are then compiled out. On lavapipe that saves a third of a simple kernel's time, because the Legendre branch
// otherwise keeps the whole PhaseParams in memory.
TY_FUNC float phaseEval(TY_IN(PhaseParams) p, float mu) {
#ifdef TY_PHASE_KIND
    int kind = TY_PHASE_KIND;
#else
    int kind = p.kind;
#endif
    if (kind == kPhaseHenyeyGreenstein) return henyeyGreenstein(mu, p.g);
    if (kind == kPhaseIsoHgMix) return (1.0f - p.a) * kInvFourPi + p.a * henyeyGreenstein(mu, p.g);
    if (kind == kPhaseRayleigh) return 3.0f / (16.0f * kPi) * (1.0f + mu * mu);
    if (kind == kPhaseEddington) return kInvFourPi * (1.0f + p.b * mu);
    if (kind == kPhaseLegendre) return max(0.0f, kInvFourPi * legendreSeries(p, mu));
    if (kind == kPhaseHazyMie || kind == kPhaseMurkyMie) return kInvFourPi * (0.5f + mieLobe(mieLobeExponent(kind), mu));
    return kInvFourPi;
}

// mu distributed as HG(g), by inverting its CDF. With xi = 2u - 1 the inverse (1 + g^2 - s^2) / (2g),
// s = (1 - g^2) / (1 + g xi), expands without cancellation to the form below, exact for every g including 0
// (derivation in docs/conventions.md).
TY_FUNC float sampleHenyeyGreensteinMu(float g, float u) {
    float xi = 2.0f * u - 1.0f;
    float d = 1.0f + g * xi;
    float numerator = xi + 0.5f * g * (xi * xi + 3.0f) + g * g * xi + 0.5f * g * g * g * (xi * xi - 1.0f);
    return clamp(numerator / (d * d), -1.0f, 1.0f);
}

// mu with density (3/8)(1 + mu^2): the real root of mu^3 + 3 mu + 4 - 8u = 0, mu = A - 1/A with
// A = cbrt(w + sqrt(w^2 + 1)), w = 4u - 2 (Cardano; derivation in docs/conventions.md).
TY_FUNC float sampleRayleighMu(float u) {
    float w = 4.0f * u - 2.0f;
    float A = pow(w + sqrt(w * w + 1.0f), 1.0f / 3.0f);
    return clamp(A - 1.0f / A, -1.0f, 1.0f);
}

// mu with density (1 + b mu) / 2: root of b mu^2 + 2 mu + c = 0, c = 2 - b - 4u, in the form stable as b -> 0.
TY_FUNC float sampleEddingtonMu(float b, float u) {
    float c = 2.0f - b - 4.0f * u;
    return clamp(-c / (1.0f + sqrt(max(0.0f, 1.0f - b * c))), -1.0f, 1.0f);
}

// mu with the Legendre series' density: bisection on the monotone CDF (float precision after 24 steps).
TY_FUNC float sampleLegendreMu(TY_IN(PhaseParams) p, float u) {
    float lo = -1.0f, hi = 1.0f;
    for (int i = 0; i < 24; ++i) {
        float mid = 0.5f * (lo + hi);
        if (legendreCdf(p, mid) < u)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5f * (lo + hi);
}

// Samples the direction light travels after scattering, given the direction `w` it travelled before.
TY_FUNC vec3 phaseSample(TY_IN(PhaseParams) p, TY_IN(vec3) w, TY_IN(vec2) u, TY_OUT(float) pdf) {
    float mu;
    if (p.kind == kPhaseHenyeyGreenstein) {
        mu = sampleHenyeyGreensteinMu(p.g, u.x);
    } else if (p.kind == kPhaseIsoHgMix) {
        // Choose the lobe with u.x, then reuse the remainder of u.x as a fresh uniform number.
        if (u.x < p.a)
            mu = sampleHenyeyGreensteinMu(p.g, min(u.x / p.a, kOneMinusEpsilon));
        else
            mu = 1.0f - 2.0f * min((u.x - p.a) / (1.0f - p.a), kOneMinusEpsilon);
    } else if (p.kind == kPhaseRayleigh) {
        mu = sampleRayleighMu(u.x);
    } else if (p.kind == kPhaseEddington) {
        mu = sampleEddingtonMu(p.b, u.x);
    } else if (p.kind == kPhaseLegendre) {
        mu = sampleLegendreMu(p, u.x);
    } else if (p.kind == kPhaseHazyMie || p.kind == kPhaseMurkyMie) {
        // Half the energy in each part: choose with u.x and reuse its remainder.
        if (u.x < 0.5f)
            mu = 1.0f - 2.0f * min(2.0f * u.x, kOneMinusEpsilon);
        else
            mu = sampleMieLobeMu(mieLobeExponent(p.kind), min(2.0f * u.x - 1.0f, kOneMinusEpsilon));
    } else {
        mu = 1.0f - 2.0f * u.x;
    }
    pdf = phaseEval(p, mu);
    return directionAround(w, mu, u.y);
}

TY_END

#endif  // TY_SHARED_PHASE_H
