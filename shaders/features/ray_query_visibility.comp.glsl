// Shadow-ray visibility with ray queries (VK_KHR_ray_query): for each ray of the input buffer, whether anything in the
// acceleration structure blocks it between tMin and tMax. Opaque geometry only, so the first hit decides and no
// candidate needs confirming. Compiled and validated in CI (tests/CMakeLists.txt); not run on machines without ray
// queries.
#version 460
#extension GL_EXT_ray_query : require

layout(local_size_x = 64) in;

struct VisibilityRay {
    vec4 originTMin;     // xyz: origin in world space; w: tMin >= 0
    vec4 directionTMax;  // xyz: direction in world space (need not be unit length); w: tMax in units of |direction|
};

layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;
layout(std430, set = 0, binding = 1) readonly buffer Rays { VisibilityRay rays[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Occluded { uint occluded[]; };  // 1 occluded, 0 visible

layout(push_constant) uniform Push {
    uint count;     // number of rays
    uint cullMask;  // instance mask, 0xFF for everything
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    VisibilityRay ray = rays[i];

    rayQueryEXT query;
    rayQueryInitializeEXT(query, scene, gl_RayFlagsOpaqueEXT | gl_RayFlagsTerminateOnFirstHitEXT, pc.cullMask & 0xFFu,
                          ray.originTMin.xyz, ray.originTMin.w, ray.directionTMax.xyz, ray.directionTMax.w);
    while (rayQueryProceedEXT(query)) {
        // Opaque rays produce no candidates to confirm; the traversal commits hits by itself.
    }
    bool hit = rayQueryGetIntersectionTypeEXT(query, true) != gl_RayQueryCommittedIntersectionNoneEXT;
    occluded[i] = hit ? 1u : 0u;
}
