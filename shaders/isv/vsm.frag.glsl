#version 460
// ISV's volumetric shadow map, fragment stage: the optical depth of the particle inside one slab along the light ray
// through this texel (shared/isv.h isvSlabDepth), added to the slab's layer by the blend state. A compute pass then
// sums the slabs front to back into slices (vsm_sum.comp.glsl).
//   TY_ISV_CHROMATIC 1  the optical depth per channel, (rgb, 0) into an RGBA target (coloured shadows)
#extension GL_GOOGLE_include_directive : require
#include "isv_view.glsl"

layout(std430, set = 0, binding = 0) readonly buffer Particles { IsvParticle particles[]; };
layout(std430, set = 0, binding = 2) readonly buffer Frame { IsvFrame frame; };

IsvRgb isvVsmTexel(int i) { return IsvRgb(0.0f); }
float isvShadowTexel(int i) { return kInfinity; }

layout(push_constant) uniform Push {
    int slab;
    int ordered;
} push;

layout(location = 0) noperspective in vec2 q;
layout(location = 1) flat in uint particle;
#if TY_ISV_CHROMATIC
layout(location = 0) out vec4 depth;
#else
layout(location = 0) out float depth;
#endif

void main() {
    IsvLightSpace g = frame.vsm;
    vec3 origin, dir;
    float cosine;
    isvGridRay(g, gl_FragCoord.x, gl_FragCoord.y, origin, dir, cosine);
    // The interval and the slab as distances along the texel's ray.
    float ta = g.perspective != 0 ? 1.0f / (q.x * cosine) : q.x, tb = g.perspective != 0 ? 1.0f / (q.y * cosine) : q.y;
    float lo = isvRayDistance(g, float(push.slab) * g.depthStep, cosine);
    float hi = isvRayDistance(g, float(push.slab + 1) * g.depthStep, cosine);
    IsvParticle p = particles[particle];
    float tau = isvSlabDepth(p, origin, dir, min(ta, tb), max(ta, tb), lo, hi, TY_ISV_FADING_OF(frame));
#if TY_ISV_CHROMATIC
    depth = vec4(tau * frame.media[p.medium].tint, 0.0f);
#else
    depth = tau;
#endif
}
