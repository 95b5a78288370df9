#version 460
// ISV: the opaque surfaces seen from the camera, per pixel centre: (radiance, distance) for the particles to be
// composited over and clipped by. Lit through the opaque shadow map (a directional light) or a shadow ray (a point
// light), and the volumetric shadow map (the medium's shadow on surfaces, Sec. 3.13).
//   TY_BVH_WORDS  BVH arrays read as 64-bit words (needs shaderFloat64)
#extension GL_GOOGLE_include_directive : require

#define TY_BVH_NODES_BINDING 0
#define TY_BVH_TRIANGLES_BINDING 1
#include "../include/bvh_buffers.glsl"
#include "isv_view.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 2) readonly buffer SurfaceTriangles { SurfaceTriangle surfaceTriangles[]; };
layout(std430, set = 0, binding = 3) readonly buffer Materials { MaterialParams materials[]; };
layout(std430, set = 0, binding = 4) readonly buffer Frame { IsvFrame frame; };
layout(std430, set = 0, binding = 5) readonly buffer View { IsvView view; };
#if TY_ISV_CHROMATIC
layout(std430, set = 0, binding = 6) readonly buffer Vsm { vec4 vsm[]; };  // RGB optical depth (coloured shadows)
vec3 isvVsmTexel(int i) { return vsm[i].xyz; }
#else
layout(std430, set = 0, binding = 6) readonly buffer Vsm { float vsm[]; };
float isvVsmTexel(int i) { return vsm[i]; }
#endif
layout(std430, set = 0, binding = 7) readonly buffer ShadowMap { float shadowMap[]; };
layout(std430, set = 0, binding = 8) writeonly buffer Surfaces { vec4 surfaces[]; };

float isvShadowTexel(int i) { return shadowMap[i]; }

layout(push_constant) uniform Push {
    uint first;  // first pixel of this dispatch
    uint end;
    float rayOffset;  // m, shadow rays leave surfaces this far along the normal
} push;

void main() {
    IsvFrame f = frame;
    CameraParams c = view.camera;
    uint pixel = push.first + gl_GlobalInvocationID.x;
    if (pixel >= push.end) return;
    int x = int(pixel % uint(view.width)), y = int(pixel / uint(view.width));
    vec3 origin, dir;
    cameraRay(c, float(x) + 0.5f, float(y) + 0.5f, origin, dir);
    BvhHit hit;
    vec4 result = vec4(0.0f, 0.0f, 0.0f, kInfinity);
    if (bvhIntersect(origin, dir, 0.0f, kInfinity, hit)) {
        SurfaceTriangle st = surfaceTriangles[hit.id];
        SurfaceFrame sf = surfaceFrame(st, hit.uv, dir);
        vec3 x = origin + hit.t * dir;
        float vis = isvSurfaceVisibility(f, x, sf.ng, push.rayOffset);
        result = vec4(isvSurfaceRadiance(f, materials[st.material], sf, x, -dir, vis), hit.t);
    }
    surfaces[pixel] = result;
}
