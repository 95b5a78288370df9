// The pinhole camera shared by every renderer: pixel coordinates to a camera ray, in GLSL and C++.
// Pixel (0, 0) is the top-left corner of the image; pixel centres sit at half-integer coordinates; y grows downwards.
// The vertical field of view spans the image height (docs/conventions.md).
#ifndef TY_SHARED_CAMERA_H
#define TY_SHARED_CAMERA_H

#include "compat.h"

TY_BEGIN

// std430 layout: vec3 + float pairs, 64 bytes.
struct CameraParams {
    vec3 position;
    float tanHalfFovY;  // tan(fovY / 2)
    vec3 forward;       // unit, towards the target
    float aspect;       // width / height
    vec3 right;         // unit, forward x up
    float width;        // pixels
    vec3 up;            // unit, right x forward
    float height;       // pixels
};

// The ray through the image point (px, py) in pixel coordinates.
TY_FUNC void cameraRay(TY_IN(CameraParams) cam, float px, float py, TY_OUT(vec3) origin, TY_OUT(vec3) dir) {
    float x = (2.0f * px / cam.width - 1.0f) * cam.tanHalfFovY * cam.aspect;
    float y = (1.0f - 2.0f * py / cam.height) * cam.tanHalfFovY;
    origin = cam.position;
    dir = normalize(cam.forward + x * cam.right + y * cam.up);
}

// The image point (pixels) that the world point p projects to, the inverse of cameraRay; `depth` is p's distance
// along `forward` (<= 0: beside or behind the camera, where the point means nothing).
TY_FUNC vec2 cameraPixel(TY_IN(CameraParams) cam, vec3 p, TY_OUT(float) depth) {
    vec3 d = p - cam.position;
    depth = dot(d, cam.forward);
    float x = dot(d, cam.right) / (depth * cam.tanHalfFovY * cam.aspect);
    float y = dot(d, cam.up) / (depth * cam.tanHalfFovY);
    return vec2(0.5f * (x + 1.0f) * cam.width, 0.5f * (1.0f - y) * cam.height);
}

TY_END

#endif  // TY_SHARED_CAMERA_H
