#version 450
// The studio's viewport: shows the frame the GUI thread composed, one 8-bit sRGB RGBA texel per pixel, from a storage
// buffer the size of the swapchain image (no texture, no sampler: the frame is already at the window's resolution).
layout(std430, set = 0, binding = 0) readonly buffer Frame { uint texels[]; };
layout(push_constant) uniform Push {
    uint width;
    uint height;
} push;
// True when the swapchain encodes sRGB itself, so the frame's sRGB values are decoded first. A constant, so that the
// usual UNORM target compiles without the decode (a software rasterizer pays for code in untaken branches too).
layout(constant_id = 0) const bool kSrgbTarget = false;
layout(location = 0) out vec4 colour;

float decode(float c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    if (p.x >= push.width || p.y >= push.height) {
        colour = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec4 c = unpackUnorm4x8(texels[p.y * push.width + p.x]);
    if (kSrgbTarget) c.rgb = vec3(decode(c.r), decode(c.g), decode(c.b));
    colour = vec4(c.rgb, 1.0);
}
