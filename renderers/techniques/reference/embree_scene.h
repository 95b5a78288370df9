// Embree 3 geometry of the reference: the scene's triangles for camera and shadow rays, and the convex volume elements
// (bounded homogeneous media and the tetrahedra of particle media) as user geometry, so that one BVH query returns every
// element a ray passes through with its exact entry and exit distances.
#pragma once

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include <vector>

namespace tyndall::reference {

using glm::vec3;
using glm::vec4;

struct TriangleGeometry {
    std::vector<vec3> positions;
    std::vector<vec3> normals;  // per vertex; empty for flat shading
    std::vector<glm::uvec3> triangles;
};

// A convex volume as the intersection of half-spaces dot(n, x) <= d, stored as (n, d).
struct ConvexVolume {
    std::vector<vec4> planes;
    vec3 boundsMin{0.0f}, boundsMax{0.0f};
};

struct SurfaceHit {
    float t = 0.0f;
    unsigned mesh = 0;      // index into the meshes given to the constructor
    unsigned triangle = 0;
    float u = 0.0f, v = 0.0f;  // barycentrics of vertices 1 and 2
    vec3 geometricNormal{0.0f};  // unit, as Embree's winding gives it
};

struct VolumeHit {
    float t0, t1;           // the part of the ray inside the volume, clipped to the query's [tnear, tfar]
    unsigned volume;        // index into the volumes given to the constructor
};

class EmbreeScene {
public:
    EmbreeScene(const std::vector<TriangleGeometry>& meshes, std::vector<ConvexVolume> volumes);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    bool intersect(const vec3& origin, const vec3& dir, float tnear, float tfar, SurfaceHit& hit) const;
    bool occluded(const vec3& origin, const vec3& dir, float tnear, float tfar) const;
    // Appends every volume the ray overlaps within [tnear, tfar], in no particular order.
    void volumeIntervals(const vec3& origin, const vec3& dir, float tnear, float tfar,
                         std::vector<VolumeHit>& out) const;

    const std::vector<TriangleGeometry>& meshes() const { return meshes_; }
    const std::vector<ConvexVolume>& volumes() const { return volumes_; }
    RTCScene surfaceScene() const { return surfaces_; }

    // Clips [t0, t1] of the ray against a convex volume; false when nothing is left.
    static bool clip(const ConvexVolume& volume, const vec3& origin, const vec3& dir, float& t0, float& t1);

private:
    RTCDevice device_ = nullptr;
    RTCScene surfaces_ = nullptr;
    RTCScene volumeScene_ = nullptr;
    std::vector<TriangleGeometry> meshes_;
    std::vector<ConvexVolume> volumes_;
};

}  // namespace tyndall::reference
