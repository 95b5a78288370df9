// The triangle BVH for visibility on the GPU: a binned-SAH build on the CPU into the layout of shaders/shared/bvh.h,
// and the binding that lets C++ run the shared traversal (bvhOccluded, bvhIntersect) on it, for tests and CPU paths.
#pragma once

#include "shared/bvh.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace tyndall {
struct TriangleMesh;
}

namespace tyndall::gpu {

// Arrays ready to upload as two std430 storage buffers. nodes is never empty (node 0 is the root).
struct Bvh {
    std::vector<shader::BvhNode> nodes;
    std::vector<shader::BvhTriangle> triangles;
    std::vector<std::uint32_t> triangleIds;  // per entry of `triangles`: its index in the input (= triangles[i].id)
};

// A deterministic binned-SAH build (16 bins per axis, leaves of at most shader::kBvhMaxLeafSize triangles, depth below
// shader::kBvhStackSize). Triangles keep their winding. No triangles give a lone root that no ray enters.
Bvh buildBvh(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles);
// Several meshes in one BVH; triangle ids count through the meshes in order (mesh 0's triangles first).
Bvh buildBvh(const std::vector<TriangleMesh>& meshes);

// Binds a BVH to the calling thread for the C++ definitions of shader::bvhNode and shader::bvhTriangle, so that the
// shared traversal runs on it. Scopes nest (the previous binding comes back on destruction); the BVH must outlive it.
class BvhScope {
public:
    explicit BvhScope(const Bvh& bvh);
    ~BvhScope();
    BvhScope(const BvhScope&) = delete;
    BvhScope& operator=(const BvhScope&) = delete;

private:
    const Bvh* previous_;
};

}  // namespace tyndall::gpu
