// ISV particles (Jandhyala 2025, ../shared/papers/004, "the thesis"): tetrahedral particles of Gaussian-faded
// extinction, rasterised as interval-shading proxies (Tricard 2024; thesis Sec. 2.3), shaded per fragment over the
// ray's interval through one tetrahedron (Sec. 3.7-3.12) and composited back to front with premultiplied blending
// (Sec. 3.2). One source for the GPU stages (shaders/isv/) and the CPU model (renderers/isv/), derivations in
// docs/isv.md.
//
// Conventions: the camera ray is origin + t dir with t in metres along a unit dir; the light space of a directional
// light is an orthographic grid over `right` and `up` whose depth runs along `forward`, the direction light travels.
// The includer defines the two accessors of the light-space maps (GLSL: over storage buffers; C++: over the maps bound
// to the calling thread, renderers/isv/prepared.cpp):
//     IsvRgb isvVsmTexel(int i);    // the volumetric shadow map: optical depth, slice-major (slice, row, column)
//     float isvShadowTexel(int i);  // the opaque shadow map: depth of the first surface from the light, m
//
// Coloured shadows (beyond the thesis, whose extinction is grey): a medium's extinction may differ per channel. Its
// particles then carry the largest channel as sigma and the medium a `tint` (extinction over that channel), and
// optical depths, transmittances and the volumetric shadow map are RGB: IsvRgb. A GLSL build for media that are all
// grey defines TY_ISV_CHROMATIC 0 (the default) and IsvRgb is one float, so that lavapipe, which pays for compiled
// code on every fragment, does not compute three identical channels; C++ always computes RGB.
#ifndef TY_SHARED_ISV_H
#define TY_SHARED_ISV_H

#include "compat.h"
#include "constants.h"
#include "phase.h"
#include "surface.h"

#ifndef __cplusplus
#ifndef TY_ISV_CHROMATIC
#define TY_ISV_CHROMATIC 0
#endif
#if TY_ISV_CHROMATIC
#define IsvRgb vec3
#else
#define IsvRgb float
#endif
#endif

TY_BEGIN

#ifdef __cplusplus
using IsvRgb = vec3;
#endif

// Integration of C_scat over a fragment's interval (parameter `integration`).
TY_CONST int kIsvAnalytic = 0;  // Sec. 3.7: constant extinction, closed form
TY_CONST int kIsvTaylor = 1;    // Sec. 3.9: Taylor series about the midpoint, finite differences
TY_CONST int kIsvSimpson = 2;   // Sec. 3.10: composite Simpson with n steps
TY_CONST int kIsvWasted = 3;    // Sec. 3.11: the wasted-pixel visualisation (red: below the threshold, green: shaded)
TY_CONST int kIsvChord = 4;     // test output: the interval's length in r, alpha 1 (additive sum of chords)

TY_CONST int kIsvMaxMedia = 4;

// One tetrahedron, std430, 80 bytes.
struct IsvParticle {
    vec3 v0;
    float sigma;  // 1/m, extinction at the centre: the medium's extinction times the particle's multiplier
    vec3 v1;
    float k;  // 1/m^2, 50 / u^2 with u = scale * falloff (Eq. 9)
    vec3 v2;
    int medium;  // index into IsvFrame::media
    vec3 v3;
    float pad0;
    vec3 centre;
    float pad1;
};

// A particle medium's optics, std430: 192 bytes (the vec3s make its alignment 16, so GLSL rounds 180 up).
struct IsvMedium {
    vec3 albedo;
    float pad0;
    vec3 tint;  // extinction per channel over its largest channel, which the particles' sigma holds: 1 when grey
    float pad1;
    PhaseParams phase;
    float pad2[3];
};

// A grid seen from the light, std430, 80 bytes: orthographic for a directional light, perspective (a frustum from the
// light's position) for a point or spot light. A point x has grid coordinates
//     orthographic: (dot(r, right), dot(r, up)),  perspective: (dot(r, right), dot(r, up)) / dot(r, forward),
// r = x - origin, minus `corner`, in units of `texel` (texel (i, j)'s centre at i + 1/2, j + 1/2), and a depth
// dot(r, forward) - depthOrigin (slice s at s depthStep). A texel's ray starts at the grid's plane (orthographic) or at
// the light (perspective).
struct IsvLightSpace {
    vec3 origin;
    float texel;  // m (orthographic) or tangent units (perspective), a texel's side
    vec3 right;
    float depthStep;  // m, between slices (volumetric shadow map only)
    vec3 up;
    int size;  // texels per side
    vec3 forward;
    int slices;  // depth slices, >= 2 (volumetric shadow map only)
    vec2 corner;
    float depthOrigin;  // m, depth of slice 0
    int perspective;    // 1 for a point or spot light's frustum
};

// Everything a fragment needs besides its particle, std430.
TY_CONST int kIsvDirectional = 0;
TY_CONST int kIsvPoint = 1;
TY_CONST int kIsvMaxDistributionTerms = 32;

struct IsvFrame {
    vec3 lightDirection;  // unit, the direction light travels (directional light)
    int integration;      // kIsv*
    vec3 irradiance;      // W/m^2 on a plane perpendicular to lightDirection (directional), W/sr (point: intensity)
    int steps;            // Simpson steps, >= 1
    vec3 lightPosition;   // m (point light)
    int lightType;        // kIsvDirectional or kIsvPoint
    vec3 lightAxis;       // unit, the axis of a point light's angular distribution
    int distributionTerms;  // 0: isotropic; > 0: I(mu) = intensity sum_k c_k mu^k; -1: spot ((1 + mu) / 2)^spotExponent
    float spotExponent;
    float pad0, pad1, pad2;
    float distribution[kIsvMaxDistributionTerms];
    float threshold;      // early out: fragments whose optical thickness is below it are skipped (Sec. 3.11)
    float multiScatter;   // m of Eq. 11, in [0, 1]
    int fading;           // 1: Gaussian extinction (Eq. 9); 0: constant sigma in the whole tetrahedron
    int pcfRadius;        // opaque shadow map filter: (2r + 1)^2 texels, 0 for one
    int hasVsm;           // 1 when the volumetric shadow map is bound (self-shadowing)
    int hasShadowMap;     // 1 when the opaque shadow map is bound
    float shadowBias;     // m, subtracted from a point's depth before the opaque shadow test
    int mediumCount;
    IsvLightSpace vsm;
    IsvLightSpace shadowMap;
    IsvMedium media[kIsvMaxMedia];
};

// A shader may fix the light's type when it is compiled (TY_ISV_LIGHT_TYPE); see also the settings below.
#ifdef TY_ISV_LIGHT_TYPE
#define TY_ISV_LIGHT_TYPE_OF(f) TY_ISV_LIGHT_TYPE
#else
#define TY_ISV_LIGHT_TYPE_OF(f) (f).lightType
#endif

// Accessors the includer defines (see the top of this file).
IsvRgb isvVsmTexel(int i);
float isvShadowTexel(int i);

// The channels of a transmittance or an optical depth, grey or RGB.
TY_FUNC float isvMaxChannel(float x) { return x; }
TY_FUNC float isvMaxChannel(TY_IN(vec3) x) { return max(x.x, max(x.y, x.z)); }
TY_FUNC float isvMeanChannel(float x) { return x; }
TY_FUNC float isvMeanChannel(TY_IN(vec3) x) { return x.x == x.y && x.y == x.z ? x.x : (x.x + x.y + x.z) / 3.0f; }

// A medium's extinction per channel relative to its particles' sigma (one in a grey build).
TY_FUNC IsvRgb isvTint(TY_IN(IsvMedium) m) {
#if defined(__cplusplus) || TY_ISV_CHROMATIC
    return m.tint;
#else
    return 1.0f;
#endif
}

// ---------------------------------------------------------------------------------------------------------------------
// Extinction

// erf(x) to 1.5e-7 absolute (Abramowitz and Stegun 7.1.26); GLSL has none.
TY_FUNC float isvErf(float x) {
    float ax = abs(x);
    float t = 1.0f / (1.0f + 0.3275911f * ax);
    float poly = t * (0.254829592f + t * (-0.284496736f + t * (1.421413741f + t * (-1.453152027f + t * 1.061405429f))));
    float y = 1.0f - poly * exp(-ax * ax);
    return x < 0.0f ? -y : y;
}

// sigma_t at x inside the particle: Eq. 9 written with the distance to the centre, or the constant sigma.
TY_FUNC float isvExtinction(TY_IN(IsvParticle) p, TY_IN(vec3) x, int fading) {
    if (fading == 0) return p.sigma;
    vec3 r = x - p.centre;
    return p.sigma * exp(-p.k * dot(r, r));
}

// Optical depth of the particle along origin + t dir over [a, b] (inside the tetrahedron): Eq. 10, derived with the
// distance h of the ray from the centre and t_c the parameter closest to it as
//     sigma e^(-k h^2) sqrt(pi / k) / 2 [erf(sqrt(k) (b - t_c)) - erf(sqrt(k) (a - t_c))]   (docs/isv.md),
// or sigma (b - a) without fading.
TY_FUNC float isvOpticalDepth(TY_IN(IsvParticle) p, TY_IN(vec3) origin, TY_IN(vec3) dir, float a, float b, int fading) {
    if (b <= a) return 0.0f;
    if (fading == 0) return p.sigma * (b - a);
    vec3 oc = p.centre - origin;
    float tc = dot(oc, dir);
    vec3 perpendicular = oc - tc * dir;  // not |oc|^2 - t_c^2, which cancels in float far from the particle
    float h2 = dot(perpendicular, perpendicular);
    float sk = sqrt(p.k);
    float gauss = isvErf(sk * (b - tc)) - isvErf(sk * (a - tc));
    return p.sigma * exp(-p.k * h2) * (0.886226925f / sk) * max(gauss, 0.0f);  // sqrt(pi) / 2
}

// ---------------------------------------------------------------------------------------------------------------------
// Geometry

// The interval [t0, t1] of the ray origin + t dir inside the tetrahedron (t0 > t1 when it misses); t is not clamped to
// the ray's start. Each face's plane clips the ray, the face's outside being away from the opposite vertex.
TY_FUNC vec2 isvRayTetrahedron(TY_IN(IsvParticle) p, TY_IN(vec3) origin, TY_IN(vec3) dir) {
    float t0 = -kInfinity, t1 = kInfinity;
    for (int f = 0; f < 4; ++f) {
        vec3 a = f == 0 ? p.v1 : p.v0;
        vec3 b = f <= 1 ? p.v2 : p.v1;
        vec3 c = f <= 2 ? p.v3 : p.v2;
        vec3 opposite = f == 0 ? p.v0 : (f == 1 ? p.v1 : (f == 2 ? p.v2 : p.v3));
        vec3 n = cross(b - a, c - a);
        if (dot(n, opposite - a) > 0.0f) n = -n;  // outward
        float denom = dot(n, dir), dist = dot(n, a - origin);
        if (denom == 0.0f) {
            if (dist < 0.0f) return vec2(1.0f, 0.0f);  // parallel and outside
            continue;
        }
        float t = dist / denom;
        if (denom < 0.0f)
            t0 = max(t0, t);
        else
            t1 = min(t1, t);
    }
    return vec2(t0, t1);
}

// The projected tetrahedron as interval-shading proxies (Sec. 2.3.3): the silhouette's 3 or 4 vertices and one inner
// vertex, each with the pair of screen-affine depth attributes (front/back in either order) that the rasteriser
// interpolates. Triangle i is (p[i], p[(i + 1) % silhouette], p[silhouette]).
struct IsvProxy {
    vec2 p[5];
    vec2 q[5];
    int silhouette;  // 3 (case 1), 4 (case 2), or 0 when the projection has no area
};

// Barycentrics of s in the triangle (a, b, c); z = 0 area gives a negative value.
TY_FUNC vec3 isvBarycentric(TY_IN(vec2) s, TY_IN(vec2) a, TY_IN(vec2) b, TY_IN(vec2) c) {
    float area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (abs(area) < 1e-20f) return vec3(-1.0f);
    float l1 = ((s.x - a.x) * (c.y - a.y) - (s.y - a.y) * (c.x - a.x)) / area;
    float l2 = ((b.x - a.x) * (s.y - a.y) - (b.y - a.y) * (s.x - a.x)) / area;
    return vec3(1.0f - l1 - l2, l1, l2);
}

// From the four vertices' screen positions s and their screen-affine depth attributes q (1/z for a perspective view,
// z for an orthographic one).
TY_FUNC IsvProxy isvProxy(TY_IN(vec2) s0, TY_IN(vec2) s1, TY_IN(vec2) s2, TY_IN(vec2) s3, TY_IN(vec4) q) {
    vec2 s[4];
    s[0] = s0;
    s[1] = s1;
    s[2] = s2;
    s[3] = s3;
    IsvProxy proxy;
    for (int i = 0; i < 5; ++i) {
        proxy.p[i] = vec2(0.0f);
        proxy.q[i] = vec2(0.0f);
    }
    proxy.silhouette = 0;
    // Case 1: one vertex projects inside the triangle of the other three; the ray through it meets the opposite face
    // at the depth interpolated with its barycentrics (Eq. 5).
    for (int inner = 0; inner < 4; ++inner) {
        int a = inner == 0 ? 1 : 0;
        int b = inner <= 1 ? 2 : 1;
        int c = inner <= 2 ? 3 : 2;
        vec3 l = isvBarycentric(s[inner], s[a], s[b], s[c]);
        if (l.x >= 0.0f && l.y >= 0.0f && l.z >= 0.0f) {
            proxy.p[0] = s[a];
            proxy.p[1] = s[b];
            proxy.p[2] = s[c];
            proxy.p[3] = s[inner];
            proxy.q[0] = vec2(q[a]);
            proxy.q[1] = vec2(q[b]);
            proxy.q[2] = vec2(q[c]);
            proxy.q[3] = vec2(q[inner], l.x * q[a] + l.y * q[b] + l.z * q[c]);
            proxy.silhouette = 3;
            return proxy;
        }
    }
    // Case 2: the silhouette is a quad whose diagonals are two opposite edges; they cross at the inner vertex, where
    // each edge's depth is interpolated along it.
    for (int pairing = 0; pairing < 3; ++pairing) {
        int a = 0;
        int c = pairing + 1;
        int b = pairing == 0 ? 2 : 1;
        int d = pairing == 2 ? 2 : 3;
        vec2 e = s[c] - s[a], f = s[d] - s[b], g = s[b] - s[a];
        float den = e.x * f.y - e.y * f.x;
        if (abs(den) < 1e-20f) continue;
        float t = (g.x * f.y - g.y * f.x) / den;
        float u = (g.x * e.y - g.y * e.x) / den;
        if (t < 0.0f || t > 1.0f || u < 0.0f || u > 1.0f) continue;
        proxy.p[0] = s[a];
        proxy.p[1] = s[b];
        proxy.p[2] = s[c];
        proxy.p[3] = s[d];
        proxy.p[4] = s[a] + t * e;
        proxy.q[0] = vec2(q[a]);
        proxy.q[1] = vec2(q[b]);
        proxy.q[2] = vec2(q[c]);
        proxy.q[3] = vec2(q[d]);
        proxy.q[4] = vec2(mix(q[a], q[c], t), mix(q[b], q[d], u));
        proxy.silhouette = 4;
        return proxy;
    }
    return proxy;
}

// ---------------------------------------------------------------------------------------------------------------------
// Light-space maps

// Grid coordinates of x: (column, row) in texels with centres at half-integers, and the depth past depthOrigin.
TY_FUNC vec3 isvGridPoint(TY_IN(IsvLightSpace) ls, TY_IN(vec3) x) {
    vec3 r = x - ls.origin;
    float z = dot(r, ls.forward);
    vec2 plane = vec2(dot(r, ls.right), dot(r, ls.up));
    if (ls.perspective != 0) plane /= max(z, 1e-30f);
    return vec3((plane - ls.corner) / ls.texel, z - ls.depthOrigin);
}

// The ray of the grid point (gx, gy) (texel units; a texel's centre is at i + 1/2): unit direction, and the origin at
// the light (perspective) or on the plane at depthOrigin (orthographic). `cosine` is dot(dir, forward);
// isvRayDistance turns a depth past depthOrigin into a distance along the ray.
TY_FUNC void isvGridRay(TY_IN(IsvLightSpace) ls, float gx, float gy, TY_OUT(vec3) origin, TY_OUT(vec3) dir,
                        TY_OUT(float) cosine) {
    vec2 plane = ls.corner + vec2(gx, gy) * ls.texel;
    if (ls.perspective != 0) {
        origin = ls.origin;
        dir = normalize(ls.forward + plane.x * ls.right + plane.y * ls.up);
        cosine = dot(dir, ls.forward);
    } else {
        origin = ls.origin + plane.x * ls.right + plane.y * ls.up + ls.depthOrigin * ls.forward;
        dir = ls.forward;
        cosine = 1.0f;
    }
}

TY_FUNC float isvRayDistance(TY_IN(IsvLightSpace) ls, float depthPastOrigin, float cosine) {
    return ls.perspective != 0 ? (ls.depthOrigin + depthPastOrigin) / cosine : depthPastOrigin;
}

// Optical depth from the light to x: bilinear between texel centres (zero outside the grid, where no particle is),
// linear between depth slices (Fig. 7).
TY_FUNC IsvRgb isvLightOpticalDepth(TY_IN(IsvLightSpace) ls, TY_IN(vec3) x) {
    vec3 c = isvGridPoint(ls, x);
    float fx = c.x - 0.5f, fy = c.y - 0.5f;
    float fs = clamp(c.z / ls.depthStep, 0.0f, float(ls.slices - 1));
    int x0 = int(floor(fx)), y0 = int(floor(fy));
    int s0 = min(int(fs), ls.slices - 2);
    float wx = fx - float(x0), wy = fy - float(y0), ws = fs - float(s0);
    IsvRgb tau = IsvRgb(0.0f);
    for (int corner = 0; corner < 8; ++corner) {
        int cx = x0 + (corner & 1), cy = y0 + ((corner >> 1) & 1), cs = s0 + (corner >> 2);
        if (cx < 0 || cy < 0 || cx >= ls.size || cy >= ls.size) continue;
        float w = ((corner & 1) != 0 ? wx : 1.0f - wx) * (((corner >> 1) & 1) != 0 ? wy : 1.0f - wy) *
                  ((corner >> 2) != 0 ? ws : 1.0f - ws);
        tau += w * isvVsmTexel((cs * ls.size + cy) * ls.size + cx);
    }
    return tau;
}

// Vis(x) from the opaque shadow map, which holds per texel the distance along its ray to the first surface: the share
// of the (2r + 1)^2 texels about x's texel whose surface lies beyond x (percentage-closer filtering, Reeves et al.
// 1987). Outside the map nothing occludes.
TY_FUNC float isvVisibility(TY_IN(IsvLightSpace) ls, TY_IN(vec3) x, int radius, float bias) {
    vec3 c = isvGridPoint(ls, x);
    int cx = int(floor(c.x)), cy = int(floor(c.y));
    // The distance along the texel's ray (isvGridRay) less the bias, which is in m (orthographic) or per m of
    // distance (perspective, where texels grow with it).
    float distance = ls.perspective != 0 ? length(x - ls.origin) * (1.0f - bias) : c.z - bias;
    float lit = 0.0f, count = 0.0f;
    for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx) {
            int tx = cx + dx, ty = cy + dy;
            count += 1.0f;
            if (tx < 0 || ty < 0 || tx >= ls.size || ty >= ls.size || distance <= isvShadowTexel(ty * ls.size + tx))
                lit += 1.0f;
        }
    return lit / count;
}

// The light arriving at x: its irradiance on a plane facing it (W/m^2), and the unit direction towards it.
TY_FUNC vec3 isvLightAt(TY_IN(IsvFrame) f, TY_IN(vec3) x, TY_OUT(vec3) toLight) {
    if (TY_ISV_LIGHT_TYPE_OF(f) == kIsvDirectional) {
        toLight = -f.lightDirection;
        return f.irradiance;
    }
    vec3 r = f.lightPosition - x;
    float d2 = max(dot(r, r), 1e-12f);
    toLight = r * inversesqrt(d2);
    float mu = -dot(toLight, f.lightAxis);
    float shape = 1.0f;
    if (f.distributionTerms < 0) {
        shape = pow(max(0.5f * (1.0f + mu), 0.0f), f.spotExponent);
    } else if (f.distributionTerms > 0) {
        shape = 0.0f;
        for (int k = kIsvMaxDistributionTerms - 1; k >= 0; --k)
            if (k < f.distributionTerms) shape = shape * mu + f.distribution[k];
        shape = max(shape, 0.0f);
    }
    return f.irradiance * (shape / d2);
}

// ---------------------------------------------------------------------------------------------------------------------
// Shading a fragment (Sec. 3.6-3.12)
//
// A shader may fix the frame's settings when it is compiled (lavapipe runs every branch of a fragment shader, so a
// setting known at compile time removes the code of the others): TY_ISV_INTEGRATION, TY_ISV_STEPS, TY_ISV_FADING,
// TY_ISV_VSM (0 or 1), TY_ISV_SHADOW_MAP (0 or 1), TY_ISV_PCF. Without them the frame's values are used (the CPU).
#ifdef TY_ISV_INTEGRATION
#define TY_ISV_INTEGRATION_OF(f) TY_ISV_INTEGRATION
#else
#define TY_ISV_INTEGRATION_OF(f) (f).integration
#endif
#ifdef TY_ISV_STEPS
#define TY_ISV_STEPS_OF(f) TY_ISV_STEPS
#else
#define TY_ISV_STEPS_OF(f) (f).steps
#endif
#ifdef TY_ISV_FADING
#define TY_ISV_FADING_OF(f) TY_ISV_FADING
#else
#define TY_ISV_FADING_OF(f) (f).fading
#endif
#ifdef TY_ISV_VSM
#define TY_ISV_VSM_OF(f) TY_ISV_VSM
#else
#define TY_ISV_VSM_OF(f) (f).hasVsm
#endif
#ifdef TY_ISV_SHADOW_MAP
#define TY_ISV_SHADOW_MAP_OF(f) TY_ISV_SHADOW_MAP
#else
#define TY_ISV_SHADOW_MAP_OF(f) (f).hasShadowMap
#endif
#ifdef TY_ISV_PCF
#define TY_ISV_PCF_OF(f) TY_ISV_PCF
#else
#define TY_ISV_PCF_OF(f) (f).pcfRadius
#endif
// A GLSL includer may define TY_ISV_MEDIUM_ACCESSOR and `IsvMedium isvMedium(int i)` to read a particle's medium
// straight from its buffer: indexing a local copy of the frame by the particle's medium makes the compiler copy all of
// it, per fragment.
#ifdef TY_ISV_MEDIUM_ACCESSOR
IsvMedium isvMedium(int i);
#define TY_ISV_MEDIUM(f, i) isvMedium(i)
#else
#define TY_ISV_MEDIUM(f, i) (f).media[i]
#endif

// What every integration node of one fragment shares: the particle's extinction along the ray as
// sigma_t(t) = tint peak e^(-k (t - t_c)^2) and tau_V(t0, t) = tint depthScale (erf(sqrt(k) (t - t_c)) - erf0)
// (Eq. 9-10), or tint sigma and tint sigma (t - t0) without fading; tau_L at the interval's ends (Eq. 8).
struct IsvFragment {
    vec3 origin;
    vec3 dir;
    float t0, t1;
    float tc, sk, k;
    float peak;        // sigma e^(-k h^2)
    float depthScale;  // peak sqrt(pi / k) / 2
    float erf0;        // erf(sqrt(k) (t0 - t_c))
    IsvRgb tint;       // the medium's extinction per channel over sigma
    IsvRgb tauL0, tauL1;
    int fading;
};

// The extinction at t of the particle's largest channel (sigma's).
TY_FUNC float isvFragmentShape(TY_IN(IsvFragment) g, float t) {
    if (g.fading == 0) return g.peak;
    float s = t - g.tc;
    return g.peak * exp(-g.k * s * s);
}

TY_FUNC IsvRgb isvFragmentExtinction(TY_IN(IsvFragment) g, float t) {
    return g.tint * isvFragmentShape(g, t);
}

TY_FUNC IsvRgb isvFragmentDepth(TY_IN(IsvFragment) g, float t) {
    if (g.fading == 0) return g.tint * (g.peak * (t - g.t0));
    return g.tint * (g.depthScale * max(isvErf(g.sk * (t - g.tc)) - g.erf0, 0.0f));
}

// The integrand of Eq. 7 without K: sigma_t(t) T_V(t0, t) T_L(t) Vis(t), T_L by Eq. 8, per channel.
TY_FUNC IsvRgb isvIntegrand(TY_IN(IsvFrame) f, TY_IN(IsvFragment) g, float t) {
    float s = g.t1 > g.t0 ? (t - g.t0) / (g.t1 - g.t0) : 0.0f;
    float vis = 1.0f;
    if (TY_ISV_SHADOW_MAP_OF(f) != 0)
        vis = isvVisibility(f.shadowMap, g.origin + t * g.dir, TY_ISV_PCF_OF(f), f.shadowBias);
    return isvFragmentExtinction(g, t) * exp(-isvFragmentDepth(g, t) - mix(g.tauL0, g.tauL1, s)) * vis;
}

// (1 - e^-x) / x, exact at x -> 0.
TY_FUNC float isvOneMinusExpOver(float x) {
    if (abs(x) < 1e-4f) return 1.0f - 0.5f * x;
    return (1.0f - exp(-x)) / x;
}
TY_FUNC vec3 isvOneMinusExpOver(TY_IN(vec3) x) {
    return vec3(isvOneMinusExpOver(x.x), isvOneMinusExpOver(x.y), isvOneMinusExpOver(x.z));
}

// K of Eq. 7 at x: the light's irradiance there times the albedo and the phase function towards it (constant along
// the ray for a directional light; a point light's 1/r^2, its distribution and the scattering angle vary).
TY_FUNC vec3 isvSourceFactor(TY_IN(IsvFrame) f, TY_IN(IsvMedium) m, TY_IN(vec3) x, TY_IN(vec3) dir) {
    vec3 toLight;
    vec3 e = isvLightAt(f, x, toLight);
    return e * m.albedo * phaseEval(m.phase, dot(dir, toLight));
}

// One fragment: the ray origin + t dir inside particle p over [t0, t1]. Returns C_scat and sets A for premultiplied
// blending C_o = C_scat + A C (Sec. 3.2), per channel: C_scat of Eq. 7 (plus Eq. 11's C_mul) and A = T_V(t0, t1).
TY_FUNC vec3 isvShade(TY_IN(IsvFrame) f, TY_IN(IsvParticle) p, TY_IN(vec3) origin, TY_IN(vec3) dir, float t0,
                      float t1, TY_OUT(IsvRgb) transmittance) {
    int integration = TY_ISV_INTEGRATION_OF(f);
    float length = t1 - t0;
    transmittance = IsvRgb(1.0f);
    if (integration == kIsvChord) return vec3(max(length, 0.0f), 0.0f, 0.0f);
    if (!(length > 0.0f)) return vec3(0.0f);

    IsvFragment g;
    g.origin = origin;
    g.dir = dir;
    g.t0 = t0;
    g.t1 = t1;
    g.fading = integration == kIsvAnalytic ? 0 : TY_ISV_FADING_OF(f);
    vec3 oc = p.centre - origin;
    g.tc = dot(oc, dir);
    vec3 perpendicular = oc - g.tc * dir;  // not |oc|^2 - t_c^2, which cancels in float far from the particle
    g.k = p.k;
    g.sk = sqrt(p.k);
    g.peak = g.fading != 0 ? p.sigma * exp(-p.k * dot(perpendicular, perpendicular)) : p.sigma;
    g.depthScale = g.peak * (0.886226925f / g.sk);  // sqrt(pi) / 2
    g.erf0 = g.fading != 0 ? isvErf(g.sk * (t0 - g.tc)) : 0.0f;
    IsvMedium medium = TY_ISV_MEDIUM(f, p.medium);
    g.tint = isvTint(medium);
    IsvRgb tauV = isvFragmentDepth(g, t1);
    bool below = isvMaxChannel(tauV) < f.threshold;  // thin in every channel
    if (integration == kIsvWasted) return below ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f);
    if (below) return vec3(0.0f);  // Sec. 3.11: set to zero, the pixel keeps what is behind

    vec3 k = isvSourceFactor(f, medium, origin + (t0 + 0.5f * length) * dir, dir);  // K = R rho p(L, V), mid-interval
    g.tauL0 = IsvRgb(0.0f);
    g.tauL1 = IsvRgb(0.0f);
    if (TY_ISV_VSM_OF(f) != 0) {
        g.tauL0 = isvLightOpticalDepth(f.vsm, origin + t0 * dir);
        g.tauL1 = isvLightOpticalDepth(f.vsm, origin + t1 * dir);
    }

    bool pointLight = TY_ISV_LIGHT_TYPE_OF(f) != kIsvDirectional;
    vec3 integral = vec3(0.0f);
    if (integration == kIsvAnalytic) {
        // Sec. 3.7 with Eq. 8: sigma L (e^-tau_min - e^(-sigma L - tau_max)) / (sigma L + tau_max - tau_min), written
        // as sigma L e^-tau_min (1 - e^-x) / x with x = sigma L + tau_max - tau_min; Vis at the midpoint.
        float vis = 1.0f;
        if (TY_ISV_SHADOW_MAP_OF(f) != 0)
            vis = isvVisibility(f.shadowMap, origin + (t0 + 0.5f * length) * dir, TY_ISV_PCF_OF(f), f.shadowBias);
        integral = k * (tauV * exp(-g.tauL0) * isvOneMinusExpOver(tauV + g.tauL1 - g.tauL0) * vis);
    } else if (integration == kIsvTaylor) {
        // Sec. 3.9: the first four terms of the Taylor series about the midpoint a, integrated over [t0, t1]; the odd
        // terms vanish there, leaving f(a) L + f''(a) L^3 / 24, with f'' by forward differences of step h = L / 4.
        float h = 0.25f * length, a = t0 + 0.5f * length;
        IsvRgb fa = isvIntegrand(f, g, a), fh = isvIntegrand(f, g, a + h), f2h = isvIntegrand(f, g, a + 2.0f * h);
        integral = k * max(fa * length + (f2h - 2.0f * fh + fa) / (h * h) * length * length * length / 24.0f, 0.0f);
    } else {
        // Sec. 3.10: composite Simpson over `steps` equal sub-intervals; for a point light K varies at each node.
        int n = max(TY_ISV_STEPS_OF(f), 1);
        float w = length / float(n);
        vec3 sum = isvIntegrand(f, g, t0) * (pointLight ? isvSourceFactor(f, medium, origin + t0 * dir, dir) : k);
        for (int i = 0; i < n; ++i) {
            float a = t0 + float(i) * w, mid = a + 0.5f * w, end = a + w;
            vec3 kMid = pointLight ? isvSourceFactor(f, medium, origin + mid * dir, dir) : k;
            vec3 kEnd = pointLight ? isvSourceFactor(f, medium, origin + end * dir, dir) : k;
            // The last end has weight 1, not 2.
            sum += 4.0f * isvIntegrand(f, g, mid) * kMid + (i == n - 1 ? 1.0f : 2.0f) * isvIntegrand(f, g, end) * kEnd;
        }
        integral = sum * (w / 6.0f);
    }
    vec3 colour = integral;
    if (f.multiScatter > 0.0f) {
        // Eq. 11: C_mul = sigma_t(mid) / sigma rho R p(L, V) 0.001 m (crude, not physically based; off by default);
        // the ratio is the same in every channel.
        float relative = isvFragmentShape(g, t0 + 0.5f * length) / max(p.sigma, 1e-30f);
        colour += relative * k * (0.001f * f.multiScatter);
    }
    transmittance = exp(-tauV);
    return colour;
}

#ifdef TY_SHARED_BVH_H
// The opaque visibility of the light from a surface point x with facing normal n (for isvSurfaceRadiance): the shadow
// map's for a directional light, a shadow ray's through the BVH (leaving x by `offset` along n) for a point light.
TY_FUNC float isvSurfaceVisibility(TY_IN(IsvFrame) f, TY_IN(vec3) x, TY_IN(vec3) n, float offset) {
    if (TY_ISV_SHADOW_MAP_OF(f) == 0) return 1.0f;
    if (TY_ISV_LIGHT_TYPE_OF(f) == kIsvDirectional) return isvVisibility(f.shadowMap, x, TY_ISV_PCF_OF(f), f.shadowBias);
    vec3 r = f.lightPosition - x;
    float d = length(r);
    return bvhOccluded(x + offset * n, r / d, 0.0f, d) ? 0.0f : 1.0f;
}
#endif

// The optical depth of particle p along a light-space ray over the slab [lo, hi] of its interval [t0, t1], of the
// particle's largest channel (times the medium's tint per channel): one slab's share of the volumetric shadow map
// (each slab is accumulated, then summed front to back into slices).
TY_FUNC float isvSlabDepth(TY_IN(IsvParticle) p, TY_IN(vec3) origin, TY_IN(vec3) dir, float t0, float t1, float lo,
                           float hi, int fading) {
    return isvOpticalDepth(p, origin, dir, max(t0, lo), min(t1, hi), fading);
}

// Radiance leaving a surface point x towards wo, lit through the medium's volumetric shadow map (Sec. 3.13). `vis` is
// the opaque visibility of the light: the shadow map's for a directional light (isvVisibility), a shadow ray's for a
// point light (a single frustum cannot hold every direction around it), found by the caller.
TY_FUNC vec3 isvSurfaceRadiance(TY_IN(IsvFrame) f, TY_IN(MaterialParams) m, TY_IN(SurfaceFrame) sf, TY_IN(vec3) x,
                                TY_IN(vec3) wo, float vis) {
    vec3 wi;
    vec3 e = isvLightAt(f, x, wi);
    vec3 reflected = surfaceReflect(m, sf, wo, wi);
    if (reflected == vec3(0.0f) || vis <= 0.0f) return vec3(0.0f);
    IsvRgb tau = IsvRgb(0.0f);
    if (TY_ISV_VSM_OF(f) != 0) tau = isvLightOpticalDepth(f.vsm, x);
    return e * reflected * (vis * exp(-tau));
}

TY_END

#endif  // TY_SHARED_ISV_H
