#version 460
// ISV's volumetric shadow map: the slabs' optical depths summed front to back into slices (slice 0 is zero), per texel
// and per channel (one, or RGBA texels for coloured shadows).
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Slabs { float slabs[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Slices { float slices[]; };

layout(push_constant) uniform Push {
    uint texels;  // per slice
    uint slices;
    uint channels;  // floats per texel: 1, or 4 for RGB optical depth
} push;

void main() {
    uint texel = gl_GlobalInvocationID.x;
    if (texel >= push.texels) return;
    uint plane = push.texels * push.channels;  // floats per slice
    for (uint c = 0; c < push.channels; ++c) {
        uint i = texel * push.channels + c;
        float sum = 0.0f;
        slices[i] = 0.0f;
        for (uint s = 1; s < push.slices; ++s) {
            sum += slabs[(s - 1) * plane + i];
            slices[s * plane + i] = sum;
        }
    }
}
