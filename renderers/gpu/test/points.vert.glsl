#version 460
// Point i from one vec4 per point: (centre.xy, half size, unused); squares.geom.glsl makes it a square.
layout(std430, set = 0, binding = 0) readonly buffer Points { vec4 points[]; };
layout(location = 0) out float halfSize;
void main() {
    vec4 point = points[gl_VertexIndex];
    gl_Position = vec4(point.xy, 0.5, 1.0);
    halfSize = point.z;
}
