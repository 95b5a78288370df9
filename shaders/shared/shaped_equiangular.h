// Equiangular sampling shaped by the rest of the single-scattering integrand (issue 32; derivation in
// docs/reference.md, "Shaped equiangular distances").
//
// Along a ray o + t d, the light scattered towards o from a point light at P is
//   f(t) = T(0, t) sigma_s p(mu) I T(t, P) / r^2,   r^2 = h^2 + (t - t0)^2,
// and Kulla & Fajardo's equiangular density cancels the 1/r^2 exactly: with t = t0 + h tan(theta) it is uniform in
// theta over [thetaA, thetaB]. What it leaves is w(theta) = T(0, t) sigma_s p(mu) T(t, P), smooth in theta, with
// mu = -sin(theta) towards the light. It varies by orders of magnitude on a ray far from the light (both
// transmittances) and by the phase function's range near it (27x for HG g = 0.5). The shaped density is
//   q(theta) = w~(theta) / W,   pdf(t) = q(theta(t)) h / r^2,
// where w~ interpolates w linearly between K + 1 equally spaced nodes, each raised to half its neighbours' larger
// weight (so that w~ stays above half of a w that is monotone within a bin) and floored at kShapedFloor of the
// nodes' mean (a defensive share of the plain equiangular density); W is its integral. Inverting a piecewise-linear
// density is continuous in u, so a Sobol u keeps its stratification, and f / pdf is continuous along the ray.
//
// The caller evaluates w at the nodes (shapedNodeGeometry gives each node's t, r and mu), then shapedFinish().
// The table is for the CPU reference today; it is written here, in the shared language, so that a GPU estimator can
// take the same density.
#ifndef TY_SHARED_SHAPED_EQUIANGULAR_H
#define TY_SHARED_SHAPED_EQUIANGULAR_H

#include "compat.h"
#include "constants.h"
#include "sampling.h"

TY_BEGIN

#define TY_SHAPED_BINS 16

// Floor of every node's weight, relative to the nodes' mean: the table never gives a part of the ray less than this
// share of the equiangular density, which bounds f / pdf where w~ undershoots w between nodes.
TY_CONST float kShapedFloor = 0.02f;
// Every node's weight is at least this share of its neighbours' larger one (shapedFinish).
TY_CONST float kShapedDilation = 0.5f;

struct ShapedEquiangular {
    Equiangular e;
    float w[TY_SHAPED_BINS + 1];    // node weights, dilated and floored
    float cdf[TY_SHAPED_BINS + 1];  // cumulative trapezoid areas in units of the node spacing; cdf[0] = 0
};

// The geometry of the nodes theta_k = thetaA + k (thetaB - thetaA) / K: each node's ray parameter t, its distance r
// to the light and the cosine mu = dot(d, direction to the light) = -sin(theta_k). sin and cos of theta_k come from
// one sin/cos pair each for thetaA and the spacing, by the angle-sum recurrence (K steps lose ~1e-6 relative).
// Nodes at theta -> pi/2 (a ray without end) get a finite, very large t and r.
struct ShapedNodes {
    float t[TY_SHAPED_BINS + 1];
    float r[TY_SHAPED_BINS + 1];
    float mu[TY_SHAPED_BINS + 1];
};

TY_FUNC void shapedNodeGeometry(TY_IN(Equiangular) e, TY_OUT(ShapedNodes) n) {
    float step = (e.thetaB - e.thetaA) / float(TY_SHAPED_BINS);
    float s = sin(e.thetaA), c = cos(e.thetaA);
    float sStep = sin(step), cStep = cos(step);
    for (int k = 0; k <= TY_SHAPED_BINS; ++k) {
        float cosine = max(c, 1e-7f);
        n.t[k] = e.t0 + e.h * s / cosine;
        n.r[k] = e.h / cosine;
        n.mu[k] = -s;
        float next = s * cStep + c * sStep;
        c = c * cStep - s * sStep;
        s = next;
    }
}

// Makes the table nearly conservative, floors it and accumulates it. Each node takes at least kShapedDilation times
// the larger weight of its two neighbours: then a w that is monotone within a bin is nowhere above twice the
// interpolant, which bounds f / pdf there. Without it, a w that stays high almost to the far end of the last bin and
// then drops (a ray that passes close to the light) met a chord falling to the floor, and its samples came out up to
// 5x the mean; full dilation (1) bounds that at 1x but spends samples on every slope: on rays past the light of the
// fog-point scene the relative deviation was 0.09 undilated, 0.14 fully dilated and 0.03 at 1/2. Weights that are
// all zero (or not finite) give plain equiangular.
TY_FUNC void shapedFinish(TY_INOUT(ShapedEquiangular) s) {
    float previous = s.w[0], sum = 0.0f;
    for (int k = 0; k <= TY_SHAPED_BINS; ++k) {
        float here = s.w[k];
        float next = k < TY_SHAPED_BINS ? s.w[k + 1] : here;
        s.w[k] = max(here, kShapedDilation * max(previous, next));
        previous = here;
        sum += s.w[k];
    }
    float mean = sum / float(TY_SHAPED_BINS + 1);
    bool usable = mean > 0.0f && mean < kInfinity;
    float floorWeight = kShapedFloor * mean;
    s.cdf[0] = 0.0f;
    for (int k = 0; k <= TY_SHAPED_BINS; ++k) {
        s.w[k] = usable ? max(s.w[k], floorWeight) : 1.0f;
        if (k > 0) s.cdf[k] = s.cdf[k - 1] + 0.5f * (s.w[k - 1] + s.w[k]);
    }
}

// The density in theta (per radian) at fraction x in [0, 1] of bin j.
TY_FUNC float shapedThetaPdf(TY_IN(ShapedEquiangular) s, int j, float x) {
    float binWidth = (s.e.thetaB - s.e.thetaA) / float(TY_SHAPED_BINS);
    return mix(s.w[j], s.w[j + 1], x) / (s.cdf[TY_SHAPED_BINS] * binWidth);
}

TY_FUNC float shapedSample(TY_IN(ShapedEquiangular) s, float u, TY_OUT(float) pdf) {
    float target = u * s.cdf[TY_SHAPED_BINS];
    int j = 0;
    while (j + 1 < TY_SHAPED_BINS && s.cdf[j + 1] <= target)
        ++j;
    // Within the bin the density is linear from a to b: its CDF is x (a (2 - x) + b x) / (a + b), inverted in the
    // cancellation-free form x = v (a + b) / (a + sqrt(mix(a^2, b^2, v))).
    float a = s.w[j], b = s.w[j + 1];
    float v = clamp((target - s.cdf[j]) / (0.5f * (a + b)), 0.0f, 1.0f);
    float x = min(v * (a + b) / (a + sqrt(mix(a * a, b * b, v))), kOneMinusEpsilon);
    float theta = mix(s.e.thetaA, s.e.thetaB, (float(j) + x) / float(TY_SHAPED_BINS));
    float d = s.e.h * tan(theta);
    pdf = shapedThetaPdf(s, j, x) * s.e.h / (s.e.h * s.e.h + d * d);
    return s.e.t0 + d;
}

TY_FUNC float shapedPdf(TY_IN(ShapedEquiangular) s, float t) {
    float d = t - s.e.t0;
    float theta = atan(d, s.e.h);
    float position = (theta - s.e.thetaA) / (s.e.thetaB - s.e.thetaA) * float(TY_SHAPED_BINS);
    if (!(position >= 0.0f && position <= float(TY_SHAPED_BINS))) return 0.0f;
    int j = min(int(position), TY_SHAPED_BINS - 1);
    return shapedThetaPdf(s, j, position - float(j)) * s.e.h / (s.e.h * s.e.h + d * d);
}

TY_END

#endif  // TY_SHARED_SHAPED_EQUIANGULAR_H
