#version 460
// Dual-source blending: the flat colour as the first output, and a per-channel factor made from its alpha and the
// triangle's depth field as the second, (a, a / 2, depth, a).
layout(location = 0) flat in vec4 colour;
layout(location = 1) flat in float depth;
layout(location = 0, index = 0) out vec4 result;
layout(location = 0, index = 1) out vec4 factor;
void main() {
    result = colour;
    factor = vec4(colour.a, 0.5 * colour.a, depth, colour.a);
}
