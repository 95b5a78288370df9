#version 460
// ISV's opaque shadow map: per texel of the light's grid, the distance along its ray to the first surface
// (FLT_MAX where there is none), by the BVH's closest hit.
//   TY_BVH_WORDS  BVH arrays read as 64-bit words (needs shaderFloat64)
#extension GL_GOOGLE_include_directive : require

#define TY_BVH_NODES_BINDING 0
#define TY_BVH_TRIANGLES_BINDING 1
#include "../include/bvh_buffers.glsl"
#include "isv_view.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 2) readonly buffer Frame { IsvFrame frame; };
layout(std430, set = 0, binding = 3) writeonly buffer ShadowMap { float shadowMap[]; };

float isvVsmTexel(int i) { return 0.0f; }
float isvShadowTexel(int i) { return kInfinity; }

layout(push_constant) uniform Push {
    uint first;
    uint end;
} push;

void main() {
    IsvLightSpace g = frame.shadowMap;
    uint texel = push.first + gl_GlobalInvocationID.x;
    if (texel >= push.end) return;
    int x = int(texel % uint(g.size)), y = int(texel / uint(g.size));
    vec3 origin, dir;
    float cosine;
    isvGridRay(g, float(x) + 0.5f, float(y) + 0.5f, origin, dir, cosine);
    BvhHit hit;
    shadowMap[texel] = bvhIntersect(origin, dir, 0.0f, kInfinity, hit) ? hit.t : kInfinity;
}
