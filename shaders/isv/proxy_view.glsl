// ISV: the projected-tetrahedron proxy of one particle in a proxy pass's view (thesis Sec. 2.3.3, shared/isv.h
// isvProxy), shared by the two producers so that they emit the same triangles: the geometry stage (proxy.geom.glsl,
// which runs everywhere) and the mesh shader (features/isv_proxy.mesh.glsl, where the device has VK_EXT_mesh_shader).
// The view is the camera's perspective one (q = 1 / view depth; tetrahedra reaching in front of the near plane are
// culled, as in the thesis, Sec. 2.3.4) or, with TY_ISV_LIGHT_VIEW, the volumetric shadow map's view of one slab
// (q = depth along the light, or 1 / depth for a point light's frustum; a particle outside the slab has no proxy).
// The includer declares `frame` (IsvFrame) and `view` (IsvView).
#ifndef TY_ISV_PROXY_VIEW_GLSL
#define TY_ISV_PROXY_VIEW_GLSL

#include "isv_view.glsl"

// silhouette 0: nothing to draw.
IsvProxy isvPassProxy(IsvParticle p, int slab) {
    IsvProxy none;
    none.silhouette = 0;
    vec3 v[4] = vec3[](p.v0, p.v1, p.v2, p.v3);
    vec2 s[4];
    vec4 depthAttribute;
#ifdef TY_ISV_LIGHT_VIEW
    IsvLightSpace g = frame.vsm;
    float lo = kInfinity, hi = -kInfinity;
    for (int i = 0; i < 4; ++i) {
        vec3 c = isvGridPoint(g, v[i]);
        s[i] = c.xy / float(g.size) * 2.0f - 1.0f;
        // Screen-affine depth: the distance along the texel's ray (orthographic) or the reciprocal depth
        // (perspective), as for the camera.
        depthAttribute[i] = g.perspective != 0 ? 1.0f / (c.z + g.depthOrigin) : c.z;
        lo = min(lo, c.z);
        hi = max(hi, c.z);
    }
    int slabs = g.slices - 1;
    int first = clamp(int(floor(lo / g.depthStep)), 0, slabs - 1), last = clamp(int(floor(hi / g.depthStep)), 0, slabs - 1);
    if (slab < first || slab > last) return none;
#else
    CameraParams c = view.camera;
    for (int i = 0; i < 4; ++i) {
        vec3 r = v[i] - c.position;
        float z = dot(r, c.forward);
        if (z < view.nearPlane) return none;
        s[i] = vec2(dot(r, c.right) / (z * c.tanHalfFovY * c.aspect), -dot(r, c.up) / (z * c.tanHalfFovY));
        depthAttribute[i] = 1.0f / z;
    }
#endif
    return isvProxy(s[0], s[1], s[2], s[3], depthAttribute);
}

#endif  // TY_ISV_PROXY_VIEW_GLSL
