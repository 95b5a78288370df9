#version 460
// ISV proxies with a mesh shader (VK_EXT_mesh_shader), the producer Tricard and the thesis use, selected by the `isv`
// technique's `proxies` parameter where the device has mesh shaders. Each workgroup takes 32 particles of the draw (in
// the sorted order for the camera pass, in index order for the volumetric shadow map); each invocation builds its
// particle's proxy with proxy_view.glsl, as the geometry stage does (shaders/isv/proxy.geom.glsl), and writes its 3 or 4
// triangles after those of the invocations before it, so that primitives keep the particles' order (blending is
// order-dependent). The fragment stages are unchanged. Compiled and validated in CI (tests/CMakeLists.txt); lavapipe
// has no mesh shaders, so this machine does not run it.
#extension GL_EXT_mesh_shader : require
#extension GL_GOOGLE_include_directive : require
#include "../isv/isv_view.glsl"

const uint kParticlesPerGroup = 32u;
layout(local_size_x = 32) in;
layout(triangles, max_vertices = 160, max_primitives = 128) out;  // 5 vertices and 4 triangles per particle

layout(std430, set = 0, binding = 0) readonly buffer Particles { IsvParticle particles[]; };
layout(std430, set = 0, binding = 1) readonly buffer Order { uvec2 order[]; };
layout(std430, set = 0, binding = 2) readonly buffer Frame { IsvFrame frame; };
layout(std430, set = 0, binding = 3) readonly buffer View { IsvView view; };

layout(push_constant) uniform Push {
    int slab;     // the volumetric shadow map's slab, -1 for the camera pass
    int ordered;  // 1: read the particle from `order`
    uint first;   // the draw's first particle (slot in `order`, or index)
    uint count;   // the draw's particles
} push;

#include "../isv/proxy_view.glsl"

layout(location = 0) noperspective out vec2 q[];
layout(location = 1) flat out uint particle[];

shared uint sides[kParticlesPerGroup];  // each invocation's silhouette: 0, 3 or 4
shared uint vertexBase[kParticlesPerGroup];
shared uint primitiveBase[kParticlesPerGroup];
shared uint totals[2];

void main() {
    uint lane = gl_LocalInvocationID.x;
    uint slot = gl_WorkGroupID.x * kParticlesPerGroup + lane;
    uint index = 0u;
    IsvProxy proxy;
    proxy.silhouette = 0;
    if (slot < push.count) {
        index = push.ordered != 0 ? order[push.first + slot].y : push.first + slot;
        proxy = isvPassProxy(particles[index], push.slab);
    }
    sides[lane] = uint(proxy.silhouette);
    barrier();
    if (lane == 0u) {
        uint vertices = 0u, primitives = 0u;
        for (uint i = 0u; i < kParticlesPerGroup; ++i) {
            vertexBase[i] = vertices;
            primitiveBase[i] = primitives;
            vertices += sides[i] == 0u ? 0u : sides[i] + 1u;
            primitives += sides[i];
        }
        totals[0] = vertices;
        totals[1] = primitives;
    }
    barrier();
    SetMeshOutputsEXT(totals[0], totals[1]);
    uint n = uint(proxy.silhouette), v0 = vertexBase[lane], p0 = primitiveBase[lane];
    for (uint k = 0u; k <= n && n > 0u; ++k) {
        gl_MeshVerticesEXT[v0 + k].gl_Position = vec4(proxy.p[k], 0.0f, 1.0f);
        q[v0 + k] = proxy.q[k];
        particle[v0 + k] = index;
    }
    for (uint t = 0u; t < n; ++t)
        gl_PrimitiveTriangleIndicesEXT[p0 + t] = uvec3(v0 + t, v0 + (t + 1u) % n, v0 + n);
}
