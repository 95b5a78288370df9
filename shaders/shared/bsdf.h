// Surface scattering shared by GLSL and C++: Lambertian diffuse and anisotropic GGX with height-correlated Smith
// masking-shadowing and Schlick's Fresnel. Directions are in the local shading frame (normal = +z); wo points towards
// the viewer, wi towards the light, both away from the surface.
#ifndef TY_SHARED_BSDF_H
#define TY_SHARED_BSDF_H

#include "compat.h"
#include "constants.h"
#include "sampling.h"

TY_BEGIN

TY_CONST int kMaterialDiffuse = 0;
TY_CONST int kMaterialGgx = 1;

struct MaterialParams {
    int kind;       // kMaterialDiffuse or kMaterialGgx
    float alphaX;   // GGX roughness along the tangent
    float alphaY;   // GGX roughness along the bitangent
    float pad0;
    vec3 albedo;    // diffuse reflectance
    float pad1;
    vec3 f0;        // GGX Fresnel at normal incidence
    float pad2;
};

// GGX normal distribution D(h), anisotropic (Trowbridge-Reitz).
TY_FUNC float ggxD(TY_IN(vec3) h, float ax, float ay) {
    if (h.z <= 0.0f) return 0.0f;
    float x = h.x / ax, y = h.y / ay;
    float s = x * x + y * y + h.z * h.z;
    return 1.0f / (kPi * ax * ay * s * s);
}

// Smith Lambda for GGX.
TY_FUNC float ggxLambda(TY_IN(vec3) w, float ax, float ay) {
    float cos2 = w.z * w.z;
    if (cos2 <= 0.0f) return 0.0f;
    float tan2Alpha2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / cos2;
    return 0.5f * (-1.0f + sqrt(1.0f + tan2Alpha2));
}

TY_FUNC float ggxG1(TY_IN(vec3) w, float ax, float ay) { return 1.0f / (1.0f + ggxLambda(w, ax, ay)); }

// Height-correlated masking-shadowing.
TY_FUNC float ggxG2(TY_IN(vec3) wo, TY_IN(vec3) wi, float ax, float ay) {
    return 1.0f / (1.0f + ggxLambda(wo, ax, ay) + ggxLambda(wi, ax, ay));
}

TY_FUNC vec3 fresnelSchlick(TY_IN(vec3) f0, float cosTheta) {
    float m = clamp(1.0f - cosTheta, 0.0f, 1.0f);
    float m2 = m * m;
    return f0 + (vec3(1.0f) - f0) * (m2 * m2 * m);
}

// f(wo, wi) (without the cosine).
TY_FUNC vec3 bsdfEval(TY_IN(MaterialParams) m, TY_IN(vec3) wo, TY_IN(vec3) wi) {
    if (wo.z <= 0.0f || wi.z <= 0.0f) return vec3(0.0f);
    if (m.kind == kMaterialDiffuse) return m.albedo * kInvPi;
    vec3 h = normalize(wo + wi);
    float d = ggxD(h, m.alphaX, m.alphaY);
    float g = ggxG2(wo, wi, m.alphaX, m.alphaY);
    return fresnelSchlick(m.f0, dot(wi, h)) * (d * g / (4.0f * wo.z * wi.z));
}

// A visible normal of GGX for view direction wo (Heitz 2018, "Sampling the GGX Distribution of Visible Normals").
TY_FUNC vec3 ggxSampleVisibleNormal(TY_IN(vec3) wo, float ax, float ay, TY_IN(vec2) u) {
    vec3 vh = normalize(vec3(ax * wo.x, ay * wo.y, wo.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0f ? vec3(-vh.y, vh.x, 0.0f) * inversesqrt(lensq) : vec3(1.0f, 0.0f, 0.0f);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x);
    float phi = kTwoPi * u.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrt(max(0.0f, 1.0f - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(ax * nh.x, ay * nh.y, max(1e-6f, nh.z)));
}

// Density of a visible normal h for view wo: G1(wo) max(0, wo.h) D(h) / wo.z.
TY_FUNC float ggxVisibleNormalPdf(TY_IN(vec3) wo, TY_IN(vec3) h, float ax, float ay) {
    if (wo.z <= 0.0f) return 0.0f;
    return ggxG1(wo, ax, ay) * max(0.0f, dot(wo, h)) * ggxD(h, ax, ay) / wo.z;
}

// Solid-angle pdf of bsdfSample's wi.
TY_FUNC float bsdfPdf(TY_IN(MaterialParams) m, TY_IN(vec3) wo, TY_IN(vec3) wi) {
    if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
    if (m.kind == kMaterialDiffuse) return wi.z * kInvPi;
    vec3 h = normalize(wo + wi);
    return ggxVisibleNormalPdf(wo, h, m.alphaX, m.alphaY) / (4.0f * dot(wo, h));
}

// Samples wi: cosine-weighted for diffuse, reflected visible normals for GGX. Returns wi; pdf may be 0 when the sample
// leaves the upper hemisphere (the caller drops it).
TY_FUNC vec3 bsdfSample(TY_IN(MaterialParams) m, TY_IN(vec3) wo, TY_IN(vec2) u, TY_OUT(float) pdf) {
    vec3 wi;
    if (m.kind == kMaterialDiffuse) {
        wi = sampleCosineHemisphere(u);
    } else {
        vec3 h = ggxSampleVisibleNormal(wo, m.alphaX, m.alphaY, u);
        wi = reflect(-wo, h);
    }
    pdf = bsdfPdf(m, wo, wi);
    return wi;
}

TY_END

#endif  // TY_SHARED_BSDF_H
