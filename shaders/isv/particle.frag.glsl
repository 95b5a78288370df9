#version 460
// ISV particles, fragment stage of the camera pass: the ray's interval through the particle from the proxy's
// interpolated depths (Eq. 5), clipped by the opaque surface in front of the camera (Sec. 3.15: occlusion of and by
// opaque objects), shaded by shared/isv.h's isvShade; the blend state composites (C_scat, A) back to front:
// C = C_scat + A C, alpha = A alpha (Sec. 3.2).
//   TY_ISV_CHROMATIC 1  A per channel (coloured shadows): the second output of dual-source blending holds
//                       (A_rgb, mean A), and the volumetric shadow map is RGB (vec4 per texel)
#extension GL_GOOGLE_include_directive : require
#define TY_ISV_MEDIUM_ACCESSOR
#include "isv_view.glsl"

layout(std430, set = 0, binding = 0) readonly buffer Particles { IsvParticle particles[]; };
layout(std430, set = 0, binding = 2) readonly buffer Frame { IsvFrame frame; };
layout(std430, set = 0, binding = 3) readonly buffer View { IsvView view; };
#if TY_ISV_CHROMATIC
layout(std430, set = 0, binding = 4) readonly buffer Vsm { vec4 vsm[]; };
vec3 isvVsmTexel(int i) { return vsm[i].xyz; }
#else
layout(std430, set = 0, binding = 4) readonly buffer Vsm { float vsm[]; };
float isvVsmTexel(int i) { return vsm[i]; }
#endif
layout(std430, set = 0, binding = 5) readonly buffer ShadowMap { float shadowMap[]; };
layout(std430, set = 0, binding = 6) readonly buffer Surfaces { vec4 surfaces[]; };  // (rgb, distance) per pixel

float isvShadowTexel(int i) { return shadowMap[i]; }
IsvMedium isvMedium(int i) { return frame.media[i]; }

layout(location = 0) noperspective in vec2 q;
layout(location = 1) flat in uint particle;
#if TY_ISV_CHROMATIC
layout(location = 0, index = 0) out vec4 colour;
layout(location = 0, index = 1) out vec4 transmittance;
#else
layout(location = 0) out vec4 colour;
#endif

void main() {
    IsvFrame f = frame;
    CameraParams c = view.camera;
    int pixel = int(gl_FragCoord.y) * view.width + int(gl_FragCoord.x);
    vec3 origin, dir;
    cameraRay(c, gl_FragCoord.x, gl_FragCoord.y, origin, dir);
    float cosine = dot(dir, c.forward);
    float ta = 1.0f / (q.x * cosine), tb = 1.0f / (q.y * cosine);
    float t0 = min(ta, tb), t1 = max(ta, tb);
    float surface = surfaces[pixel].w;
    if (t0 >= surface) discard;
    IsvRgb a;
    vec3 scattered = isvShade(f, particles[particle], origin, dir, t0, min(t1, surface), a);
#if TY_ISV_CHROMATIC
    colour = vec4(scattered, 0.0f);
    transmittance = vec4(a, isvMeanChannel(a));
#else
    colour = vec4(scattered, a);
#endif
}
