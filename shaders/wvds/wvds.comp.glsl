#version 460
// The WVDS technique on the GPU: one invocation per pixel adds one camera sample of the shared renderer
// (shared/wvds_scene.h) to the pixel's accumulators. renderers/wvds/ compiles variants at run time by inserting defines
// after the #version line:
//   TY_WVDS_ESTIMATOR k     one estimator (kWvds* in wvds_scene.h): the code and arrays of the others are left out
//   TY_WVDS_MAX_PLANES n    arrays for at most n faces (6 for a box): loops unroll and the arrays stay in registers
//   TY_WVDS_BOX             the medium is a box (its planes in opposite pairs): 3 lines and 3 segments
//   TY_PHASE_KIND k         the medium's phase function (kPhase* in phase.h): the other kinds are left out
//   TY_WVDS_LIGHTS n        exactly n collimated lights: the loops over them run n times, not kWvdsMaxLights
//   TY_WVDS_PLANES n        exactly n medium planes: the slab tests over the medium unroll
//   TY_WVDS_NO_GOBOS        no light has a gobo: no beam clipping
//   TY_WVDS_GREY            the medium's extinction is the same in every channel: one integral and one exponential
//   TY_WVDS_NO_SURFACES     the scene has no triangles: no camera hits, shadow rays or surface shading (lavapipe runs
//                           the code of a branch that no lane takes, so its absence pays even where nothing is hit)
//   TY_BVH_WORDS            BVH arrays read as 64-bit words (needs shaderFloat64; the cheaper loads on lavapipe)
// The build compiles this file as it is (every estimator, 16 faces, every phase function) so that CI validates it with spirv-val.
#extension GL_GOOGLE_include_directive : require

#define TY_BVH_NODES_BINDING 0
#define TY_BVH_TRIANGLES_BINDING 1
#include "../include/bvh_buffers.glsl"
#include "../shared/wvds_scene.h"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 2) readonly buffer Frame { WvdsFrame frame; };
layout(std430, set = 0, binding = 3) readonly buffer Planes { vec4 planes[]; };
layout(std430, set = 0, binding = 4) readonly buffer Lights { WvdsLight lights[]; };
layout(std430, set = 0, binding = 5) readonly buffer SurfaceTriangles { SurfaceTriangle surfaceTriangles[]; };
layout(std430, set = 0, binding = 6) readonly buffer Materials { MaterialParams materials[]; };
// Per pixel and half (even and odd samples, for the variance estimate): `stride` vec4s, the direct sum first, then
// per light of a ratio estimator its analytic term, numerator and denominator. Each dispatch covers a pixel once.
layout(std430, set = 0, binding = 7) buffer Accumulators { vec4 accumulators[]; };

layout(push_constant) uniform Push {
    uint first;   // first pixel of this dispatch
    uint end;     // one past the last pixel of this dispatch: the next slice adds the pixels after it
    uint width;
    uint index;   // the camera sample every pixel adds
    uint stride;  // vec4s per pixel and half
    uint ratioLights;
} push;

vec4 wvdsPlane(int i) { return planes[i]; }
WvdsLight wvdsLight(int i) { return lights[i]; }
SurfaceTriangle wvdsTriangle(int id) { return surfaceTriangles[id]; }
MaterialParams wvdsMaterial(int i) { return materials[i]; }

void main() {
    uint pixel = push.first + gl_GlobalInvocationID.x;
    if (pixel >= push.end) return;
    int px = int(pixel % push.width), py = int(pixel / push.width);
    WvdsTerms terms = wvdsSample(frame, px, py, push.index);
    uint base = (pixel * 2u + (push.index & 1u)) * push.stride;
    accumulators[base] += vec4(terms.direct, 1.0);
#ifdef TY_WVDS_ESTIMATOR
    if (!wvdsIsRatio(TY_WVDS_ESTIMATOR)) return;
#endif
    for (int l = 0; l < kWvdsMaxLights; ++l) {
        if (uint(l) >= push.ratioLights) continue;
        accumulators[base + 1u + 3u * uint(l)] += vec4(terms.analytic[l], 0.0);
        accumulators[base + 2u + 3u * uint(l)] += vec4(terms.numerator[l], 0.0);
        accumulators[base + 3u + 3u * uint(l)] += vec4(terms.denominator[l], 0.0);
    }
}
