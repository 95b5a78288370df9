#version 460
// ISV: the opaque surfaces' radiance (surfaces.comp.glsl) as the colour the particles are composited over, alpha 1.
layout(std430, set = 0, binding = 0) readonly buffer Surfaces { vec4 surfaces[]; };
layout(push_constant) uniform Push {
    int width;
} push;
layout(location = 0) out vec4 colour;

void main() {
    colour = vec4(surfaces[int(gl_FragCoord.y) * push.width + int(gl_FragCoord.x)].rgb, 1.0f);
}
