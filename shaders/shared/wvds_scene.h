// The WVDS technique's scene as the GPU sees it (std430 layouts, declared once for GLSL and C++), and the per-sample
// renderer shared by its compute shader and its CPU path: one camera ray through the pixel, the closest surface, and
// for every collimated light the medium's single scattering with the chosen estimator plus the direct light at the
// surface. Everything is float.
//
// Estimators (Sec. 3, 6 and 7 of the WVDS paper (001)); d_m is the distance to the medium's boundary towards the light,
// P(t) = t - tIn + d_m(t) the light's path length in the medium, W = sigma_s p(mu) E:
//   analytic  W Tbox: the unoccluded integral alone (no visibility; Sec. 4);
//   mcwvds    whole-volume distance sampling; e^{-sigma P}/pdf = Tbox, so each sample is W Tbox V(t) (Sec. 6);
//   reds      ratio estimator, Eq. 3: W Tbox sum(w V) / sum(w), w = e^{-sigma P(t)} / pdf(t), t by distance sampling;
//   rees      the same ratio with jittered equidistant t;
//   rm        jittered ray marching: sum of W e^{-sigma P(t)} V(t) (b - a) / N, d_m by a slab test per step;
//   mcds      distance sampling, W e^{-sigma P(t)} V(t) / pdf(t), d_m by a slab test per sample.
// The ratio estimators return their three parts per light (analytic term, numerator, denominator) so that progressive
// rendering accumulates each on its own and divides at the end, as the paper requires (Sec. 3).
//
// The includer defines, after including this header:
//   vec4 wvdsPlane(int i);               medium planes [0, planeCount), then each light's beam planes
//   WvdsLight wvdsLight(int i);          SurfaceTriangle wvdsTriangle(int id);     MaterialParams wvdsMaterial(int i);
// and bvhNode / bvhTriangle for bvh.h.
#ifndef TY_SHARED_WVDS_SCENE_H
#define TY_SHARED_WVDS_SCENE_H

#include "bvh.h"
#include "camera.h"
#include "compat.h"
#include "constants.h"
#include "phase.h"
#include "rng.h"
#include "surface.h"
#include "wvds.h"

TY_BEGIN

TY_CONST int kWvdsMaxLights = 4;
TY_CONST int kWvdsMaxGoboPlanes = 8;

TY_CONST int kWvdsAnalytic = 0;
TY_CONST int kWvdsMcwvds = 1;
TY_CONST int kWvdsReds = 2;
TY_CONST int kWvdsRees = 3;
TY_CONST int kWvdsRm = 4;
TY_CONST int kWvdsMcds = 5;

// A collimated light, 32 bytes.
struct WvdsLight {
    vec3 toLight;    // unit: from a lit point towards the light (minus the direction light travels)
    int goboFirst;   // its beam's planes among wvdsPlane: [goboFirst, goboFirst + goboCount); none without a gobo
    vec3 irradiance; // W/m^2 on a plane perpendicular to the beam, linear RGB
    int goboCount;
};

// Everything else a frame needs, 276 bytes.
struct WvdsFrame {
    CameraParams camera;
    vec3 sigmaS;  // 1/m
    int planeCount;
    vec3 sigmaT;        // 1/m
    float sigmaSample;  // 1/m, the extinction the samplers use (the channels' mean; exact for grey media)
    int lightCount;
    int estimator;       // kWvds*
    int raySamples;      // distance samples per camera ray (N_sample)
    int shadows;         // 1: visibility by shadow rays; 0: the unoccluded image
    int lightSelection;  // 1: mcwvds and mcds pick one light per sample by its unoccluded radiance; 0: every light
    float pdfScale;      // 1; other values bias the estimate by 1 / pdfScale (to check that tests can see a bias)
    float rayOffset;     // m, offset of rays leaving surfaces
    uint seed;
    PhaseParams phase;
};

// What one camera sample adds to its pixel.
struct WvdsTerms {
    vec3 direct;                        // W/(m^2 sr): surfaces, and the medium for the non-ratio estimators
    vec3 analytic[kWvdsMaxLights];      // ratio estimators: W Tbox per light
    vec3 numerator[kWvdsMaxLights];     // sum of w V
    vec3 denominator[kWvdsMaxLights];   // sum of w
};

// Supplied by the includer (see the top of the file).
WvdsLight wvdsLight(int i);
SurfaceTriangle wvdsTriangle(int id);
MaterialParams wvdsMaterial(int i);

// The estimator: a compile-time constant where the shader defines TY_WVDS_ESTIMATOR (one variant per estimator, so that
// the code and the arrays of the others are not there), else the frame's.
TY_FUNC int wvdsEstimator(TY_IN(WvdsFrame) f) {
#ifdef TY_WVDS_ESTIMATOR
    return TY_WVDS_ESTIMATOR;
#else
    return f.estimator;
#endif
}

// The loops over the lights run to the light count where the shader defines TY_WVDS_LIGHTS (one variant per count),
// else to kWvdsMaxLights with the lights beyond the frame's count skipped. Constant bounds keep the per-light arrays in
// registers, and an exact bound matters on lavapipe, which runs a loop's body for lanes that skip it: a bound of 4 cost
// the analytic frame four lights' work for one.
#ifdef TY_WVDS_LIGHTS
TY_CONST int kWvdsLightLoop = TY_WVDS_LIGHTS;
#else
TY_CONST int kWvdsLightLoop = kWvdsMaxLights;
#endif

// The medium's plane count: a compile-time constant where the shader defines TY_WVDS_PLANES (one variant per count), so
// that the slab tests over the medium unroll and read their planes at constant offsets; else the frame's.
TY_FUNC int wvdsPlaneCount(TY_IN(WvdsFrame) f) {
#ifdef TY_WVDS_PLANES
    return TY_WVDS_PLANES;
#else
    return f.planeCount;
#endif
}

TY_FUNC bool wvdsIsRatio(int estimator) {
    return estimator == kWvdsReds || estimator == kWvdsRees;
}

TY_FUNC float wvdsMean(TY_IN(vec3) v) {
    return (v.x + v.y + v.z) * (1.0f / 3.0f);
}

// The part of the camera ray [tIn, tEnd] inside light i's beam (all of it without a gobo). False when empty.
TY_FUNC bool wvdsLitInterval(TY_IN(WvdsLight) light, TY_IN(vec3) origin, TY_IN(vec3) dir, float tIn, float tEnd,
                             TY_OUT(float) a, TY_OUT(float) b) {
    a = tIn;
    b = tEnd;
#ifdef TY_WVDS_NO_GOBOS
    return a < b;
#else
    return wvdsClip_float(light.goboFirst, light.goboCount, origin, dir, a, b);
#endif
}

// V(t): 1 when nothing blocks the way from x to the light.
TY_FUNC float wvdsVisible(TY_IN(WvdsFrame) f, TY_IN(vec3) x, TY_IN(vec3) toLight) {
    if (f.shadows == 0) return 1.0f;
#ifdef TY_WVDS_NO_SURFACES
    return 1.0f;
#else
    return bvhOccluded(x, toLight, f.rayOffset, kInfinity) ? 0.0f : 1.0f;
#endif
}

// True when the medium's extinction is the same in every channel: a compile-time constant where the shader defines
// TY_WVDS_GREY (a grey variant: lavapipe would otherwise run the other channels' integrals, a branch no lane takes).
TY_FUNC bool wvdsGrey(TY_IN(WvdsFrame) f) {
#ifdef TY_WVDS_GREY
    return true;
#else
    return f.sigmaT.y == f.sigmaT.x && f.sigmaT.z == f.sigmaT.x;
#endif
}

// The transmittance per channel on the way camera -> x(t) -> boundary.
TY_FUNC vec3 wvdsTransmittance(TY_IN(WvdsFrame) f, float pathLength) {
#ifdef TY_WVDS_GREY
    return vec3(exp(-f.sigmaT.x * pathLength));
#else
    return exp(-f.sigmaT * pathLength);
#endif
}

// Random numbers of distance sample k of a camera sample: the first from the pixel's Sobol sequence (stratified over
// the pixel's samples), the others from its PCG stream.
TY_FUNC vec2 wvdsRandom2(int k, TY_IN(vec2) first, TY_INOUT(Pcg32) rng) {
    if (k == 0) return first;
    float u0 = pcg32NextFloat(rng);
    return vec2(u0, pcg32NextFloat(rng));
}

// The medium radiance of light i along [a, b] of the camera ray by the non-ratio estimators, for the distance samples
// k of N, with random number u; `selection` is the probability with which light selection chose the light (1 without).
TY_FUNC vec3 wvdsMediumEstimate(TY_IN(WvdsFrame) f, int estimator, TY_IN(WvdsLight) light, TY_IN(vec3) weight, TY_IN(vec3) origin,
                                TY_IN(vec3) dir, float tIn, float a, float b, TY_IN(WvdsPieces_float) pieces,
                                float u, int stratum, int strata, float selection) {
    float t = a, pdf = 0.0f;
    vec3 transmittance = vec3(0.0f);
    if (estimator == kWvdsMcwvds) {
        float path;
        t = wvdsSample_float(pieces, f.sigmaSample, u, pdf, path);
        if (!(pdf > 0.0f)) return vec3(0.0f);
        // e^{-sigma_t P} / pdf = Tbox e^{-(sigma_t - sigma) P}: Tbox for a grey medium (Sec. 6).
        transmittance = wvdsTransmittance(f, path) / pdf;
    } else if (estimator == kWvdsMcds) {
        t = wvdsDistanceSample_float(f.sigmaSample, a, b, u, pdf);
        if (!(pdf > 0.0f)) return vec3(0.0f);
        vec3 x = origin + t * dir;
        float dm = wvdsExitDistance_float(0, wvdsPlaneCount(f), x, light.toLight);
        transmittance = wvdsTransmittance(f, t - tIn + dm) / pdf;
    } else {  // kWvdsRm: stratum `stratum` of `strata` equal steps, jittered
        t = a + (float(stratum) + u) / float(strata) * (b - a);
        vec3 x = origin + t * dir;
        float dm = wvdsExitDistance_float(0, wvdsPlaneCount(f), x, light.toLight);
        transmittance = wvdsTransmittance(f, t - tIn + dm) * (b - a);
    }
    float v = wvdsVisible(f, origin + t * dir, light.toLight);
    return weight * transmittance * (v / (f.pdfScale * selection));
}

// Camera sample `index` of pixel (px, py); it belongs to the half index & 1 of the pixel's samples.
TY_FUNC WvdsTerms wvdsSample(TY_IN(WvdsFrame) f, int px, int py, uint index) {
    WvdsTerms terms;
    terms.direct = vec3(0.0f);
    for (int i = 0; i < kWvdsMaxLights; ++i) {
        terms.analytic[i] = vec3(0.0f);
        terms.numerator[i] = vec3(0.0f);
        terms.denominator[i] = vec3(0.0f);
    }
    // Even and odd camera samples come from two independently scrambled sequences, so that the two halves of a pixel's
    // samples are independent and their difference estimates the variance (as in the reference).
    uint pixelSeed = hashCombine(hashCombine(hashCombine(f.seed, uint(px)), uint(py)), index & 1u);
    uint sequenceIndex = index >> 1u;
    vec2 jitter = sobolSample2D(pixelSeed, sequenceIndex, 0u);
    vec2 first = sobolSample2D(pixelSeed, sequenceIndex, 1u);
    Pcg32 rng = pcg32Seed(pixelSeed, sequenceIndex);
    vec3 origin, dir;
    cameraRay(f.camera, float(px) + jitter.x, float(py) + jitter.y, origin, dir);
#ifdef TY_WVDS_NO_SURFACES
    bool hasHit = false;
    float tEnd = kInfinity;
#else
    BvhHit hit;
    bool hasHit = bvhIntersect(origin, dir, 0.0f, kInfinity, hit);
    float tEnd = hasHit ? hit.t : kInfinity;
#endif

    // The medium along the ray: [tIn, tOut], and the part in front of the surface.
    float tIn = 0.0f, tOut = kInfinity;
    bool inMedium = wvdsClip_float(0, wvdsPlaneCount(f), origin, dir, tIn, tOut);
    float mediumEnd = min(tOut, tEnd);
    bool scatters = inMedium && tIn < mediumEnd;
    int N = max(f.raySamples, 1);
    int estimator = wvdsEstimator(f);

    // Light selection (mcwvds, mcds): each light's unoccluded radiance, from the analytic integral.
    bool select = f.lightSelection != 0 && (estimator == kWvdsMcwvds || estimator == kWvdsMcds) && f.lightCount > 1;
    float selectionWeights[kWvdsMaxLights];
    float selectionTotal = 0.0f;
    for (int i = 0; i < kWvdsMaxLights; ++i)
        selectionWeights[i] = 0.0f;

    for (int i = 0; i < kWvdsLightLoop; ++i) {
        if (i >= f.lightCount || !scatters) continue;
        WvdsLight light = wvdsLight(i);
        float a, b;
        if (!wvdsLitInterval(light, origin, dir, tIn, mediumEnd, a, b)) continue;
        WvdsPieces_float pieces;
        wvdsPieces_float(0, wvdsPlaneCount(f), origin, dir, light.toLight, tIn, a, b, pieces);
        vec3 weight = f.sigmaS * phaseEval(f.phase, dot(dir, light.toLight)) * light.irradiance;
        vec3 analytic = vec3(wvdsTotal_float(pieces, f.sigmaT.x));
        if (!wvdsGrey(f))  // chromatic: one integral per channel
            analytic = vec3(analytic.x, wvdsTotal_float(pieces, f.sigmaT.y), wvdsTotal_float(pieces, f.sigmaT.z));
        if (select) {
            selectionWeights[i] = wvdsMean(weight * analytic);
            selectionTotal += selectionWeights[i];
            continue;
        }
        if (estimator == kWvdsAnalytic) {
            terms.direct += weight * analytic / f.pdfScale;
            continue;
        }
        if (wvdsIsRatio(estimator)) {
            terms.analytic[i] = weight * analytic / f.pdfScale;
            for (int k = 0; k < N; ++k) {
                vec2 u = wvdsRandom2(k, first, rng);
                float t, pdf;
                if (estimator == kWvdsReds) {
                    t = wvdsDistanceSample_float(f.sigmaSample, a, b, u.y, pdf);
                } else {
                    t = a + (float(k) + u.y) / float(N) * (b - a);
                    pdf = 1.0f / (b - a);
                }
                if (!(pdf > 0.0f)) continue;
                vec3 w = wvdsTransmittance(f, wvdsPathLength_float(pieces, t)) / pdf;
                terms.numerator[i] += w * wvdsVisible(f, origin + t * dir, light.toLight);
                terms.denominator[i] += w;
            }
            continue;
        }
        for (int k = 0; k < N; ++k) {
            vec2 u = wvdsRandom2(k, first, rng);
            terms.direct += wvdsMediumEstimate(f, estimator, light, weight, origin, dir, tIn, a, b, pieces, u.y, k, N, 1.0f) /
                            float(N);
        }
    }

    // One light per distance sample, with probability proportional to its unoccluded radiance.
    if (select && selectionTotal > 0.0f) {
        for (int k = 0; k < N; ++k) {
            vec2 u = wvdsRandom2(k, first, rng);
            float target = u.x * selectionTotal, below = 0.0f;
            int chosen = -1;
            bool passed = false;
            float probability = 0.0f;
            for (int i = 0; i < kWvdsLightLoop; ++i) {
                if (i >= f.lightCount || passed) continue;
                if (selectionWeights[i] > 0.0f) {
                    chosen = i;
                    probability = selectionWeights[i] / selectionTotal;
                }
                passed = target < below + selectionWeights[i];
                below += selectionWeights[i];
            }
            if (chosen < 0) continue;
            WvdsLight light = wvdsLight(chosen);
            float a, b;
            wvdsLitInterval(light, origin, dir, tIn, mediumEnd, a, b);
            WvdsPieces_float pieces;
            wvdsPieces_float(0, wvdsPlaneCount(f), origin, dir, light.toLight, tIn, a, b, pieces);
            vec3 weight = f.sigmaS * phaseEval(f.phase, dot(dir, light.toLight)) * light.irradiance;
            terms.direct += wvdsMediumEstimate(f, estimator, light, weight, origin, dir, tIn, a, b, pieces, u.y, k, N,
                                               probability) /
                            float(N);
        }
    }

    // Direct light at the surface (Eq. 1's first term): the BSDF, the beam, a shadow ray, and the transmittance on
    // both legs through the medium.
#ifndef TY_WVDS_NO_SURFACES
    if (hasHit) {
        SurfaceTriangle st = wvdsTriangle(int(hit.id));
        SurfaceFrame frame = surfaceFrame(st, hit.uv, dir);
        MaterialParams material = wvdsMaterial(st.material);
        vec3 xs = origin + hit.t * dir;
        float cameraDepth = inMedium ? max(min(tOut, hit.t) - tIn, 0.0f) : 0.0f;
        for (int i = 0; i < kWvdsLightLoop; ++i) {
            if (i >= f.lightCount) continue;
            WvdsLight light = wvdsLight(i);
            bool inBeam = true;
#ifndef TY_WVDS_NO_GOBOS
            for (int p = 0; p < light.goboCount; ++p) {
                vec4 plane = wvdsPlane(light.goboFirst + p);
                if (dot(vec3(plane), xs) > plane.w) inBeam = false;
            }
#endif
            if (!inBeam) continue;
            vec3 reflected = surfaceReflect(material, frame, -dir, light.toLight);
            if (reflected == vec3(0.0f)) continue;
            vec3 start = xs + f.rayOffset * frame.ng;
            if (f.shadows != 0 && bvhOccluded(start, light.toLight, 0.0f, kInfinity)) continue;
            float la = 0.0f, lb = kInfinity;
            float lightDepth = wvdsClip_float(0, wvdsPlaneCount(f), xs, light.toLight, la, lb) ? lb - la : 0.0f;
            terms.direct += light.irradiance * reflected * wvdsTransmittance(f, cameraDepth + lightDepth);
        }
    }
#endif
    return terms;
}

TY_END

#endif  // TY_SHARED_WVDS_SCENE_H
