// The Pegoraro technique's scene as the GPU sees it (std430 layouts, declared once for GLSL and C++), and the
// per-pixel renderer shared by its compute shader and its CPU path: camera rays, closest hits, the closed-form medium
// radiance of every (medium, light) pair over the lit parts of the ray, and the surface behind (Eq. 1, 2, 8 of the
// Pegoraro paper (003)). Precision-independent parts are here; pegoraro_pixel_impl.h holds the rest, per precision.
//
// The includer defines the accessors after including this header (as for bvh.h):
//   PegoraroLight pegoraroLight(int i);      PegoraroMedium pegoraroMedium(int i);
//   vec2 pegoraroCoefficient(int i);          a polynomial coefficient as a float pair (hi, lo), value = hi + lo
//   SurfaceTriangle surfaceTriangle(int id);  MaterialParams surfaceMaterial(int i);
// and bvhNode / bvhTriangle for bvh.h.
#ifndef TY_SHARED_PEGORARO_SCENE_H
#define TY_SHARED_PEGORARO_SCENE_H

#include "bvh.h"
#include "camera.h"
#include "compat.h"
#include "constants.h"
#include "lit_intervals.h"
#include "pegoraro.h"
#include "primary_hits.h"
#include "singular_pixel.h"
#include "surface.h"

TY_BEGIN

// A point light, 48 bytes: I(s) = intensity * sum_k c_k s^k with s the cosine to the axis.
struct PegoraroLight {
    vec3 position;         // m
    int firstCoefficient;  // index of c_0 among the coefficients
    vec3 axis;             // unit
    int terms;             // number of coefficients, >= 1
    vec3 intensity;        // W/sr, linear RGB
    float pad0;
};

// An infinite homogeneous medium, 32 bytes: its scattering coefficient and phase function Phi(mu) = sum_k c_k mu^k.
struct PegoraroMedium {
    vec3 sigmaS;  // 1/m
    int firstCoefficient;
    int terms;
    float pad0;
    float pad1;
    float pad2;
};

TY_CONST int kPegoraroFallbackAuto = 0;    // quadrature where the closed form's error bound exceeds the tolerance
TY_CONST int kPegoraroFallbackNever = 1;   // the closed form everywhere
TY_CONST int kPegoraroFallbackAlways = 2;  // quadrature everywhere (for comparison)

// Everything else a frame needs, 144 bytes.
struct PegoraroFrame {
    CameraParams camera;
    vec3 sigmaT;  // 1/m, the sum of every medium's extinction
    int lightCount;
    int mediumCount;
    int supersampling;          // S: S x S sub-pixel samples on a regular grid (a box filter)
    int shadows;                // 1: lit intervals in the medium and shadow rays at surfaces
    int fallbackMode;           // kPegoraroFallback*
    float fallbackTolerance;    // relative error bound above which the closed form falls back
    float quadratureTolerance;  // relative tolerance of the fallback quadrature
    float rayOffset;            // m, offset of shadow rays from surfaces
    float pad0;
    vec3 boundsMin;  // m, the bounds of every triangle: beyond them nothing casts a shadow
    float pad1;
    vec3 boundsMax;
    float pad2;
};

// True when the extinction is the same in every channel: then one closed form serves the three. A compile-time
// constant where the shader defines TY_PEGORARO_GREY, and the channel loop runs once (lavapipe would otherwise run the
// other channels' evaluations, a branch that no lane takes).
TY_FUNC bool pegoraroGrey(TY_IN(PegoraroFrame) f) {
#ifdef TY_PEGORARO_GREY
    return true;
#else
    return f.sigmaT.x == f.sigmaT.y && f.sigmaT.x == f.sigmaT.z;
#endif
}
#ifdef TY_PEGORARO_GREY
TY_CONST int kPegoraroChannelLoop = 1;
#else
TY_CONST int kPegoraroChannelLoop = 3;
#endif

// Supplied by the includer (see the top of the file).
PegoraroLight pegoraroLight(int i);
PegoraroMedium pegoraroMedium(int i);
vec2 pegoraroCoefficient(int i);
SurfaceTriangle surfaceTriangle(int id);
MaterialParams surfaceMaterial(int i);

// Where the ray origin + t dir leaves the box [lo, hi] (0 when it starts outside and misses it).
TY_FUNC float pegoraroBoxExit(TY_IN(vec3) origin, TY_IN(vec3) dir, TY_IN(vec3) lo, TY_IN(vec3) hi) {
    float tNear = 0.0f, tFar = kInfinity;
    for (int a = 0; a < 3; ++a) {
        if (abs(dir[a]) < 1e-30f) {
            if (origin[a] < lo[a] || origin[a] > hi[a]) return 0.0f;
            continue;
        }
        float t0 = (lo[a] - origin[a]) / dir[a];
        float t1 = (hi[a] - origin[a]) / dir[a];
        tNear = max(tNear, min(t0, t1));
        tFar = min(tFar, max(t0, t1));
    }
    return tNear <= tFar ? tFar : 0.0f;
}

// The pixels around a point light's projection (docs/pegoraro.md, Sec. 9): the four triangles of singular_pixel.h,
// signed by their orientation so that the pixel is covered whether p is inside or outside it, each integrated by
// Gauss-Legendre of order kPegoraroSingularOrder in s and tau: 4 * 8 * 8 = 256 rays for such a pixel.
TY_CONST int kPegoraroSingularOrder = 8;
TY_CONST int kPegoraroSingularNodes = 4 * kPegoraroSingularOrder * kPegoraroSingularOrder;

// Node i of the 8-point Gauss-Legendre rule on [0, 1]: (position, weight).
TY_FUNC vec2 pegoraroGaussNode(int i) {
    int k = i < 4 ? 3 - i : i - 4;  // 0 nearest the middle
    float x = k == 0 ? 0.18343464249564981f
                     : (k == 1 ? 0.52553240991632899f : (k == 2 ? 0.79666647741362684f : 0.96028985649753629f));
    float w = k == 0 ? 0.36268378337836199f
                     : (k == 1 ? 0.31370664587788738f : (k == 2 ? 0.22238103445337445f : 0.10122853629037618f));
    return vec2(0.5f + 0.5f * (i < 4 ? -x : x), 0.5f * w);
}

// True when pixel (px, py) is the pixel of a light's projection or one of its eight neighbours (and the frame has a
// medium, which is where the 1/h peak comes from); p is then the nearest such projection.
TY_FUNC bool pegoraroSingularPoint(TY_IN(PegoraroFrame) f, int px, int py, TY_OUT(vec2) p) {
    p = vec2(0.0f);
    if (f.mediumCount == 0) return false;
    bool found = false;
    float nearest = kInfinity;
    vec2 centre = vec2(float(px) + 0.5f, float(py) + 0.5f);
    for (int l = 0; l < f.lightCount; ++l) {
        vec2 q;
        if (!cameraProject(f.camera, pegoraroLight(l).position, q)) continue;
        vec2 cell = floor(q);
        if (abs(cell.x - float(px)) > 1.0f || abs(cell.y - float(py)) > 1.0f) continue;
        float distance = length(q - centre);
        if (distance < nearest) {
            nearest = distance;
            p = q;
            found = true;
        }
    }
    return found;
}

// Node `node` (< kPegoraroSingularNodes) of the pixel (px, py) around the point p: the image point in xy and its
// weight in z (the weights of a pixel sum to its area, 1).
TY_FUNC vec3 pegoraroSingularNode(int px, int py, TY_IN(vec2) p, int node) {
    int n = kPegoraroSingularOrder;
    int side = node / (n * n);
    int i = (node - side * n * n) / n, j = node - side * n * n - i * n;
    vec2 a, b;
    pixelEdge(px, py, side, a, b);
    vec2 gs = pegoraroGaussNode(i), gt = pegoraroGaussNode(j);
    vec3 x = singularTriangleMap(p, a, b, gs.x, gt.x);
    return vec3(x.x, x.y, gs.y * gt.y * x.z);
}

#ifndef TY_PEGORARO_NO_SHADOWS
// Appends the lit piece p to the first `pieces` of `lit`, merged with the last one when they touch; kLitOverflow when
// there is no room.
TY_FUNC int pegoraroAppendPiece(TY_IN(vec2) p, int pieces, TY_INOUT(LitIntervals) lit) {
    if (pieces == kLitOverflow) return pieces;
    if (pieces > 0 && lit.pieces[pieces - 1].y >= p.x) {
        lit.pieces[pieces - 1].y = p.y;
        return pieces;
    }
    if (pieces == kMaxLitIntervals) return kLitOverflow;
    lit.pieces[pieces] = p;
    return pieces + 1;
}

// The lit parts of origin + t dir, t in [0, tEnd], for a light: exact lit intervals inside the bounds of the
// triangles (with float precision relative to that length), then again, more coarsely, up to where the camera's
// transmittance falls below e^-40 (points outside the bounds can still see the light through them); beyond that the
// ray counts as lit, a tail below 1e-17 of the radiance. A ray whose pieces do not fit counts as unshadowed and
// increments `overflows`. Returns the number of pieces.
TY_FUNC int pegoraroLitPieces(TY_IN(PegoraroFrame) f, TY_IN(PegoraroLight) light, TY_IN(vec3) origin, TY_IN(vec3) dir,
                              float tEnd, TY_OUT(LitIntervals) lit, TY_INOUT(int) overflows) {
    float tNear = min(tEnd, pegoraroBoxExit(origin, dir, f.boundsMin, f.boundsMax));
    float sigmaMin = max(min(f.sigmaT.x, min(f.sigmaT.y, f.sigmaT.z)), 1e-30f);
    float tFar = min(tEnd, max(tNear, 40.0f / sigmaMin));
    int pieces = tNear > 0.0f ? litIntervals(light.position, origin, dir, 0.0f, tNear, lit) : 0;
    if (pieces != kLitOverflow && tFar > tNear) {
        LitIntervals far;
        int farPieces = litIntervals(light.position, origin, dir, tNear, tFar, far);
        if (farPieces == kLitOverflow) pieces = kLitOverflow;
        for (int i = 0; i < farPieces && pieces != kLitOverflow; ++i)
            pieces = pegoraroAppendPiece(far.pieces[i], pieces, lit);
    }
    if (tEnd > tFar) pieces = pegoraroAppendPiece(vec2(tFar, tEnd), pieces, lit);
    if (pieces == kLitOverflow) {
        ++overflows;
        pieces = 1;
        lit.pieces[0] = vec2(0.0f, tEnd);
    }
    return pieces;
}
#endif

TY_END

#define TY_R float
#define TY_R2 vec2
#define TY_R3 vec3
#include "pegoraro_pixel_impl.h"
#undef TY_R
#undef TY_R2
#undef TY_R3

#ifdef TY_HAS_DOUBLE
#define TY_R double
#define TY_R2 dvec2
#define TY_R3 dvec3
#include "pegoraro_pixel_impl.h"
#undef TY_R
#undef TY_R2
#undef TY_R3
#endif

#endif  // TY_SHARED_PEGORARO_SCENE_H
