// The Pegoraro technique's per-pixel renderer for one precision of the closed form (TY_R, TY_R2, TY_R3 defined by
// pegoraro_scene.h, which includes this file once per precision). Geometry (rays, hits, lit intervals) is float; the
// closed form and everything it depends on (h, xh, the cosines, the interval ends) is computed in TY_R.

TY_BEGIN

TY_FUNC TY_RS(PegoraroPolynomial) TY_RS(pegoraroLoadPolynomial)(int first, int terms) {
    TY_RS(PegoraroPolynomial) p;
    p.terms = min(terms, kPegoraroMaxTerms);
    for (int k = 0; k < kPegoraroMaxTerms; ++k) {
        vec2 split = k < p.terms ? pegoraroCoefficient(first + k) : vec2(0.0f);
        p.c[k] = TY_R(split.x) + TY_R(split.y);
    }
    return p;
}

// I over [ua, ub] (pegoraro.h) for one channel: the closed form with its a priori error bound; where that bound exceeds
// the tolerance, the bound measured by pegoraroSeriesRefine (once per series: `refined`); where that exceeds it too,
// the quadrature (counted in `fallbacks`).
TY_FUNC TY_R TY_RS(pegoraroClosedForm)(TY_IN(TY_RS(PegoraroSeries)) s, TY_R H, TY_R ua, TY_R ub,
                                       TY_OUT(TY_R) errorBound) {
#ifdef TY_PEGORARO_NO_SURFACES  // nothing ends or shadows a ray: every interval runs to infinity
    return pegoraroIntegralToInfinity(s, H, ua, errorBound);
#else
    return pegoraroIntegral(s, H, ua, ub, errorBound);
#endif
}

TY_FUNC TY_R pegoraroChannel(TY_IN(PegoraroFrame) f, TY_INOUT(TY_RS(PegoraroSeries)) s, TY_INOUT(bool) refined,
                             TY_IN(TY_RS(PegoraroPolynomial)) phase, TY_IN(TY_RS(PegoraroPolynomial)) light, TY_R H,
                             TY_R ua, TY_R ub, TY_R del, TY_R dc, TY_INOUT(int) fallbacks) {
    bool quadrature = f.fallbackMode == kPegoraroFallbackAlways || s.terms == 0;
    TY_R value = TY_R(0.0f);
    if (!quadrature) {
        TY_R errorBound;
        value = TY_RS(pegoraroClosedForm)(s, H, ua, ub, errorBound);
        quadrature = f.fallbackMode == kPegoraroFallbackAuto && errorBound > TY_R(f.fallbackTolerance) * abs(value);
#if TY_PEGORARO_MAX_TERMS > 8 && !defined(TY_PEGORARO_DEFERRED_FALLBACK)
        // Up to order 7 the a priori bound is below 1e-8 in double (docs/pegoraro.md, Sec. 5), so the variants of
        // few terms go without this code (lavapipe would run it for every evaluation); so does the first GPU pass,
        // which defers these evaluations to the full shader.
        if (quadrature && !refined) {
            pegoraroSeriesRefine(del, dc, phase, light, s);
            refined = true;
            value = TY_RS(pegoraroClosedForm)(s, H, ua, ub, errorBound);
            quadrature = errorBound > TY_R(f.fallbackTolerance) * abs(value);
        }
#endif
    }
#ifdef TY_PEGORARO_DEFERRED_FALLBACK
    // The first pass of the GPU renderer: no quadrature code (lavapipe would run it for every evaluation, taken or
    // not). The evaluation is counted, and the host renders the samples that have any again with the full shader.
    if (quadrature) {
        value = TY_R(0.0f);
        ++fallbacks;
    }
#else
    if (quadrature) {
        int panels;
        value = pegoraroQuadrature(H, ua, ub, del, dc, phase, light, TY_R(f.quadratureTolerance), panels);
        ++fallbacks;
    }
#endif
    return value;
}

// Eq. 3-7 summed over the lit parts of origin + t dir, t in [0, tEnd] (tEnd >= kInfinity: the ray never ends), for
// one light and every medium: the medium radiance arriving at the origin.
TY_FUNC vec3 TY_RS(pegoraroMediumRadiance)(TY_IN(PegoraroFrame) f, TY_IN(PegoraroLight) light,
                                           TY_IN(TY_RS(PegoraroPolynomial)) lightPolynomial, TY_IN(vec3) origin,
                                           TY_IN(vec3) dir, float tEnd, TY_INOUT(int) fallbacks,
                                           TY_INOUT(int) overflows) {
    TY_R3 o = TY_R3(origin), d = TY_R3(dir), pl = TY_R3(light.position), axis = TY_R3(light.axis);
    TY_R xh = dot(pl - o, d);  // the foot of the perpendicular from the light
    TY_R3 foot = o + xh * d;
    TY_R h = length(foot - pl);
    vec3 radiance = vec3(0.0f);
    if (!(h > TY_R(0.0f))) return radiance;  // the light on the ray itself: a set of measure zero
    TY_R del = dot(d, axis);
    TY_R dc = dot(foot - pl, axis) / h;

    LitIntervals lit;
    int pieces = 1;
    lit.pieces[0] = vec2(0.0f, tEnd);
#if !defined(TY_PEGORARO_NO_SHADOWS) && !defined(TY_PEGORARO_NO_SURFACES)
    // A GPU variant without them is much faster on lavapipe, even with shadows == 0.
    if (f.shadows != 0) pieces = pegoraroLitPieces(f, light, origin, dir, tEnd, lit, overflows);
#endif

    bool grey = pegoraroGrey(f);
    for (int m = 0; m < f.mediumCount; ++m) {
        PegoraroMedium medium = pegoraroMedium(m);
        TY_RS(PegoraroPolynomial) phase = TY_RS(pegoraroLoadPolynomial)(medium.firstCoefficient, medium.terms);
        TY_RS(PegoraroSeries) s;
        pegoraroSeries(del, dc, phase, lightPolynomial, s);
        bool refined = false;
        for (int i = 0; i < pieces; ++i) {
            TY_R ta = TY_R(lit.pieces[i].x);
            TY_R ua = (ta - xh) / h;
            TY_R ub = lit.pieces[i].y >= kInfinity ? TY_R(kInfinity) : (TY_R(lit.pieces[i].y) - xh) / h;
            vec3 integral = vec3(0.0f);
            for (int c = 0; c < kPegoraroChannelLoop; ++c) {
                if (c > 0 && grey) continue;
                TY_R sigmaT = TY_R(f.sigmaT[c]);
                integral[c] = float(
                    pegoraroChannel(f, s, refined, phase, lightPolynomial, sigmaT * h, ua, ub, del, dc, fallbacks) *
                    realExp(-sigmaT * ta) / h);
            }
            if (grey) integral = vec3(integral[0]);
            // Eq. 4: Lm = sigma_s / h * I, with the transmittance e^(-sigma_t ta) from the camera to the interval.
            radiance += medium.sigmaS * light.intensity * integral;
        }
    }
    return radiance;
}

// The radiance along the ray through the image point (x, y) in pixel coordinates: the medium radiance of every light
// plus the reduced radiance of the surface behind (Eq. 1, 2, 8). Returns the radiance in xyz and the number of
// closed-form evaluations that fell back to quadrature in w; `overflows` counts lights whose shadow boundaries did not
// fit. `sampleIndex`: the ray's record in the rasterised primary hits (primary_hits.h), or -1 to trace it.
TY_FUNC vec4 TY_RS(pegoraroRay)(TY_IN(PegoraroFrame) f, float x, float y, int sampleIndex, TY_INOUT(int) overflows) {
    vec3 sum = vec3(0.0f);
    int fallbacks = 0;
    vec3 origin, dir;
    cameraRay(f.camera, x, y, origin, dir);
#ifdef TY_PEGORARO_NO_SURFACES
    float tEnd = kInfinity;
#else
    BvhHit hit;
    bool hasHit = primaryIntersect(sampleIndex, origin, dir, hit);
    float tEnd = hasHit ? hit.t : kInfinity;
    // Without a hit these stay unused; they are filled so that every path initialises them.
    SurfaceTriangle st = surfaceTriangle(hasHit ? int(hit.id) : 0);
    SurfaceFrame frame = surfaceFrame(st, hasHit ? hit.uv : vec2(0.0f), dir);
    MaterialParams material = surfaceMaterial(st.material);
    vec3 xs = origin + (hasHit ? hit.t : 0.0f) * dir;
#endif
    for (int l = 0; l < f.lightCount; ++l) {
        PegoraroLight light = pegoraroLight(l);
        TY_RS(PegoraroPolynomial) lightPolynomial = TY_RS(pegoraroLoadPolynomial)(light.firstCoefficient, light.terms);
        if (f.mediumCount > 0)
            sum += TY_RS(pegoraroMediumRadiance)(f, light, lightPolynomial, origin, dir, tEnd, fallbacks, overflows);
#ifndef TY_PEGORARO_NO_SURFACES
        if (!hasHit) continue;
        // Eq. 8 and Eq. 2: direct light at the surface, attenuated on both legs.
        vec3 toLight = light.position - xs;
        float distance = length(toLight);
        if (!(distance > 0.0f)) continue;
        vec3 wi = toLight / distance;
        vec3 reflected = surfaceReflect(material, frame, -dir, wi);
        if (reflected == vec3(0.0f)) continue;
#ifndef TY_PEGORARO_NO_SHADOWS
        if (f.shadows != 0 && bvhOccluded(xs + f.rayOffset * frame.ng, wi, 0.0f, distance * (1.0f - 1e-4f))) continue;
#endif
        float intensity = float(pegoraroHorner(lightPolynomial, TY_R(dot(-wi, light.axis))));
        vec3 transmittance = exp(-f.sigmaT * (hit.t + distance));
        sum += light.intensity * max(intensity, 0.0f) / (distance * distance) * transmittance * reflected;
#endif
    }
    return vec4(sum, float(fallbacks));
}

// Sample k of pixel (px, py): the S x S regular grid of a box filter like the reference's, k = sy * S + sx.
TY_FUNC vec4 TY_RS(pegoraroSample)(TY_IN(PegoraroFrame) f, int px, int py, int k, TY_INOUT(int) overflows) {
    int S = max(f.supersampling, 1);
    int sy = k / S, sx = k - sy * S;
    vec2 point = primarySamplePoint(S, px, py, sx, sy);
    return TY_RS(pegoraroRay)(f, point.x, point.y, primarySampleIndex(int(f.camera.width), S, px, py, sx, sy),
                              overflows);
}

// Node `node` of a pixel around a light's projection p (pegoraroSingularNode): its radiance times its weight in xyz,
// its fallbacks in w. The pixel's average is the sum over its kPegoraroSingularNodes nodes.
TY_FUNC vec4 TY_RS(pegoraroSingularSample)(TY_IN(PegoraroFrame) f, int px, int py, TY_IN(vec2) p, int node,
                                           TY_INOUT(int) overflows) {
    vec3 x = pegoraroSingularNode(px, py, p, node);
    if (x.z == 0.0f) return vec4(0.0f);
    vec4 r = TY_RS(pegoraroRay)(f, x.x, x.y, -1, overflows);
    return vec4(x.z * vec3(r), r.w);
}

// The pixel (px, py): the mean of its S x S samples (radiance in xyz) and the sum of their fallbacks (w); around a
// light's projection, the singularity-cancelling rule of pegoraroSingularNode instead.
TY_FUNC vec4 TY_RS(pegoraroPixel)(TY_IN(PegoraroFrame) f, int px, int py, TY_OUT(int) overflows) {
    overflows = 0;
    vec4 sum = vec4(0.0f);
    vec2 p;
    if (pegoraroSingularPoint(f, px, py, p)) {
        for (int k = 0; k < kPegoraroSingularNodes; ++k)
            sum += TY_RS(pegoraroSingularSample)(f, px, py, p, k, overflows);
        return sum;
    }
    int S = max(f.supersampling, 1);
    for (int k = 0; k < S * S; ++k)
        sum += TY_RS(pegoraroSample)(f, px, py, k, overflows);
    return vec4(vec3(sum) / float(S * S), sum.w);
}

TY_END
