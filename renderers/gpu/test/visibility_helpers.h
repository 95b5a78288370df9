// Helpers shared by the tests that check visibility on the bundled projects (test_bvh.cpp, test_visibility.cpp,
// test_lit_intervals.cpp): the same triangles in Embree, which the reference renders with, and random rays through a
// scene's bounds.
#pragma once

#include "tyndall/core/geometry.h"

#include "shared/bvh.h"
#include "shared/rng.h"

#include <embree3/rtcore.h>
#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

namespace tyndall::gpu::test {

// The same triangles in Embree, configured as the reference configures them (robust, high quality), with the
// triangle ids of buildBvh (meshes concatenated) recovered from geometry and primitive ids.
class EmbreeTriangles {
public:
    explicit EmbreeTriangles(const std::vector<TriangleMesh>& meshes) {
        device_ = rtcNewDevice("threads=1");
        scene_ = rtcNewScene(device_);
        rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
        rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
        std::uint32_t first = 0;
        for (unsigned m = 0; m < meshes.size(); ++m) {
            const TriangleMesh& mesh = meshes[m];
            RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
            void* positions = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                      sizeof(glm::vec3), mesh.positions.size());
            std::memcpy(positions, mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3));
            void* indices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                    sizeof(glm::uvec3), mesh.triangles.size());
            std::memcpy(indices, mesh.triangles.data(), mesh.triangles.size() * sizeof(glm::uvec3));
            rtcCommitGeometry(geometry);
            rtcAttachGeometryByID(scene_, geometry, m);
            rtcReleaseGeometry(geometry);
            firstId_.push_back(first);
            first += std::uint32_t(mesh.triangles.size());
        }
        rtcCommitScene(scene_);
        EXPECT_EQ(rtcGetDeviceError(device_), RTC_ERROR_NONE);
    }
    ~EmbreeTriangles() {
        rtcReleaseScene(scene_);
        rtcReleaseDevice(device_);
    }
    EmbreeTriangles(const EmbreeTriangles&) = delete;
    EmbreeTriangles& operator=(const EmbreeTriangles&) = delete;

    // True when a triangle lies on the ray within (0, tMax).
    bool occluded(const glm::vec3& origin, const glm::vec3& dir, float tMax) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay ray = makeRay(origin, dir, tMax);
        rtcOccluded1(scene_, &context, &ray);
        return ray.tfar < 0.0f;
    }

    // The closest hit within (0, tMax), as the shared traversal reports it.
    bool intersect(const glm::vec3& origin, const glm::vec3& dir, float tMax, shader::BvhHit& hit) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rayHit{};
        rayHit.ray = makeRay(origin, dir, tMax);
        rayHit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene_, &context, &rayHit);
        if (rayHit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
        hit.t = rayHit.ray.tfar;
        hit.id = firstId_[rayHit.hit.geomID] + rayHit.hit.primID;
        hit.uv = glm::vec2(rayHit.hit.u, rayHit.hit.v);
        return true;
    }

private:
    static RTCRay makeRay(const glm::vec3& origin, const glm::vec3& dir, float tMax) {
        RTCRay ray{};
        ray.org_x = origin.x;
        ray.org_y = origin.y;
        ray.org_z = origin.z;
        ray.dir_x = dir.x;
        ray.dir_y = dir.y;
        ray.dir_z = dir.z;
        ray.tnear = 0.0f;
        ray.tfar = tMax;
        ray.mask = 0xffffffffu;
        return ray;
    }

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    std::vector<std::uint32_t> firstId_;
};

// Random rays between random points of the scene's bounds, enlarged by 10 % on every side so that rays also cross
// the surfaces that lie on the bounds (ground planes).
struct RandomRays {
    explicit RandomRays(const std::vector<TriangleMesh>& meshes, std::uint32_t seed)
        : rng(shader::pcg32Seed(seed, 0u)) {
        for (const TriangleMesh& mesh : meshes)
            for (const glm::vec3& p : mesh.positions) {
                lo = glm::min(lo, p);
                hi = glm::max(hi, p);
            }
        glm::vec3 margin = 0.1f * (hi - lo);
        lo -= margin;
        hi += margin;
    }
    glm::vec3 point() {
        glm::vec3 u(shader::pcg32NextFloat(rng), shader::pcg32NextFloat(rng), shader::pcg32NextFloat(rng));
        return lo + u * (hi - lo);
    }
    // A unit direction and the distance to the end point.
    void next(glm::vec3& origin, glm::vec3& dir, float& tMax) {
        origin = point();
        glm::vec3 d = point() - origin;
        tMax = glm::length(d);
        dir = d / tMax;
    }

    shader::Pcg32 rng;
    glm::vec3 lo{1e30f}, hi{-1e30f};
};

// `count` rays of RandomRays as (origin, tMax), (dir, 0), the layout the GPU kernels read.
inline std::vector<glm::vec4> randomRays(const std::vector<TriangleMesh>& meshes, std::uint32_t seed, int count) {
    RandomRays random(meshes, seed);
    std::vector<glm::vec4> rays;
    rays.reserve(2 * std::size_t(count));
    for (int i = 0; i < count; ++i) {
        glm::vec3 origin, dir;
        float tMax;
        random.next(origin, dir, tMax);
        rays.push_back(glm::vec4(origin, tMax));
        rays.push_back(glm::vec4(dir, 0.0f));
    }
    return rays;
}

// How far a hit is from its triangle's nearest edge, in barycentric units.
inline float edgeDistance(const glm::vec2& uv) {
    return std::min({uv.x, uv.y, 1.0f - uv.x - uv.y});
}

}  // namespace tyndall::gpu::test
