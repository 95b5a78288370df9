#version 460
// ISV's volumetric shadow map: the slabs' optical depths summed front to back into slices (slice 0 is zero).
// Each float sums on its own, so an RGBA map sums per channel.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Slabs { float slabs[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Slices { float slices[]; };

layout(push_constant) uniform Push {
    uint texels;  // floats per slice: texels times their channels (1, or 4 for RGB optical depth)
    uint slices;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.texels) return;
    float sum = 0.0f;
    slices[i] = 0.0f;
    for (uint s = 1; s < push.slices; ++s) {
        sum += slabs[(s - 1) * push.texels + i];
        slices[s * push.texels + i] = sum;
    }
}
