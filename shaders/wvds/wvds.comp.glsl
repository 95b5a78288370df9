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
//   TY_WVDS_PLANE_TOTAL n   exactly n planes in all (the medium's and the gobos'): copied to private memory once
//   TY_WVDS_NO_GOBOS        no light has a gobo: no beam clipping
//   TY_WVDS_GREY            the medium's extinction is the same in every channel: one integral and one exponential
//   TY_WVDS_NO_SURFACES     the scene has no triangles: no camera hits, shadow rays or surface shading (lavapipe runs
//                           the code of a branch that no lane takes, so its absence pays even where nothing is hit)
//   TY_BVH_WORDS            BVH arrays read as 64-bit words (needs shaderFloat64; the cheaper loads on lavapipe)
//   TY_ACCUMULATOR_WORDS    the accumulators read and written as 64-bit words too (needs shaderFloat64)
// The build compiles this file as it is (every estimator, 16 faces, every phase function) so that CI validates it with spirv-val.
#extension GL_GOOGLE_include_directive : require

#define TY_BVH_NODES_BINDING 0
#define TY_BVH_TRIANGLES_BINDING 1
#include "../include/bvh_buffers.glsl"
#include "../shared/accumulation.h"
#include "../shared/wvds_scene.h"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 2) readonly buffer Frame { WvdsFrame frame; };
layout(std430, set = 0, binding = 3) readonly buffer Planes { vec4 planes[]; };
layout(std430, set = 0, binding = 4) readonly buffer Lights { WvdsLight lights[]; };
layout(std430, set = 0, binding = 5) readonly buffer SurfaceTriangles { SurfaceTriangle surfaceTriangles[]; };
layout(std430, set = 0, binding = 6) readonly buffer Materials { MaterialParams materials[]; };
// Per pixel and half (even and odd samples, for the variance estimate): `stride` vec4s, the direct sum first, then
// per light of a ratio estimator its analytic term, numerator and denominator. Each dispatch covers a pixel once.
// On lavapipe, a load or store at an index that differs per invocation costs a scalar loop over the lanes per
// component, so the vec4s are moved as two 64-bit words where the device has them (the bits pass through unchanged).
#ifdef TY_ACCUMULATOR_WORDS
layout(std430, set = 0, binding = 7) buffer Accumulators { dvec2 accumulators[]; };
vec4 loadAccumulator(uint i) {
    dvec2 w = accumulators[i];
    return uintBitsToFloat(uvec4(unpackDouble2x32(w.x), unpackDouble2x32(w.y)));
}
void storeAccumulator(uint i, vec4 v) {
    uvec4 bits = floatBitsToUint(v);
    accumulators[i] = dvec2(packDouble2x32(bits.xy), packDouble2x32(bits.zw));
}
#else
layout(std430, set = 0, binding = 7) buffer Accumulators { vec4 accumulators[]; };
vec4 loadAccumulator(uint i) { return accumulators[i]; }
void storeAccumulator(uint i, vec4 v) { accumulators[i] = v; }
#endif
void addToAccumulator(uint i, vec4 v) { storeAccumulator(i, loadAccumulator(i) + v); }

layout(push_constant) uniform Push {
    uint first;   // first work item of this dispatch (see main for items and pixels)
    uint end;     // one past its last item: the next slice adds the items after it
    uint width;
    uint index;   // the camera sample every pixel adds
    uint stride;  // vec4s per pixel and half
    uint ratioLights;
    uint pixels;      // width * height
    uint bandGroups;  // pixel groups of 64 per band: ((pixels + 63) / 64 + 15) / 16
} push;

// Lavapipe loads from a storage buffer with one scalar load only outside control flow (where it knows invocation 0
// is active); after the first branch, even a load that every invocation makes at the same address becomes a loop
// over the SIMD lanes, per component. The scene's uniform data (the frame, its planes, its lights) is therefore
// copied to private variables at the top of main, once, and read from there: a third of the analytic frame without
// meshes (9.4 -> 6.4 ms at 512 x 512).
WvdsFrame sceneFrame;
#ifdef TY_WVDS_PLANE_TOTAL
vec4 scenePlanes[TY_WVDS_PLANE_TOTAL];
vec4 wvdsPlane(int i) { return scenePlanes[i]; }
#else
vec4 wvdsPlane(int i) { return planes[i]; }
#endif
#if defined(TY_WVDS_LIGHTS) && TY_WVDS_LIGHTS > 0
#define TY_WVDS_SCENE_LIGHTS
WvdsLight sceneLights[TY_WVDS_LIGHTS];
WvdsLight wvdsLight(int i) { return sceneLights[i]; }
#else
WvdsLight wvdsLight(int i) { return lights[i]; }
#endif
SurfaceTriangle wvdsTriangle(int id) { return surfaceTriangles[id]; }
MaterialParams wvdsMaterial(int i) { return materials[i]; }

void main() {
    // Before any branch: see sceneFrame.
    sceneFrame = frame;
#ifdef TY_WVDS_PLANE_TOTAL
    for (int i = 0; i < TY_WVDS_PLANE_TOTAL; ++i)
        scenePlanes[i] = planes[i];
#endif
#ifdef TY_WVDS_SCENE_LIGHTS
    for (int i = 0; i < TY_WVDS_LIGHTS; ++i)
        sceneLights[i] = lights[i];
#endif
    // The pixel of each work item, every pixel once per dispatch (shared/accumulation.h).
    uint item = push.first + gl_GlobalInvocationID.x;
    if (item >= push.end) return;
    uint pixel = accumulationPixel(item, push.bandGroups);
    if (pixel >= push.pixels) return;
    int px = int(pixel % push.width), py = int(pixel / push.width);
    WvdsTerms terms = wvdsSample(sceneFrame, px, py, push.index);
    uint base = (pixel * 2u + (push.index & 1u)) * push.stride;
    addToAccumulator(base, vec4(terms.direct, 1.0));
#ifdef TY_WVDS_ESTIMATOR
    if (!wvdsIsRatio(TY_WVDS_ESTIMATOR)) return;
#endif
    for (int l = 0; l < kWvdsMaxLights; ++l) {
        if (uint(l) >= push.ratioLights) continue;
        addToAccumulator(base + 1u + 3u * uint(l), vec4(terms.analytic[l], 0.0));
        addToAccumulator(base + 2u + 3u * uint(l), vec4(terms.numerator[l], 0.0));
        addToAccumulator(base + 3u + 3u * uint(l), vec4(terms.denominator[l], 0.0));
    }
}
