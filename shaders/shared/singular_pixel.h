// The pixel that holds a point light's image. In a scattering medium the radiance along a camera ray that passes at a
// distance h from a point light grows like 1/h, and h is proportional to the distance r in the image from the light's
// projection p: the pixel's average is finite, but a regular grid cannot integrate it and uniform jitter has an
// infinite variance there (the second moment of 1/r over a disc diverges like log r).
//
// Both the Pegoraro technique's quadrature and the reference's Monte Carlo jitter split the pixel into the four
// triangles (p, a, b) over its edges and map each from [0, 1]^2 (docs/reference.md, "The pixel that holds a point
// light"; docs/pegoraro.md, Sec. 9):
//   x = p + s (a + t (b - a) - p)                (Duffy: the Jacobian carries s = r / |edge point - p|, cancelling 1/r)
//   t = t0 + (d / L) sinh(tau)                   (t0 the foot of the perpendicular from p, d its length, L the edge's:
//                                                 dt/dtau = |edge point - p| / L, cancelling the rest)
// so that 1/r becomes constant in (s, tau): the integral of 1/r over the triangle is d (tau_b - tau_a).
#ifndef TY_SHARED_SINGULAR_PIXEL_H
#define TY_SHARED_SINGULAR_PIXEL_H

#include "camera.h"
#include "compat.h"
#include "constants.h"

TY_BEGIN

// The image point (pixel coordinates, as cameraRay takes them) where the point at `position` projects; false when it
// is not in front of the camera.
TY_FUNC bool cameraProject(TY_IN(CameraParams) cam, TY_IN(vec3) position, TY_OUT(vec2) p) {
    vec3 v = position - cam.position;
    float z = dot(v, cam.forward);
    p = vec2(0.0f);
    if (!(z > 0.0f)) return false;
    float x = dot(v, cam.right) / (z * cam.tanHalfFovY * cam.aspect);
    float y = dot(v, cam.up) / (z * cam.tanHalfFovY);
    p = vec2((x + 1.0f) * 0.5f * cam.width, (1.0f - y) * 0.5f * cam.height);
    return true;
}

// Edge `side` (0..3) of pixel (px, py), counter-clockwise in the image's y-down coordinates: a triangle (p, a, b) with
// p inside the pixel has a positive orientation.
TY_FUNC void pixelEdge(int px, int py, int side, TY_OUT(vec2) a, TY_OUT(vec2) b) {
    vec2 corner0 = vec2(float(px), float(py));
    a = corner0 + vec2(side == 1 || side == 2 ? 1.0f : 0.0f, side >= 2 ? 1.0f : 0.0f);
    b = corner0 + vec2(side == 0 || side == 1 ? 1.0f : 0.0f, side == 1 || side == 2 ? 1.0f : 0.0f);
}

TY_FUNC float singularAsinh(float x) {
    return sign(x) * log(abs(x) + sqrt(x * x + 1.0f));
}

// The integral of 1/|x - p| over the triangle (p, a, b), signed by its orientation: d (tau_b - tau_a). Zero when p is
// on the edge's line (the triangle is empty).
TY_FUNC float singularTriangleMeasure(TY_IN(vec2) p, TY_IN(vec2) a, TY_IN(vec2) b) {
    vec2 e = b - a, pa = p - a;
    float L = length(e);
    float area2 = (a.x - p.x) * (b.y - p.y) - (a.y - p.y) * (b.x - p.x);  // twice the signed area of (p, a, b)
    float d = abs(area2) / L;
    if (!(d > 1e-6f * L)) return 0.0f;
    float t0 = dot(pa, e) / (L * L);
    float tauA = singularAsinh(-t0 * L / d), tauB = singularAsinh((1.0f - t0) * L / d);
    return (area2 < 0.0f ? -d : d) * (tauB - tauA);
}

// The point of the triangle (p, a, b) at (s, v) in [0, 1]^2 in xy, and the Jacobian dA / (ds dv) signed by the
// triangle's orientation in z (0 for an empty triangle). Over [0, 1]^2, z / |x - p| is the constant
// singularTriangleMeasure.
TY_FUNC vec3 singularTriangleMap(TY_IN(vec2) p, TY_IN(vec2) a, TY_IN(vec2) b, float s, float v) {
    vec2 e = b - a, pa = p - a;
    float L = length(e);
    float area2 = (a.x - p.x) * (b.y - p.y) - (a.y - p.y) * (b.x - p.x);
    float d = abs(area2) / L;
    if (!(d > 1e-6f * L)) return vec3(p, 0.0f);
    float t0 = dot(pa, e) / (L * L);
    float tauA = singularAsinh(-t0 * L / d), tauB = singularAsinh((1.0f - t0) * L / d);
    float tau = tauA + (tauB - tauA) * v;
    float et = exp(tau);
    float t = t0 + d / L * 0.5f * (et - 1.0f / et);
    float dtdtau = d / L * 0.5f * (et + 1.0f / et);
    vec2 x = p + s * (a + t * e - p);
    return vec3(x, (tauB - tauA) * dtdtau * s * area2);
}

// A pixel prepared for jittering about p: the signed measures of its four triangles (singularTriangleMeasure), found
// once per pixel rather than at every try.
struct SingularPixel {
    vec4 measures;  // side k in component k
    vec2 p;
    int px, py;
};

TY_FUNC SingularPixel singularPixelSetup(int px, int py, TY_IN(vec2) p) {
    SingularPixel s;
    s.p = p;
    s.px = px;
    s.py = py;
    for (int side = 0; side < 4; ++side) {
        vec2 a, b;
        pixelEdge(px, py, side, a, b);
        s.measures[side] = singularTriangleMeasure(p, a, b);
    }
    return s;
}

// The integral of 1/|x - p| over the pixel, for p anywhere: the sum of its four signed triangles.
TY_FUNC float singularPixelMeasure(TY_IN(SingularPixel) s) {
    return s.measures.x + s.measures.y + s.measures.z + s.measures.w;
}

// Whether the image point q is in the pixel (closed): the test a try's point must pass.
TY_FUNC bool singularPixelContains(TY_IN(SingularPixel) s, TY_IN(vec2) q) {
    return q.x >= float(s.px) && q.x <= float(s.px + 1) && q.y >= float(s.py) && q.y <= float(s.py + 1);
}

// One try at a point of the pixel with a density proportional to 1 / |x - p|, from u in [0, 1)^2. The triangles of
// positive orientation (all four when p is in the closed pixel; those over the edges facing away from p otherwise)
// cover the pixel and, when p is outside, the region between p and the pixel once more; a triangle is chosen in
// proportion to its measure m_k and (s, v) are the rest of u.x and u.y. Returns the point, which the caller rejects
// unless singularPixelContains it (it always does when p is inside): the accepted points have the density
// 1 / (M |x - p|) over the pixel's unit area, M = singularPixelMeasure, so f(x) M |x - p| estimates the pixel's
// box-filtered average of f without bias, and is exactly that average when f is proportional to 1 / |x - p|.
// The stratification of u carries over, piecewise.
TY_FUNC vec2 singularPixelTry(TY_IN(SingularPixel) sp, TY_IN(vec2) u) {
    vec4 m = max(sp.measures, vec4(0.0f));
    float target = u.x * (m.x + m.y + m.z + m.w), before = 0.0f;
    int chosen = -1;
    for (int side = 0; side < 4; ++side) {
        if (m[side] <= 0.0f) continue;
        chosen = side;
        if (target < before + m[side]) break;
        before += m[side];
    }
    if (chosen < 0) return vec2(float(sp.px) + u.x, float(sp.py) + u.y);  // not reached: a triangle faces away from p
    float s = min(max((target - before) / m[chosen], 0.0f), kOneMinusEpsilon);
    vec2 a, b;
    pixelEdge(sp.px, sp.py, chosen, a, b);
    vec3 x = singularTriangleMap(sp.p, a, b, s, u.y);
    return vec2(x.x, x.y);
}

TY_END

#endif  // TY_SHARED_SINGULAR_PIXEL_H
