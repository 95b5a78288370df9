// Volume-RIS: resampled importance sampling of single scattering from polygonal area lights in a homogeneous medium
// (Lin, Wyman and Yuksel 2021, "Fast Volume Rendering with Spatiotemporal Reservoir Resampling", without its spatial
// and temporal reuse, as the LTSD paper (000) uses it for its baseline). Shared by the compute shader
// (shaders/volume_ris/volume_ris.comp.glsl) and the CPU path (renderers/volume_ris/); derivation in docs/volume-ris.md.
//
// Per camera sample: the camera ray to its first surface; M candidates (t, y) of a distance t along the ray inside the
// medium and a point y on a light, from cheap source pdfs p(t, y); the target p_hat(t, y) = mean over RGB of the
// unshadowed contribution T(o, x) sigma_s p(mu) L_e T(x, y) G(x, y) (x = o + t d); one candidate chosen by weighted
// reservoir sampling with weights w_i = p_hat_i / p_i; ONE shadow ray for it; the estimate
// f(y) V(y) W with W = (1 / p_hat(y)) (1 / M) sum_i w_i. At the surface hit, the same with candidate light points only.
//
// The includer defines, after including this header:
//   vec4 risPlane(int i);       the medium's half-spaces dot(n, x) <= w as (n, w), n of unit length
//   RisLight risLight(int i);   vec4 risVertex(int i);
//   SurfaceTriangle risTriangle(int id);   MaterialParams risMaterial(int i);
// and bvhNode / bvhTriangle for bvh.h.
//
// Compile-time variants (each optional; without it the frame's value is used):
//   TY_RIS_LIGHTS n       exactly n lights                  TY_RIS_MEDIUM k    kRisMedium* of the medium
//   TY_RIS_PLANES n       exactly n medium planes           TY_RIS_GREY        grey extinction
//   TY_RIS_DISTANCE k     kRisTransmittance / kRisEquiangular
//   TY_RIS_LIGHT_SAMPLING k   kRisSolidAngle / kRisArea
//   TY_RIS_VERTICES n     no light has more than n vertices: the fan walk runs n - 2 times, not kRisMaxVertices - 2
//   TY_RIS_NO_SURFACES    the scene has no triangles (no camera hits, no shadow rays)
#ifndef TY_SHARED_VOLUME_RIS_H
#define TY_SHARED_VOLUME_RIS_H

#include "bvh.h"
#include "camera.h"
#include "compat.h"
#include "constants.h"
#include "phase.h"
#include "rng.h"
#include "sampling.h"
#include "surface.h"

TY_BEGIN

TY_CONST int kRisMaxLights = 16;
TY_CONST int kRisMaxPlanes = 32;
TY_CONST int kRisMaxVertices = 64;  // per light
TY_CONST int kRisMaxCandidates = 1024;

TY_CONST int kRisMediumNone = 0;
TY_CONST int kRisMediumInfinite = 1;
TY_CONST int kRisMediumPlanes = 2;  // a box or a convex polyhedron, as half-spaces

TY_CONST int kRisTransmittance = 0;  // t with density proportional to the camera transmittance on the segment
TY_CONST int kRisEquiangular = 1;    // t equiangular about the chosen light (Kulla and Fajardo 2012)

TY_CONST int kRisSolidAngle = 0;  // the light point uniform in the polygon's solid angle seen from the shading point
TY_CONST int kRisArea = 1;        // the light point uniform on the polygon's area

// A convex planar polygon light, 64 bytes (std430). Its vertices are risVertex(vertexFirst + k), k < vertexCount, as
// (position, w): w of vertex k >= 2 is the cumulative area fraction of the fan triangles (v0, v1, v2) .. (v0, v_k-1,
// v_k); w of vertices 0 and 1 is 0.
struct RisLight {
    vec3 normal;  // unit, right-hand rule: the front side
    int vertexFirst;
    vec3 radiance;  // W/(m^2 sr)
    int vertexCount;
    float area;         // m^2
    float selectStart;  // the selection cdf before this light (lights are chosen by power)
    float selectPdf;    // the probability with which it is chosen
    int twoSided;
    vec3 centre;  // the vertices' mean: what equiangular sampling aims at
    float pad0;
};

// Everything else a frame needs, 276 bytes (the phase parameters have 4-byte members only).
struct RisFrame {
    CameraParams camera;
    vec3 sigmaS;  // 1/m
    int mediumKind;
    vec3 sigmaT;        // 1/m
    float sigmaSample;  // 1/m, the extinction the distance sampler uses (the channels' mean)
    int planeCount;
    int lightCount;
    int candidates;        // M
    int distanceSampling;  // kRisTransmittance or kRisEquiangular
    float rayOffset;       // m, offset of shadow rays leaving surfaces
    uint seed;
    int shadows;        // 1: the chosen candidate's visibility by a shadow ray; 0: the unshadowed image
    int lightSampling;  // kRisSolidAngle or kRisArea
    PhaseParams phase;
};

// What one camera sample adds to its pixel: the medium's single scattering and the surface's direct light, apart so
// that a denoiser can filter them separately (as the LTSD paper does for Volume-RIS, Sec. 8).
struct RisTerms {
    vec3 medium;
    vec3 surface;
};

// Supplied by the includer (see the top of the file).
vec4 risPlane(int i);
RisLight risLight(int i);
vec4 risVertex(int i);
SurfaceTriangle risTriangle(int id);
MaterialParams risMaterial(int i);

// Constant loop bounds, exact where the shader knows them (lavapipe runs a loop's body for lanes that skip it).
#ifdef TY_RIS_VERTICES
TY_CONST int kRisVertexLoop = TY_RIS_VERTICES;
#else
TY_CONST int kRisVertexLoop = kRisMaxVertices;
#endif
#ifdef TY_RIS_LIGHTS
TY_CONST int kRisLightLoop = TY_RIS_LIGHTS;
#else
TY_CONST int kRisLightLoop = kRisMaxLights;
#endif

TY_FUNC int risMediumKind(TY_IN(RisFrame) f) {
#ifdef TY_RIS_MEDIUM
    return TY_RIS_MEDIUM;
#else
    return f.mediumKind;
#endif
}

TY_FUNC int risPlaneCount(TY_IN(RisFrame) f) {
#ifdef TY_RIS_PLANES
    return TY_RIS_PLANES;
#else
    return f.planeCount;
#endif
}

TY_FUNC int risDistanceSampling(TY_IN(RisFrame) f) {
#ifdef TY_RIS_DISTANCE
    return TY_RIS_DISTANCE;
#else
    return f.distanceSampling;
#endif
}

TY_FUNC int risLightSampling(TY_IN(RisFrame) f) {
#ifdef TY_RIS_LIGHT_SAMPLING
    return TY_RIS_LIGHT_SAMPLING;
#else
    return f.lightSampling;
#endif
}

TY_FUNC float risMean(TY_IN(vec3) v) {
    return (v.x + v.y + v.z) * (1.0f / 3.0f);
}

// Transmittance over a length in the medium, per channel.
TY_FUNC vec3 risTransmittance(TY_IN(RisFrame) f, float length) {
#ifdef TY_RIS_GREY
    return vec3(exp(-f.sigmaT.x * length));
#else
    return exp(-f.sigmaT * length);
#endif
}

// Clips [a, b] of the ray o + t d to the medium; false when nothing is left. An infinite medium keeps all of it.
TY_FUNC bool risClip(TY_IN(RisFrame) f, TY_IN(vec3) o, TY_IN(vec3) d, TY_INOUT(float) a, TY_INOUT(float) b) {
    int kind = risMediumKind(f);
    if (kind == kRisMediumNone) return false;
    if (kind == kRisMediumPlanes) {
        for (int i = 0; i < risPlaneCount(f); ++i) {
            vec4 plane = risPlane(i);
            vec3 n = vec3(plane);
            float nd = dot(n, d);
            float room = plane.w - dot(n, o);  // inside where t nd <= room
            if (nd > 0.0f)
                b = min(b, room / nd);
            else if (nd < 0.0f)
                a = max(a, room / nd);
            else if (room < 0.0f)
                b = a;
        }
    }
    return a < b;
}

// The length of the segment from x along the unit direction l over distance r that lies inside the medium.
TY_FUNC float risLengthInMedium(TY_IN(RisFrame) f, TY_IN(vec3) x, TY_IN(vec3) l, float r) {
    float a = 0.0f, b = r;
    return risClip(f, x, l, a, b) ? b - a : 0.0f;
}

// Distance sampling on [a, b] (b may be kInfinity) with density proportional to e^{-sigma (t - a)}, by inversion.
// Where sigma (b - a) < 1e-4 the segment is sampled uniformly instead (a sampler of its own, with its own pdf). Returns
// t; pdf 0 when nothing can be sampled (an infinite segment without extinction).
TY_FUNC float risDistanceSample(float sigma, float a, float b, float u, TY_OUT(float) pdf) {
    float len = b - a;
    bool finite = len < kInfinity;
    if (!(sigma * len >= 1e-4f)) {
        pdf = finite && len > 0.0f ? 1.0f / len : 0.0f;
        return a + u * (finite ? len : 0.0f);
    }
    float norm = finite ? 1.0f - exp(-sigma * len) : 1.0f;
    float s = -log(1.0f - u * norm) / sigma;
    s = finite ? min(s, len) : s;
    pdf = sigma * exp(-sigma * s) / norm;
    return a + s;
}

// The pdf of risDistanceSample at t.
TY_FUNC float risDistancePdf(float sigma, float a, float b, float t) {
    if (t < a || t > b) return 0.0f;
    float len = b - a;
    bool finite = len < kInfinity;
    if (!(sigma * len >= 1e-4f)) return finite && len > 0.0f ? 1.0f / len : 0.0f;
    float norm = finite ? 1.0f - exp(-sigma * len) : 1.0f;
    return sigma * exp(-sigma * (t - a)) / norm;
}

// Chooses a light by power from u in [0, 1): returns its index (-1 when none can be chosen); `rest` receives u
// rescaled to [0, 1) within the light's share, for the next choice.
TY_FUNC int risChooseLight(TY_IN(RisFrame) f, float u, TY_OUT(float) rest) {
    int light = -1;
    // Breaks (not continues) past the counts: on the CPU the constant bounds are the maxima.
    for (int i = 0; i < kRisLightLoop; ++i) {
        if (i >= f.lightCount) break;
        RisLight candidate = risLight(i);
        if (candidate.selectPdf > 0.0f && (light < 0 || u >= candidate.selectStart)) light = i;
    }
    rest = 0.0f;
    if (light < 0) return light;
    RisLight l = risLight(light);
    rest = clamp((u - l.selectStart) / l.selectPdf, 0.0f, kOneMinusEpsilon);
    return light;
}

// A point uniform on light l's area from v (the fan triangle, by area) and u (the point in it). Returns the point;
// `pdfArea` receives 1 / area.
TY_FUNC vec3 risSampleArea(TY_IN(RisLight) l, float v, TY_IN(vec2) u, TY_OUT(float) pdfArea) {
    vec3 p0 = vec3(risVertex(l.vertexFirst));
    vec4 p1 = risVertex(l.vertexFirst + 1), p2 = risVertex(l.vertexFirst + 2);
    bool found = false;
    for (int k = 2; k < kRisVertexLoop; ++k) {
        if (found || k >= l.vertexCount) break;
        vec4 q = risVertex(l.vertexFirst + k);
        if (v < q.w || k == l.vertexCount - 1) {
            found = true;
            p2 = q;
        } else {
            p1 = q;
        }
    }
    // Uniform on the triangle (p0, p1, p2).
    float s = sqrt(u.x);
    pdfArea = 1.0f / l.area;
    return p0 * (1.0f - s) + vec3(p1) * (s * (1.0f - u.y)) + vec3(p2) * (s * u.y);
}

// A point on light l uniform in the solid angle its polygon subtends at x: the fan triangles' spherical triangles, one
// chosen by solid angle with v, then Arvo's sampler (sampling.h) with u, as the reference samples area lights. Returns
// the point; `pdfArea` receives the density in area measure, |cos theta_y| / (r^2 Omega); 0 when x sees the polygon
// from behind (one-sided), in its plane, or under a solid angle below 1e-9 sr (the reference's cut).
TY_FUNC vec3 risSampleSolidAngle(TY_IN(RisLight) l, TY_IN(vec3) x, float v, TY_IN(vec2) u, TY_OUT(float) pdfArea) {
    pdfArea = 0.0f;
    vec3 v0 = vec3(risVertex(l.vertexFirst));
    float side = dot(x - v0, l.normal);
    if (side == 0.0f || (l.twoSided == 0 && side < 0.0f)) return v0;
    // The directions to the vertices and the fan's solid angles, once (arrays with a constant bound: registers on the
    // GPU where TY_RIS_VERTICES is small).
    vec3 dirs[kRisVertexLoop];
    float omegas[kRisVertexLoop];
    vec3 a = normalize(v0 - x);
    dirs[0] = a;
    omegas[0] = 0.0f;
    omegas[1] = 0.0f;
    float total = 0.0f;
    for (int k = 1; k < kRisVertexLoop; ++k) {
        if (k >= l.vertexCount) break;
        dirs[k] = normalize(vec3(risVertex(l.vertexFirst + k)) - x);
        omegas[k] = k >= 2 ? sphericalTriangleSolidAngle(a, dirs[k - 1], dirs[k]) : 0.0f;
        total += omegas[k];
    }
    if (!(total > 1e-9f)) return v0;
    // The triangle whose share of the total holds v.
    float target = v * total, below = 0.0f;
    vec3 cb = a, cc = a;
    bool found = false;
    for (int k = 2; k < kRisVertexLoop; ++k) {
        if (found || k >= l.vertexCount) break;
        if (target < below + omegas[k] || k == l.vertexCount - 1) {
            found = true;
            cb = dirs[k - 1];
            cc = dirs[k];
        } else {
            below += omegas[k];
        }
    }
    float omega;
    vec3 dir = sampleSphericalTriangle(a, cb, cc, u, omega);
    if (!(omega > 1e-7f)) return v0;  // a degenerate sliver: no usable direction
    float cosLight = dot(dir, l.normal);
    if (cosLight == 0.0f) return v0;
    float r = -side / cosLight;
    if (!(r > 0.0f)) return v0;
    pdfArea = abs(cosLight) / (r * r * total);
    return x + r * dir;
}

// A point on a light for the shading point x: the light by power (u.x), then by the frame's light sampling (the rest
// of u.x and u.yz). Returns the point; `light` receives the light, `pdfArea` the density in area measure (0 when none).
TY_FUNC vec3 risSampleLightPoint(TY_IN(RisFrame) f, TY_IN(vec3) x, TY_IN(vec3) u, TY_OUT(int) light,
                                 TY_OUT(float) pdfArea) {
    float v;
    light = risChooseLight(f, u.x, v);
    pdfArea = 0.0f;
    if (light < 0) return vec3(0.0f);
    RisLight l = risLight(light);
    float pdf;
    vec3 y = risLightSampling(f) == kRisArea ? risSampleArea(l, v, vec2(u.y, u.z), pdf)
                                             : risSampleSolidAngle(l, x, v, vec2(u.y, u.z), pdf);
    pdfArea = l.selectPdf * pdf;
    return y;
}

// Light emitted by light `i` from its point y towards x, times the geometry term |cos_y| / r^2: zero behind a one-sided
// light and in its plane. `l` receives the unit direction from x to y and `r` the distance.
TY_FUNC vec3 risEmission(TY_IN(RisLight) light, TY_IN(vec3) y, TY_IN(vec3) x, TY_OUT(vec3) l, TY_OUT(float) r) {
    vec3 toY = y - x;
    float r2 = dot(toY, toY);
    r = sqrt(r2);
    l = r > 0.0f ? toY / r : vec3(0.0f, 0.0f, 1.0f);
    float side = -dot(light.normal, toY);  // > 0 on the front side
    if (!(r2 > 0.0f) || side == 0.0f || (light.twoSided == 0 && side < 0.0f)) return vec3(0.0f);
    return light.radiance * (abs(side) / (r2 * r));
}

// True when a triangle blocks the way from x towards l over distance r (the last 1e-4 of it spared, as the other
// techniques do, so that a light lying on a surface is not shadowed by it).
TY_FUNC bool risOccluded(TY_IN(RisFrame) f, TY_IN(vec3) x, TY_IN(vec3) l, float r) {
    if (f.shadows == 0) return false;
#ifdef TY_RIS_NO_SURFACES
    return false;
#else
    return bvhOccluded(x, l, 0.0f, r * (1.0f - 1e-4f));
#endif
}

// One medium candidate for the camera ray o + t d whose medium part is [a, b] (entered at tIn) from u in [0, 1)^4:
// returns the unshadowed contribution f(t, y); `pdf` receives p(t, y) in the measure dt dA(y), `x`, `l`, `r` the
// scattering point, the direction and the distance to the light point. The light is chosen first (u.x); then t
// (u.w: transmittance-proportional, or equiangular about the light's centre); then y seen from x (u.yz).
TY_FUNC vec3 risMediumCandidate(TY_IN(RisFrame) f, TY_IN(vec3) o, TY_IN(vec3) d, float tIn, float a, float b,
                                TY_IN(vec4) u, TY_OUT(float) pdf, TY_OUT(vec3) x, TY_OUT(vec3) l, TY_OUT(float) r) {
    pdf = 0.0f;
    x = o;
    l = vec3(0.0f, 0.0f, 1.0f);
    r = 0.0f;
    float v;
    int light = risChooseLight(f, u.x, v);
    if (light < 0) return vec3(0.0f);
    RisLight lt = risLight(light);
    float t, pdfT;
    if (risDistanceSampling(f) == kRisEquiangular) {
        Equiangular e = equiangularSetup(o, d, lt.centre, a, b);
        t = clamp(equiangularSample(e, u.w, pdfT), a, b);
    } else {
        t = risDistanceSample(f.sigmaSample, a, b, u.w, pdfT);
    }
    if (!(pdfT > 0.0f)) return vec3(0.0f);
    x = o + t * d;
    float pdfY;
    vec3 y = risLightSampling(f) == kRisArea ? risSampleArea(lt, v, vec2(u.y, u.z), pdfY)
                                             : risSampleSolidAngle(lt, x, v, vec2(u.y, u.z), pdfY);
    if (!(pdfY > 0.0f)) return vec3(0.0f);
    pdf = lt.selectPdf * pdfY * pdfT;
    vec3 emitted = risEmission(lt, y, x, l, r);
    if (emitted == vec3(0.0f)) return vec3(0.0f);
    vec3 cameraT = risTransmittance(f, t - tIn);
    vec3 lightT = risTransmittance(f, risLengthInMedium(f, x, l, r));
    return cameraT * f.sigmaS * (phaseEval(f.phase, dot(d, l)) * emitted) * lightT;
}

// Camera sample `index` of pixel (px, py); it belongs to the half index & 1 of the pixel's samples.
TY_FUNC RisTerms risSample(TY_IN(RisFrame) f, int px, int py, uint index) {
    // Even and odd camera samples come from two independently scrambled sequences, so that the two halves of a pixel's
    // samples are independent and their difference estimates the variance (as in the reference).
    uint pixelSeed = hashCombine(hashCombine(hashCombine(f.seed, uint(px)), uint(py)), index & 1u);
    uint sequenceIndex = index >> 1u;
    vec2 jitter = sobolSample2D(pixelSeed, sequenceIndex, 0u);
    Pcg32 rng = pcg32Seed(pixelSeed, sequenceIndex);
    vec3 o, d;
    cameraRay(f.camera, float(px) + jitter.x, float(py) + jitter.y, o, d);
#ifdef TY_RIS_NO_SURFACES
    bool hasHit = false;
    float tEnd = kInfinity;
#else
    BvhHit hit;
    bool hasHit = bvhIntersect(o, d, 0.0f, kInfinity, hit);
    float tEnd = hasHit ? hit.t : kInfinity;
#endif
    int M = clamp(f.candidates, 1, kRisMaxCandidates);
    RisTerms result;
    result.medium = vec3(0.0f);
    result.surface = vec3(0.0f);

    // The medium: [tIn, tOut] of the ray inside it, and the part in front of the surface.
    float tIn = 0.0f, tOut = kInfinity;
    bool inMedium = risClip(f, o, d, tIn, tOut);
    float b = min(tOut, tEnd);
    if (inMedium && tIn < b && f.lightCount > 0) {
        float wSum = 0.0f, chosenTarget = 0.0f, chosenR = 0.0f;
        vec3 chosenF = vec3(0.0f), chosenX = o, chosenL = vec3(0.0f, 0.0f, 1.0f);
        for (int i = 0; i < M; ++i) {
            vec4 u;
            u.x = pcg32NextFloat(rng);
            u.y = pcg32NextFloat(rng);
            u.z = pcg32NextFloat(rng);
            u.w = pcg32NextFloat(rng);
            float pdf, r;
            vec3 x, l;
            vec3 c = risMediumCandidate(f, o, d, tIn, tIn, b, u, pdf, x, l, r);
            float target = risMean(c);
            float w = pdf > 0.0f ? target / pdf : 0.0f;
            if (!(w > 0.0f) || !(w < kInfinity)) w = 0.0f;
            wSum += w;
            // Weighted reservoir sampling: candidate i replaces the kept one with probability w_i / sum of w so far.
            if (pcg32NextFloat(rng) * wSum < w) {
                chosenTarget = target;
                chosenF = c;
                chosenX = x;
                chosenL = l;
                chosenR = r;
            }
        }
        // W = (1 / p_hat(y)) (1 / M) sum w_i; the visibility only multiplies the chosen sample.
        if (wSum > 0.0f && chosenTarget > 0.0f && !risOccluded(f, chosenX, chosenL, chosenR))
            result.medium = chosenF * (wSum / (float(M) * chosenTarget));
    }

#ifndef TY_RIS_NO_SURFACES
    // Direct light at the surface: RIS over M candidate light points, one shadow ray, attenuated by the camera
    // transmittance in front of the surface.
    if (hasHit && f.lightCount > 0) {
        SurfaceTriangle st = risTriangle(int(hit.id));
        SurfaceFrame frame = surfaceFrame(st, hit.uv, d);
        MaterialParams material = risMaterial(st.material);
        vec3 xs = o + hit.t * d;
        float wSum = 0.0f, chosenTarget = 0.0f, chosenR = 0.0f;
        vec3 chosenF = vec3(0.0f), chosenL = vec3(0.0f, 0.0f, 1.0f);
        for (int i = 0; i < M; ++i) {
            vec3 u;
            u.x = pcg32NextFloat(rng);
            u.y = pcg32NextFloat(rng);
            u.z = pcg32NextFloat(rng);
            int light;
            float pdfArea;
            vec3 y = risSampleLightPoint(f, xs, u, light, pdfArea);
            vec3 c = vec3(0.0f), l = vec3(0.0f, 0.0f, 1.0f);
            float r = 0.0f;
            if (pdfArea > 0.0f) {
                vec3 emitted = risEmission(risLight(light), y, xs, l, r);
                if (emitted != vec3(0.0f)) {
                    vec3 reflected = surfaceReflect(material, frame, -d, l);
                    if (reflected != vec3(0.0f))
                        c = emitted * reflected * risTransmittance(f, risLengthInMedium(f, xs, l, r));
                }
            }
            float target = risMean(c);
            float w = pdfArea > 0.0f ? target / pdfArea : 0.0f;
            if (!(w > 0.0f) || !(w < kInfinity)) w = 0.0f;
            wSum += w;
            if (pcg32NextFloat(rng) * wSum < w) {
                chosenTarget = target;
                chosenF = c;
                chosenL = l;
                chosenR = r;
            }
        }
        if (wSum > 0.0f && chosenTarget > 0.0f &&
            !risOccluded(f, xs + f.rayOffset * frame.ng, chosenL, chosenR)) {
            float cameraDepth = inMedium ? max(min(tOut, hit.t) - tIn, 0.0f) : 0.0f;
            result.surface = chosenF * risTransmittance(f, cameraDepth) * (wSum / (float(M) * chosenTarget));
        }
    }
#endif
    return result;
}

TY_END

#endif  // TY_SHARED_VOLUME_RIS_H
