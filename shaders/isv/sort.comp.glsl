#version 460
// ISV's back-to-front order on the GPU: a bitonic sort of (key, particle) pairs, the key being the centre's distance
// from the camera as float bits. Pass -1 writes the keys (padding entries last); the others are the compare-exchange
// steps (k, j) of the bitonic network, in the order "farther first, then lower index" that the CPU model uses.
#extension GL_GOOGLE_include_directive : require
#include "isv_view.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Particles { IsvParticle particles[]; };
layout(std430, set = 0, binding = 1) buffer Order { uvec2 order[]; };
layout(std430, set = 0, binding = 2) readonly buffer View { IsvView view; };

layout(push_constant) uniform Push {
    uint count;   // padded to a power of two
    uint k;       // 0: write the keys
    uint j;
} push;

bool before(uvec2 a, uvec2 b) { return a.x > b.x || (a.x == b.x && a.y < b.y); }

void main() {
    // Two-dimensional dispatches past the 65535 groups a dimension is guaranteed (more than 2^22 particles).
    uint i = gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x) + gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    if (push.k == 0u) {
        if (i < uint(view.particleCount)) {
            vec3 centre = particles[i].centre;
            order[i] = uvec2(floatBitsToUint(length(centre - view.camera.position)), i);
        } else {
            order[i] = uvec2(0u, 0xffffffffu);
        }
        return;
    }
    uint l = i ^ push.j;
    if (l <= i) return;
    uvec2 a = order[i], b = order[l];
    bool forward = (i & push.k) == 0u;
    if (forward ? before(b, a) : before(a, b)) {
        order[i] = b;
        order[l] = a;
    }
}
