#version 460
// The primary-hits raster pass, fragment stage: the exact hit of this grid sample's camera ray with the triangle the
// rasteriser found there, by the test a BVH traversal runs (bvhTriangleHit), so that a rasterised record equals the
// traced one bit for bit where both find the same triangle. The depth is 1 / (1 + t) (greater wins, cleared to 0):
// the closest exact t wins, with float's relative precision at every distance. A sample the exact test misses
// (rounding on an edge) is marked kPrimaryTrace, at the depth of the triangle's plane, and is traced by the reader.
#extension GL_GOOGLE_include_directive : require
#include "primary_view.glsl"

// The triangle (primary.vert.glsl): the BvhTriangle's fields, bit for bit.
layout(location = 0) flat in vec3 triangleV0;
layout(location = 1) flat in vec3 triangleE1;
layout(location = 2) flat in vec3 triangleE2;
layout(location = 3) flat in uint triangleId;
layout(location = 0) out vec4 record;

void main() {
    const int S = push.samplesPerSide;
    const ivec2 texel = ivec2(gl_FragCoord.xy);
    const int px = texel.x / S, py = texel.y / S;
    vec2 point = primarySamplePoint(S, px, py, texel.x - px * S, texel.y - py * S);
    vec3 origin, dir;
    cameraRay(push.camera, point.x, point.y, origin, dir);
    BvhTriangle tri;
    tri.v0 = triangleV0;
    tri.id = triangleId;
    tri.e1 = triangleE1;
    tri.pad1 = 0.0;
    tri.e2 = triangleE2;
    tri.pad2 = 0.0;
    float t;
    vec2 uv;
    if (bvhTriangleHit(tri, origin, dir, 0.0, kInfinity, t, uv)) {
        record = vec4(t, float(tri.id), uv);
        gl_FragDepth = 1.0 / (1.0 + t);
        return;
    }
    // The plane's t along the ray (Moeller-Trumbore's t without the edge tests); 1 (nearest) when the ray is in the
    // plane, so that the sample is traced rather than shown wrong.
    vec3 p = cross(dir, tri.e2);
    float det = dot(tri.e1, p);
    float plane = det != 0.0 ? dot(tri.e2, cross(origin - tri.v0, tri.e1)) / det : 0.0;
    record = vec4(kPrimaryTrace, float(tri.id), 0.0, 0.0);
    gl_FragDepth = plane > 0.0 ? 1.0 / (1.0 + plane) : 1.0;
}
