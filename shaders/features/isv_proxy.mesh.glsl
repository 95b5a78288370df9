// ISV proxies with a mesh shader (VK_EXT_mesh_shader), the producer Tricard and the thesis use: one invocation per
// particle emits the same projected-tetrahedron proxy as the geometry-shader path (shaders/isv/proxy.geom.glsl; both
// call shared/isv.h isvProxy), up to 5 vertices and 4 triangles, for the camera's perspective view; tetrahedra reaching
// in front of the near plane are culled. Its fragment stage is shaders/isv/particle.frag.glsl unchanged. Compiled and
// validated in CI (tests/CMakeLists.txt); not run on machines without mesh shaders (lavapipe).
#version 460
#extension GL_EXT_mesh_shader : require
#extension GL_GOOGLE_include_directive : require
#include "../isv/isv_view.glsl"

layout(local_size_x = 1) in;
layout(triangles, max_vertices = 5, max_primitives = 4) out;

layout(std430, set = 0, binding = 0) readonly buffer Particles { IsvParticle particles[]; };
layout(std430, set = 0, binding = 1) readonly buffer Order { uvec2 order[]; };
layout(std430, set = 0, binding = 3) readonly buffer View { IsvView view; };

layout(location = 0) noperspective out vec2 q[];
layout(location = 1) flat out uint particle[];

void main() {
    uint index = order[gl_WorkGroupID.x].y;
    IsvParticle p = particles[index];
    vec3 v[4] = vec3[](p.v0, p.v1, p.v2, p.v3);
    CameraParams c = view.camera;
    vec2 s[4];
    vec4 depthAttribute;
    for (int i = 0; i < 4; ++i) {
        vec3 r = v[i] - c.position;
        float z = dot(r, c.forward);
        if (z < view.nearPlane) {
            SetMeshOutputsEXT(0, 0);
            return;
        }
        s[i] = vec2(dot(r, c.right) / (z * c.tanHalfFovY * c.aspect), -dot(r, c.up) / (z * c.tanHalfFovY));
        depthAttribute[i] = 1.0f / z;
    }
    IsvProxy proxy = isvProxy(s[0], s[1], s[2], s[3], depthAttribute);
    int n = proxy.silhouette;
    SetMeshOutputsEXT(uint(n == 0 ? 0 : n + 1), uint(n));
    for (int k = 0; k <= n && n > 0; ++k) {
        gl_MeshVerticesEXT[k].gl_Position = vec4(proxy.p[k], 0.0f, 1.0f);
        q[k] = proxy.q[k];
        particle[k] = index;
    }
    for (int t = 0; t < n; ++t)
        gl_PrimitiveTriangleIndicesEXT[t] = uvec3(uint(t), uint((t + 1) % n), uint(n));
}
