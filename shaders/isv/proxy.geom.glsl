#version 460
// ISV proxies, geometry stage: the producer that runs everywhere (shaders/features/isv_proxy.mesh.glsl is the
// mesh-shader one). Per particle the projected-tetrahedron proxy of its pass's view (proxy_view.glsl), three or four
// triangles whose vertices carry the two screen-affine depth attributes q the fragment stage turns into the ray's
// interval. TY_ISV_LIGHT_VIEW selects the volumetric shadow map's view of one slab, otherwise the camera's.
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

#include "proxy_view.glsl"

layout(location = 0) flat in uint vParticle[];
layout(location = 0) noperspective out vec2 q;
layout(location = 1) flat out uint particle;

void main() {
    uint index = vParticle[0];
    IsvProxy proxy = isvPassProxy(particles[index], push.slab);
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
