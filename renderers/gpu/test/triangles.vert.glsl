#version 460
// Triangle t of a list, from three vec4 per triangle: (a.xy, b.xy), (c.xy, depth, unused), colour. No vertex inputs:
// the corners come from a storage buffer by gl_VertexIndex, as graphics pipelines do in Tyndall.
layout(std430, set = 0, binding = 0) readonly buffer Triangles { vec4 triangles[]; };
layout(location = 0) flat out vec4 colour;
layout(location = 1) flat out float depth;
void main() {
    uint t = uint(gl_VertexIndex) / 3u, corner = uint(gl_VertexIndex) % 3u;
    vec4 ab = triangles[3u * t], cd = triangles[3u * t + 1u];
    vec2 p = corner == 0u ? ab.xy : (corner == 1u ? ab.zw : cd.xy);
    gl_Position = vec4(p, 0.5, 1.0);
    colour = triangles[3u * t + 2u];
    depth = cd.z;
}
