// The triangle BVH for visibility, shared by GLSL and C++: the GPU layout of nodes and triangles (std430), and the
// traversal (any hit for shadow rays, closest hit for camera rays). Built on the CPU by renderers/gpu/src/bvh.cpp.
//
// GLSL has no pointers, so the traversal reads nodes and triangles through two accessor functions that this header
// only declares; the includer defines them, after the include, over whatever holds the arrays:
//  - GLSL: over storage buffers, e.g.
//        layout(std430, binding = 0) readonly buffer BvhNodes { BvhNode bvhNodes[]; };
//        layout(std430, binding = 1) readonly buffer BvhTriangles { BvhTriangle bvhTriangles[]; };
//        BvhNode bvhNode(int i) { return bvhNodes[i]; }
//        BvhTriangle bvhTriangle(int i) { return bvhTriangles[i]; }
//  - C++: tyndall/gpu/bvh.h defines them over the Bvh bound to the calling thread by a tyndall::gpu::BvhScope.
// On lavapipe (Mesa's llvmpipe) a storage-buffer load with a different index per invocation runs a scalar loop over
// the SIMD lanes with a guarded scalar load per component, so its cost grows with the number of components and not
// with their width. With shaderFloat64, the includer therefore reads the same std430 arrays as 64-bit words (one dvec4
// per node, three dvec2 per triangle) and rebuilds the structs with bvhNodeFromWords and bvhTriangleFromWords, e.g.
//        layout(std430, binding = 0) readonly buffer BvhNodes { dvec4 bvhNodes[]; };
//        layout(std430, binding = 1) readonly buffer BvhTriangles { dvec2 bvhTriangles[]; };
//        uvec4 bvhWords(dvec2 w) { return uvec4(unpackDouble2x32(w.x), unpackDouble2x32(w.y)); }
//        BvhNode bvhNode(int i) { dvec4 w = bvhNodes[i]; return bvhNodeFromWords(bvhWords(w.xy), bvhWords(w.zw)); }
//        BvhTriangle bvhTriangle(int i) {
//            return bvhTriangleFromWords(bvhWords(bvhTriangles[3 * i]), bvhWords(bvhTriangles[3 * i + 1]),
//                                        bvhWords(bvhTriangles[3 * i + 2]));
//        }
// The traversal needs no stack: each node carries the link to the next subtree (see BvhNode).
// Model: nvpro-samples' ray_tracing__simple/shaders/host_device.h (one declaration of the layout for both sides).
#ifndef TY_SHARED_BVH_H
#define TY_SHARED_BVH_H

#include "compat.h"

TY_BEGIN

// A node of the BVH, 32 bytes. The root is node 0. An interior node (count 0) has its two children next to each
// other at leftOrFirst and leftOrFirst + 1; a leaf (count > 0) holds triangles leftOrFirst .. leftOrFirst + count - 1.
// Each node also carries its miss link: the node a depth-first traversal visits after this node's subtree (its right
// sibling, or the miss link of its parent; 0, the root, for none), so that traversals need no stack (bvhTraverse).
// An empty BVH is a lone root with empty bounds (boundsMin > boundsMax), which no ray enters.
struct BvhNode {
    vec3 boundsMin;    // m, world space
    int leftOrFirst;   // interior: index of the first child; leaf: index of the first triangle
    vec3 boundsMax;    // m, world space
    int countAndMiss;  // bits 0-2: triangles in a leaf, [1, kBvhMaxLeafSize], 0 for an interior node; bits 3-31: miss
};

// A triangle as Moeller-Trumbore wants it, 48 bytes: a vertex and the two edges from it, in the input's winding, so
// that barycentrics (u, v) weigh vertices 1 and 2 of the input triangle.
struct BvhTriangle {
    vec3 v0;  // m, vertex 0
    uint id;  // index of the triangle in the builder's input (meshes concatenated in order)
    vec3 e1;  // m, vertex 1 - vertex 0
    float pad1;
    vec3 e2;  // m, vertex 2 - vertex 0
    float pad2;
};

// The closest hit along a ray.
struct BvhHit {
    float t;  // ray parameter of the hit, in (tMin, tMax)
    uint id;  // BvhTriangle::id of the triangle hit
    vec2 uv;  // barycentrics of vertices 1 and 2
};

TY_CONST int kBvhMaxLeafSize = 4;
TY_CONST int kBvhCountBits = 3;  // of countAndMiss; holds kBvhMaxLeafSize
// The builder keeps the tree at most this deep.
TY_CONST int kBvhMaxDepth = 64;

// What bvhBoxEntry returns for a box the ray misses: FLT_MAX, like kInfinity in constants.h.
TY_CONST float kBvhMiss = 3.402823466e38f;

// Supplied by the includer (see the top of the file).
BvhNode bvhNode(int i);
BvhTriangle bvhTriangle(int i);

// A node from its eight 32-bit words in memory order (words 0-3 in lo, 4-7 in hi), for includers that read the node
// array as wider words (see the top of the file).
TY_FUNC BvhNode bvhNodeFromWords(TY_IN(uvec4) lo, TY_IN(uvec4) hi) {
    BvhNode node;
    node.boundsMin = uintBitsToFloat(uvec3(lo.x, lo.y, lo.z));
    node.leftOrFirst = int(lo.w);
    node.boundsMax = uintBitsToFloat(uvec3(hi.x, hi.y, hi.z));
    node.countAndMiss = int(hi.w);
    return node;
}

// Triangles in a leaf; 0 for an interior node.
TY_FUNC int bvhCount(TY_IN(BvhNode) node) {
    return node.countAndMiss & ((1 << kBvhCountBits) - 1);
}

// The node after this one's subtree in depth-first order; 0 when there is none.
TY_FUNC int bvhMiss(TY_IN(BvhNode) node) {
    return node.countAndMiss >> kBvhCountBits;
}

// A triangle from its twelve 32-bit words in memory order (words 0-3 in a, 4-7 in b, 8-11 in c).
TY_FUNC BvhTriangle bvhTriangleFromWords(TY_IN(uvec4) a, TY_IN(uvec4) b, TY_IN(uvec4) c) {
    BvhTriangle tri;
    tri.v0 = uintBitsToFloat(uvec3(a.x, a.y, a.z));
    tri.id = a.w;
    tri.e1 = uintBitsToFloat(uvec3(b.x, b.y, b.z));
    tri.pad1 = uintBitsToFloat(b.w);
    tri.e2 = uintBitsToFloat(uvec3(c.x, c.y, c.z));
    tri.pad2 = uintBitsToFloat(c.w);
    return tri;
}

// 1 / d, with |d| clamped away from zero so that slab distances stay finite (no 0 * inf = NaN for a ray in a slab's
// plane).
TY_FUNC float bvhSafeInverse(float d) {
    const float kTiny = 1e-20f;
    return 1.0f / (abs(d) > kTiny ? d : (d < 0.0f ? -kTiny : kTiny));
}

// Entry distance of the ray into a node's box within [tMin, tMax], or kBvhMiss. The near and far planes are chosen by
// the sign of the direction (not by min/max of the two distances), so that empty bounds (min > max) are never entered.
// The exit distance is enlarged by a few ulps so that rounding cannot cull a box the ray just touches (Pharr et al.,
// PBR 4th ed., Sec. 6.8.6: 1 + 2 gamma(3)).
TY_FUNC float bvhBoxEntry(TY_IN(BvhNode) node, TY_IN(vec3) origin, TY_IN(vec3) invDir, float tMin, float tMax) {
    vec3 tLow = (node.boundsMin - origin) * invDir;
    vec3 tHigh = (node.boundsMax - origin) * invDir;
    bvec3 negative = lessThan(invDir, vec3(0.0f));
    vec3 tNear = mix(tLow, tHigh, negative);
    vec3 tFar = mix(tHigh, tLow, negative);
    float entry = max(max(tNear.x, tNear.y), max(tNear.z, tMin));
    float exit = min(min(tFar.x, tFar.y), tFar.z) * 1.0000008f;
    return entry <= min(exit, tMax) ? entry : kBvhMiss;
}

// Moeller & Trumbore 1997, "Fast, Minimum Storage Ray/Triangle Intersection". True for a hit with t in (tMin, tMax);
// degenerate triangles and rays in the triangle's plane never hit.
TY_FUNC bool bvhTriangleHit(TY_IN(BvhTriangle) tri, TY_IN(vec3) origin, TY_IN(vec3) dir, float tMin, float tMax,
                            TY_OUT(float) t, TY_OUT(vec2) uv) {
    vec3 p = cross(dir, tri.e2);
    float det = dot(tri.e1, p);
    if (det == 0.0f) return false;
    float invDet = 1.0f / det;
    vec3 s = origin - tri.v0;
    float u = dot(s, p) * invDet;
    if (u < 0.0f || u > 1.0f) return false;
    vec3 q = cross(s, tri.e1);
    float v = dot(dir, q) * invDet;
    if (v < 0.0f || u + v > 1.0f) return false;
    t = dot(tri.e2, q) * invDet;
    uv = vec2(u, v);
    return t > tMin && t < tMax;
}

// The traversal behind bvhOccluded and bvhIntersect: depth first along the miss links, one node per iteration and no
// stack. A node whose box the ray enters (before the closest hit so far) continues with its first child, or tests its
// triangles and continues with its miss link; a box it misses continues with the miss link. With anyHit it returns at
// the first hit (which need not be the closest). Children are visited in their stored order, not nearest first: a
// stack to order them costs more than it saves on devices without fast private memory (on lavapipe, arrays indexed at
// run time live in memory). anyHit is a constant at both call sites, so the branches on it fold away. dir need not be
// unit length; t is in units of |dir|.
TY_FUNC bool bvhTraverse(TY_IN(vec3) origin, TY_IN(vec3) dir, float tMin, float tMax, bool anyHit, TY_OUT(BvhHit) hit) {
    vec3 invDir = vec3(bvhSafeInverse(dir.x), bvhSafeInverse(dir.y), bvhSafeInverse(dir.z));
    hit.t = tMax;
    hit.id = 0u;
    hit.uv = vec2(0.0f);
    bool found = false;
    int index = 0;
    do {
        BvhNode node = bvhNode(index);
        int next = bvhMiss(node);
        if (bvhBoxEntry(node, origin, invDir, tMin, hit.t) != kBvhMiss) {
            int count = bvhCount(node);
            if (count == 0) next = node.leftOrFirst;
            for (int i = node.leftOrFirst; i < node.leftOrFirst + count; ++i) {
                BvhTriangle tri = bvhTriangle(i);
                float t;
                vec2 uv;
                if (bvhTriangleHit(tri, origin, dir, tMin, hit.t, t, uv)) {
                    hit.t = t;
                    hit.id = tri.id;
                    hit.uv = uv;
                    found = true;
                    if (anyHit) return true;
                }
            }
        }
        index = next;
    } while (index != 0);
    return found;
}

// True when a triangle lies on the ray within (tMin, tMax): shadow rays.
TY_FUNC bool bvhOccluded(TY_IN(vec3) origin, TY_IN(vec3) dir, float tMin, float tMax) {
    BvhHit hit;
    return bvhTraverse(origin, dir, tMin, tMax, true, hit);
}

// The closest triangle on the ray within (tMin, tMax); false (and hit.t = tMax) when there is none.
TY_FUNC bool bvhIntersect(TY_IN(vec3) origin, TY_IN(vec3) dir, float tMin, float tMax, TY_OUT(BvhHit) hit) {
    return bvhTraverse(origin, dir, tMin, tMax, false, hit);
}

TY_END

#endif  // TY_SHARED_BVH_H
