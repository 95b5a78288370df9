#version 460
// One triangle covering the target (for passes that write every pixel).
void main() {
    vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2));
    gl_Position = vec4(p * 2.0f - 1.0f, 0.0f, 1.0f);
}
