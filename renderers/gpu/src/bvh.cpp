#include "tyndall/gpu/bvh.h"

#include "tyndall/core/error.h"
#include "tyndall/core/scene.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <type_traits>

namespace tyndall::gpu {

using shader::BvhNode;
using shader::BvhTriangle;

// The shared structs are the GPU layout: std430 puts a vec3 on 16 bytes and the scalar after it in its last 4, which
// is exactly where C++ puts them after a 12-byte glm::vec3.
static_assert(std::is_standard_layout_v<BvhNode> && std::is_trivially_copyable_v<BvhNode>);
static_assert(sizeof(BvhNode) == 32);
static_assert(offsetof(BvhNode, boundsMin) == 0);
static_assert(offsetof(BvhNode, leftOrFirst) == 12);
static_assert(offsetof(BvhNode, boundsMax) == 16);
static_assert(offsetof(BvhNode, countAndMiss) == 28);
static_assert(std::is_standard_layout_v<BvhTriangle> && std::is_trivially_copyable_v<BvhTriangle>);
static_assert(sizeof(BvhTriangle) == 48);
static_assert(offsetof(BvhTriangle, v0) == 0);
static_assert(offsetof(BvhTriangle, id) == 12);
static_assert(offsetof(BvhTriangle, e1) == 16);
static_assert(offsetof(BvhTriangle, pad1) == 28);
static_assert(offsetof(BvhTriangle, e2) == 32);
static_assert(offsetof(BvhTriangle, pad2) == 44);

namespace {

constexpr int kBins = 16;
// Costs of the surface area heuristic, relative to one ray/triangle test.
constexpr float kTraversalCost = 1.0f;
// From this depth on, nodes split at the object median, which halves the triangle count: whatever the geometry, the
// tree then stays within kBvhMaxDepth levels (2^32 triangles need 32 more).
constexpr int kMedianDepth = shader::kBvhMaxDepth - 32;

struct Box {
    glm::vec3 lo{std::numeric_limits<float>::max()};
    glm::vec3 hi{-std::numeric_limits<float>::max()};

    void grow(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void grow(const Box& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
    bool empty() const { return lo.x > hi.x; }
    // Half the surface area: the SAH only compares ratios.
    float halfArea() const {
        if (empty()) return 0.0f;
        glm::vec3 d = hi - lo;
        return d.x * d.y + d.y * d.z + d.z * d.x;
    }
};

struct Split {
    int axis = -1;  // -1: none found
    int bin = 0;    // triangles whose centroid falls in bins [0, bin] go left
    float cost = std::numeric_limits<float>::max();
};

class Builder {
public:
    Builder(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles)
        : positions_(positions), triangles_(triangles) {}

    Bvh build() {
        Bvh bvh;
        const std::size_t n = triangles_.size();
        if (n > std::size_t(std::numeric_limits<int>::max()))
            throw ContractError("buildBvh: " + std::to_string(n) + " triangles are more than a BVH can index");
        bounds_.resize(n);
        centroids_.resize(n);
        order_.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const glm::uvec3& tri = triangles_[i];
            for (int k = 0; k < 3; ++k) {
                if (tri[k] >= positions_.size())
                    throw ContractError("buildBvh: triangle " + std::to_string(i) + " refers to vertex " +
                                        std::to_string(tri[k]) + " of " + std::to_string(positions_.size()));
                bounds_[i].grow(positions_[tri[k]]);
            }
            centroids_[i] = 0.5f * (bounds_[i].lo + bounds_[i].hi);
            order_[i] = std::uint32_t(i);
        }

        nodes_.push_back(BvhNode{});
        if (n == 0) {
            // A lone root with empty bounds: the traversal's slab test never enters it.
            Box empty;
            nodes_[0] = BvhNode{empty.lo, 0, empty.hi, 0};
        } else {
            buildNode(0, 0, int(n), 0);
        }

        linkMisses();
        bvh.nodes = std::move(nodes_);
        bvh.triangles.reserve(n);
        bvh.triangleIds = order_;
        for (std::uint32_t id : order_) {
            const glm::uvec3& tri = triangles_[id];
            const glm::vec3& v0 = positions_[tri.x];
            bvh.triangles.push_back(BvhTriangle{v0, id, positions_[tri.y] - v0, 0.0f, positions_[tri.z] - v0, 0.0f});
        }
        return bvh;
    }

private:
    // Packs each node's miss link next to its triangle count: the right sibling for a first child, the parent's link
    // for a second child, 0 (none) for the root.
    void linkMisses() {
        if (nodes_.size() == 1) return;  // a lone root (a leaf, or empty): nothing follows it
        if (nodes_.size() >= (std::size_t(1) << (31 - shader::kBvhCountBits)))
            throw ContractError("buildBvh: " + std::to_string(nodes_.size()) + " nodes are more than a link can name");
        struct Pending {
            int node, miss;
        };
        std::vector<Pending> todo{{0, 0}};
        while (!todo.empty()) {
            const Pending p = todo.back();
            todo.pop_back();
            BvhNode& node = nodes_[std::size_t(p.node)];
            const int count = node.countAndMiss;  // the builder stores the bare count
            node.countAndMiss = count | (p.miss << shader::kBvhCountBits);
            if (count == 0) {
                todo.push_back({node.leftOrFirst, node.leftOrFirst + 1});
                todo.push_back({node.leftOrFirst + 1, p.miss});
            }
        }
    }

    static int binOf(float centroid, float lo, float scale) {
        return std::clamp(int((centroid - lo) * scale), 0, kBins - 1);
    }

    // The cheapest binned split of [begin, end) in SAH units (half areas times triangle counts).
    Split findSplit(int begin, int end, const Box& centroidBox, float nodeHalfArea) const {
        Split best;
        for (int axis = 0; axis < 3; ++axis) {
            float extent = centroidBox.hi[axis] - centroidBox.lo[axis];
            if (!(extent > 0.0f)) continue;
            float scale = float(kBins) / extent;
            std::array<Box, kBins> binBox;
            std::array<int, kBins> binCount{};
            for (int i = begin; i < end; ++i) {
                std::uint32_t t = order_[i];
                int b = binOf(centroids_[t][axis], centroidBox.lo[axis], scale);
                binBox[b].grow(bounds_[t]);
                ++binCount[b];
            }
            // Sweep from the right for the cost of everything right of each boundary, then from the left.
            std::array<float, kBins> rightCost{};
            Box right;
            int rightCount = 0;
            for (int b = kBins - 1; b > 0; --b) {
                right.grow(binBox[b]);
                rightCount += binCount[b];
                rightCost[b - 1] = right.halfArea() * float(rightCount);
            }
            Box left;
            int leftCount = 0;
            for (int b = 0; b < kBins - 1; ++b) {
                left.grow(binBox[b]);
                leftCount += binCount[b];
                if (leftCount == 0 || leftCount == end - begin) continue;
                float cost = kTraversalCost * nodeHalfArea + left.halfArea() * float(leftCount) + rightCost[b];
                if (cost < best.cost) best = Split{axis, b, cost};
            }
        }
        return best;
    }

    void buildNode(int nodeIndex, int begin, int end, int depth) {
        Box box, centroidBox;
        for (int i = begin; i < end; ++i) {
            box.grow(bounds_[order_[i]]);
            centroidBox.grow(centroids_[order_[i]]);
        }
        const int count = end - begin;
        nodes_[nodeIndex] = BvhNode{box.lo, begin, box.hi, count};
        if (count == 1) return;

        const float nodeHalfArea = box.halfArea();
        Split split;
        if (depth < kMedianDepth) split = findSplit(begin, end, centroidBox, nodeHalfArea);
        const float leafCost = nodeHalfArea * float(count);
        if (count <= shader::kBvhMaxLeafSize && (split.axis < 0 || split.cost >= leafCost)) return;

        int middle;
        if (split.axis >= 0) {
            const int axis = split.axis;
            const float lo = centroidBox.lo[axis];
            const float scale = float(kBins) / (centroidBox.hi[axis] - lo);
            auto* mid = std::partition(order_.data() + begin, order_.data() + end, [&](std::uint32_t t) {
                return binOf(centroids_[t][axis], lo, scale) <= split.bin;
            });
            middle = int(mid - order_.data());
        } else {
            // No useful binning (coincident centroids) or too deep: the object median along the widest centroid
            // extent, ties broken by input index so that the result does not depend on the standard library.
            glm::vec3 extent = centroidBox.hi - centroidBox.lo;
            int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
            middle = begin + count / 2;
            std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                             [&](std::uint32_t a, std::uint32_t b) {
                                 float ca = centroids_[a][axis], cb = centroids_[b][axis];
                                 return ca < cb || (ca == cb && a < b);
                             });
        }

        const int left = int(nodes_.size());
        nodes_.resize(nodes_.size() + 2);
        nodes_[nodeIndex].leftOrFirst = left;
        nodes_[nodeIndex].countAndMiss = 0;
        buildNode(left, begin, middle, depth + 1);
        buildNode(left + 1, middle, end, depth + 1);
    }

    const std::vector<glm::vec3>& positions_;
    const std::vector<glm::uvec3>& triangles_;
    std::vector<Box> bounds_;           // per input triangle
    std::vector<glm::vec3> centroids_;  // of each triangle's bounds
    std::vector<std::uint32_t> order_;  // input indices, grouped by leaf as the build proceeds
    std::vector<BvhNode> nodes_;
};

thread_local const Bvh* boundBvh = nullptr;

const Bvh& bound() {
    if (!boundBvh) throw ContractError("BVH traversal on the CPU needs a BvhScope on this thread");
    return *boundBvh;
}

}  // namespace

Bvh buildBvh(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles) {
    return Builder(positions, triangles).build();
}

Bvh buildBvh(const std::vector<TriangleMesh>& meshes) {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    for (const TriangleMesh& mesh : meshes) {
        const glm::uvec3 offset(std::uint32_t(positions.size()));
        positions.insert(positions.end(), mesh.positions.begin(), mesh.positions.end());
        for (const glm::uvec3& tri : mesh.triangles)
            triangles.push_back(tri + offset);
    }
    return buildBvh(positions, triangles);
}

BvhScope::BvhScope(const Bvh& bvh) : previous_(boundBvh) {
    boundBvh = &bvh;
}

BvhScope::~BvhScope() {
    boundBvh = previous_;
}

}  // namespace tyndall::gpu

// The accessors that shaders/shared/bvh.h leaves to its includer, over the BVH bound by a BvhScope. Bounds-checked:
// these serve tests and CPU paths, where a wrong index should fail loudly rather than read past the arrays.
namespace tyndall::shader {

BvhNode bvhNode(int i) {
    const gpu::Bvh& bvh = gpu::bound();
    if (i < 0 || std::size_t(i) >= bvh.nodes.size())
        throw ContractError("bvhNode: index " + std::to_string(i) + " out of " + std::to_string(bvh.nodes.size()));
    return bvh.nodes[std::size_t(i)];
}

BvhTriangle bvhTriangle(int i) {
    const gpu::Bvh& bvh = gpu::bound();
    if (i < 0 || std::size_t(i) >= bvh.triangles.size())
        throw ContractError("bvhTriangle: index " + std::to_string(i) + " out of " +
                            std::to_string(bvh.triangles.size()));
    return bvh.triangles[std::size_t(i)];
}

}  // namespace tyndall::shader
