#version 460
// A point in, a square out as two triangles (a strip of four vertices), in the push constant's colour.
layout(points) in;
layout(triangle_strip, max_vertices = 4) out;
layout(location = 0) in float halfSize[];
layout(location = 0) flat out vec4 colour;
layout(push_constant) uniform Push { vec4 colour; } push;
void main() {
    const vec2 corners[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));
    for (int i = 0; i < 4; ++i) {
        gl_Position = gl_in[0].gl_Position + vec4(corners[i] * halfSize[0], 0.0, 0.0);
        colour = push.colour;
        EmitVertex();
    }
    EndPrimitive();
}
