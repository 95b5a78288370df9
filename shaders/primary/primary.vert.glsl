#version 460
// The primary-hits raster pass, vertex stage: vertex gl_VertexIndex % 3 of BVH triangle gl_VertexIndex / 3, projected
// by the pinhole of shared/camera.h (cameraPixel) onto the grid, which spans the image exactly: NDC x = -1 is the
// image's left edge, y = -1 its top row. Clip z is 0: nothing is clipped in depth except behind the camera plane
// (w <= 0); the fragment stage writes the depth that decides which triangle is closest.
#extension GL_GOOGLE_include_directive : require
#include "primary_view.glsl"

// The triangle itself travels to the fragment stage as flat varyings: read here once per vertex, not once per fragment
// (a storage-buffer read at a per-fragment index is a gather, lane by lane, on lavapipe: 2.8 of a 10 ms pass).
layout(location = 0) flat out vec3 triangleV0;
layout(location = 1) flat out vec3 triangleE1;
layout(location = 2) flat out vec3 triangleE2;
layout(location = 3) flat out uint triangleId;

void main() {
    const uint index = uint(gl_VertexIndex) / 3u, corner = uint(gl_VertexIndex) % 3u;
    BvhTriangle tri = bvhTriangle(int(index));
    vec3 p = tri.v0 + (corner == 1u ? tri.e1 : vec3(0.0)) + (corner == 2u ? tri.e2 : vec3(0.0));
    CameraParams cam = push.camera;
    vec3 d = p - cam.position;
    float w = dot(d, cam.forward);
    float x = dot(d, cam.right) / (cam.tanHalfFovY * cam.aspect);
    float y = -dot(d, cam.up) / cam.tanHalfFovY;
    gl_Position = vec4(x, y, 0.0, w);
    triangleV0 = tri.v0;
    triangleE1 = tri.e1;
    triangleE2 = tri.e2;
    triangleId = tri.id;
}
