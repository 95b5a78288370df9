#version 460
// ISV proxies, vertex stage: one point per particle, drawn in the order the sort left in `order` (the camera pass) or
// in index order (the volumetric shadow map). The geometry stage builds the proxy.
#extension GL_GOOGLE_include_directive : require

layout(std430, set = 0, binding = 1) readonly buffer Order { uvec2 order[]; };  // (key, particle), back to front

layout(push_constant) uniform Push {
    int slab;     // the volumetric shadow map's slab, -1 for the camera pass
    int ordered;  // 1: read the particle from `order`
} push;

layout(location = 0) flat out uint vParticle;

void main() {
    vParticle = push.ordered != 0 ? order[gl_VertexIndex].y : uint(gl_VertexIndex);
    gl_Position = vec4(0.0f, 0.0f, 0.0f, 1.0f);
}
