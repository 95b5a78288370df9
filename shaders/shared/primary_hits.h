// The camera rays' closest hits, rasterised (issue 31): a G-buffer of one record per camera sample on a regular grid
// of S x S samples per pixel, drawn by shaders/primary/ (renderers/framework's RasterPrimaryHits), read by compute
// kernels through primaryIntersect instead of a BVH traversal from the camera. Shadow and other secondary rays still
// trace the BVH.
//
// A record is a vec4 (t, id, u, v): the hit's ray parameter (for the unit direction of cameraRay), the BvhTriangle id
// as a float (exact up to 2^24 triangles: RasterPrimaryHits refuses more), and the barycentrics of vertices 1 and 2,
// computed in the fragment shader by the same Moeller-Trumbore test (bvhTriangleHit) on the same ray as a traversal
// would. t = kInfinity: the sample sees no triangle. t < 0 (kPrimaryTrace): the rasteriser covered the sample with a
// triangle that the exact test misses by rounding (a sample on an edge): the sample is traced instead.
//
// Sample k = sy * S + sx of pixel (px, py) sits at (px + (sx + 0.5) / S, py + (sy + 0.5) / S), the texel
// (px * S + sx, py * S + sy) of a grid of (W S) x (H S) texels, row-major.
#ifndef TY_SHARED_PRIMARY_HITS_H
#define TY_SHARED_PRIMARY_HITS_H

#include "bvh.h"
#include "compat.h"
#include "constants.h"

TY_BEGIN

TY_CONST float kPrimaryTrace = -1.0f;

// The record's index of sample (sx, sy) of pixel (px, py) in an image `width` pixels wide, S samples per side.
TY_FUNC int primarySampleIndex(int width, int S, int px, int py, int sx, int sy) {
    return (py * S + sy) * (width * S) + px * S + sx;
}

// The image point of that sample, in pixel coordinates, as cameraRay takes it.
TY_FUNC vec2 primarySamplePoint(int S, int px, int py, int sx, int sy) {
    return vec2(float(px) + (float(sx) + 0.5f) / float(S), float(py) + (float(sy) + 0.5f) / float(S));
}

#ifdef TY_PRIMARY_HITS
// Supplied by the includer (shaders/include/primary_hits.glsl): record `index` of the rasterised grid.
vec4 primaryHitRecord(int index);
#endif

// The closest hit of the camera ray (origin, dir) of grid sample `sampleIndex` (primarySampleIndex; -1 for a ray off
// the grid, e.g. a jittered one): the rasterised record when the kernel is compiled with TY_PRIMARY_HITS and the record
// is exact, else a BVH traversal. As bvhIntersect: false (and hit.t = kInfinity) for no hit.
TY_FUNC bool primaryIntersect(int sampleIndex, TY_IN(vec3) origin, TY_IN(vec3) dir, TY_OUT(BvhHit) hit) {
#ifdef TY_PRIMARY_HITS
    if (sampleIndex >= 0) {
        vec4 r = primaryHitRecord(sampleIndex);
        if (r.x >= 0.0f) {
            hit.t = r.x;
            hit.id = uint(r.y);
            hit.uv = vec2(r.z, r.w);
            return r.x < kInfinity;
        }
    }
#else
    // Traced only: the record index is unused.
    if (sampleIndex < -1) hit.id = 0u;
#endif
    return bvhIntersect(origin, dir, 0.0f, kInfinity, hit);
}

TY_END

#endif  // TY_SHARED_PRIMARY_HITS_H
