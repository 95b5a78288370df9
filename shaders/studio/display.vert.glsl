#version 450
// The studio's viewport: one triangle that covers the screen (its fragment shader reads the composed frame).
void main() {
    vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
