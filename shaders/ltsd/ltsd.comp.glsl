#version 460
// The LTSD technique on the GPU: one invocation per pixel runs the shared renderer (shared/ltsd_scene.h).
// renderers/ltsd/ compiles variants at run time by inserting defines after the #version line (see the top of
// ltsd_scene.h): the light and plane counts, the placement and transmittance modes, and TY_LTSD_NO_MEDIUM,
// TY_LTSD_NO_SURFACES, TY_LTSD_ONE_SIDED, TY_LTSD_NO_GGX, TY_LTSD_NO_ANISOTROPIC for what the scene lacks, so that
// lavapipe does not run code no lane takes; TY_BVH_WORDS where the device has shaderFloat64; TY_PRIMARY_HITS when the
// analytic pass reads its camera hits from the rasterised records (binding 9) instead of tracing them. With
// TY_LTSD_RATIO the kernel is the ratio estimators' pass instead: each invocation sums push.samples camera samples of
// its pixel. The build compiles this file as it is (every mode, the analytic pass) so that CI validates it with spirv-val.
#extension GL_GOOGLE_include_directive : require

#define TY_BVH_NODES_BINDING 0
#define TY_BVH_TRIANGLES_BINDING 1
#include "../include/bvh_buffers.glsl"
#define TY_PRIMARY_HITS_BINDING 9
#include "../include/primary_hits.glsl"
#include "../shared/ltsd_scene.h"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 2) readonly buffer Frame { LtsdFrame frame; };
layout(std430, set = 0, binding = 3) readonly buffer Lights { LtsdLight lights[]; };
layout(std430, set = 0, binding = 4) readonly buffer Planes { vec4 planes[]; };
layout(std430, set = 0, binding = 5) readonly buffer SurfaceTriangles { SurfaceTriangle surfaceTriangles[]; };
layout(std430, set = 0, binding = 6) readonly buffer Materials { MaterialParams materials[]; };
// Per pixel: the analytic pass writes A-bar and T L_c-bar (2 vec4s); the ratio pass the sums of the four terms of
// LtsdRatioTerms (4 vec4s).
layout(std430, set = 0, binding = 7) writeonly buffer Output { vec4 outputs[]; };
// The LTC GGX tables (shared/ltc.h; isotropic, then anisotropic from frame.ltcAnisoBase), read by GGX surfaces (a
// dummy entry without them).
layout(std430, set = 0, binding = 8) readonly buffer LtcEntries { LtcEntry ltcEntries[]; };

layout(push_constant) uniform Push {
    uint first;    // first pixel of this dispatch
    uint count;    // pixels in the image
    uint width;
    uint samples;  // the ratio pass: camera samples per pixel
    uint seed;
} push;

// Lavapipe loads from a storage buffer with one scalar load only outside control flow; inside it, a loop over the
// lanes. The frame, the lights and the planes are uniform: copied to private variables at the top of main, once.
LtsdFrame sceneFrame;
#if defined(TY_LTSD_LIGHTS) && TY_LTSD_LIGHTS > 0
LtsdLight sceneLights[TY_LTSD_LIGHTS];
LtsdLight ltsdLight(int i) { return sceneLights[i]; }
#else
LtsdLight ltsdLight(int i) { return lights[i]; }
#endif
#if defined(TY_LTSD_PLANES) && TY_LTSD_PLANES > 0
vec4 scenePlanes[TY_LTSD_PLANES];
vec4 ltsdPlane(int i) { return scenePlanes[i]; }
#else
vec4 ltsdPlane(int i) { return planes[i]; }
#endif
SurfaceTriangle ltsdTriangle(int id) { return surfaceTriangles[id]; }
MaterialParams ltsdMaterial(int i) { return materials[i]; }
LtcEntry ltsdLtcEntry(int i) { return ltcEntries[i]; }

void main() {
    sceneFrame = frame;
#if defined(TY_LTSD_LIGHTS) && TY_LTSD_LIGHTS > 0
    for (int i = 0; i < TY_LTSD_LIGHTS; ++i)
        sceneLights[i] = lights[i];
#endif
#if defined(TY_LTSD_PLANES) && TY_LTSD_PLANES > 0
    for (int i = 0; i < TY_LTSD_PLANES; ++i)
        scenePlanes[i] = planes[i];
#endif
    uint pixel = push.first + gl_GlobalInvocationID.x;
    if (pixel >= push.count) return;
    int px = int(pixel % push.width), py = int(pixel / push.width);
#ifdef TY_LTSD_RATIO
    vec3 sums[4] = vec3[4](vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0));
    for (uint k = 0u; k < push.samples; ++k) {
        LtsdRatioTerms r = ltsdRatioSample(sceneFrame, px, py, k, push.seed);
        sums[0] += r.airNumerator;
        sums[1] += r.airDenominator;
        sums[2] += r.surfaceNumerator;
        sums[3] += r.surfaceDenominator;
    }
    for (int i = 0; i < 4; ++i)
        outputs[4u * pixel + uint(i)] = vec4(sums[i], 0.0);
#else
    vec3 air, surface;
    ltsdPixelTerms(sceneFrame, px, py, air, surface);
    outputs[2u * pixel] = vec4(air, 0.0);
    outputs[2u * pixel + 1u] = vec4(surface, 0.0);
#endif
}
