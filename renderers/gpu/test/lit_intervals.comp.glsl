#version 460
// litIntervals (shared/lit_intervals.h) for one ray per invocation, for the GPU-vs-CPU test in test_lit_intervals.cpp.
// Rays are three vec4 each: (origin, t0), (dir, t1), (light, 0). Per ray the kernel writes the count (or
// kLitOverflow) and kMaxLitIntervals pieces.
#extension GL_GOOGLE_include_directive : require
#include "shared/lit_intervals.h"
#include "bvh_struct_buffers.glsl"
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 2) readonly buffer Rays { vec4 rays[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Counts { int counts[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Pieces { vec2 pieces[]; };
layout(push_constant) uniform Push { uint count; } push;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    vec4 originT0 = rays[3 * i], dirT1 = rays[3 * i + 1], light = rays[3 * i + 2];
    LitIntervals lit;
    int count = litIntervals(light.xyz, originT0.xyz, dirT1.xyz, originT0.w, dirT1.w, lit);
    counts[i] = count;
    for (int k = 0; k < kMaxLitIntervals; ++k) pieces[kMaxLitIntervals * i + k] = k < count ? lit.pieces[k] : vec2(0.0f);
}
