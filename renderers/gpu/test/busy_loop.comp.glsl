#version 460
// A deliberately expensive kernel (a long dependent loop per item) to exercise slicing and cancellation.
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) buffer Data { float values[]; };
layout(push_constant) uniform Push { uint count; uint offset; uint iterations; } push;
void main() {
    uint i = gl_GlobalInvocationID.x + push.offset;
    if (i >= push.count) return;
    float x = values[i];
    for (uint k = 0u; k < push.iterations; ++k) x = fract(x * 1.000173f + 0.1234567f);
    values[i] = x + 1.0f;
}
