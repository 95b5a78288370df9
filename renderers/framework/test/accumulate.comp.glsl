// The smallest accumulating kernel (tests of tyndall/framework/gpu_accumulation.h): each work item adds, to its
// pixel's accumulator of the sample's half, (pixel, sample index, 1, 0), so that the test can check that every pixel
// got every sample exactly once.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "shared/accumulation.h"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer Scale { float scale[]; };
layout(std430, set = 0, binding = 1) buffer Accumulators { vec4 acc[]; };

layout(push_constant) uniform Push {
    uint first, end, width, index, pixels, bandGroups;
} push;

void main() {
    uint item = push.first + gl_GlobalInvocationID.x;
    if (item >= push.end) return;
    uint pixel = accumulationPixel(item, push.bandGroups);
    if (pixel >= push.pixels) return;
    uint slot = pixel * 2u + (push.index & 1u);
    acc[slot] += vec4(float(pixel), float(push.index), 1.0, 0.0) * scale[0];
}
