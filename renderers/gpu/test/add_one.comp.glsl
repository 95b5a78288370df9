#version 460
// out[i] = in[i] + value: the smallest kernel that proves buffers, descriptors and push constants work.
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Input { float inputs[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Output { float outputs[]; };
layout(push_constant) uniform Push { uint count; uint offset; float value; } push;
void main() {
    uint i = gl_GlobalInvocationID.x + push.offset;
    if (i < push.count) outputs[i] = inputs[i] + push.value;
}
