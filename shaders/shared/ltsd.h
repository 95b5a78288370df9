// Linearly transformed spherical distributions (LTSDs) over spherical polygons, shared by GLSL and C++: the exact
// clamped-cosine polygon integral with horizon clipping, the inverse clamped cosine (Eq. 20 of the LTSD paper (000)),
// S(z, A(z)) of Eq. 21 with the horizon split, and the table fetch of Eq. 24. Derivations: docs/tables.md.
//
// Frame: omega_o (the direction towards the viewer, opposite to the camera ray's direction d) is +z. A phase function
// with the project's convention mu = dot(d, omega_i) is therefore evaluated at mu = -omega_i.z: forward scattering
// (g > 0) peaks at -z, in the lower hemisphere, as Eq. 19 of 000 assumes.
//
// A polygon is the cone through its vertices (directions, any length > 0); it must lie inside an open hemisphere, as a
// planar light that does not contain the point does. Vertex order does not matter: every integral here is oriented by
// the sign of the polygon's own solid angle.
#ifndef TY_SHARED_LTSD_H
#define TY_SHARED_LTSD_H

#include "compat.h"
#include "constants.h"

TY_BEGIN

// A polygon holds up to kLtsdMaxVertices vertices; inputs (lights, `tyndall tables eval`) take at most
// kLtsdMaxVertices - 1, so that a clipped polygon (one vertex more) fits too where a caller stores one.
TY_CONST int kLtsdMaxVertices = 10;

// Loops over a polygon's vertices stop at kLtsdLoopVertices: kLtsdMaxVertices, or fewer where the includer knows that
// no polygon it builds has more (TY_LTSD_VERTICES; the LTSD kernel defines it as its lights' most vertices). Lavapipe
// runs every unrolled iteration for every lane, taken or not, so a quad in a loop of ten pays for ten edges.
#ifdef TY_LTSD_VERTICES
TY_CONST int kLtsdLoopVertices = TY_LTSD_VERTICES;
#else
TY_CONST int kLtsdLoopVertices = kLtsdMaxVertices;
#endif

TY_CONST int kLtsdSourceClampedCosine = 0;         // D_o = max(z, 0) / pi
TY_CONST int kLtsdSourceInverseClampedCosine = 1;  // D_o = (1 - z) / pi for z > 0, else 0

struct SphericalPolygon {
    vec3 v[kLtsdMaxVertices];
    int count;
};

// One fitted table entry: the LTSD of one hemisphere of a phase function (std430-compatible, 48 bytes).
struct LtsdEntry {
    float m[9];       // M, column-major (m[3 * column + row]); the distribution is D_o transformed by M
    float amplitude;  // the phase function's integral over the hemisphere the entry fits, in [0, 1]
    int source;       // kLtsdSource*
    float g;          // the table coordinate the entry was fitted at (informative; not used by the fetch)
};

// ---------------------------------------------------------------------------------------------------------------------
// Polygons

// Loops over a polygon's vertices run over the constant kLtsdLoopVertices with the count as a condition, and read the
// next vertex by a select of two constant indices: unrolled, every access has a constant index, so the polygon stays
// in registers. A loop bounded by the count indexes it dynamically, which lavapipe serves from memory, lane by lane.
TY_FUNC vec3 ltsdNextVertex(TY_IN(SphericalPolygon) p, int i) {
    return i + 1 < p.count ? p.v[min(i + 1, kLtsdMaxVertices - 1)] : p.v[0];
}

// Signed solid angle: a fan of Van Oosterom-Strackee triangles, tan(Omega / 2) = a.(b x c) / (1 + a.b + b.c + c.a).
// Positive when the vertices turn counter-clockwise seen from outside the sphere.
TY_FUNC float ltsdSignedSolidAngle(TY_IN(SphericalPolygon) p) {
    vec3 a = normalize(p.v[0]);
    float sum = 0.0f;
    for (int i = 1; i + 1 < kLtsdLoopVertices; ++i) {
        if (i + 1 < p.count) {
            vec3 b = normalize(p.v[i]);
            vec3 c = normalize(p.v[i + 1]);
            float numerator = dot(a, cross(b, c));
            float denominator = 1.0f + dot(a, b) + dot(b, c) + dot(c, a);
            sum += 2.0f * atan(numerator, denominator);
        }
    }
    return p.count < 3 ? 0.0f : sum;
}

// The edge a -> b's term of Lambert's formula, theta n.z with n the edge's unit normal and theta its angle (atan(|c|,
// d), accurate for short edges too), without the 1 / (2 pi).
TY_FUNC float ltsdEdgeCosineTerm(TY_IN(vec3) a, TY_IN(vec3) b) {
    vec3 c = cross(a, b);
    float s = length(c);
    return s > 0.0f ? atan(s, dot(a, b)) * c.z / s : 0.0f;
}

// (1 / 2 pi) sum over edges of theta_i n_i.z, the edge integral of Lambert's formula: the integral of z / pi over the
// polygon, with the sign of ltsdSignedSolidAngle.
TY_FUNC float ltsdSignedCosineSum(TY_IN(SphericalPolygon) p) {
    float sum = 0.0f;
    for (int i = 0; i < kLtsdLoopVertices; ++i) {
        if (i < p.count) sum += ltsdEdgeCosineTerm(normalize(p.v[i]), normalize(ltsdNextVertex(p, i)));
    }
    return sum * (0.5f * kInvPi);
}

// ---------------------------------------------------------------------------------------------------------------------
// Clipped moments, edge by edge
//
// The integrals of the sources over a polygon clipped to the horizon need two numbers of the clipped polygon: its
// signed solid angle and its signed cosine sum. Both are sums over its edges, so they are accumulated edge by edge
// while each edge of P is clipped, with no clipped polygon ever stored (an array written at a running count is
// indexed dynamically). Clipping a convex polygon to z >= 0 cuts each edge to its part above, and adds one edge along
// the horizon, from the point where the boundary leaves the upper hemisphere to the point where it comes back. The
// solid angle is a fan from +z, Van Oosterom-Strackee per edge: every clipped polygon lies in the closed upper
// hemisphere, so -z, where the fan is singular, is never inside it.

struct LtsdHorizonCut {
    vec3 exitPoint;   // where the boundary crosses from z >= 0 to z < 0
    vec3 entryPoint;  // where it comes back
    bool exits;
    bool enters;
};

TY_FUNC LtsdHorizonCut ltsdNoCut() {
    LtsdHorizonCut cut;
    cut.exitPoint = vec3(0.0f);
    cut.entryPoint = vec3(0.0f);
    cut.exits = false;
    cut.enters = false;
    return cut;
}

// Clips the edge a -> b to z >= 0 in place and records a crossing in `cut`; false when nothing of it is above.
TY_FUNC bool ltsdClipEdge(TY_INOUT(vec3) a, TY_INOUT(vec3) b, TY_INOUT(LtsdHorizonCut) cut) {
    float da = a.z;
    float db = b.z;
    if (da < 0.0f && db < 0.0f) return false;
    if (da >= 0.0f && db >= 0.0f) return true;
    vec3 c = mix(a, b, da / (da - db));
    c.z = 0.0f;
    if (da >= 0.0f) {
        b = c;
        cut.exitPoint = c;
        cut.exits = true;
    } else {
        a = c;
        cut.entryPoint = c;
        cut.enters = true;
    }
    return true;
}

// Adds the edge a -> b (both with z >= 0, any length > 0) to the signed solid angle (x, fan from +z) and the signed
// cosine sum (y, without its 1 / (2 pi)). Without `solidAngle`, x stays 0 and the vertices need no normalising: the
// cosine term's angle atan(|a x b|, a.b) and the edge normal's z are both independent of the vertices' lengths.
TY_FUNC vec2 ltsdEdgeMoments(TY_IN(vec3) a0, TY_IN(vec3) b0, bool solidAngle) {
    if (!solidAngle) return vec2(0.0f, ltsdEdgeCosineTerm(a0, b0));
    vec3 a = normalize(a0);
    vec3 b = normalize(b0);
    float omega = 2.0f * atan(cross(a, b).z, 1.0f + a.z + b.z + dot(a, b));
    return vec2(omega, ltsdEdgeCosineTerm(a, b));
}

// The moments (x: the signed solid angle, y: the signed cosine sum without its 1 / (2 pi)) of mInv (side P)^+ clipped
// again to z >= 0: P with z scaled by side (+1, or -1 to mirror its lower half up), clipped to the upper hemisphere,
// mapped by mInv (det > 0, so orientation is kept), clipped once more. The result's sign is P's orientation (flipped
// by the mirror). Without `solidAngle` only y is computed (x is 0): the callers pass a constant, which the shader
// compilers fold, so the clamped cosine's integral pays for no solid angle (ltsdClippedCosineSum).
TY_FUNC vec2 ltsdClippedMomentsOf(TY_IN(SphericalPolygon) p, TY_IN(mat3) mInv, float side, bool solidAngle) {
    vec2 moments = vec2(0.0f);
    LtsdHorizonCut first = ltsdNoCut();
    LtsdHorizonCut second = ltsdNoCut();
    for (int i = 0; i < kLtsdLoopVertices; ++i) {
        if (i < p.count) {
            vec3 a = p.v[i];
            vec3 b = ltsdNextVertex(p, i);
            a.z *= side;
            b.z *= side;
            if (ltsdClipEdge(a, b, first)) {
                a = mInv * a;
                b = mInv * b;
                if (ltsdClipEdge(a, b, second)) moments += ltsdEdgeMoments(a, b, solidAngle);
            }
        }
    }
    if (first.exits && first.enters) {
        vec3 a = mInv * first.exitPoint;
        vec3 b = mInv * first.entryPoint;
        if (ltsdClipEdge(a, b, second)) moments += ltsdEdgeMoments(a, b, solidAngle);
    }
    if (second.exits && second.enters) moments += ltsdEdgeMoments(second.exitPoint, second.entryPoint, solidAngle);
    return moments;
}

TY_FUNC vec2 ltsdClippedMoments(TY_IN(SphericalPolygon) p, TY_IN(mat3) mInv, float side) {
    return ltsdClippedMomentsOf(p, mInv, side, true);
}

// The clamped cosine's integral over mInv (P clipped to z >= 0), clipped again: |cosine sum| / (2 pi). The cosine is
// non-negative over the clipped polygon, so the signed sum's magnitude is the integral whatever P's orientation, and
// the solid angle that orients the inverse clamped cosine is not needed (half the transcendental work of an edge).
TY_FUNC float ltsdClippedCosineIntegral(TY_IN(SphericalPolygon) p, TY_IN(mat3) mInv) {
    return abs(ltsdClippedMomentsOf(p, mInv, 1.0f, false).y) * (0.5f * kInvPi);
}

// A source's integral over the clipped polygon from its moments: the clamped cosine's is E = |cosine sum| / (2 pi),
// the inverse clamped cosine's Omega / pi - E (Eq. 20 of 000), each signed by the polygon's orientation.
TY_FUNC float ltsdSourceFromMoments(TY_IN(vec2) moments, int source) {
    float orientation = moments.x < 0.0f ? -1.0f : 1.0f;
    float cosine = orientation * moments.y * (0.5f * kInvPi);
    if (source == kLtsdSourceClampedCosine) return max(0.0f, cosine);
    return max(0.0f, orientation * moments.x * kInvPi - cosine);
}

// The polygon's solid angle in sr, in [0, 2 pi] for a polygon inside a hemisphere.
TY_FUNC float ltsdSolidAngle(TY_IN(SphericalPolygon) p) {
    return abs(ltsdSignedSolidAngle(p));
}

// E(P): the integral of the clamped cosine max(z, 0) / pi over P, in [0, 1] (the normalised cosine irradiance of Eq. 8
// of 000): the edge integral over the part of P above the horizon.
TY_FUNC float ltsdClampedCosineIntegral(TY_IN(SphericalPolygon) p) {
    return ltsdClippedCosineIntegral(p, mat3(1.0f));
}

// The integral over P of the inverse clamped cosine on the upper hemisphere, (1 - z) / pi for z > 0 (normalised: it
// integrates to 1 over the hemisphere): Omega(P+) / pi - E(P), Eq. 20 of 000 with the normalisation (docs/tables.md).
TY_FUNC float ltsdInverseClampedCosineIntegral(TY_IN(SphericalPolygon) p) {
    return ltsdSourceFromMoments(ltsdClippedMoments(p, mat3(1.0f), 1.0f), kLtsdSourceInverseClampedCosine);
}


// ---------------------------------------------------------------------------------------------------------------------
// Source distributions: densities (per sr) and samplers

TY_FUNC float ltsdSourceEval(int source, float z) {
    if (z <= 0.0f) return 0.0f;
    return source == kLtsdSourceClampedCosine ? z * kInvPi : (1.0f - z) * kInvPi;
}

// The inverse clamped cosine (1 - z) / pi on the upper hemisphere: P(Z > z) = (1 - z)^2, so z = 1 - sqrt(u)
// (docs/tables.md).
TY_FUNC vec3 ltsdSampleInverseClampedCosine(TY_IN(vec2) u) {
    float z = 1.0f - sqrt(u.x);
    float r = sqrt(max(0.0f, 1.0f - z * z));
    float phi = kTwoPi * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// ---------------------------------------------------------------------------------------------------------------------
// Transformed distributions

TY_FUNC mat3 ltsdMatrix(TY_IN(LtsdEntry) e) {
    return mat3(vec3(e.m[0], e.m[1], e.m[2]), vec3(e.m[3], e.m[4], e.m[5]), vec3(e.m[6], e.m[7], e.m[8]));
}

// M^-1 by the adjugate (GLSL's inverse() has no counterpart in the shared subset); det(M) > 0 for every loaded entry.
TY_FUNC mat3 ltsdInverse(TY_IN(mat3) m) {
    vec3 r0 = cross(m[1], m[2]);
    vec3 r1 = cross(m[2], m[0]);
    vec3 r2 = cross(m[0], m[1]);
    float invDet = 1.0f / dot(m[0], r0);
    // The rows of M^-1 are r0, r1, r2 / det; mat3() takes columns, hence the transposed layout.
    return mat3(vec3(r0.x, r1.x, r2.x), vec3(r0.y, r1.y, r2.y), vec3(r0.z, r1.z, r2.z)) * invDet;
}

// D(w) = D_o(M^-1 w / |M^-1 w|) |det M^-1| / |M^-1 w|^3 (Eq. 6 of 000) for a unit direction w: the entry's fitted
// density per sr, without its amplitude.
TY_FUNC float ltsdEval(TY_IN(LtsdEntry) e, TY_IN(vec3) w) {
    mat3 mInv = ltsdInverse(ltsdMatrix(e));
    vec3 wo = mInv * w;
    float l = length(wo);
    float detInv = abs(dot(mInv[0], cross(mInv[1], mInv[2])));
    return ltsdSourceEval(e.source, wo.z / l) * detInv / (l * l * l);
}

// The integral of the entry's fitted distribution over P: Eq. 7 of 000, the source's integral over M^-1 P.
TY_FUNC float ltsdPolygonIntegral(TY_IN(LtsdEntry) e, TY_IN(SphericalPolygon) p) {
    return ltsdSourceFromMoments(ltsdClippedMoments(p, ltsdInverse(ltsdMatrix(e)), 1.0f), e.source);
}

// Eq. 21 of 000 (with Eq. 17-19): S(z, A(z)) = a_u int_{M_u^-1 A^u} D_o^u + a_l int_{M_l^-1 A^l} D_o^l, the LTSD
// approximation of the phase function's integral over P. `upper` is M_u with a_u, `lower` the table entry T with a_l
// such that M_l = diag(1, 1, -1) T (Eq. 24): the lower half of P is mirrored to the upper hemisphere and transformed
// by T^-1, so that M_l^-1 = T^-1 diag(1, 1, -1). Each half is P clipped to its hemisphere (after the mirror: to the
// upper one), transformed, and clipped again, since M^-1 may move part of it below the horizon.
TY_FUNC float ltsdS(TY_IN(SphericalPolygon) p, TY_IN(LtsdEntry) upper, TY_IN(LtsdEntry) lower) {
    float sum = 0.0f;
    if (upper.amplitude > 0.0f)
        sum += upper.amplitude *
               ltsdSourceFromMoments(ltsdClippedMoments(p, ltsdInverse(ltsdMatrix(upper)), 1.0f), upper.source);
    if (lower.amplitude > 0.0f)
        sum += lower.amplitude *
               ltsdSourceFromMoments(ltsdClippedMoments(p, ltsdInverse(ltsdMatrix(lower)), -1.0f), lower.source);
    return sum;
}

// The exact part of a phase function beyond the paper (docs/tables.md, "Other phase functions"): the integral over P of
// (isotropic + linear mu) / (4 pi) with mu = -z, i.e. (isotropic Omega(P) - linear int_P z) / (4 pi), where
// int_P z = pi x the (unclipped) edge sum of Lambert's formula, valid for any polygon inside an open hemisphere.
TY_FUNC float ltsdLinearPhaseIntegral(TY_IN(SphericalPolygon) p, float isotropic, float linear) {
    float signedOmega = ltsdSignedSolidAngle(p);
    float orientation = signedOmega < 0.0f ? -1.0f : 1.0f;
    float zIntegral = kPi * orientation * ltsdSignedCosineSum(p);
    return (isotropic * abs(signedOmega) - linear * zIntegral) * kInvFourPi;
}

// The integral of a phase function over P: S of Eq. 21 for the part the table's LTSDs fit (the entries' amplitudes
// carry its weight) plus the exact isotropic and linear parts. HG: isotropic = linear = 0, so this is ltsdS; isotropic
// and Eddington need no entries (amplitudes 0); the HG-isotropic mix, Rayleigh and the Mie presets have both parts.
TY_FUNC float ltsdPhaseIntegral(TY_IN(SphericalPolygon) p, TY_IN(LtsdEntry) upper, TY_IN(LtsdEntry) lower,
                                float isotropic, float linear) {
    float s = ltsdS(p, upper, lower);
    if (isotropic != 0.0f || linear != 0.0f) s += ltsdLinearPhaseIntegral(p, isotropic, linear);
    return s;
}

// ---------------------------------------------------------------------------------------------------------------------
// Table fetch (Eq. 24 of 000)
//
// A table of 2n entries for the upper hemisphere of the phase function at g: entries [0, n) are T_1, g uniform over
// [-gMax, 0] (fitted to the clamped cosine); entries [n, 2n) are T_2, g uniform over [0, gMax] (inverse clamped
// cosine). g outside [-gMax, gMax] is clamped (docs/tables.md). The caller reads entries i0 and i1 from its buffer and
// blends them with ltsdLerp.

struct LtsdFetch {
    int i0;
    int i1;
    float w;  // weight of i1
};

TY_FUNC LtsdFetch ltsdFetchAt(float g, bool firstTableAtZero, int n, float gMax) {
    float gc = clamp(g, -gMax, gMax);
    bool first = gc < 0.0f || (gc == 0.0f && firstTableAtZero);
    float x = (first ? gc + gMax : gc) / gMax * float(n - 1);
    int i = clamp(int(floor(x)), 0, n - 2);
    LtsdFetch f;
    f.i0 = (first ? 0 : n) + i;
    f.i1 = f.i0 + 1;
    f.w = clamp(x - float(i), 0.0f, 1.0f);
    return f;
}

// M_u: T_1(g) for g < 0, T_2(g) for g >= 0.
TY_FUNC LtsdFetch ltsdFetchUpper(float g, int n, float gMax) {
    return ltsdFetchAt(g, false, n, gMax);
}

// The T of M_l = diag(1, 1, -1) T: T_2(|g|) for g < 0, T_1(-g) for g >= 0. Its amplitude is a_l(g) = a_u(-g).
TY_FUNC LtsdFetch ltsdFetchLower(float g, int n, float gMax) {
    return ltsdFetchAt(-g, true, n, gMax);
}

// Linear interpolation of M and the amplitude; the fitted matrices are aligned (docs/tables.md), so this is well
// defined. Both entries come from the same half of the table, so they share their source.
TY_FUNC LtsdEntry ltsdLerp(TY_IN(LtsdEntry) a, TY_IN(LtsdEntry) b, float w) {
    LtsdEntry e = a;
    for (int i = 0; i < 9; ++i) e.m[i] = mix(a.m[i], b.m[i], w);
    e.amplitude = mix(a.amplitude, b.amplitude, w);
    e.g = mix(a.g, b.g, w);
    return e;
}

TY_END

#endif  // TY_SHARED_LTSD_H
