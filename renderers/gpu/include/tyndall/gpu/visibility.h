// Visibility on the GPU: whether anything in the scene's triangles blocks a ray between its origin and tMax. What the
// techniques' ratio estimators and Monte Carlo visibility call. Two backends behind one interface:
//  - RayQuery: a bottom-level acceleration structure over all triangles and a top-level one with a single identity
//    instance, traversed by shaders/features/ray_query_visibility.comp.glsl (VK_KHR_ray_query). Chosen whenever the
//    Context was created with ray queries (Context::rayQueryEnabled()).
//  - Bvh: the binned-SAH BVH of tyndall/gpu/bvh.h, built on the CPU, uploaded as two storage buffers and traversed by
//    the shared code of shaders/shared/bvh.h. Everywhere else (lavapipe, or ContextOptions::rayQuery = false).
// Technique kernels that trace their own rays bind bvhNodes() and bvhTriangles(), or topLevel(), directly.
#pragma once

#include "tyndall/gpu/context.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace tyndall {
struct TriangleMesh;
}

namespace tyndall::gpu {

class Buffer;
class ComputeKernel;

class Visibility {
public:
    enum class Backend { Bvh, RayQuery };

    // Builds the backend's structures over all triangles of `meshes` (in order) and compiles its kernel. Throws
    // GpuError for GPU failures. An empty mesh list is allowed: nothing is ever occluded.
    Visibility(Context& context, const std::vector<TriangleMesh>& meshes);
    ~Visibility();
    Visibility(const Visibility&) = delete;
    Visibility& operator=(const Visibility&) = delete;

    Backend backend() const { return backend_; }
    const char* backendName() const;  // "bvh" or "ray query"

    // Rays come as pairs of vec4: (origin.xyz, tMax), (direction.xyz, 0), in world space; the direction need not be
    // unit length and tMax is in units of its length. Returns per ray 1 when a triangle lies on it within (0, tMax),
    // else 0. One submission, waited for. Not thread-safe (calls on one Visibility must not overlap).
    std::vector<std::uint32_t> occluded(const std::vector<glm::vec4>& rays);

    // The BVH backend's storage buffers in the layout of shaders/shared/bvh.h (BvhNode[], BvhTriangle[]); null on the
    // ray-query backend. The triangle buffer holds at least one (unused) entry when there are no triangles.
    Buffer* bvhNodes() const { return nodes_.get(); }
    Buffer* bvhTriangles() const { return triangles_.get(); }
    // The ray-query backend's top-level acceleration structure; VK_NULL_HANDLE on the BVH backend.
    VkAccelerationStructureKHR topLevel() const;

    std::size_t triangleCount() const { return triangleCount_; }

private:
    struct RayQuery;  // acceleration structures, their memory and the ray-query pipeline (visibility.cpp)

    void createBvhBackend(const std::vector<TriangleMesh>& meshes);
    std::vector<std::uint32_t> occludedBvh(const std::vector<glm::vec4>& rays);
    std::vector<std::uint32_t> occludedRayQuery(const std::vector<glm::vec4>& rays);

    Context& context_;
    Backend backend_ = Backend::Bvh;
    std::size_t triangleCount_ = 0;
    std::unique_ptr<Buffer> nodes_, triangles_;
    std::unique_ptr<ComputeKernel> bvhKernel_;
    std::unique_ptr<RayQuery> rayQuery_;
};

}  // namespace tyndall::gpu
