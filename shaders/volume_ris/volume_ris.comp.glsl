#version 460
// The Volume-RIS technique on the GPU: one invocation per pixel adds one camera sample of the shared renderer
// (shared/volume_ris.h) to the pixel's accumulator. renderers/volume_ris/ compiles variants at run time by inserting
// defines after the #version line:
//   TY_RIS_MEDIUM k        the medium (kRisMedium* in volume_ris.h): none, infinite, or planes
//   TY_RIS_PLANES n        exactly n medium planes: the slab tests unroll
//   TY_RIS_LIGHTS n        exactly n area lights: the selection loop runs n times
//   TY_RIS_VERTEX_TOTAL n  exactly n light vertices in all: copied to private memory once
//   TY_RIS_DISTANCE k      the distance sampler (kRisTransmittance, kRisEquiangular)
//   TY_RIS_VERTICES n      no light has more than n vertices
//   TY_RIS_LIGHT_SAMPLING k  the light-point sampler (kRisSolidAngle, kRisArea)
//   TY_PHASE_KIND k        the medium's phase function (kPhase* in phase.h): the other kinds are left out
//   TY_RIS_GREY            the medium's extinction is the same in every channel
//   TY_RIS_NO_SURFACES     the scene has no triangles: no camera hits, shadow rays or surface shading
//   TY_BVH_WORDS           BVH arrays read as 64-bit words (needs shaderFloat64; the cheaper loads on lavapipe)
// The build compiles this file as it is (every variant decided at run time) so that CI validates it with spirv-val.
#extension GL_GOOGLE_include_directive : require

#define TY_BVH_NODES_BINDING 0
#define TY_BVH_TRIANGLES_BINDING 1
#include "../include/bvh_buffers.glsl"
#include "../shared/accumulation.h"
#include "../shared/volume_ris.h"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 2) readonly buffer Frame { RisFrame frame; };
layout(std430, set = 0, binding = 3) readonly buffer Planes { vec4 planes[]; };
layout(std430, set = 0, binding = 4) readonly buffer Lights { RisLight lights[]; };
layout(std430, set = 0, binding = 5) readonly buffer Vertices { vec4 vertices[]; };
layout(std430, set = 0, binding = 6) readonly buffer SurfaceTriangles { SurfaceTriangle surfaceTriangles[]; };
layout(std430, set = 0, binding = 7) readonly buffer Materials { MaterialParams materials[]; };
// Per pixel and half (even and odd samples, for the variance estimate): two vec4s, the sums of the medium's samples
// (w counting them) and of the surface's.
layout(std430, set = 0, binding = 8) buffer Accumulators { vec4 accumulators[]; };

layout(push_constant) uniform Push {
    uint first;  // first work item of this dispatch (see main for items and pixels)
    uint end;    // one past its last item
    uint width;
    uint index;       // the camera sample every pixel adds
    uint pixels;      // width * height
    uint bandGroups;  // pixel groups of 64 per band: ((pixels + 63) / 64 + 15) / 16
} push;

// The scene's uniform data is copied to private variables at the top of main, before any branch (lavapipe loads a
// storage buffer with one scalar load only there; see shaders/wvds/wvds.comp.glsl).
RisFrame sceneFrame;
#if defined(TY_RIS_PLANES) && TY_RIS_PLANES > 0
vec4 scenePlanes[TY_RIS_PLANES];
vec4 risPlane(int i) { return scenePlanes[i]; }
#else
vec4 risPlane(int i) { return planes[i]; }
#endif
#if defined(TY_RIS_LIGHTS) && TY_RIS_LIGHTS > 0
RisLight sceneLights[TY_RIS_LIGHTS];
RisLight risLight(int i) { return sceneLights[i]; }
#else
RisLight risLight(int i) { return lights[i]; }
#endif
#ifdef TY_RIS_VERTEX_TOTAL
vec4 sceneVertices[TY_RIS_VERTEX_TOTAL];
vec4 risVertex(int i) { return sceneVertices[i]; }
#else
vec4 risVertex(int i) { return vertices[i]; }
#endif
SurfaceTriangle risTriangle(int id) { return surfaceTriangles[id]; }
MaterialParams risMaterial(int i) { return materials[i]; }

void main() {
    sceneFrame = frame;
#if defined(TY_RIS_PLANES) && TY_RIS_PLANES > 0
    for (int i = 0; i < TY_RIS_PLANES; ++i)
        scenePlanes[i] = planes[i];
#endif
#if defined(TY_RIS_LIGHTS) && TY_RIS_LIGHTS > 0
    for (int i = 0; i < TY_RIS_LIGHTS; ++i)
        sceneLights[i] = lights[i];
#endif
#ifdef TY_RIS_VERTEX_TOTAL
    for (int i = 0; i < TY_RIS_VERTEX_TOTAL; ++i)
        sceneVertices[i] = vertices[i];
#endif
    // The pixel of each work item, every pixel once per dispatch (shared/accumulation.h).
    uint item = push.first + gl_GlobalInvocationID.x;
    if (item >= push.end) return;
    uint pixel = accumulationPixel(item, push.bandGroups);
    if (pixel >= push.pixels) return;
    int px = int(pixel % push.width), py = int(pixel / push.width);
    RisTerms terms = risSample(sceneFrame, px, py, push.index);
    vec3 value = terms.medium + terms.surface;
    if (any(isnan(value)) || any(isinf(value))) {  // as the CPU path, which also counts them
        terms.medium = vec3(0.0);
        terms.surface = vec3(0.0);
    }
    uint slot = (pixel * 2u + (push.index & 1u)) * 2u;
    accumulators[slot] += vec4(terms.medium, 1.0);
    accumulators[slot + 1u] += vec4(terms.surface, 0.0);
}
