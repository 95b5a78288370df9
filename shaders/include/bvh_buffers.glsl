// The BVH's two storage buffers and the accessors shared/bvh.h needs, for compute shaders. The includer chooses the
// bindings (TY_BVH_NODES_BINDING, TY_BVH_TRIANGLES_BINDING) and, on devices with shaderFloat64, defines TY_BVH_WORDS to
// read the arrays as 64-bit words, the cheaper loads on lavapipe (see the top of shared/bvh.h).
#ifndef TY_BVH_BUFFERS_GLSL
#define TY_BVH_BUFFERS_GLSL

#include "../shared/bvh.h"

#ifdef TY_BVH_WORDS
layout(std430, set = 0, binding = TY_BVH_NODES_BINDING) readonly buffer BvhNodes { dvec4 bvhNodes[]; };
layout(std430, set = 0, binding = TY_BVH_TRIANGLES_BINDING) readonly buffer BvhTriangles { dvec2 bvhTriangles[]; };
uvec4 bvhWords(dvec2 w) { return uvec4(unpackDouble2x32(w.x), unpackDouble2x32(w.y)); }
BvhNode bvhNode(int i) {
    dvec4 w = bvhNodes[i];
    return bvhNodeFromWords(bvhWords(w.xy), bvhWords(w.zw));
}
BvhTriangle bvhTriangle(int i) {
    return bvhTriangleFromWords(bvhWords(bvhTriangles[3 * i]), bvhWords(bvhTriangles[3 * i + 1]),
                                bvhWords(bvhTriangles[3 * i + 2]));
}
#else
layout(std430, set = 0, binding = TY_BVH_NODES_BINDING) readonly buffer BvhNodes { BvhNode bvhNodes[]; };
layout(std430, set = 0, binding = TY_BVH_TRIANGLES_BINDING) readonly buffer BvhTriangles { BvhTriangle bvhTriangles[]; };
BvhNode bvhNode(int i) { return bvhNodes[i]; }
BvhTriangle bvhTriangle(int i) { return bvhTriangles[i]; }
#endif

#endif  // TY_BVH_BUFFERS_GLSL
