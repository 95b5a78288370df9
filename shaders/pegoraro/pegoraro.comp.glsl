#version 460
// The Pegoraro technique on the GPU: one invocation per pixel runs the shared per-pixel renderer
// (shared/pegoraro_scene.h) over the scene in storage buffers. renderers/pegoraro/ compiles variants at run time by
// inserting defines after the #version line:
//   TY_PEGORARO_MAX_TERMS n   arrays for at most n terms of the closed form (default 40, shared/pegoraro.h)
//   TY_ENABLE_DOUBLE          the closed form in double precision (the device needs shaderFloat64)
//   TY_BVH_WORDS              BVH arrays read as 64-bit words (needs shaderFloat64)
//   TY_PEGORARO_NO_SHADOWS    without the lit intervals and shadow rays, for renders with shadows off: lavapipe runs
//                             the shader ~40 % faster when that code is absent, even though it would not execute
//   TY_PEGORARO_NO_SURFACES   the scene has no triangles: no camera hits, lit intervals or surface shading
//   TY_PEGORARO_GREY          the extinction is the same in every channel: one closed form per evaluation, not three
//   TY_PRIMARY_HITS           the camera hits of the grid samples come from the rasterised records (binding 11)
//   TY_PEGORARO_DEFERRED_FALLBACK  the first pass: no quadrature code; an evaluation that needs it is counted in w, and
//                             the host renders those samples again with the full shader over a list (push.listed)
// The pixels around a light's projection are rendered by the full shader once more, node by node over a list
// (push.listed = 2; pegoraroSingularNode in shared/pegoraro_scene.h).
// The build compiles this file as it is (float, 40 terms) so that CI validates it with spirv-val.
#extension GL_GOOGLE_include_directive : require

#define TY_BVH_NODES_BINDING 0
#define TY_BVH_TRIANGLES_BINDING 1
#include "../include/bvh_buffers.glsl"
#define TY_PRIMARY_HITS_BINDING 11
#include "../include/primary_hits.glsl"
#include "../shared/pegoraro_scene.h"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 2) readonly buffer Frame { PegoraroFrame frame; };
layout(std430, set = 0, binding = 3) readonly buffer Lights { PegoraroLight lights[]; };
layout(std430, set = 0, binding = 4) readonly buffer Media { PegoraroMedium media[]; };
layout(std430, set = 0, binding = 5) readonly buffer Coefficients { vec2 coefficients[]; };
layout(std430, set = 0, binding = 6) readonly buffer SurfaceTriangles { SurfaceTriangle surfaceTriangles[]; };
layout(std430, set = 0, binding = 7) readonly buffer Materials { MaterialParams materials[]; };
// One entry per sample (pixel-major, S x S samples per pixel): the host averages them. One invocation per sample
// rather than a loop over a pixel's samples: lavapipe runs that loop tens of times slower than the same rays spread
// over invocations.
layout(std430, set = 0, binding = 8) writeonly buffer Radiance { vec4 radiance[]; };  // rgb, fallbacks
layout(std430, set = 0, binding = 9) writeonly buffer Overflows { uint overflows[]; };
// With push.listed: the samples this dispatch renders (those whose first pass deferred a fallback).
layout(std430, set = 0, binding = 10) readonly buffer SampleList { uint sampleList[]; };

layout(push_constant) uniform Push {
    uint first;   // first sample (or, with listed, first list entry) of this dispatch
    uint count;   // samples in the image, width * height * S * S (or, with listed, entries in the list)
    uint width;
    uint listed;  // 1: invocation i renders sample sampleList[first + i]; 2: node sampleList[first + i] of a pixel
                  // around a light's projection, written to radiance[first + i]
} push;

PegoraroLight pegoraroLight(int i) { return lights[i]; }
PegoraroMedium pegoraroMedium(int i) { return media[i]; }
vec2 pegoraroCoefficient(int i) { return coefficients[i]; }
SurfaceTriangle surfaceTriangle(int id) { return surfaceTriangles[id]; }
MaterialParams surfaceMaterial(int i) { return materials[i]; }

void main() {
    uint i = push.first + gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    if (push.listed == 2u) {
        // A node of a pixel around a light's projection: the list holds pixel * kPegoraroSingularNodes + node.
        uint item = sampleList[i];
        uint pixel = item / uint(kPegoraroSingularNodes);
        int node = int(item - pixel * uint(kPegoraroSingularNodes));
        int px = int(pixel % push.width), py = int(pixel / push.width);
        vec2 p;
        int overflowCount = 0;
        vec4 value = vec4(0.0f);
        if (pegoraroSingularPoint(frame, px, py, p)) {
#ifdef TY_ENABLE_DOUBLE
            value = pegoraroSingularSample_double(frame, px, py, p, node, overflowCount);
#else
            value = pegoraroSingularSample_float(frame, px, py, p, node, overflowCount);
#endif
        }
        radiance[i] = value;
        overflows[i] = uint(overflowCount);
        return;
    }
    if (push.listed != 0u) i = sampleList[i];
    uint samples = uint(max(frame.supersampling, 1) * max(frame.supersampling, 1));
    uint pixel = i / samples;
    int k = int(i - pixel * samples);
    int px = int(pixel % push.width), py = int(pixel / push.width);
    int overflowCount = 0;
#ifdef TY_ENABLE_DOUBLE
    radiance[i] = pegoraroSample_double(frame, px, py, k, overflowCount);
#else
    radiance[i] = pegoraroSample_float(frame, px, py, k, overflowCount);
#endif
    overflows[i] = uint(overflowCount);
}
