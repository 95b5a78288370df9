#version 460
// ISV proxies, geometry stage (the path that runs everywhere; shaders/features/isv_proxy.mesh.glsl is the mesh-shader
// producer): per particle the projected-tetrahedron proxy of thesis Sec. 2.3.3 (shared/isv.h isvProxy), three or four
// triangles whose vertices carry the two screen-affine depth attributes q the fragment stage turns into the ray's
// interval. TY_ISV_LIGHT_VIEW selects the volumetric shadow map's orthographic view of one slab (q = depth along the
// light, or 1 / depth for a point light's frustum; particles outside the slab emit nothing); otherwise the camera's
// perspective view (q = 1 / view depth;
// tetrahedra reaching in front of the near plane are culled, as in the thesis, Sec. 2.3.4).
#extension GL_GOOGLE_include_directive : require
#include "isv_view.glsl"

layout(points) in;
layout(triangle_strip, max_vertices = 12) out;

layout(std430, set = 0, binding = 0) readonly buffer Particles { IsvParticle particles[]; };
layout(std430, set = 0, binding = 2) readonly buffer Frame { IsvFrame frame; };
layout(std430, set = 0, binding = 3) readonly buffer View { IsvView view; };

layout(push_constant) uniform Push {
    int slab;
    int ordered;
} push;

layout(location = 0) flat in uint vParticle[];
layout(location = 0) noperspective out vec2 q;
layout(location = 1) flat out uint particle;

void main() {
    uint index = vParticle[0];
    IsvParticle p = particles[index];
    vec3 v[4] = vec3[](p.v0, p.v1, p.v2, p.v3);
    vec2 s[4];
    vec4 depthAttribute;
#ifdef TY_ISV_LIGHT_VIEW
    IsvLightSpace g = frame.vsm;
    float lo = kInfinity, hi = -kInfinity;
    for (int i = 0; i < 4; ++i) {
        vec3 c = isvGridPoint(g, v[i]);
        s[i] = c.xy / float(g.size) * 2.0f - 1.0f;
        // Screen-affine depth: the distance along the texel's ray (orthographic) or the reciprocal depth
        // (perspective), as for the camera.
        depthAttribute[i] = g.perspective != 0 ? 1.0f / (c.z + g.depthOrigin) : c.z;
        lo = min(lo, c.z);
        hi = max(hi, c.z);
    }
    int slabs = g.slices - 1;
    int first = clamp(int(floor(lo / g.depthStep)), 0, slabs - 1), last = clamp(int(floor(hi / g.depthStep)), 0, slabs - 1);
    if (push.slab < first || push.slab > last) return;
#else
    CameraParams c = view.camera;
    for (int i = 0; i < 4; ++i) {
        vec3 r = v[i] - c.position;
        float z = dot(r, c.forward);
        if (z < view.nearPlane) return;
        s[i] = vec2(dot(r, c.right) / (z * c.tanHalfFovY * c.aspect), -dot(r, c.up) / (z * c.tanHalfFovY));
        depthAttribute[i] = 1.0f / z;
    }
#endif
    IsvProxy proxy = isvProxy(s[0], s[1], s[2], s[3], depthAttribute);
    int n = proxy.silhouette;
    for (int t = 0; t < n; ++t) {
        int corners[3] = int[](t, (t + 1) % n, n);
        for (int k = 0; k < 3; ++k) {
            gl_Position = vec4(proxy.p[corners[k]], 0.0f, 1.0f);
            q = proxy.q[corners[k]];
            particle = index;
            EmitVertex();
        }
        EndPrimitive();
    }
}
