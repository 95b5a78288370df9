// Evaluates the Henyey-Greenstein phase function at a list of cosines: the smallest kernel that exercises the shared
// headers on the GPU (tests compare it with the C++ side of shared/phase.h).
#version 460
#extension GL_GOOGLE_include_directive : require

#include "shared/phase.h"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer Cosines { float mu[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Values { float value[]; };

layout(push_constant) uniform Push {
    uint count;  // number of cosines
    float g;     // asymmetry in (-1, 1)
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    PhaseParams p;
    p.kind = kPhaseHenyeyGreenstein;
    p.g = pc.g;
    p.a = 1.0f;
    p.b = 0.0f;
    p.terms = 0;
    value[i] = phaseEval(p, mu[i]);
}
