// Tests of GPU visibility (renderers/gpu/src/visibility.cpp): the backend chosen for the device (the BVH here; ray
// queries on a GPU that has them, where the same tests then check that backend), agreement with Embree on random rays
// through every bundled project, and the small cases.
#include "tyndall/gpu/visibility.h"

#include "bundled_scenes.h"
#include "gpu_test.h"
#include "visibility_helpers.h"

#include "test_paths.h"
#include "tyndall/core/geometry.h"
#include "tyndall/gpu/resources.h"
#include "tyndall/gpu/shader_compiler.h"
#include "tyndall/project/project.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace tyndall::gpu {
namespace {

using glm::uvec3;
using glm::vec3;
using glm::vec4;

using test::BundledScene;
using test::bundledScenes;
using test::EmbreeTriangles;
using test::randomRays;

// One triangle in the plane z = 0: (0, 0), (1, 0), (0, 1).
std::vector<TriangleMesh> singleTriangle() {
    TriangleMesh mesh;
    mesh.positions = {vec3(0.0f, 0.0f, 0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f)};
    mesh.triangles = {uvec3(0, 1, 2)};
    return {mesh};
}

// Rays through and beside the single triangle, with the expected answers; `copies` times over.
void expectSingleTriangleAnswers(Visibility& visibility, int copies = 1) {
    const vec4 down(0.0f, 0.0f, -1.0f, 0.0f), up(0.0f, 0.0f, 1.0f, 0.0f);
    std::vector<vec4> rays = {
        vec4(0.25f, 0.25f, 2.0f, 10.0f),  down,                           // through it
        vec4(0.25f, 0.25f, 2.0f, 1.5f),   down,                           // stops short
        vec4(0.25f, 0.25f, -2.0f, 10.0f), up,                             // from behind (no culling)
        vec4(1.5f, 1.5f, 2.0f, 10.0f),    down,                           // beside it
        vec4(0.25f, 0.25f, 2.0f, 4.0f),   vec4(0.0f, 0.0f, -2.0f, 0.0f),  // unnormalised direction, t in its units
    };
    std::vector<std::uint32_t> answers = {1, 0, 1, 0, 1};
    std::vector<vec4> allRays;
    std::vector<std::uint32_t> expected;
    for (int i = 0; i < copies; ++i) {
        allRays.insert(allRays.end(), rays.begin(), rays.end());
        expected.insert(expected.end(), answers.begin(), answers.end());
    }
    EXPECT_EQ(visibility.occluded(allRays), expected);
}

constexpr int kRays = 100000;
constexpr int kMaxDisagreements = kRays / 1000;

// GpuTest under the name the Visibility* filter selects.
class VisibilityTest : public test::GpuTest {};

TEST_F(VisibilityTest, ChoosesTheDevicesBackend) {
    Visibility visibility(context(), singleTriangle());
    if (!context().device().rayQuery) {
        EXPECT_EQ(visibility.backend(), Visibility::Backend::Bvh);
        EXPECT_STREQ(visibility.backendName(), "bvh");
    } else {
        EXPECT_EQ(visibility.backend(), Visibility::Backend::RayQuery);
        EXPECT_STREQ(visibility.backendName(), "ray query");
    }
    if (visibility.backend() == Visibility::Backend::Bvh) {
        EXPECT_NE(visibility.bvhNodes(), nullptr);
        EXPECT_NE(visibility.bvhTriangles(), nullptr);
        EXPECT_EQ(visibility.topLevel(), VK_NULL_HANDLE);
    } else {
        EXPECT_EQ(visibility.bvhNodes(), nullptr);
        EXPECT_EQ(visibility.bvhTriangles(), nullptr);
        EXPECT_NE(visibility.topLevel(), VK_NULL_HANDLE);
    }
    EXPECT_EQ(visibility.triangleCount(), 1u);
    std::cout << "[ Visibility ] backend on " << context().device().name << ": " << visibility.backendName() << "\n";
    expectSingleTriangleAnswers(visibility);
}

TEST_F(VisibilityTest, AgreesWithEmbreeOnBundledProjects) {
    for (const BundledScene& scene : bundledScenes()) {
        SCOPED_TRACE(scene.name);
        Visibility visibility(context(), scene.meshes);
        EmbreeTriangles embree(scene.meshes);
        std::vector<vec4> rays = randomRays(scene.meshes, 21u, kRays);
        auto start = std::chrono::steady_clock::now();
        std::vector<std::uint32_t> ours = visibility.occluded(rays);
        double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        ASSERT_EQ(ours.size(), std::size_t(kRays));
        int occludedCount = 0, disagreements = 0;
        for (int i = 0; i < kRays; ++i) {
            ASSERT_LE(ours[std::size_t(i)], 1u);
            const vec4& originTMax = rays[2 * std::size_t(i)];
            bool theirs = embree.occluded(vec3(originTMax), vec3(rays[2 * std::size_t(i) + 1]), originTMax.w);
            occludedCount += theirs ? 1 : 0;
            disagreements += (ours[std::size_t(i)] == 1u) != theirs ? 1 : 0;
        }
        std::cout << "[ Visibility ] " << scene.name << " (" << visibility.backendName() << ", "
                  << visibility.triangleCount() << " triangles): " << occludedCount << " of " << kRays
                  << " rays occluded, " << disagreements << " disagreements, " << ms << " ms\n";
        // Both outcomes well represented, or the comparison says little.
        EXPECT_GT(occludedCount, kRays / 20);
        EXPECT_LT(occludedCount, kRays - kRays / 20);
        EXPECT_LE(disagreements, kMaxDisagreements);
    }
}

TEST_F(VisibilityTest, ManyRaysSpanSeveralDispatches) {
    // 1.25 M rays: more than one dispatch of 2^20 rays, in one submission.
    Visibility visibility(context(), singleTriangle());
    expectSingleTriangleAnswers(visibility, 250000);
}

TEST_F(VisibilityTest, WithoutRayQueriesUsesTheBvh) {
    Context bvhOnly(ContextOptions{.validation = 1, .rayQuery = false});
    EXPECT_FALSE(bvhOnly.rayQueryEnabled());
    {
        Visibility visibility(bvhOnly, singleTriangle());
        EXPECT_EQ(visibility.backend(), Visibility::Backend::Bvh);
        EXPECT_NE(visibility.bvhNodes(), nullptr);
        EXPECT_EQ(visibility.topLevel(), VK_NULL_HANDLE);
        expectSingleTriangleAnswers(visibility);
    }
    for (const std::string& error : bvhOnly.validationErrors())
        ADD_FAILURE() << "Vulkan validation error: " << error;
}

TEST_F(VisibilityTest, EmptyMeshListIsNeverOccluded) {
    Visibility visibility(context(), {});
    EXPECT_EQ(visibility.triangleCount(), 0u);
    std::vector<vec4> rays = randomRays(singleTriangle(), 5u, 1000);
    // Long rays along the axes through the origin, too.
    for (vec3 dir : {vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, -1.0f, 0.0f), vec3(0.0f, 0.0f, 1.0f)}) {
        rays.push_back(vec4(-dir * 1e6f, 2e6f));
        rays.push_back(vec4(dir, 0.0f));
    }
    std::vector<std::uint32_t> occluded = visibility.occluded(rays);
    ASSERT_EQ(occluded.size(), rays.size() / 2);
    EXPECT_EQ(std::count(occluded.begin(), occluded.end(), 1u), 0);
    EXPECT_TRUE(visibility.occluded({}).empty());
}

TEST_F(VisibilityTest, RayQueryKernelCompiles) {
    // The ray-query backend's kernel compiles everywhere, though it runs only where the device has ray queries.
    CompileResult compiled =
        compileGlsl(tyndall::test::sourceDir() + "/shaders/features/ray_query_visibility.comp.glsl");
    EXPECT_TRUE(compiled.ok) << compiled.log;
}

}  // namespace
}  // namespace tyndall::gpu
