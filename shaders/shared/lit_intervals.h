// The lit intervals of a ray for a point light: the parts of o + t d, t in [t0, t1], whose segment to the light crosses
// no triangle of the BVH (shared/bvh.h). The closed-form single scattering of a point light (Pegoraro et al.) is summed
// over them to add exact volumetric shadows (issue #5, item 5). Derivation, degenerate cases, epsilons and cost:
// docs/lit-intervals.md.
//
// One triangle T = (v0, v1, v2) shadows the convex set {p + s (y - p) : y in T, s >= 1} (its shadow volume). With
// A, B, C the vertices relative to the light p and w = x - p, write w = l0 A + l1 B + l2 C; then
//     l0 = (B x C).w / D,  l1 = (C x A).w / D,  l2 = (A x B).w / D,  l0 + l1 + l2 = n.w / D,
// with n = (v1 - v0) x (v2 - v0) and D = det(A, B, C) = n.A. x is shadowed by T when l0, l1, l2 > 0 (w inside the
// cone from p over T) and l0 + l1 + l2 > 1 (beyond T's plane). Each condition is linear in t along the ray, so the
// shadowed part of the ray is one interval: [t0, t1] clipped against 4 planes (3 through p and an edge, and T's plane).
//
// Like shared/bvh.h, the traversal reads the BVH through bvhNode and bvhTriangle, which the includer defines.
#ifndef TY_SHARED_LIT_INTERVALS_H
#define TY_SHARED_LIT_INTERVALS_H

#include "bvh.h"
#include "compat.h"

TY_BEGIN

// Room for the lit pieces of one ray; a ray whose lit set needs more reports kLitOverflow.
TY_CONST int kMaxLitIntervals = 16;
// What litIntervals returns when the lit pieces do not fit: the caller must fall back (e.g. to sampled shadow rays).
TY_CONST int kLitOverflow = -1;
// A lit piece shorter than this times max(|t0|, |t1|) is dropped (counted as shadowed). Two shadows that meet (a mesh's
// neighbouring triangles) end at the same t but for rounding: without this they would leave zero-length pieces where
// their ends coincide and cracks of 1e-8 to 1e-6 t1 where the shared edge is rebuilt differently from the two
// triangles' (v0, e1, e2), and a ray through a finely tessellated shadow would overflow. Each dropped piece loses at
// most this much lit length.
TY_CONST float kLitMinPiece = 1e-6f;
// Relative slack of the culling test (box against the triangle spanned by the light and the ray segment): the box is
// grown by this times the largest coordinate involved, well above the rounding of the test (a few ulps), so that no
// triangle touching that triangle is culled.
TY_CONST float kLitCullSlack = 1e-5f;

// Sorted, disjoint lit pieces (start, end) of a ray, in units of |d|; litIntervals says how many are valid.
struct LitIntervals {
    vec2 pieces[kMaxLitIntervals];
};

// Clips (lo, hi) to the t where a + b t > 0. A ray parallel to the plane (b == 0) keeps everything when strictly
// inside and nothing otherwise: the shadow volume is taken open, so a ray along its boundary is lit.
TY_FUNC void litClip(float a, float b, TY_INOUT(float) lo, TY_INOUT(float) hi) {
    if (b > 0.0f) {
        lo = max(lo, -a / b);
    } else if (b < 0.0f) {
        hi = min(hi, -a / b);
    } else if (!(a > 0.0f)) {
        hi = lo;
    }
}

// The part (shadow.x, shadow.y) of [t0, t1] of the ray origin + t dir whose segments to the light cross the triangle:
// true when it is not empty. A light in the triangle's plane (the triangle seen edge-on) and a degenerate triangle
// (D == 0) shadow nothing, as bvhTriangleHit never hits a segment in a triangle's plane.
TY_FUNC bool litShadowInterval(TY_IN(BvhTriangle) tri, TY_IN(vec3) light, TY_IN(vec3) origin, TY_IN(vec3) dir, float t0,
                               float t1, TY_OUT(vec2) shadow) {
    shadow = vec2(t0, t0);
    vec3 n = cross(tri.e1, tri.e2);
    vec3 a = tri.v0 - light;
    float det = dot(n, a);  // D = det(A, B, C)
    if (det == 0.0f) return false;
    // Every condition times sign(D), so that it reads "> 0" inside.
    float s = det > 0.0f ? 1.0f : -1.0f;
    float lo = t0;
    float hi = t1;
    // Beyond T's plane: l0 + l1 + l2 > 1, i.e. sign(D) n.(x - v0) > 0.
    vec3 sn = s * n;
    litClip(dot(sn, origin - tri.v0), dot(sn, dir), lo, hi);
    if (!(lo < hi)) return false;
    // Inside the cone: each of l0, l1, l2 > 0, i.e. sign(D) (edge plane normal).w > 0.
    vec3 b = (tri.v0 + tri.e1) - light;
    vec3 c = (tri.v0 + tri.e2) - light;
    vec3 w0 = origin - light;
    vec3 m = s * cross(b, c);
    litClip(dot(m, w0), dot(m, dir), lo, hi);
    m = s * cross(c, a);
    litClip(dot(m, w0), dot(m, dir), lo, hi);
    m = s * cross(a, b);
    litClip(dot(m, w0), dot(m, dir), lo, hi);
    shadow = vec2(lo, hi);
    return lo < hi;
}

// Removes the shadow (lo, hi) from the lit pieces. Pieces shorter than minPiece are dropped. False when a piece would
// split in two and there is no room for the second.
TY_FUNC bool litSubtract(float lo, float hi, float minPiece, TY_INOUT(LitIntervals) lit, TY_INOUT(int) count) {
    int kept = 0;
    for (int i = 0; i < count; ++i) {
        vec2 piece = lit.pieces[i];
        if (piece.y <= lo || hi <= piece.x) {
            lit.pieces[kept] = piece;
            ++kept;
            continue;
        }
        bool left = lo - piece.x >= minPiece;
        bool right = piece.y - hi >= minPiece;
        if (left && right) {
            // The shadow lies inside this piece, so it touched no other piece (kept == i): shift the rest up by one.
            if (count == kMaxLitIntervals) return false;
            for (int j = count; j > i + 1; --j)
                lit.pieces[j] = lit.pieces[j - 1];
            lit.pieces[i] = vec2(piece.x, lo);
            lit.pieces[i + 1] = vec2(hi, piece.y);
            ++count;
            return true;
        }
        if (left) {
            lit.pieces[kept] = vec2(piece.x, lo);
            ++kept;
        }
        if (right) {
            lit.pieces[kept] = vec2(hi, piece.y);
            ++kept;
        }
    }
    count = kept;
    return true;
}

TY_FUNC float litMaxComponent(TY_IN(vec3) v) {
    return max(max(v.x, v.y), v.z);
}

// True unless the projections of the triangle (vertices relative to the box centre) and of the box (half extent h) on
// the axis are disjoint; `slack` widens the box's projection.
TY_FUNC bool litOverlapOnAxis(TY_IN(vec3) axis, TY_IN(vec3) a, TY_IN(vec3) b, TY_IN(vec3) c, TY_IN(vec3) h,
                              float slack) {
    float pa = dot(axis, a);
    float pb = dot(axis, b);
    float pc = dot(axis, c);
    float r = dot(h, abs(axis)) + slack;
    return min(pa, min(pb, pc)) <= r && max(pa, max(pb, pc)) >= -r;
}

// The window of a ray: the triangle W = (light, origin + lo dir, origin + hi dir). A triangle can shadow a point of
// the segment only where it meets W, so the traversal visits only the boxes that may meet W.
struct LitWindow {
    vec3 a;            // m, the light
    vec3 b;            // m, origin + lo dir
    vec3 c;            // m, origin + hi dir
    vec3 boundsMin;    // m, W's bounds
    vec3 boundsMax;    // m
    vec3 normal;       // (origin - light) x dir: W's plane whatever lo and hi; zero when the light is on the ray's line
    float magnitude;   // m, the largest |coordinate| of W, for the slack
    float planeSlack;  // bound on the rounding of normal.(vertex - a), for the plane test
};

TY_FUNC LitWindow litWindow(TY_IN(vec3) light, TY_IN(vec3) origin, TY_IN(vec3) dir, float lo, float hi) {
    LitWindow w;
    w.a = light;
    w.b = origin + lo * dir;
    w.c = origin + hi * dir;
    w.boundsMin = min(w.a, min(w.b, w.c));
    w.boundsMax = max(w.a, max(w.b, w.c));
    w.magnitude = max(litMaxComponent(abs(w.boundsMin)), litMaxComponent(abs(w.boundsMax)));
    vec3 w0 = origin - light;
    w.normal = cross(w0, dir);
    // |normal.(v - a)| for the vertices v of W is zero in exact arithmetic; its rounding is a few ulps of
    // |w0| |dir| |v - a|, and |v - a| <= |w0| + max(|lo|, |hi|) |dir|.
    float lw0 = length(w0);
    float ldir = length(dir);
    w.planeSlack = kLitCullSlack * lw0 * ldir * (lw0 + max(abs(lo), abs(hi)) * ldir);
    return w;
}

// A conservative box-triangle overlap test by separating axes (Akenine-Moeller's 13 axes: the box's 3 axes, W's
// normal, and the 9 cross products of box axes and W's edges), with the box grown by kLitCullSlack. Empty bounds
// (min > max) never overlap.
TY_FUNC bool litBoxOverlapsWindow(TY_IN(BvhNode) node, TY_IN(LitWindow) w) {
    float slack = kLitCullSlack *
                  max(w.magnitude, max(litMaxComponent(abs(node.boundsMin)), litMaxComponent(abs(node.boundsMax))));
    if (any(greaterThan(w.boundsMin, node.boundsMax + slack)) || any(lessThan(w.boundsMax, node.boundsMin - slack)))
        return false;
    vec3 centre = 0.5f * (node.boundsMin + node.boundsMax);
    vec3 h = 0.5f * (node.boundsMax - node.boundsMin);
    vec3 a = w.a - centre;
    vec3 b = w.b - centre;
    vec3 c = w.c - centre;
    if (!litOverlapOnAxis(w.normal, a, b, c, h, slack * dot(vec3(1.0f), abs(w.normal)) + w.planeSlack)) return false;
    vec3 edges[3];
    edges[0] = b - a;
    edges[1] = c - b;
    edges[2] = a - c;
    for (int k = 0; k < 3; ++k) {
        vec3 e = edges[k];
        float s = slack * (abs(e.x) + abs(e.y) + abs(e.z));
        if (!litOverlapOnAxis(vec3(0.0f, -e.z, e.y), a, b, c, h, s)) return false;
        if (!litOverlapOnAxis(vec3(e.z, 0.0f, -e.x), a, b, c, h, s)) return false;
        if (!litOverlapOnAxis(vec3(-e.y, e.x, 0.0f), a, b, c, h, s)) return false;
    }
    return true;
}

// The lit pieces of [t0, t1] (finite, t0 <= t1) of the ray origin + t dir for a point light: sorted, disjoint
// (start, end) pairs in lit.pieces[0 .. count - 1], where count is the return value, in [0, kMaxLitIntervals]; 0 when
// the whole segment is shadowed (or t0 == t1). kLitOverflow when, at some step, the pieces would have been more than
// kMaxLitIntervals (lit.pieces is then undefined). dir need not be unit length; t is in units of |dir|.
// The traversal is depth first over the nodes whose boxes may meet the window W of what is still lit (litWindow),
// along the miss links like bvhTraverse's; it stops as soon as nothing is lit.
TY_FUNC int litIntervals(TY_IN(vec3) light, TY_IN(vec3) origin, TY_IN(vec3) dir, float t0, float t1,
                         TY_OUT(LitIntervals) lit) {
    lit.pieces[0] = vec2(t0, t1);
    if (!(t0 < t1)) return 0;
    int count = 1;
    float minPiece = kLitMinPiece * max(abs(t0), abs(t1));
    LitWindow window = litWindow(light, origin, dir, t0, t1);

    // Depth first along the miss links (bvh.h), without a stack.
    int node = 0;
    do {
        BvhNode current = bvhNode(node);
        int next = bvhMiss(current);
        if (litBoxOverlapsWindow(current, window)) {
            int triangles = bvhCount(current);
            if (triangles == 0) next = current.leftOrFirst;  // interior: its first child, then the rest
            for (int i = current.leftOrFirst; i < current.leftOrFirst + triangles; ++i) {
                vec2 shadow;
                if (litShadowInterval(bvhTriangle(i), light, origin, dir, lit.pieces[0].x, lit.pieces[count - 1].y,
                                      shadow)) {
                    if (!litSubtract(shadow.x, shadow.y, minPiece, lit, count)) return kLitOverflow;
                    if (count == 0) return 0;
                }
            }
            // What is still lit may have shrunk: so does the window.
            if (triangles > 0) window = litWindow(light, origin, dir, lit.pieces[0].x, lit.pieces[count - 1].y);
        }
        node = next;
    } while (node != 0);
    return count;
}

TY_END

#endif  // TY_SHARED_LIT_INTERVALS_H
