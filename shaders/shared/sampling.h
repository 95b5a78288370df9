// Sampling routines shared by GLSL and C++. Each returns its pdf alongside, and each has a chi-square test
// (renderers/test/test_sampling.cpp).
#ifndef TY_SHARED_SAMPLING_H
#define TY_SHARED_SAMPLING_H

#include "compat.h"
#include "constants.h"

TY_BEGIN

// An orthonormal basis around a unit vector n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
TY_FUNC void buildFrame(TY_IN(vec3) n, TY_OUT(vec3) t, TY_OUT(vec3) b) {
    float s = n.z >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// A direction at cosine mu from axis w, at azimuth phi = 2 pi u.
TY_FUNC vec3 directionAround(TY_IN(vec3) w, float mu, float u) {
    vec3 t, b;
    buildFrame(w, t, b);
    float sinTheta = sqrt(max(0.0f, 1.0f - mu * mu));
    float phi = kTwoPi * u;
    return normalize(sinTheta * cos(phi) * t + sinTheta * sin(phi) * b + mu * w);
}

TY_FUNC vec3 sampleUniformSphere(TY_IN(vec2) u) {
    float z = 1.0f - 2.0f * u.x;
    float r = sqrt(max(0.0f, 1.0f - z * z));
    float phi = kTwoPi * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// Cosine-weighted hemisphere about +z; pdf = cos(theta) / pi.
TY_FUNC vec3 sampleCosineHemisphere(TY_IN(vec2) u) {
    float r = sqrt(u.x);
    float phi = kTwoPi * u.y;
    return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0f, 1.0f - u.x)));
}

// ---------------------------------------------------------------------------------------------------------------------
// Equiangular sampling along a ray (Kulla & Fajardo 2012): t in [ta, tb] with pdf proportional to 1 / (h^2 + (t-t0)^2),
// where t0 is the ray parameter closest to the light and h the light's distance from the ray. tb may be kInfinity.
struct Equiangular {
    float t0;      // ray parameter of the foot of the perpendicular from the light
    float h;       // distance from the light to the ray, > 0
    float thetaA;  // angles seen from the light, relative to the perpendicular
    float thetaB;
};

// With `softening2` = s^2 > 0 the density is proportional to 1 / (h^2 + s^2 + (t - t0)^2) instead: the inverse
// square of the distance to a light of size ~s, which stays bounded near it (an area light's solid angle does).
TY_FUNC Equiangular equiangularSetupSoftened(TY_IN(vec3) origin, TY_IN(vec3) dir, TY_IN(vec3) light, float ta, float tb,
                                             float softening2) {
    // atan of a far end rounds to float(pi/2) = 1.5707964, which lies above pi/2: its tangent is -2.3e7, and samples
    // near that end would land far outside [ta, tb]. Keep both angles strictly inside (-pi/2, pi/2).
    const float kBelowHalfPi = 1.57079625f;  // the largest float below pi/2
    Equiangular e;
    e.t0 = dot(light - origin, dir);
    vec3 perpendicular = origin + e.t0 * dir - light;
    e.h = max(sqrt(dot(perpendicular, perpendicular) + softening2), 1e-7f);
    e.thetaA = clamp(atan(ta - e.t0, e.h), -kBelowHalfPi, kBelowHalfPi);
    e.thetaB = tb >= kInfinity ? kBelowHalfPi : clamp(atan(tb - e.t0, e.h), -kBelowHalfPi, kBelowHalfPi);
    return e;
}

TY_FUNC Equiangular equiangularSetup(TY_IN(vec3) origin, TY_IN(vec3) dir, TY_IN(vec3) light, float ta, float tb) {
    return equiangularSetupSoftened(origin, dir, light, ta, tb, 0.0f);
}

TY_FUNC float equiangularSample(TY_IN(Equiangular) e, float u, TY_OUT(float) pdf) {
    float theta = mix(e.thetaA, e.thetaB, u);
    float d = e.h * tan(theta);
    pdf = e.h / ((e.thetaB - e.thetaA) * (e.h * e.h + d * d));
    return e.t0 + d;
}

TY_FUNC float equiangularPdf(TY_IN(Equiangular) e, float t) {
    float d = t - e.t0;
    return e.h / ((e.thetaB - e.thetaA) * (e.h * e.h + d * d));
}

// ---------------------------------------------------------------------------------------------------------------------
// Uniform sampling of the solid angle of a spherical triangle (Arvo 1995, "Stratified Sampling of Spherical
// Triangles"). A, B, C are unit directions from the shading point. Returns the direction; `solidAngle` receives the
// triangle's solid angle (the pdf is its reciprocal).

TY_FUNC float sphericalTriangleSolidAngle(TY_IN(vec3) a, TY_IN(vec3) b, TY_IN(vec3) c) {
    // Van Oosterom & Strackee: tan(Omega / 2) = |a.(b x c)| / (1 + a.b + b.c + c.a)
    float numerator = abs(dot(a, cross(b, c)));
    float denominator = 1.0f + dot(a, b) + dot(b, c) + dot(c, a);
    return 2.0f * atan(numerator, denominator);
}

// The unit vector in the plane of (x, y) orthogonal to y, pointing towards x.
TY_FUNC vec3 orthonormalComponent(TY_IN(vec3) x, TY_IN(vec3) y) {
    vec3 v = x - dot(x, y) * y;
    float l2 = dot(v, v);
    return l2 > 0.0f ? v * inversesqrt(l2) : vec3(0.0f);
}

TY_FUNC vec3 sampleSphericalTriangle(TY_IN(vec3) A, TY_IN(vec3) B, TY_IN(vec3) C, TY_IN(vec2) u, TY_OUT(float) solidAngle) {
    // Interior angles at the vertices, from the normals of the great circles through each edge.
    vec3 nAB = normalize(cross(A, B));
    vec3 nBC = normalize(cross(B, C));
    vec3 nCA = normalize(cross(C, A));
    float alpha = acos(clamp(-dot(nCA, nAB), -1.0f, 1.0f));
    float beta = acos(clamp(-dot(nAB, nBC), -1.0f, 1.0f));
    float gamma = acos(clamp(-dot(nBC, nCA), -1.0f, 1.0f));
    float area = alpha + beta + gamma - kPi;
    solidAngle = area;
    if (area <= 1e-7f) {
        // Degenerate: return a point by barycentric interpolation (the caller's pdf is then meaningless; it skips it).
        return normalize(A + B + C);
    }
    // Choose the sub-triangle area, then the vertex C' on edge AC that realises it.
    float areaHat = u.x * area;
    float s = sin(areaHat - alpha);
    float t = cos(areaHat - alpha);
    float cosAlpha = cos(alpha), sinAlpha = sin(alpha);
    float cosC = dot(A, B);
    float uu = t - cosAlpha;
    float vv = s + sinAlpha * cosC;
    float q = clamp(((vv * t - uu * s) * cosAlpha - vv) / ((vv * s + uu * t) * sinAlpha), -1.0f, 1.0f);
    vec3 cHat = q * A + sqrt(max(0.0f, 1.0f - q * q)) * orthonormalComponent(C, A);
    // Then the point on the arc from B to C' with the right cosine.
    float z = 1.0f - u.y * (1.0f - dot(cHat, B));
    return normalize(z * B + sqrt(max(0.0f, 1.0f - z * z)) * orthonormalComponent(cHat, B));
}

// ---------------------------------------------------------------------------------------------------------------------
// Exponential free-flight distances, pdf sigma exp(-sigma t).
TY_FUNC float sampleExponential(float sigma, float u) { return -log(1.0f - u) / sigma; }

// Balance heuristic weight of technique a among a and b (one sample each).
TY_FUNC float balanceHeuristic(float pdfA, float pdfB) {
    float sum = pdfA + pdfB;
    return sum > 0.0f ? pdfA / sum : 0.0f;
}

TY_END

#endif  // TY_SHARED_SAMPLING_H
