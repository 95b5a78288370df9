// Tests of the GPU BVH (renderers/gpu/src/bvh.cpp) and of the traversal in shaders/shared/bvh.h: the tree's
// invariants; the traversal run on the CPU against Embree (what the reference renders with) on random rays through
// every bundled project; and the same traversal compiled as GLSL against its C++ side, which checks the std430 layout.
#include "tyndall/gpu/bvh.h"

#include "bundled_scenes.h"
#include "gpu_test.h"
#include "test_paths.h"
#include "visibility_helpers.h"

#include "shared/rng.h"
#include "shared/sampling.h"
#include "tyndall/core/geometry.h"
#include "tyndall/gpu/resources.h"
#include "tyndall/gpu/shader_compiler.h"
#include "tyndall/project/project.h"

#include <gtest/gtest.h>

#include <map>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace tyndall::gpu {
namespace {

using glm::uvec3;
using glm::vec2;
using glm::vec3;

using test::BundledScene;
using test::bundledScenes;
using test::edgeDistance;
using test::EmbreeTriangles;
using test::RandomRays;

constexpr int kRays = 100000;
// Watertight Embree and Moeller-Trumbore may disagree only for hits within this of an edge, and on few rays.
constexpr float kEdgeEpsilon = 1e-4f;
constexpr int kMaxDisagreements = kRays / 1000;

// Walks the tree from the root and checks what the traversal relies on.
void expectValidTree(const Bvh& bvh, const std::vector<vec3>& positions, const std::vector<uvec3>& triangles) {
    ASSERT_FALSE(bvh.nodes.empty());
    ASSERT_EQ(bvh.triangles.size(), triangles.size());
    ASSERT_EQ(bvh.triangleIds.size(), triangles.size());
    std::vector<int> referencedByLeaf(triangles.size(), 0);
    std::vector<int> idSeen(triangles.size(), 0);
    std::vector<int> nodeSeen(bvh.nodes.size(), 0);

    struct Entry {
        int node, depth;
    };
    std::vector<Entry> todo{{0, 1}};
    int maxDepth = 0;
    while (!todo.empty()) {
        Entry e = todo.back();
        todo.pop_back();
        ASSERT_GE(e.node, 0);
        ASSERT_LT(std::size_t(e.node), bvh.nodes.size());
        ++nodeSeen[std::size_t(e.node)];
        maxDepth = std::max(maxDepth, e.depth);
        const shader::BvhNode& node = bvh.nodes[std::size_t(e.node)];
        const int count = shader::bvhCount(node);
        if (count > 0) {
            ASSERT_LE(count, shader::kBvhMaxLeafSize);
            ASSERT_GE(node.leftOrFirst, 0);
            ASSERT_LE(std::size_t(node.leftOrFirst + count), bvh.triangles.size());
            for (int i = node.leftOrFirst; i < node.leftOrFirst + count; ++i) {
                ++referencedByLeaf[std::size_t(i)];
                const shader::BvhTriangle& tri = bvh.triangles[std::size_t(i)];
                ASSERT_LT(tri.id, triangles.size());
                for (vec3 v : {tri.v0, tri.v0 + tri.e1, tri.v0 + tri.e2}) {
                    // e1 and e2 round, so the rebuilt vertices may lie an ulp or so outside.
                    vec3 slack = 1e-6f * (glm::abs(node.boundsMin) + glm::abs(node.boundsMax) + 1.0f);
                    EXPECT_TRUE(glm::all(glm::greaterThanEqual(v, node.boundsMin - slack)));
                    EXPECT_TRUE(glm::all(glm::lessThanEqual(v, node.boundsMax + slack)));
                }
            }
        } else {
            ASSERT_EQ(count, 0);
            for (int c = node.leftOrFirst; c < node.leftOrFirst + 2; ++c) {
                ASSERT_GT(c, e.node);
                ASSERT_LT(std::size_t(c), bvh.nodes.size());
                const shader::BvhNode& child = bvh.nodes[std::size_t(c)];
                EXPECT_TRUE(glm::all(glm::greaterThanEqual(child.boundsMin, node.boundsMin)));
                EXPECT_TRUE(glm::all(glm::lessThanEqual(child.boundsMax, node.boundsMax)));
                todo.push_back({c, e.depth + 1});
            }
        }
    }
    EXPECT_LE(maxDepth, shader::kBvhMaxDepth);
    for (int seen : nodeSeen)
        EXPECT_EQ(seen, 1);
    // The miss links thread the tree in depth-first order: entering every box, the traversal visits each node once,
    // every child after its parent, and ends at the root's link, 0.
    std::vector<int> visits(bvh.nodes.size(), 0);
    int index = 0, steps = 0;
    do {
        ASSERT_LT(std::size_t(index), bvh.nodes.size());
        ++visits[std::size_t(index)];
        const shader::BvhNode& node = bvh.nodes[std::size_t(index)];
        const int next = shader::bvhCount(node) == 0 ? node.leftOrFirst : shader::bvhMiss(node);
        ASSERT_TRUE(next == 0 || next > index || shader::bvhCount(node) > 0) << "node " << index;
        index = next;
        ASSERT_LE(++steps, int(bvh.nodes.size()));
    } while (index != 0);
    for (int v : visits)
        EXPECT_EQ(v, 1);
    for (int n : referencedByLeaf)
        EXPECT_EQ(n, 1);

    for (std::size_t i = 0; i < bvh.triangles.size(); ++i) {
        const shader::BvhTriangle& tri = bvh.triangles[i];
        ASSERT_EQ(tri.id, bvh.triangleIds[i]);
        ++idSeen[tri.id];
        const uvec3& input = triangles[tri.id];
        EXPECT_EQ(tri.v0, positions[input.x]);
        EXPECT_EQ(tri.e1, positions[input.y] - positions[input.x]);
        EXPECT_EQ(tri.e2, positions[input.z] - positions[input.x]);
    }
    for (int n : idSeen)
        EXPECT_EQ(n, 1);
}

void concatenate(const std::vector<TriangleMesh>& meshes, std::vector<vec3>& positions, std::vector<uvec3>& triangles) {
    for (const TriangleMesh& mesh : meshes) {
        uvec3 offset(std::uint32_t(positions.size()));
        positions.insert(positions.end(), mesh.positions.begin(), mesh.positions.end());
        for (const uvec3& tri : mesh.triangles)
            triangles.push_back(tri + offset);
    }
}

TEST(Bvh, TreeInvariantsOnBundledProjects) {
    for (const BundledScene& scene : bundledScenes()) {
        SCOPED_TRACE(scene.name);
        std::vector<vec3> positions;
        std::vector<uvec3> triangles;
        concatenate(scene.meshes, positions, triangles);
        ASSERT_FALSE(triangles.empty());
        expectValidTree(buildBvh(scene.meshes), positions, triangles);
    }
}

TEST(Bvh, TreeInvariantsOnRandomAndDegenerateTriangles) {
    shader::Pcg32 rng = shader::pcg32Seed(7u, 0u);
    auto random = [&] { return shader::pcg32NextFloat(rng); };
    std::vector<vec3> positions;
    std::vector<uvec3> triangles;
    for (std::uint32_t i = 0; i < 3000; ++i) {
        // Small triangles scattered in a box, some of them long slivers.
        vec3 c(random() * 10.0f, random() * 2.0f, random() * 5.0f);
        float size = random() < 0.1f ? 3.0f : 0.05f;
        for (int k = 0; k < 3; ++k)
            positions.push_back(c + size * vec3(random(), random(), random()));
        triangles.push_back(uvec3(3 * i, 3 * i + 1, 3 * i + 2));
    }
    // 200 copies of one triangle: coincident centroids, which binning cannot separate.
    std::uint32_t base = std::uint32_t(positions.size());
    positions.insert(positions.end(), {vec3(1.0f, 1.0f, 1.0f), vec3(2.0f, 1.0f, 1.0f), vec3(1.0f, 2.0f, 1.0f)});
    for (int i = 0; i < 200; ++i)
        triangles.push_back(uvec3(base, base + 1, base + 2));
    // Zero-area triangles: a point and a line.
    triangles.push_back(uvec3(0, 0, 0));
    triangles.push_back(uvec3(0, 1, 1));

    Bvh bvh = buildBvh(positions, triangles);
    expectValidTree(bvh, positions, triangles);

    // Deterministic: a second build gives the same bytes.
    Bvh again = buildBvh(positions, triangles);
    ASSERT_EQ(again.nodes.size(), bvh.nodes.size());
    EXPECT_EQ(std::memcmp(again.nodes.data(), bvh.nodes.data(), bvh.nodes.size() * sizeof(shader::BvhNode)), 0);
    EXPECT_EQ(
        std::memcmp(again.triangles.data(), bvh.triangles.data(), bvh.triangles.size() * sizeof(shader::BvhTriangle)),
        0);
}

TEST(Bvh, SingleTriangleHitGivesDistanceIdAndBarycentrics) {
    std::vector<vec3> positions{vec3(0.0f, 0.0f, 0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f)};
    Bvh bvh = buildBvh(positions, {uvec3(0, 1, 2)});
    ASSERT_EQ(bvh.nodes.size(), 1u);
    BvhScope scope(bvh);

    vec3 origin(0.25f, 0.5f, 2.0f), dir(0.0f, 0.0f, -1.0f);
    shader::BvhHit hit;
    ASSERT_TRUE(shader::bvhIntersect(origin, dir, 0.0f, 10.0f, hit));
    EXPECT_FLOAT_EQ(hit.t, 2.0f);
    EXPECT_EQ(hit.id, 0u);
    EXPECT_FLOAT_EQ(hit.uv.x, 0.25f);  // weight of vertex 1
    EXPECT_FLOAT_EQ(hit.uv.y, 0.5f);   // weight of vertex 2
    EXPECT_TRUE(shader::bvhOccluded(origin, dir, 0.0f, 10.0f));
    // The interval is open and respected at both ends; the triangle is seen from both sides.
    EXPECT_FALSE(shader::bvhOccluded(origin, dir, 0.0f, 1.5f));
    EXPECT_FALSE(shader::bvhOccluded(origin, dir, 2.5f, 10.0f));
    EXPECT_TRUE(shader::bvhOccluded(vec3(0.25f, 0.5f, -2.0f), -dir, 0.0f, 10.0f));
    // Axis-aligned rays (zero direction components) in the triangle's plane and beside it miss.
    EXPECT_FALSE(shader::bvhOccluded(vec3(-1.0f, 0.25f, 0.0f), vec3(1.0f, 0.0f, 0.0f), 0.0f, 10.0f));
    EXPECT_FALSE(shader::bvhOccluded(vec3(1.5f, 1.5f, 2.0f), dir, 0.0f, 10.0f));
}

TEST(Bvh, EmptyMeshListGivesAnEmptyBvhWithoutHits) {
    Bvh bvh = buildBvh(std::vector<TriangleMesh>{});
    EXPECT_EQ(bvh.nodes.size(), 1u);
    EXPECT_TRUE(bvh.triangles.empty());
    EXPECT_TRUE(bvh.triangleIds.empty());
    BvhScope scope(bvh);
    shader::Pcg32 rng = shader::pcg32Seed(3u, 0u);
    for (int i = 0; i < 1000; ++i) {
        vec3 origin =
            4.0f * vec3(shader::pcg32NextFloat(rng), shader::pcg32NextFloat(rng), shader::pcg32NextFloat(rng)) - 2.0f;
        vec3 dir = shader::sampleUniformSphere(vec2(shader::pcg32NextFloat(rng), shader::pcg32NextFloat(rng)));
        shader::BvhHit hit;
        EXPECT_FALSE(shader::bvhOccluded(origin, dir, 0.0f, 1e30f));
        EXPECT_FALSE(shader::bvhIntersect(origin, dir, 0.0f, 1e30f, hit));
    }
    // Rays along the axes, and through the origin.
    for (vec3 dir : {vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, -1.0f, 0.0f), vec3(0.0f, 0.0f, 1.0f)})
        EXPECT_FALSE(shader::bvhOccluded(vec3(0.0f), dir, 0.0f, 1e30f));
}

TEST(Bvh, OccludedAgreesWithEmbreeOnBundledProjects) {
    for (const BundledScene& scene : bundledScenes()) {
        SCOPED_TRACE(scene.name);
        Bvh bvh = buildBvh(scene.meshes);
        BvhScope scope(bvh);
        EmbreeTriangles embree(scene.meshes);
        RandomRays rays(scene.meshes, 11u);
        int occludedCount = 0, disagreements = 0;
        for (int i = 0; i < kRays; ++i) {
            vec3 origin, dir;
            float tMax;
            rays.next(origin, dir, tMax);
            bool ours = shader::bvhOccluded(origin, dir, 0.0f, tMax);
            bool theirs = embree.occluded(origin, dir, tMax);
            occludedCount += theirs ? 1 : 0;
            if (ours == theirs) continue;
            ++disagreements;
            // Whichever side saw a hit: its closest one must graze an edge.
            shader::BvhHit hit;
            bool found =
                theirs ? embree.intersect(origin, dir, tMax, hit) : shader::bvhIntersect(origin, dir, 0.0f, tMax, hit);
            ASSERT_TRUE(found);
            EXPECT_LT(edgeDistance(hit.uv), kEdgeEpsilon) << "ray " << i << ": ours " << ours << ", Embree " << theirs;
        }
        std::cout << "[ Bvh      ] " << scene.name << ": " << occludedCount << " of " << kRays << " rays occluded, "
                  << disagreements << " disagreements\n";
        // Both outcomes well represented, or the comparison says little.
        EXPECT_GT(occludedCount, kRays / 20);
        EXPECT_LT(occludedCount, kRays - kRays / 20);
        EXPECT_LE(disagreements, kMaxDisagreements);
    }
}

TEST(Bvh, ClosestHitAgreesWithEmbreeOnBundledProjects) {
    for (const BundledScene& scene : bundledScenes()) {
        SCOPED_TRACE(scene.name);
        Bvh bvh = buildBvh(scene.meshes);
        BvhScope scope(bvh);
        std::map<std::uint32_t, std::size_t> byId;
        for (std::size_t k = 0; k < bvh.triangles.size(); ++k)
            byId[bvh.triangles[k].id] = k;
        EmbreeTriangles embree(scene.meshes);
        RandomRays rays(scene.meshes, 12u);
        int hitCount = 0, disagreements = 0;
        for (int i = 0; i < kRays; ++i) {
            vec3 origin, dir;
            float tMax;
            rays.next(origin, dir, tMax);
            shader::BvhHit ours, theirs;
            bool oursFound = shader::bvhIntersect(origin, dir, 0.0f, tMax, ours);
            bool theirsFound = embree.intersect(origin, dir, tMax, theirs);
            hitCount += theirsFound ? 1 : 0;
            if (oursFound && theirsFound && std::abs(ours.t - theirs.t) <= 1e-4f * theirs.t) {
                // The same triangle (coplanar overlapping faces may differ) must give the same barycentrics, up to
                // how far apart the two hits may lie: within the t tolerance above they are |dt| apart in the plane at
                // most, which moves a barycentric by |dt| over the triangle's altitude (at least half the shorter edge
                // for the bundled meshes' triangles). The WVDS example's 8 m ground plane needs this.
                if (ours.id == theirs.id) {
                    const shader::BvhTriangle& tri = bvh.triangles[byId.at(ours.id)];
                    const float shortEdge = std::sqrt(std::min(glm::dot(tri.e1, tri.e1), glm::dot(tri.e2, tri.e2)));
                    const float tolerance = 1e-4f + 2.0f * std::abs(ours.t - theirs.t) / shortEdge;
                    EXPECT_NEAR(ours.uv.x, theirs.uv.x, tolerance) << "ray " << i;
                    EXPECT_NEAR(ours.uv.y, theirs.uv.y, tolerance) << "ray " << i;
                }
                continue;
            }
            if (!oursFound && !theirsFound) continue;
            // One side missed the closest hit of the other (or found a nearer one): that hit must graze an edge.
            ++disagreements;
            bool oursNearer = oursFound && (!theirsFound || ours.t < theirs.t);
            const shader::BvhHit& nearer = oursNearer ? ours : theirs;
            EXPECT_LT(edgeDistance(nearer.uv), kEdgeEpsilon) << "ray " << i << ": ours " << (oursFound ? ours.t : -1.0f)
                                                             << ", Embree " << (theirsFound ? theirs.t : -1.0f);
        }
        std::cout << "[ Bvh      ] " << scene.name << ": " << hitCount << " of " << kRays << " rays hit, "
                  << disagreements << " disagreements\n";
        EXPECT_GT(hitCount, kRays / 20);
        EXPECT_LE(disagreements, kMaxDisagreements);
    }
}

// One ray per invocation through both traversals; rays are (origin, tMax) and (dir, 0). Compiled as if it were a file
// of renderers/gpu/test, where its relative include lies.
constexpr const char* kTraceShader = R"(#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh.h"
#include "bvh_struct_buffers.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 2) readonly buffer Rays { vec4 rays[]; };
layout(std430, binding = 3) writeonly buffer Hits { vec4 hits[]; };     // t, u, v, id bits
layout(std430, binding = 4) writeonly buffer Flags { uint flags[]; };  // 1: closest hit found, 2: occluded
layout(push_constant) uniform Push { uint count; } push;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    vec3 origin = rays[2 * i].xyz;
    float tMax = rays[2 * i].w;
    vec3 dir = rays[2 * i + 1].xyz;
    BvhHit hit;
    bool found = bvhIntersect(origin, dir, 0.0f, tMax, hit);
    bool occluded = bvhOccluded(origin, dir, 0.0f, tMax);
    hits[i] = vec4(hit.t, hit.uv, uintBitsToFloat(hit.id));
    flags[i] = (found ? 1u : 0u) | (occluded ? 2u : 0u);
}
)";

class BvhGpu : public test::GpuTest {};

TEST_F(BvhGpu, GlslTraversalAgreesWithCpp) {
    CompileResult compiled = compileGlslSource(
        kTraceShader, tyndall::test::sourceDir() + "/renderers/gpu/test/bvh_trace.comp.glsl", ShaderStage::Compute);
    ASSERT_TRUE(compiled.ok) << compiled.log;
    // Every bundled project's geometry, 2^17 rays each, against the C++ side of the same code and against Embree.
    for (const BundledScene& scene : bundledScenes()) {
        Bvh bvh = buildBvh(scene.meshes);
        EmbreeTriangles embree(scene.meshes);
        BvhScope scope(bvh);

        constexpr std::uint32_t kGpuRays = 1u << 17;
        RandomRays random(scene.meshes, 13u);
        std::vector<glm::vec4> rays;
        for (std::uint32_t i = 0; i < kGpuRays; ++i) {
            vec3 origin, dir;
            float tMax;
            random.next(origin, dir, tMax);
            rays.push_back(glm::vec4(origin, tMax));
            rays.push_back(glm::vec4(dir, 0.0f));
        }
        Buffer nodes(context(), bvh.nodes.size() * sizeof(shader::BvhNode));
        Buffer triangles(context(), bvh.triangles.size() * sizeof(shader::BvhTriangle));
        Buffer rayBuffer(context(), rays.size() * sizeof(glm::vec4));
        Buffer hitBuffer(context(), kGpuRays * sizeof(glm::vec4));
        Buffer flagBuffer(context(), kGpuRays * sizeof(std::uint32_t));
        nodes.upload(bvh.nodes);
        triangles.upload(bvh.triangles);
        rayBuffer.upload(rays);
        ComputeKernel kernel(context(), compiled.spirv, 5, sizeof(std::uint32_t), "bvh_trace");
        context().submitAndWait([&](VkCommandBuffer cmd) {
            kernel.record(cmd, {&nodes, &triangles, &rayBuffer, &hitBuffer, &flagBuffer}, &kGpuRays, kGpuRays / 64);
        });
        kernel.resetDescriptors();
        const std::vector<glm::vec4> hits = hitBuffer.download<glm::vec4>(kGpuRays);
        const std::vector<std::uint32_t> flags = flagBuffer.download<std::uint32_t>(kGpuRays);

        // The GPU may contract to fma and round divisions differently: rays that graze an edge may go either way.
        int hitCount = 0, disagreements = 0, embreeDisagreements = 0;
        for (std::uint32_t i = 0; i < kGpuRays; ++i) {
            vec3 origin(rays[2 * i]), dir(rays[2 * i + 1]);
            float tMax = rays[2 * i].w;
            shader::BvhHit cpu;
            bool cpuFound = shader::bvhIntersect(origin, dir, 0.0f, tMax, cpu);
            bool cpuOccluded = shader::bvhOccluded(origin, dir, 0.0f, tMax);
            shader::BvhHit gpu{hits[i].x, glm::floatBitsToUint(hits[i].w), vec2(hits[i].y, hits[i].z)};
            bool gpuFound = (flags[i] & 1u) != 0, gpuOccluded = (flags[i] & 2u) != 0;
            hitCount += cpuFound ? 1 : 0;
            embreeDisagreements += embree.occluded(origin, dir, tMax) != gpuOccluded ? 1 : 0;
            EXPECT_EQ(cpuFound, cpuOccluded) << "ray " << i;
            if (cpuFound == gpuFound && cpuOccluded == gpuOccluded &&
                (!cpuFound || std::abs(cpu.t - gpu.t) <= 1e-4f * cpu.t)) {
                if (cpuFound && cpu.id == gpu.id) {
                    EXPECT_NEAR(cpu.uv.x, gpu.uv.x, 1e-4f) << "ray " << i;
                    EXPECT_NEAR(cpu.uv.y, gpu.uv.y, 1e-4f) << "ray " << i;
                }
                continue;
            }
            ++disagreements;
            bool gpuNearer = gpuFound && (!cpuFound || gpu.t < cpu.t);
            EXPECT_LT(edgeDistance(gpuNearer ? gpu.uv : cpu.uv), kEdgeEpsilon) << "ray " << i;
        }
        std::cout << "[ BvhGpu   ] " << scene.name << " on " << context().device().name << ": " << hitCount << " of "
                  << kGpuRays << " rays hit, " << disagreements << " disagreements with C++, " << embreeDisagreements
                  << " with Embree\n";
        EXPECT_GT(hitCount, int(kGpuRays / 20));
        EXPECT_LE(disagreements, int(kGpuRays / 1000));
        EXPECT_LE(embreeDisagreements, int(kGpuRays / 1000)) << "GPU occlusion against rtcOccluded1 on " << scene.name;
    }
}

}  // namespace
}  // namespace tyndall::gpu
