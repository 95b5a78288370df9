// Linearly transformed cosines (LTCs, Heitz et al. 2016) of GGX with height-correlated Smith, shared by GLSL and C++:
// the fitted tables' entry, the isotropic table's fetch with bilinear interpolation over (alpha, sqrt(1 - cos
// theta_o)), the anisotropic table's quadrilinear fetch with the symmetries of 002 (Eq. 13-15), the polygon integral of
// an LTC (the polygon clipped to the surface's horizon, transformed by M^-1, then the clamped cosine's edge integral of
// ltsd.h), and Schlick's Fresnel applied at run time from the entry's two moments. Derivations, the tables' format and
// their measured quality: docs/tables.md ("LTC GGX tables").
//
// Frame: the shading normal is +z. An isotropic entry is fitted with omega_o in the xz-plane, x >= 0, so a polygon is
// expressed in the frame (x, y, n) with x the direction of omega_o projected onto the surface (any tangent when
// omega_o = n) and y = n x x.
#ifndef TY_SHARED_LTC_H
#define TY_SHARED_LTC_H

#include "compat.h"
#include "constants.h"
#include "ltsd.h"

TY_BEGIN

// One fitted table entry, 48 bytes (std430-compatible).
struct LtcEntry {
    float m[9];     // M, column-major (m[3 * column + row]), its third column of unit length (002, Sec. 7)
    float norm;     // int f cos over the hemisphere with F = 1: the directional albedo, in (0, 1]
    float fresnel;  // int f cos (1 - omega_i . h)^5 with F = 1: the weight of (1 - F0) in Schlick's term, in [0, norm]
    float error;    // the fit's total-variation distance between the normalised lobe and the LTC (informative)
};

// The isotropic table's grazing end: cos theta_o below this is fitted (and looked up) as this.
TY_CONST float kLtcMinCosTheta = 1e-3f;

// ---------------------------------------------------------------------------------------------------------------------
// Isotropic table: nX x nAlpha entries, entry (ix, ia) at index ia * nX + ix, with x = sqrt(1 - cos theta_o) uniform
// over [0, 1] (Heitz et al. 2016) and alpha uniform over [alphaMin, 1] (M's aperture is linear in alpha at low
// roughness, 002 Sec. 7, so M interpolates well in alpha).

struct LtcBilinear {
    int i00;   // (ix, ia)
    int i10;   // (ix + 1, ia)
    int i01;   // (ix, ia + 1)
    int i11;   // (ix + 1, ia + 1)
    float wx;  // weight of ix + 1
    float wa;  // weight of ia + 1
};

TY_FUNC LtcBilinear ltcFetchIsotropic(float alpha, float cosTheta, int nX, int nAlpha, float alphaMin) {
    float x = sqrt(clamp(1.0f - cosTheta, 0.0f, 1.0f)) * float(nX - 1);
    float a = clamp((alpha - alphaMin) / (1.0f - alphaMin), 0.0f, 1.0f) * float(nAlpha - 1);
    int ix = clamp(int(floor(x)), 0, nX - 2);
    int ia = clamp(int(floor(a)), 0, nAlpha - 2);
    LtcBilinear f;
    f.i00 = ia * nX + ix;
    f.i10 = f.i00 + 1;
    f.i01 = f.i00 + nX;
    f.i11 = f.i01 + 1;
    f.wx = clamp(x - float(ix), 0.0f, 1.0f);
    f.wa = clamp(a - float(ia), 0.0f, 1.0f);
    return f;
}

// Linear interpolation of every field; the fitted matrices are aligned (docs/tables.md), so this is well defined.
TY_FUNC LtcEntry ltcLerp(TY_IN(LtcEntry) a, TY_IN(LtcEntry) b, float w) {
    LtcEntry e = a;
    for (int i = 0; i < 9; ++i)
        e.m[i] = mix(a.m[i], b.m[i], w);
    e.norm = mix(a.norm, b.norm, w);
    e.fresnel = mix(a.fresnel, b.fresnel, w);
    e.error = mix(a.error, b.error, w);
    return e;
}

TY_FUNC LtcEntry ltcBilinearBlend(TY_IN(LtcEntry) e00, TY_IN(LtcEntry) e10, TY_IN(LtcEntry) e01, TY_IN(LtcEntry) e11,
                                  TY_IN(LtcBilinear) f) {
    return ltcLerp(ltcLerp(e00, e10, f.wx), ltcLerp(e01, e11, f.wx), f.wa);
}

// The polygon (shading frame) in the isotropic entries' frame: rotated about the normal so that omega_o lies in the
// xz-plane with x >= 0 (x along +x of the shading frame when omega_o is the normal).
TY_FUNC SphericalPolygon ltcToIsotropicFrame(TY_IN(SphericalPolygon) p, TY_IN(vec3) wo) {
    float l = sqrt(wo.x * wo.x + wo.y * wo.y);
    vec2 x = l > 0.0f ? vec2(wo.x, wo.y) / l : vec2(1.0f, 0.0f);
    SphericalPolygon r = p;
    for (int i = 0; i < p.count; ++i)
        r.v[i] = vec3(x.x * p.v[i].x + x.y * p.v[i].y, x.x * p.v[i].y - x.y * p.v[i].x, p.v[i].z);
    return r;
}

// ---------------------------------------------------------------------------------------------------------------------
// Anisotropic table (002): nTheta x nPhi x nAlpha x nRatio entries, entry (it, ip, ia, ir) at index
// ((ir * nAlpha + ia) * nPhi + ip) * nTheta + it, over theta_o and phi_o uniform over [0, pi / 2] (omega_o's angles in
// the shading frame: x the tangent, along which the roughness is alphaX), alpha = max(alphaX, alphaY) uniform over
// [alphaMin, 1] and r = min / max uniform over [ratioMin, 1] (002 Eq. 15; fitted with the smaller roughness
// max(r alpha, alphaMin)). r below ratioMin is looked up as ratioMin (docs/tables.md: more anisotropic lobes are thin
// arcs that no LTC follows). The symmetries recover everything else (002 Eq. 13-14): with S the swap of x and y and F
// the flips of x and/or y, the lobe of (alphaX, alphaY, omega_o) is that of the canonical (alpha, r, F S omega_o) seen
// through F S, where S applies when alphaY > alphaX and F makes F S omega_o's x and y non-negative; so the polygon's
// integral is the canonical LTC's over F S P, and M^-1 of the lookup is M_c^-1 F S.

TY_CONST float kLtcHalfPi = 1.57079632679489661923f;

struct LtcQuadrilinear {
    int base;         // the lower corner (it, ip, ia, ir)
    int strideTheta;  // index steps to the upper corner in each dimension
    int stridePhi;
    int strideAlpha;
    int strideRatio;
    vec4 w;            // weights of the upper corners: theta, phi, alpha, ratio
    mat3 toCanonical;  // F S: the polygon in the canonical frame is F S P
};

TY_FUNC float ltcGridCoordinate(float t, int n, TY_OUT(int) i) {
    float x = clamp(t, 0.0f, 1.0f) * float(n - 1);
    i = clamp(int(floor(x)), 0, n - 2);
    return clamp(x - float(i), 0.0f, 1.0f);
}

// The 16 entries to blend for GGX (alphaX, alphaY) seen from wo (unit, shading frame, wo.z > 0 expected).
TY_FUNC LtcQuadrilinear ltcFetchAnisotropic(float alphaX, float alphaY, TY_IN(vec3) wo, int nTheta, int nPhi,
                                            int nAlpha, int nRatio, float alphaMin, float ratioMin) {
    bool swapXY = alphaY > alphaX;
    vec3 w = swapXY ? vec3(wo.y, wo.x, wo.z) : wo;
    float fx = w.x < 0.0f ? -1.0f : 1.0f;
    float fy = w.y < 0.0f ? -1.0f : 1.0f;
    w = vec3(fx * w.x, fy * w.y, w.z);
    float alpha = max(alphaX, alphaY);
    float r = min(alphaX, alphaY) / alpha;
    float theta = acos(clamp(w.z, 0.0f, 1.0f));
    float phi = atan(w.y, max(w.x, 1e-30f));
    int it, ip, ia, ir;
    LtcQuadrilinear q;
    q.w = vec4(ltcGridCoordinate(theta / kLtcHalfPi, nTheta, it), ltcGridCoordinate(phi / kLtcHalfPi, nPhi, ip),
               ltcGridCoordinate((alpha - alphaMin) / (1.0f - alphaMin), nAlpha, ia),
               ltcGridCoordinate((r - ratioMin) / (1.0f - ratioMin), nRatio, ir));
    q.base = ((ir * nAlpha + ia) * nPhi + ip) * nTheta + it;
    q.strideTheta = 1;
    q.stridePhi = nTheta;
    q.strideAlpha = nTheta * nPhi;
    q.strideRatio = nTheta * nPhi * nAlpha;
    // F S as a matrix (columns): S swaps the x and y columns of the identity, F negates rows.
    vec3 cx = swapXY ? vec3(0.0f, 1.0f, 0.0f) : vec3(1.0f, 0.0f, 0.0f);
    vec3 cy = swapXY ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f);
    vec3 f = vec3(fx, fy, 1.0f);
    q.toCanonical = mat3(f * cx, f * cy, vec3(0.0f, 0.0f, 1.0f));
    return q;
}

// Corner k in [0, 16) of the fetch: bit 0 theta, bit 1 phi, bit 2 alpha, bit 3 ratio.
TY_FUNC int ltcCornerIndex(TY_IN(LtcQuadrilinear) q, int k) {
    return q.base + ((k & 1) != 0 ? q.strideTheta : 0) + ((k & 2) != 0 ? q.stridePhi : 0) +
           ((k & 4) != 0 ? q.strideAlpha : 0) + ((k & 8) != 0 ? q.strideRatio : 0);
}

TY_FUNC float ltcCornerWeight(TY_IN(LtcQuadrilinear) q, int k) {
    return ((k & 1) != 0 ? q.w.x : 1.0f - q.w.x) * ((k & 2) != 0 ? q.w.y : 1.0f - q.w.y) *
           ((k & 4) != 0 ? q.w.z : 1.0f - q.w.z) * ((k & 8) != 0 ? q.w.w : 1.0f - q.w.w);
}

// acc + w e, every field (the quadrilinear blend is sum over corners of ltcCornerWeight times the corner's entry).
TY_FUNC LtcEntry ltcAddWeighted(TY_IN(LtcEntry) acc, TY_IN(LtcEntry) e, float w) {
    LtcEntry r = acc;
    for (int i = 0; i < 9; ++i)
        r.m[i] += w * e.m[i];
    r.norm += w * e.norm;
    r.fresnel += w * e.fresnel;
    r.error += w * e.error;
    return r;
}

TY_FUNC LtcEntry ltcZeroEntry() {
    LtcEntry e;
    for (int i = 0; i < 9; ++i)
        e.m[i] = 0.0f;
    e.norm = 0.0f;
    e.fresnel = 0.0f;
    e.error = 0.0f;
    return e;
}

// ---------------------------------------------------------------------------------------------------------------------
// Evaluation

TY_FUNC mat3 ltcMatrix(TY_IN(LtcEntry) e) {
    return mat3(vec3(e.m[0], e.m[1], e.m[2]), vec3(e.m[3], e.m[4], e.m[5]), vec3(e.m[6], e.m[7], e.m[8]));
}

// The integral of the LTC of M over P (a polygon in the LTC's frame, normal +z), given M^-1: Eq. 8 of 000 (Eq. 8 of
// 002), the clamped cosine's integral over M^-1 P. P is first clipped to the surface's upper hemisphere, where the
// BRDF lives: the fit counts the LTC's mass below the horizon as error (docs/tables.md), so the run time drops it too.
// Both clips are made edge by edge (ltsdClippedCosineIntegral).
TY_FUNC float ltcPolygonIntegral(TY_IN(mat3) mInv, TY_IN(SphericalPolygon) p) {
    return ltsdClippedCosineIntegral(p, mInv);
}

// The LTC's density per sr in direction w (unit, LTC frame): the clamped cosine at M^-1 w / |M^-1 w| times the
// Jacobian |det M^-1| / |M^-1 w|^3 (Eq. 7 of 002).
TY_FUNC float ltcEval(TY_IN(mat3) mInv, TY_IN(vec3) w) {
    vec3 ws = mInv * w;
    float l = length(ws);
    float detInv = abs(dot(mInv[0], cross(mInv[1], mInv[2])));
    return max(ws.z / l, 0.0f) * kInvPi * detInv / (l * l * l);
}

// The hemispherical integral of f cos with Schlick's Fresnel, F = F0 + (1 - F0)(1 - omega_i . h)^5:
// F0 (norm - fresnel) + fresnel (Hill and Heitz 2016's split of the Fresnel term), per channel.
TY_FUNC vec3 ltcFresnelNorm(TY_IN(LtcEntry) e, TY_IN(vec3) f0) {
    return f0 * (e.norm - e.fresnel) + vec3(e.fresnel);
}

// The LTC approximation of int_P f(omega_o, omega_i) cos theta_i d omega_i for the entry (P in the LTC's frame): the
// normalised lobe's integral times Schlick's hemispherical moment.
TY_FUNC vec3 ltcBrdfIntegral(TY_IN(LtcEntry) e, TY_IN(vec3) f0, TY_IN(SphericalPolygon) p) {
    return ltcFresnelNorm(e, f0) * ltcPolygonIntegral(ltsdInverse(ltcMatrix(e)), p);
}

TY_END

#endif  // TY_SHARED_LTC_H
