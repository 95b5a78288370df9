// The LTSD technique's scene as the GPU sees it (std430 layouts, declared once for GLSL and C++) and the per-pixel
// renderer shared by its compute shader and its CPU path: unshadowed single scattering from polygonal area lights in
// one homogeneous medium (KT, Shah, Narayanan 2025, ../shared/papers/000), the semi-analytic Eq. 15 with the analytic
// in-scattered radiance of Eq. 14 and the analytic surface radiance of Eq. 12 (diffuse: the clamped cosine's exact
// integral; GGX: the fitted LTCs of shared/ltc.h). Derivations and what is approximated: docs/ltsd.md.
//
// The includer defines the accessors after including this header (as for bvh.h):
//   LtsdLight ltsdLight(int i);  vec4 ltsdPlane(int i);  SurfaceTriangle ltsdTriangle(int id);
//   MaterialParams ltsdMaterial(int i);  LtcEntry ltsdLtcEntry(int i);
// and bvhNode / bvhTriangle for bvh.h.
//
// Compile-time variants (the GPU renderer defines them; the CPU path uses the frame's values):
//   TY_LTSD_LIGHTS n         exactly n lights        TY_LTSD_PLANES n     exactly n medium planes (0: infinite)
//   TY_LTSD_NO_MEDIUM        surfaces in vacuum      TY_LTSD_NO_SURFACES  no triangles
//   TY_LTSD_ONE_SIDED        no light is two-sided   TY_LTSD_PLACEMENT k  TY_LTSD_TRANSMITTANCE k
//   TY_LTSD_NO_GGX           no GGX material         TY_LTSD_NO_ANISOTROPIC  no anisotropic GGX material
//   TY_LTSD_S_METHOD k       kLtsdSMethod*           TY_LTSD_S_LOBE k     the boundary form's lobe (kLtsdLobe*)
//   TY_PRIMARY_HITS          the analytic pass's camera hits come rasterised (primary_hits.h)
#ifndef TY_SHARED_LTSD_SCENE_H
#define TY_SHARED_LTSD_SCENE_H

#include "bvh.h"
#include "camera.h"
#include "compat.h"
#include "constants.h"
#include "ltc.h"
#include "ltsd.h"
#include "ltsd_boundary.h"
#include "phase.h"
#include "primary_hits.h"
#include "rng.h"
#include "sampling.h"
#include "surface.h"

TY_BEGIN

TY_CONST int kLtsdMaxLights = 8;
TY_CONST int kLtsdMaxPlanes = 16;
TY_CONST int kLtsdLightMaxVertices = 8;  // a horizon clip adds one: within kLtsdMaxVertices
// Loops over a light's vertices stop here: the lights' most vertices where the kernel is compiled for its scene
// (TY_LTSD_VERTICES, at most kLtsdLightMaxVertices; see kLtsdLoopVertices in ltsd.h).
#ifdef TY_LTSD_VERTICES
TY_CONST int kLtsdLightLoopVertices = TY_LTSD_VERTICES;
#else
TY_CONST int kLtsdLightLoopVertices = kLtsdLightMaxVertices;
#endif

// Where the N nodes z_i* of Eq. 15 go on each light's part of the camera ray (docs/ltsd.md, "Quadrature").
TY_CONST int kLtsdPlacementMidpoint = 0;       // N equal partitions, the node at each one's middle (the paper)
TY_CONST int kLtsdPlacementTransmittance = 1;  // midpoints of equal parts of the camera transmittance
TY_CONST int kLtsdPlacementEquiangular = 2;    // midpoints of equal angles seen from the light's centroid

// The aggregated transmittance towards a light (docs/ltsd.md, "Aggregated transmittance").
TY_CONST int kLtsdTransmittanceMinDistance = 0;  // Eq. 10: e^(-sigma_t d), d the distance to the nearest point
TY_CONST int kLtsdTransmittancePolygon = 1;      // the solid-angle mean of e^(-sigma_t r) by quadrature
TY_CONST int kLtsdTransmittanceGrid = 3;         // its nodes: a 3 x 3 grid per fan triangle, uniform in solid angle

// How S, the phase function's integral over a light's polygon, is computed (docs/ltsd.md, "S").
TY_CONST int kLtsdSMethodPaper = 0;     // Eq. 21: the fitted LTSDs of the phase function's table
TY_CONST int kLtsdSMethodAccurate = 1;  // the boundary form of shared/ltsd_boundary.h: no table, ~1e-5 relative

// A polygonal area light, 176 bytes.
struct LtsdLight {
    vec4 vertices[kLtsdLightMaxVertices];  // xyz in m; the first vertexCount are used
    vec3 normal;                           // unit, right-hand rule of the vertex order: the emitting side
    int vertexCount;
    vec3 radiance;  // W/(m^2 sr), linear RGB
    int twoSided;
    vec3 centre;    // m, the vertices' mean: the centre of the equiangular placement
    float radius2;  // m^2, area / pi: the squared radius of the disc of the light's area
};

// Everything else a frame needs, 296 bytes.
struct LtsdFrame {
    CameraParams camera;
    vec3 sigmaT;  // 1/m
    int lightCount;
    vec3 sigmaS;     // 1/m
    int planeCount;  // half-spaces bounding the medium (0: infinite)
    int hasMedium;
    int nodes;          // N of Eq. 15, per light and per side of its plane that the ray crosses
    int placement;      // kLtsdPlacement*
    int transmittance;  // kLtsdTransmittance*
    int supersampling;  // S: S x S rays per pixel on a regular grid (a box filter)
    float tailDistance;  // m: an unbounded camera segment ends here, where e^(-sigma_t t) < e^-9.2 ~ 1e-4
    float g;             // the medium's HG (and mix) asymmetry, for the ratio estimators' true phase function
    float rayOffset;     // m, offset of shadow rays from surfaces (the ratio estimators)
    LtsdEntry upper;  // M_u and a_u of the medium's phase function (Eq. 24, fetched on the CPU: g is per medium)
    LtsdEntry lower;  // T (M_l = diag(1, 1, -1) T) and a_l
    int phaseKind;         // kPhase* of the medium (the ratio estimators' true phase function)
    float phaseA;          // mix: the HG lobe's weight
    float phaseB;          // eddington: b
    float phaseIsotropic;  // the exact part (isotropic + linear mu) / (4 pi) of ltsdPhaseIntegral (docs/tables.md)
    float phaseLinear;
    int ltcXCount;      // the isotropic LTC GGX table (ltsdLtcEntry from 0): entries over sqrt(1 - cos theta_o)
    int ltcAlphaCount;  // entries over alpha
    float ltcAlphaMin;  // alpha's grid is uniform over [ltcAlphaMin, 1]
    int ltcAnisoBase;   // the anisotropic table (ltsdLtcEntry from ltcAnisoBase): its first entry's index
    int ltcAnisoThetaCount;  // entries over theta_o, phi_o, alpha and r (shared/ltc.h)
    int ltcAnisoPhiCount;
    int ltcAnisoAlphaCount;
    int ltcAnisoRatioCount;
    float ltcAnisoAlphaMin;
    float ltcAnisoRatioMin;
    int sMethod;        // kLtsdSMethod*
    int sLobe;          // the accurate method's lobe (kLtsdLobe*, shared/ltsd_boundary.h); its asymmetry is g
    float sLobeWeight;  // the lobe's weight; phaseIsotropic and phaseLinear are the rest
};

// Supplied by the includer (see the top of the file).
LtsdLight ltsdLight(int i);
vec4 ltsdPlane(int i);
SurfaceTriangle ltsdTriangle(int id);
MaterialParams ltsdMaterial(int i);
LtcEntry ltsdLtcEntry(int i);

TY_FUNC int ltsdLightCount(TY_IN(LtsdFrame) f) {
#ifdef TY_LTSD_LIGHTS
    return TY_LTSD_LIGHTS;
#else
    return f.lightCount;
#endif
}

TY_FUNC int ltsdPlaneCount(TY_IN(LtsdFrame) f) {
#ifdef TY_LTSD_PLANES
    return TY_LTSD_PLANES;
#else
    return f.planeCount;
#endif
}

TY_FUNC int ltsdPlacement(TY_IN(LtsdFrame) f) {
#ifdef TY_LTSD_PLACEMENT
    return TY_LTSD_PLACEMENT;
#else
    return f.placement;
#endif
}

TY_FUNC int ltsdSMethod(TY_IN(LtsdFrame) f) {
#ifdef TY_LTSD_S_METHOD
    return TY_LTSD_S_METHOD;
#else
    return f.sMethod;
#endif
}

TY_FUNC int ltsdSLobe(TY_IN(LtsdFrame) f) {
#ifdef TY_LTSD_S_LOBE
    return TY_LTSD_S_LOBE;
#else
    return f.sLobe;
#endif
}

TY_FUNC int ltsdTransmittanceMode(TY_IN(LtsdFrame) f) {
#ifdef TY_LTSD_TRANSMITTANCE
    return TY_LTSD_TRANSMITTANCE;
#else
    return f.transmittance;
#endif
}

// ---------------------------------------------------------------------------------------------------------------------
// The medium

// The part [t0, t1] of origin + t dir, t in [tMin, tMax], inside the medium's half-spaces (t0 >= t1: none).
TY_FUNC vec2 ltsdMediumSegment(TY_IN(LtsdFrame) f, TY_IN(vec3) origin, TY_IN(vec3) dir, float tMin, float tMax) {
    float t0 = tMin, t1 = tMax;
    for (int i = 0; i < ltsdPlaneCount(f); ++i) {
        vec4 p = ltsdPlane(i);
        float denom = dot(vec3(p), dir);
        float num = p.w - dot(vec3(p), origin);  // inside where num - t denom >= 0
        if (abs(denom) < 1e-30f) {
            if (num < 0.0f) t1 = -1.0f;
            continue;
        }
        float t = num / denom;
        if (denom > 0.0f)
            t1 = min(t1, t);
        else
            t0 = max(t0, t);
    }
    return vec2(t0, t1);
}

// The length of the segment from `origin` to `origin + v` inside the medium (0 without one).
TY_FUNC float ltsdChord(TY_IN(LtsdFrame) f, TY_IN(vec3) origin, TY_IN(vec3) v) {
#ifdef TY_LTSD_NO_MEDIUM
    return 0.0f;
#else
    if (f.hasMedium == 0) return 0.0f;
    float l = length(v);
    if (ltsdPlaneCount(f) == 0) return l;
    if (!(l > 0.0f)) return 0.0f;
    vec2 s = ltsdMediumSegment(f, origin, v / l, 0.0f, l);
    return max(s.y - s.x, 0.0f);
#endif
}

// ---------------------------------------------------------------------------------------------------------------------
// Lights

// The signed distance of p from the light's plane, positive on the emitting side.
TY_FUNC float ltsdPlaneDistance(TY_IN(LtsdLight) light, TY_IN(vec3) p) {
    return dot(light.normal, p - vec3(light.vertices[0]));
}

// True when the light emits towards p: p in front of it, or on either side of a two-sided light.
TY_FUNC bool ltsdFacing(TY_IN(LtsdLight) light, TY_IN(vec3) p) {
    float s = ltsdPlaneDistance(light, p);
#ifdef TY_LTSD_ONE_SIDED
    return s > 0.0f;
#else
    return light.twoSided != 0 ? s != 0.0f : s > 0.0f;
#endif
}

// Loops over a light's vertices run over the constant kLtsdLightLoopVertices with the count as a condition, and the
// next vertex is a select of two constant indices, so that, unrolled, no access indexes the light dynamically
// (lavapipe serves dynamically indexed arrays from memory, lane by lane; see shared/ltsd.h).
TY_FUNC vec4 ltsdNextLightVertex(TY_IN(LtsdLight) light, int i) {
    return i + 1 < light.vertexCount ? light.vertices[min(i + 1, kLtsdLightMaxVertices - 1)] : light.vertices[0];
}

// The light's polygon seen from p in the frame (x, y, z): its vertices relative to p in that basis.
TY_FUNC SphericalPolygon ltsdLocalPolygon(TY_IN(LtsdLight) light, TY_IN(vec3) p, TY_IN(vec3) x, TY_IN(vec3) y,
                                          TY_IN(vec3) z) {
    SphericalPolygon poly;
    for (int i = 0; i < kLtsdMaxVertices; ++i) poly.v[i] = vec3(0.0f);
    poly.count = light.vertexCount;
    for (int i = 0; i < kLtsdLightLoopVertices; ++i) {
        vec3 v = vec3(light.vertices[i]) - p;
        if (i < light.vertexCount) poly.v[i] = vec3(dot(v, x), dot(v, y), dot(v, z));
    }
    return poly;
}

// The point of the light's (convex, planar) polygon nearest to p.
TY_FUNC vec3 ltsdNearestPoint(TY_IN(LtsdLight) light, TY_IN(vec3) p) {
    vec3 q = p - ltsdPlaneDistance(light, p) * light.normal;  // p projected onto the plane
    bool inside = true;
    float best = kInfinity;
    vec3 nearest = q;
    for (int i = 0; i < kLtsdLightLoopVertices; ++i) {
        if (i < light.vertexCount) {
            vec3 a = vec3(light.vertices[i]);
            vec3 b = vec3(ltsdNextLightVertex(light, i));
            vec3 e = b - a;
            if (dot(cross(e, q - a), light.normal) < 0.0f) inside = false;
            float t = clamp(dot(q - a, e) / max(dot(e, e), 1e-30f), 0.0f, 1.0f);
            vec3 c = a + t * e;
            float d2 = dot(q - c, q - c);
            if (d2 < best) {
                best = d2;
                nearest = c;
            }
        }
    }
    return inside ? q : nearest;
}

// The aggregated transmittance from p towards the light divided by its solid angle: the mean of e^(-sigma_t r) over
// the directions towards it, which multiplies S (Eq. 13-14) and E (Eq. 11-12). Eq. 10 writes T(p) = e^(-mu_t d) A(p)
// and Eq. 11/13 multiply the integrals over A; dimensionally the split sum multiplies by the mean, T(p) / A(p), which
// is what this returns (docs/ltsd.md). Only the path inside the medium attenuates.
TY_FUNC vec3 ltsdMeanTransmittance(TY_IN(LtsdFrame) f, TY_IN(LtsdLight) light, TY_IN(vec3) p) {
#ifdef TY_LTSD_NO_MEDIUM
    return vec3(1.0f);
#else
    if (f.hasMedium == 0) return vec3(1.0f);
    if (ltsdTransmittanceMode(f) == kLtsdTransmittanceMinDistance) {
        // Eq. 10 of 000 with d = min over the light of the distance (the paper's choice).
        return exp(-f.sigmaT * ltsdChord(f, p, ltsdNearestPoint(light, p) - p));
    }
    // The mean over the light's solid angle: each fan triangle (v0, v_i, v_i+1) seen from p is a spherical triangle,
    // mapped from [0, 1]^2 uniformly in solid angle (Arvo 1995, sampling.h) with kLtsdTransmittanceGrid^2 midpoint
    // nodes, each weighted by its triangle's solid angle. The ray towards a node meets the light's plane at r = h / cos.
    vec3 sum = vec3(0.0f);
    float weights = 0.0f;
    float h = abs(ltsdPlaneDistance(light, p));
    vec3 a = normalize(vec3(light.vertices[0]) - p);
    for (int i = 1; i + 1 < kLtsdLightLoopVertices; ++i) {
        if (i + 1 < light.vertexCount) {
            vec3 b = normalize(vec3(light.vertices[i]) - p);
            vec3 c = normalize(vec3(light.vertices[i + 1]) - p);
            // The weight from Van Oosterom and Strackee's formula, accurate for tiny triangles too (far lights),
            // where the sampler's own area from the interior angles is not.
            float omega = sphericalTriangleSolidAngle(a, b, c);
            for (int k = 0; k < kLtsdTransmittanceGrid * kLtsdTransmittanceGrid; ++k) {
                int ku = k / kLtsdTransmittanceGrid, kv = k - ku * kLtsdTransmittanceGrid;
                vec2 u = (vec2(float(ku), float(kv)) + 0.5f) / float(kLtsdTransmittanceGrid);
                float unused;
                vec3 w = sampleSphericalTriangle(a, b, c, u, unused);
                float r = h / max(abs(dot(w, light.normal)), 1e-6f);
                sum += omega * exp(-f.sigmaT * ltsdChord(f, p, r * w));
                weights += omega;
            }
        }
    }
    return weights > 0.0f ? sum / weights : vec3(1.0f);
#endif
}

// The medium's true phase function at mu (the kinds the technique accepts), for the ratio estimators.
TY_FUNC float ltsdTruePhase(TY_IN(LtsdFrame) f, float mu) {
    if (f.phaseKind == kPhaseHenyeyGreenstein) return henyeyGreenstein(mu, f.g);
    if (f.phaseKind == kPhaseIsoHgMix) return (1.0f - f.phaseA) * kInvFourPi + f.phaseA * henyeyGreenstein(mu, f.g);
    if (f.phaseKind == kPhaseRayleigh) return 3.0f / (16.0f * kPi) * (1.0f + mu * mu);
    if (f.phaseKind == kPhaseEddington) return kInvFourPi * (1.0f + f.phaseB * mu);
    if (f.phaseKind == kPhaseHazyMie || f.phaseKind == kPhaseMurkyMie)
        return kInvFourPi * (0.5f + mieLobe(mieLobeExponent(f.phaseKind), mu));
    return kInvFourPi;
}

// ---------------------------------------------------------------------------------------------------------------------
// Radiance

// Eq. 14 without L_i's transmittance split: L_s(z) = L_i T_mean(z) S(z, A(z)) for one light, at the point z of a ray
// with unit direction `dir` (omega_o = -dir, the +z axis of the LTSD frame).
TY_FUNC vec3 ltsdInScattered(TY_IN(LtsdFrame) f, TY_IN(LtsdLight) light, TY_IN(vec3) z, TY_IN(vec3) tx,
                             TY_IN(vec3) ty, TY_IN(vec3) wo) {
    if (!ltsdFacing(light, z)) return vec3(0.0f);
    SphericalPolygon polygon = ltsdLocalPolygon(light, z, tx, ty, wo);
    float s;
    if (ltsdSMethod(f) == kLtsdSMethodAccurate)  // the boundary form of the lobe, plus the exact part
        s = ltsdAccuratePhaseIntegral(polygon, ltsdSLobe(f), f.g, f.sLobeWeight, f.phaseIsotropic, f.phaseLinear);
    else  // Eq. 21 for the fitted lobe, plus the phase function's exact isotropic and linear part
        s = ltsdPhaseIntegral(polygon, f.upper, f.lower, f.phaseIsotropic, f.phaseLinear);
    return light.radiance * ltsdMeanTransmittance(f, light, z) * s;
}

// Node i of N on [a, b] for the placement: its position in x, its weight (the Delta z of Eq. 15) in y. `sigma` is the
// grey extinction for the transmittance placement; `centre` holds the light's centre's foot on the ray (t) and the
// equiangular distance D for the equiangular placement.
TY_FUNC vec2 ltsdNode(int placement, int i, int n, float a, float b, float sigma, TY_IN(vec2) centre) {
    float u = (float(i) + 0.5f) / float(n);
    if (placement == kLtsdPlacementEquiangular) {
        // t = t_c + D tan(theta), theta uniform: dt = D / cos^2(theta) dtheta.
        float thetaA = atan((a - centre.x) / centre.y), thetaB = atan((b - centre.x) / centre.y);
        float theta = mix(thetaA, thetaB, u);
        float c = cos(theta);
        return vec2(centre.x + centre.y * tan(theta), centre.y * (thetaB - thetaA) / (float(n) * c * c));
    }
    if (placement == kLtsdPlacementTransmittance) {
        // Equal parts of int_a^b e^(-sigma (t - t_in)) dt: t = a - ln(1 - u (1 - e^(-sigma L))) / sigma, weight
        // (1 - e^(-sigma L)) / (sigma N) e^(sigma (t - a)) (the midpoint rule in the transformed variable).
        float span = b - a;
        if (sigma * span > 1e-4f) {
            float mass = 1.0f - exp(-sigma * span);
            float t = a - log(1.0f - u * mass) / sigma;
            return vec2(t, mass / (sigma * float(n)) * exp(sigma * (t - a)));
        }
    }
    return vec2(mix(a, b, u), (b - a) / float(n));
}

// The air-light of one light over the camera segment [a, b] of the medium (Eq. 15's first term without mu_s):
// sum_i T(y, z_i) L_s(z_i) Delta z_i, with T(y, z) = e^(-sigma_t (t - tIn)).
TY_FUNC vec3 ltsdAirLightPart(TY_IN(LtsdFrame) f, TY_IN(LtsdLight) light, TY_IN(vec3) origin, TY_IN(vec3) dir,
                              float a, float b, float tIn) {
    vec3 sum = vec3(0.0f);
    if (!(b > a)) return sum;
    vec3 tx, ty;
    buildFrame(-dir, tx, ty);
    float sigma = (f.sigmaT.x + f.sigmaT.y + f.sigmaT.z) / 3.0f;
    float foot = dot(light.centre - origin, dir);
    // The equiangular distance: the centre's distance from the ray, widened by the light's radius so that a ray that
    // passes close to a large light spreads its nodes over the light's extent rather than around its centre alone.
    vec3 off = light.centre - (origin + foot * dir);
    float D = sqrt(dot(off, off) + light.radius2) + 1e-6f * (1.0f + abs(foot));
    int placement = ltsdPlacement(f);
    for (int i = 0; i < f.nodes; ++i) {
        vec2 node = ltsdNode(placement, i, f.nodes, a, b, sigma, vec2(foot, D));
        vec3 z = origin + node.x * dir;
        sum += exp(-f.sigmaT * (node.x - tIn)) * ltsdInScattered(f, light, z, tx, ty, -dir) * node.y;
    }
    return sum;
}

// The air-light of one light over [t0, t1]: only the part of the ray on the emitting side of the light's plane can be
// lit, so the segment is split where it crosses the plane and each piece the light faces is integrated apart (both,
// for a two-sided light). No node then straddles the plane, where L_s jumps to zero: adjacent rays whose nodes fell on
// either side of it would ring (docs/ltsd.md).
TY_FUNC vec3 ltsdAirLight(TY_IN(LtsdFrame) f, TY_IN(LtsdLight) light, TY_IN(vec3) origin, TY_IN(vec3) dir, float t0,
                          float t1) {
    float s0 = ltsdPlaneDistance(light, origin);
    float ds = dot(light.normal, dir);
    float tc = abs(ds) > 1e-30f ? clamp(-s0 / ds, t0, t1) : t1;
    vec3 sum = vec3(0.0f);
    for (int piece = 0; piece < 2; ++piece) {
        float a = piece == 0 ? t0 : tc, b = piece == 0 ? tc : t1;
        if (!(b > a)) continue;
        float side = s0 + 0.5f * (a + b) * ds;
#ifdef TY_LTSD_ONE_SIDED
        bool lit = side > 0.0f;
#else
        bool lit = side > 0.0f || (light.twoSided != 0 && side < 0.0f);
#endif
        if (lit) sum += ltsdAirLightPart(f, light, origin, dir, a, b, t0);
    }
    return sum;
}

// What the analytic surface term (Eq. 11-12 with Eq. 8) needs at a hit, once for all lights: the frame in which the
// light's polygon is integrated and the lobe. Diffuse: the shading frame and the exact clamped cosine (BRDF albedo /
// pi, so int f cos = albedo E). Isotropic GGX: the LTC frame (omega_o in its xz-plane), M^-1 of the bilinearly fetched
// table entry and Schlick's hemispherical moment F0 (norm - fresnel) + fresnel (docs/tables.md, "LTC GGX tables").
// Anisotropic GGX: the shading frame (x the tangent), M^-1 of the quadrilinearly fetched canonical entry times F S,
// the symmetries' map into its frame (002 Eq. 13-14).
struct LtsdSurfaceLobe {
    vec3 x;  // the polygon's frame (x, y, n)
    vec3 y;
    vec3 n;
    int ggx;      // 1: the LTC of mInv; 0: the clamped cosine
    mat3 mInv;    // GGX: M^-1
    vec3 weight;  // diffuse: albedo; GGX: int f cos over the hemisphere with Schlick's Fresnel (0 seen from below)
};

TY_FUNC LtsdSurfaceLobe ltsdSurfaceLobe(TY_IN(LtsdFrame) f, TY_IN(MaterialParams) material, TY_IN(SurfaceFrame) frame,
                                        TY_IN(vec3) wo) {
    LtsdSurfaceLobe lobe;
    lobe.x = frame.t;
    lobe.y = frame.b;
    lobe.n = frame.n;
    lobe.ggx = 0;
    lobe.mInv = mat3(1.0f);
    lobe.weight = material.albedo;
#ifndef TY_LTSD_NO_GGX
    if (material.kind == kMaterialGgx) {
        lobe.ggx = 1;
        float cosTheta = dot(wo, frame.n);
        vec3 tangent = wo - cosTheta * frame.n;
        float l = length(tangent);
        if (l > 1e-6f) lobe.x = tangent / l;
        lobe.y = cross(frame.n, lobe.x);
        LtcEntry e;
#ifndef TY_LTSD_NO_ANISOTROPIC
        if (material.alphaX != material.alphaY) {
            lobe.x = frame.t;
            lobe.y = frame.b;
            LtcQuadrilinear q =
                ltcFetchAnisotropic(material.alphaX, material.alphaY, surfaceToLocal(frame, wo), f.ltcAnisoThetaCount,
                                    f.ltcAnisoPhiCount, f.ltcAnisoAlphaCount, f.ltcAnisoRatioCount,
                                    f.ltcAnisoAlphaMin, f.ltcAnisoRatioMin);
            e = ltcZeroEntry();
            for (int k = 0; k < 16; ++k)
                e = ltcAddWeighted(e, ltsdLtcEntry(f.ltcAnisoBase + ltcCornerIndex(q, k)), ltcCornerWeight(q, k));
            lobe.mInv = ltsdInverse(ltcMatrix(e)) * q.toCanonical;
        } else
#endif
        {
            LtcBilinear b =
                ltcFetchIsotropic(material.alphaX, cosTheta, f.ltcXCount, f.ltcAlphaCount, f.ltcAlphaMin);
            e = ltcBilinearBlend(ltsdLtcEntry(b.i00), ltsdLtcEntry(b.i10), ltsdLtcEntry(b.i01), ltsdLtcEntry(b.i11),
                                 b);
            lobe.mInv = ltsdInverse(ltcMatrix(e));
        }
        lobe.weight = cosTheta > 0.0f ? ltcFresnelNorm(e, material.f0) : vec3(0.0f);
    }
#endif
    return lobe;
}

// int over the light's polygon of f cos, approximately (GGX) or exactly (diffuse), seen from xs.
TY_FUNC vec3 ltsdSurfaceIntegral(TY_IN(LtsdSurfaceLobe) lobe, TY_IN(LtsdLight) light, TY_IN(vec3) xs) {
    SphericalPolygon p = ltsdLocalPolygon(light, xs, lobe.x, lobe.y, lobe.n);
#ifndef TY_LTSD_NO_GGX
    // Eq. 8 of 000: the LTC's integral, the clamped cosine's over M^-1 of the polygon clipped to the horizon.
    if (lobe.ggx != 0) return lobe.weight * ltcPolygonIntegral(lobe.mInv, p);
#endif
    // Eq. 12: E of the polygon in the shading frame, clipped at its horizon.
    return lobe.weight * ltsdClampedCosineIntegral(p);
}

// The BRDF of the ratio estimators' surface samples: albedo / pi for diffuse (for any view, as the analytic term), the
// shared GGX (bsdf.h) otherwise; wo and wi in the shading frame.
TY_FUNC vec3 ltsdSurfaceBrdf(TY_IN(MaterialParams) material, TY_IN(vec3) wo, TY_IN(vec3) wi) {
#ifndef TY_LTSD_NO_GGX
    if (material.kind == kMaterialGgx) return bsdfEval(material, wo, wi);
#endif
    return material.albedo * kInvPi;
}

// The radiance along the camera ray through the image point (x, y) in pixel coordinates, Eq. 15 in its two terms: the
// quadrature of the air-light (`air`, A-bar) and the attenuated analytic surface radiance (Eq. 12) of the surface
// behind (`surface`, T(y, x) L_c-bar). `sampleIndex`: the ray's record in the rasterised primary hits (primary_hits.h),
// or -1 to trace it.
TY_FUNC void ltsdRayTerms(TY_IN(LtsdFrame) f, float x, float y, int sampleIndex, TY_OUT(vec3) air,
                          TY_OUT(vec3) surface) {
    vec3 origin, dir;
    cameraRay(f.camera, x, y, origin, dir);
    air = vec3(0.0f);
    surface = vec3(0.0f);
#ifdef TY_LTSD_NO_SURFACES
    float tEnd = kInfinity;
#else
    BvhHit hit;
    bool hasHit = primaryIntersect(sampleIndex, origin, dir, hit);
    float tEnd = hasHit ? hit.t : kInfinity;
#endif
#ifndef TY_LTSD_NO_MEDIUM
    if (f.hasMedium != 0) {
        vec2 seg = ltsdMediumSegment(f, origin, dir, 0.0f, tEnd);
        seg.y = min(seg.y, seg.x + f.tailDistance);
        if (seg.y > seg.x) {
            for (int l = 0; l < kLtsdMaxLights; ++l) {
                if (l >= ltsdLightCount(f)) break;
                air += ltsdAirLight(f, ltsdLight(l), origin, dir, seg.x, seg.y);
            }
            air *= f.sigmaS;
        }
    }
#endif
#ifndef TY_LTSD_NO_SURFACES
    if (hasHit) {
        SurfaceTriangle st = ltsdTriangle(int(hit.id));
        SurfaceFrame frame = surfaceFrame(st, hit.uv, dir);
        MaterialParams material = ltsdMaterial(st.material);
        vec3 xs = origin + hit.t * dir;
        LtsdSurfaceLobe lobe = ltsdSurfaceLobe(f, material, frame, -dir);
        vec3 reflected = vec3(0.0f);
        for (int l = 0; l < kLtsdMaxLights; ++l) {
            if (l >= ltsdLightCount(f)) break;
            LtsdLight light = ltsdLight(l);
            if (!ltsdFacing(light, xs)) continue;
            reflected += light.radiance * ltsdMeanTransmittance(f, light, xs) * ltsdSurfaceIntegral(lobe, light, xs);
        }
        surface = exp(-f.sigmaT * ltsdChord(f, origin, hit.t * dir)) * reflected;
    }
#endif
}

TY_FUNC vec3 ltsdRay(TY_IN(LtsdFrame) f, float x, float y) {
    vec3 air, surface;
    ltsdRayTerms(f, x, y, -1, air, surface);
    return air + surface;
}

// The pixel (px, py): the means of its S x S rays on a regular grid, a box filter like the reference's, in its two
// terms.
TY_FUNC void ltsdPixelTerms(TY_IN(LtsdFrame) f, int px, int py, TY_OUT(vec3) air, TY_OUT(vec3) surface) {
    int S = max(f.supersampling, 1);
    air = vec3(0.0f);
    surface = vec3(0.0f);
    for (int k = 0; k < S * S; ++k) {
        int sy = k / S, sx = k - sy * S;
        vec2 point = primarySamplePoint(S, px, py, sx, sy);
        vec3 a, c;
        ltsdRayTerms(f, point.x, point.y, primarySampleIndex(int(f.camera.width), S, px, py, sx, sy), a, c);
        air += a;
        surface += c;
    }
    air /= float(S * S);
    surface /= float(S * S);
}

TY_FUNC vec3 ltsdPixel(TY_IN(LtsdFrame) f, int px, int py) {
    vec3 air, surface;
    ltsdPixelTerms(f, px, py, air, surface);
    return air + surface;
}

// ---------------------------------------------------------------------------------------------------------------------
// Ratio estimators for shadows (Sec. 6)

// One camera sample's Monte Carlo estimates of the numerators (with visibility) and denominators (without) of the
// ratio estimators of Eq. 22 for the air-light and of its counterpart for the surface: the true phase function and
// transmittance, every light with one point sampled uniformly on its area and, for the air-light, one distance
// sampled equiangularly from its centre. Numerator and denominator share every sample, so their ratio is far less
// noisy than either.
struct LtsdRatioTerms {
    vec3 airNumerator;
    vec3 airDenominator;
    vec3 surfaceNumerator;
    vec3 surfaceDenominator;
};

// A point uniform on the light's area (a fan triangle chosen by area, then a point in it); returns 1 / pdf (the area).
TY_FUNC float ltsdSampleLightPoint(TY_IN(LtsdLight) light, TY_IN(vec2) u, TY_IN(float) uTriangle, TY_OUT(vec3) q) {
    vec3 a = vec3(light.vertices[0]);
    float total = 0.0f;
    for (int i = 1; i + 1 < kLtsdLightLoopVertices; ++i) {
        if (i + 1 < light.vertexCount)
            total += length(cross(vec3(light.vertices[i]) - a, vec3(light.vertices[i + 1]) - a));
    }
    float target = uTriangle * total, running = 0.0f;
    q = a;
    bool chosen = false;
    for (int i = 1; i + 1 < kLtsdLightLoopVertices; ++i) {
        if (i + 1 < light.vertexCount && !chosen) {
            vec3 b = vec3(light.vertices[i]), c = vec3(light.vertices[i + 1]);
            running += length(cross(b - a, c - a));
            if (target <= running || i + 2 >= light.vertexCount) {
                float su = sqrt(u.x);
                q = (1.0f - su) * a + su * (1.0f - u.y) * b + su * u.y * c;
                chosen = true;
            }
        }
    }
    return 0.5f * total;
}

TY_FUNC LtsdRatioTerms ltsdRatioSample(TY_IN(LtsdFrame) f, int px, int py, uint index, uint seed) {
    LtsdRatioTerms r;
    r.airNumerator = vec3(0.0f);
    r.airDenominator = vec3(0.0f);
    r.surfaceNumerator = vec3(0.0f);
    r.surfaceDenominator = vec3(0.0f);
    uint pixelSeed = hashCombine(seed, uint(py) * 65536u + uint(px));
    vec2 jitter = sobolSample2D(pixelSeed, index, 0u);
    vec3 origin, dir;
    cameraRay(f.camera, float(px) + jitter.x, float(py) + jitter.y, origin, dir);
#ifdef TY_LTSD_NO_SURFACES
    float tEnd = kInfinity;
#else
    BvhHit hit;
    bool hasHit = bvhIntersect(origin, dir, 0.0f, kInfinity, hit);
    float tEnd = hasHit ? hit.t : kInfinity;
#endif
    for (int l = 0; l < kLtsdMaxLights; ++l) {
        if (l >= ltsdLightCount(f)) break;
        LtsdLight light = ltsdLight(l);
        uint pair = 1u + 4u * uint(l);
#ifndef TY_LTSD_NO_MEDIUM
        vec2 seg = f.hasMedium != 0 ? ltsdMediumSegment(f, origin, dir, 0.0f, tEnd) : vec2(0.0f);
        seg.y = min(seg.y, seg.x + f.tailDistance);
        if (f.hasMedium != 0 && seg.y > seg.x) {
            vec2 ud = sobolSample2D(pixelSeed, index, pair);
            vec2 uq = sobolSample2D(pixelSeed, index, pair + 1u);
            Equiangular e = equiangularSetup(origin, dir, light.centre, seg.x, seg.y);
            float pdfT;
            float t = equiangularSample(e, ud.x, pdfT);
            vec3 z = origin + t * dir;
            vec3 q;
            float area = ltsdSampleLightPoint(light, uq, ud.y, q);
            vec3 v = q - z;
            float r2 = dot(v, v);
            float rl = sqrt(r2);
            vec3 wi = v / rl;
            float cosLight = -dot(wi, light.normal);
#ifndef TY_LTSD_ONE_SIDED
            if (light.twoSided != 0) cosLight = abs(cosLight);
#endif
            if (cosLight > 0.0f && pdfT > 0.0f && r2 > 0.0f) {
                // Eq. 1-2 with the true phase function (mu = dot(d, omega_i)) and the true transmittance on both legs.
                vec3 value = exp(-f.sigmaT * (t - seg.x + ltsdChord(f, z, v))) * f.sigmaS * light.radiance *
                             (ltsdTruePhase(f, dot(dir, wi)) * cosLight / r2 * area / pdfT);
                r.airDenominator += value;
                if (!bvhOccluded(z, wi, 0.0f, rl * (1.0f - 1e-4f))) r.airNumerator += value;
            }
        }
#endif
#ifndef TY_LTSD_NO_SURFACES
        if (hasHit) {
            vec2 uq = sobolSample2D(pixelSeed, index, pair + 2u);
            SurfaceTriangle st = ltsdTriangle(int(hit.id));
            SurfaceFrame frame = surfaceFrame(st, hit.uv, dir);
            MaterialParams material = ltsdMaterial(st.material);
            vec3 xs = origin + hit.t * dir;
            vec3 q;
            float area = ltsdSampleLightPoint(light, uq, sobolSample2D(pixelSeed, index, pair + 3u).x, q);
            vec3 v = q - xs;
            float r2 = dot(v, v);
            float rl = sqrt(r2);
            vec3 wi = v / rl;
            float cosLight = -dot(wi, light.normal);
#ifndef TY_LTSD_ONE_SIDED
            if (light.twoSided != 0) cosLight = abs(cosLight);
#endif
            float cosSurface = dot(wi, frame.ng) > 0.0f ? dot(wi, frame.n) : 0.0f;
            if (cosLight > 0.0f && cosSurface > 0.0f && r2 > 0.0f) {
                vec3 brdf = ltsdSurfaceBrdf(material, surfaceToLocal(frame, -dir), surfaceToLocal(frame, wi));
                vec3 value = exp(-f.sigmaT * ltsdChord(f, xs, v)) * brdf * light.radiance *
                             (cosSurface * cosLight / r2 * area);
                r.surfaceDenominator += value;
                if (!bvhOccluded(xs + f.rayOffset * frame.ng, wi, 0.0f, rl * (1.0f - 1e-4f)))
                    r.surfaceNumerator += value;
            }
        }
#endif
    }
    return r;
}

TY_END

#endif  // TY_SHARED_LTSD_SCENE_H
