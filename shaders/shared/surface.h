// Surface shading data per triangle and the shading frame at a hit, shared by the GPU renderers and their CPU paths.
// The conventions are the reference's (docs/conventions.md, "Surfaces"): the geometric normal is flipped to face the
// incoming ray, the interpolated shading normal (when the mesh has vertex normals) is flipped to the same side, and
// light counts only from directions above both. The GGX tangent is the mesh's tangent projected onto the surface.
//
// Compile-time variant (GpuSurfaces::shaderDefines sets it from the scene; the CPU paths do not):
//   TY_SURFACE_NO_TANGENTS  every material is diffuse: the frame's tangent is any one (buildFrame), not the mesh's
// so that a kernel does not read what the scene lacks: each field read at a per-pixel triangle is a gather, lane by
// lane, on lavapipe (the tangent: about 2 of the LTSD room's 15 ms kernel). The vertex normals are read under their
// own condition (hasNormals), which costs nothing measurable where a triangle has none.
#ifndef TY_SHARED_SURFACE_H
#define TY_SHARED_SURFACE_H

#include "bsdf.h"
#include "compat.h"
#include "sampling.h"

TY_BEGIN

// Per triangle, indexed by BvhTriangle::id, 80 bytes (std430).
struct SurfaceTriangle {
    vec3 n0;       // vertex normals (unused when hasNormals == 0)
    int material;  // index into the material array
    vec3 n1;
    int hasNormals;  // 1 when the mesh has vertex normals
    vec3 n2;
    float pad0;
    vec3 tangent;  // the mesh's GGX tangent, world space
    float pad1;
    vec3 ng;  // unit geometric normal, in the winding's right-hand direction
    float pad2;
};

// The frame at a hit of a ray with direction `dir` at barycentrics uv (of vertices 1 and 2).
struct SurfaceFrame {
    vec3 ng;  // geometric normal, facing the ray's origin
    vec3 n;   // shading normal, on ng's side
    vec3 t;   // tangent
    vec3 b;   // bitangent = n x t
};

TY_FUNC SurfaceFrame surfaceFrame(TY_IN(SurfaceTriangle) st, TY_IN(vec2) uv, TY_IN(vec3) dir) {
    SurfaceFrame f;
    f.ng = st.ng;
    if (dot(f.ng, dir) > 0.0f) f.ng = -f.ng;
    f.n = f.ng;
    if (st.hasNormals != 0) {
        vec3 ns = normalize((1.0f - uv.x - uv.y) * st.n0 + uv.x * st.n1 + uv.y * st.n2);
        if (dot(ns, f.ng) < 0.0f) ns = -ns;
        f.n = ns;
    }
#ifdef TY_SURFACE_NO_TANGENTS
    buildFrame(f.n, f.t, f.b);
    return f;
#endif
    f.t = st.tangent - dot(st.tangent, f.n) * f.n;
    if (dot(f.t, f.t) < 1e-8f) {
        buildFrame(f.n, f.t, f.b);
    }
    f.t = normalize(f.t);
    f.b = cross(f.n, f.t);
    return f;
}

TY_FUNC vec3 surfaceToLocal(TY_IN(SurfaceFrame) f, TY_IN(vec3) v) {
    return vec3(dot(v, f.t), dot(v, f.b), dot(v, f.n));
}

// BSDF times the cosine for light arriving from direction wi (unit, towards the light) and leaving towards wo; zero
// from below either normal.
TY_FUNC vec3 surfaceReflect(TY_IN(MaterialParams) m, TY_IN(SurfaceFrame) f, TY_IN(vec3) wo, TY_IN(vec3) wi) {
    vec3 wiLocal = surfaceToLocal(f, wi);
    if (wiLocal.z <= 0.0f || dot(wi, f.ng) <= 0.0f) return vec3(0.0f);
    return bsdfEval(m, surfaceToLocal(f, wo), wiLocal) * wiLocal.z;
}

TY_END

#endif  // TY_SHARED_SURFACE_H
