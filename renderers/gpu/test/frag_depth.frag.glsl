#version 460
// The depth test sees the triangle's own depth (the rasterised z is 0.5 everywhere).
layout(location = 0) flat in vec4 colour;
layout(location = 1) flat in float depth;
layout(location = 0) out vec4 result;
void main() {
    result = colour;
    gl_FragDepth = depth;
}
