// Tests of the lit intervals of a ray for a point light (shaders/shared/lit_intervals.h): one triangle's shadow
// interval against segment tests at dense samples; the lit pieces of rays through every bundled project against the
// any-hit traversal of shared/bvh.h and against Embree at dense samples; the overflow signal; and the same function
// compiled as GLSL against its C++ side.
#include "shared/lit_intervals.h"

#include "bundled_scenes.h"
#include "gpu_test.h"
#include "visibility_helpers.h"

#include "shared/rng.h"
#include "tyndall/core/geometry.h"
#include "tyndall/gpu/bvh.h"
#include "tyndall/gpu/resources.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

namespace tyndall::gpu {
namespace {

using glm::uvec3;
using glm::vec2;
using glm::vec3;
using glm::vec4;

using shader::BvhTriangle;
using shader::kLitOverflow;
using shader::kMaxLitIntervals;
using shader::LitIntervals;
using test::BundledScene;
using test::bundledScenes;
using test::EmbreeTriangles;
using test::RandomRays;

BvhTriangle makeTriangle(const vec3& v0, const vec3& v1, const vec3& v2) {
    BvhTriangle tri{};
    tri.v0 = v0;
    tri.e1 = v1 - v0;
    tri.e2 = v2 - v0;
    return tri;
}

// True when the segment from the light to x crosses the triangle (Moeller-Trumbore, open at both ends).
bool segmentHits(const BvhTriangle& tri, const vec3& light, const vec3& x) {
    float t;
    vec2 uv;
    return shader::bvhTriangleHit(tri, light, x - light, 0.0f, 1.0f, t, uv);
}

// Distance from t to the nearest end of the pieces (infinite when there are none).
float distanceToEnd(float t, const vec2* pieces, int count) {
    float d = std::numeric_limits<float>::infinity();
    for (int k = 0; k < count; ++k)
        d = std::min({d, std::abs(t - pieces[k].x), std::abs(t - pieces[k].y)});
    return d;
}

vec3 randomPoint(shader::Pcg32& rng, const vec3& lo, const vec3& hi) {
    vec3 u(shader::pcg32NextFloat(rng), shader::pcg32NextFloat(rng), shader::pcg32NextFloat(rng));
    return lo + u * (hi - lo);
}

// Samples per ray for the dense comparisons, and how close to an end a disagreement may lie, relative to t1.
constexpr int kSamples = 256;
constexpr float kEndEpsilon = 1e-4f;

TEST(LitIntervals, TriangleShadowOfAKnownCase) {
    // The triangle (0, 0, 0), (1, 0, 0), (0, 1, 0) and a light at height 1 above (0.25, 0.25): at z = -1 the shadow is
    // the triangle scaled by 2 about the light, (-0.25, -0.25), (1.75, -0.25), (-0.25, 1.75), whose hypotenuse is
    // x + y = 1.5. The line y = 0.25, z = -1 crosses it for x in (-0.25, 1.25).
    BvhTriangle tri = makeTriangle(vec3(0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f));
    vec3 light(0.25f, 0.25f, 1.0f);
    vec3 origin(-5.0f, 0.25f, -1.0f), dir(1.0f, 0.0f, 0.0f);
    vec2 shadow;
    ASSERT_TRUE(shader::litShadowInterval(tri, light, origin, dir, 0.0f, 10.0f, shadow));
    EXPECT_NEAR(shadow.x, 4.75f, 1e-6f);
    EXPECT_NEAR(shadow.y, 6.25f, 1e-6f);
    // Clipped to [t0, t1]; an unnormalised direction gives t in its units; the winding does not matter.
    ASSERT_TRUE(shader::litShadowInterval(tri, light, origin, dir, 5.0f, 6.0f, shadow));
    EXPECT_EQ(shadow, vec2(5.0f, 6.0f));
    ASSERT_TRUE(shader::litShadowInterval(tri, light, origin, 2.0f * dir, 0.0f, 10.0f, shadow));
    EXPECT_NEAR(shadow.x, 2.375f, 1e-6f);
    EXPECT_NEAR(shadow.y, 3.125f, 1e-6f);
    BvhTriangle flipped = makeTriangle(vec3(0.0f), vec3(0.0f, 1.0f, 0.0f), vec3(1.0f, 0.0f, 0.0f));
    ASSERT_TRUE(shader::litShadowInterval(flipped, light, origin, dir, 0.0f, 10.0f, shadow));
    EXPECT_NEAR(shadow.x, 4.75f, 1e-6f);
    EXPECT_NEAR(shadow.y, 6.25f, 1e-6f);
    // Between the light and the triangle, and beside the shadow, nothing.
    EXPECT_FALSE(shader::litShadowInterval(tri, light, vec3(-5.0f, 0.25f, 0.5f), dir, 0.0f, 10.0f, shadow));
    EXPECT_FALSE(shader::litShadowInterval(tri, light, vec3(-5.0f, 2.0f, -1.0f), dir, 0.0f, 10.0f, shadow));
    // A ray that starts inside the shadow and goes down, away from the light: shadowed all along.
    ASSERT_TRUE(
        shader::litShadowInterval(tri, light, vec3(0.25f, 0.25f, -1.0f), vec3(0.0f, 0.0f, -1.0f), 0.0f, 10.0f, shadow));
    EXPECT_EQ(shadow, vec2(0.0f, 10.0f));
    // Straight up through the triangle and the light: shadowed below the triangle only (the plane at t = 1).
    ASSERT_TRUE(
        shader::litShadowInterval(tri, light, vec3(0.25f, 0.25f, -1.0f), vec3(0.0f, 0.0f, 1.0f), 0.0f, 10.0f, shadow));
    EXPECT_EQ(shadow, vec2(0.0f, 1.0f));
}

TEST(LitIntervals, DegenerateTrianglesAndRays) {
    BvhTriangle tri = makeTriangle(vec3(0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f));
    vec3 dir(1.0f, 0.0f, 0.0f);
    vec2 shadow;
    // The light in the triangle's plane (the triangle seen edge-on), inside or outside the triangle: no shadow.
    for (vec3 light : {vec3(0.25f, 0.25f, 0.0f), vec3(-1.0f, 0.5f, 0.0f)}) {
        EXPECT_FALSE(shader::litShadowInterval(tri, light, vec3(-5.0f, 0.25f, -1.0f), dir, 0.0f, 10.0f, shadow));
        EXPECT_FALSE(shader::litShadowInterval(tri, light, vec3(-5.0f, 0.25f, 0.0f), dir, 0.0f, 10.0f, shadow));
    }
    // Zero-area triangles: a point and a segment.
    vec3 light(0.25f, 0.25f, 1.0f);
    EXPECT_FALSE(shader::litShadowInterval(makeTriangle(vec3(0.2f), vec3(0.2f), vec3(0.2f)), light,
                                           vec3(-5.0f, 0.25f, -1.0f), dir, 0.0f, 10.0f, shadow));
    EXPECT_FALSE(shader::litShadowInterval(makeTriangle(vec3(0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(2.0f, 0.0f, 0.0f)),
                                           light, vec3(-5.0f, 0.0f, -1.0f), dir, 0.0f, 10.0f, shadow));
    // A ray in the triangle's plane: the triangle itself is not its own shadow (the volume is open).
    EXPECT_FALSE(shader::litShadowInterval(tri, light, vec3(-5.0f, 0.25f, 0.0f), dir, 0.0f, 10.0f, shadow));
    // A ray in the plane through the light and the edge y = 0 (on the volume's boundary): lit.
    EXPECT_FALSE(shader::litShadowInterval(tri, light, vec3(-5.0f, -0.25f, -1.0f), dir, 0.0f, 10.0f, shadow));
    // A ray through the light itself, in the direction of the triangle: shadowed beyond it only.
    vec3 down(0.0f, 0.0f, -1.0f);
    ASSERT_TRUE(shader::litShadowInterval(tri, light, light - down, down, 0.0f, 10.0f, shadow));
    EXPECT_EQ(shadow, vec2(2.0f, 10.0f));
    // Empty and reversed ranges.
    EXPECT_FALSE(shader::litShadowInterval(tri, light, vec3(-5.0f, 0.25f, -1.0f), dir, 5.0f, 5.0f, shadow));
    EXPECT_FALSE(shader::litShadowInterval(tri, light, vec3(-5.0f, 0.25f, -1.0f), dir, 6.0f, 5.0f, shadow));
}

TEST(LitIntervals, TriangleShadowAgreesWithSegmentTests) {
    shader::Pcg32 rng = shader::pcg32Seed(31u, 0u);
    constexpr int kCases = 4000;
    int shadowed = 0, disagreements = 0, samplesInShadow = 0;
    float worst = 0.0f;
    for (int i = 0; i < kCases; ++i) {
        BvhTriangle tri =
            makeTriangle(randomPoint(rng, vec3(-1.0f), vec3(1.0f)), randomPoint(rng, vec3(-1.0f), vec3(1.0f)),
                         randomPoint(rng, vec3(-1.0f), vec3(1.0f)));
        vec3 light = randomPoint(rng, vec3(-2.0f), vec3(2.0f));
        // Rays from anywhere towards a point near the triangle, so that most of them cross its shadow.
        vec3 origin = randomPoint(rng, vec3(-4.0f), vec3(4.0f));
        vec3 target = randomPoint(rng, vec3(-1.5f), vec3(1.5f));
        vec3 dir = glm::normalize(target - origin);
        float t1 = 2.0f * glm::length(target - origin);
        vec2 shadow;
        bool found = shader::litShadowInterval(tri, light, origin, dir, 0.0f, t1, shadow);
        shadowed += found ? 1 : 0;
        int count = found ? 1 : 0;
        for (int k = 0; k < kSamples; ++k) {
            float t = (float(k) + 0.5f) / float(kSamples) * t1;
            bool inShadow = found && shadow.x < t && t < shadow.y;
            samplesInShadow += inShadow ? 1 : 0;
            if (inShadow == segmentHits(tri, light, origin + t * dir)) continue;
            ++disagreements;
            float d = distanceToEnd(t, &shadow, count) / t1;
            worst = std::max(worst, d);
            EXPECT_LT(d, kEndEpsilon) << "case " << i << ", t " << t << ", shadow " << shadow.x << " .. " << shadow.y;
        }
    }
    std::cout << "[ LitIntervals ] " << shadowed << " of " << kCases << " rays cross a shadow, " << samplesInShadow
              << " samples in it, " << disagreements << " disagreements, the worst " << worst << " t1 from an end\n";
    EXPECT_GT(shadowed, kCases / 4);
}

// A comb of `teeth` thin rectangles (two triangles each) in the plane z = 0 under a light at height 1, and a ray at
// z = -1 across all their shadows.
struct Comb {
    Bvh bvh;
    float reach;  // m, the ray runs from x = -reach to x = reach
    vec3 light{0.0f, 0.0f, 1.0f};
    vec3 origin;
    vec3 dir{1.0f, 0.0f, 0.0f};
    // Tooth k spans x in [k - teeth / 2, k - teeth / 2 + 0.25]; at z = -1 its shadow is twice as wide and twice as far
    // from the light's foot.
    float shadowStart(int k, int teeth) const { return reach + 2.0f * (float(k) - 0.5f * float(teeth)); }
    static constexpr float kShadowWidth = 0.5f;

    explicit Comb(int teeth) : reach(float(teeth) + 2.0f), origin(-reach, 0.0f, -1.0f) {
        std::vector<vec3> positions;
        std::vector<uvec3> triangles;
        for (int k = 0; k < teeth; ++k) {
            float x = float(k) - 0.5f * float(teeth);
            std::uint32_t base = std::uint32_t(positions.size());
            positions.insert(positions.end(), {vec3(x, -1.0f, 0.0f), vec3(x + 0.25f, -1.0f, 0.0f),
                                               vec3(x + 0.25f, 1.0f, 0.0f), vec3(x, 1.0f, 0.0f)});
            triangles.push_back(uvec3(base, base + 1, base + 2));
            triangles.push_back(uvec3(base, base + 2, base + 3));
        }
        bvh = buildBvh(positions, triangles);
    }
};

TEST(LitIntervals, CombGivesOnePiecePerGapUntilItOverflows) {
    for (int teeth = 1; teeth <= kMaxLitIntervals + 4; ++teeth) {
        SCOPED_TRACE(teeth);
        Comb comb(teeth);
        BvhScope scope(comb.bvh);
        LitIntervals lit;
        float t1 = 2.0f * comb.reach;
        int count = shader::litIntervals(comb.light, comb.origin, comb.dir, 0.0f, t1, lit);
        if (teeth + 1 > kMaxLitIntervals) {
            EXPECT_EQ(count, kLitOverflow);
            continue;
        }
        ASSERT_EQ(count, teeth + 1);
        for (int k = 0; k <= teeth; ++k) {
            // Gap k runs from the end of shadow k - 1 (or t0) to the start of shadow k (or t1).
            float start = k == 0 ? 0.0f : comb.shadowStart(k - 1, teeth) + Comb::kShadowWidth;
            float end = k == teeth ? t1 : comb.shadowStart(k, teeth);
            EXPECT_NEAR(lit.pieces[k].x, start, 1e-5f) << "piece " << k;
            EXPECT_NEAR(lit.pieces[k].y, end, 1e-5f) << "piece " << k;
        }
    }
    // A ray that crosses only a few of the shadows fits, however many teeth there are: shadows start at t = 2, 4, 6
    // and 8, so [0, 8] has four lit pieces.
    Comb comb(kMaxLitIntervals + 4);
    BvhScope scope(comb.bvh);
    LitIntervals lit;
    EXPECT_EQ(shader::litIntervals(comb.light, comb.origin, comb.dir, 0.0f, 8.0f, lit), 4);
}

TEST(LitIntervals, EmptySceneAndEmptyRange) {
    Bvh bvh = buildBvh(std::vector<TriangleMesh>{});
    BvhScope scope(bvh);
    LitIntervals lit;
    ASSERT_EQ(shader::litIntervals(vec3(1.0f), vec3(0.0f), vec3(0.0f, 0.0f, 1.0f), 0.5f, 7.0f, lit), 1);
    EXPECT_EQ(lit.pieces[0], vec2(0.5f, 7.0f));
    EXPECT_EQ(shader::litIntervals(vec3(1.0f), vec3(0.0f), vec3(0.0f, 0.0f, 1.0f), 3.0f, 3.0f, lit), 0);
}

// A ray with its own light: (origin, t0), (dir, t1), (light, 0), as the GPU kernel reads it.
struct LitRay {
    vec3 light, origin, dir;
    float t0, t1;
};

// Random camera rays through the scene's bounds (RandomRays), each with a light at a random point inside the bounds.
std::vector<LitRay> litRays(const std::vector<TriangleMesh>& meshes, std::uint32_t seed, int count) {
    RandomRays random(meshes, seed);
    // RandomRays' bounds are the scene's, grown by a tenth of its size on every side.
    vec3 size = (random.hi - random.lo) / 1.2f;
    vec3 lo = random.lo + 0.1f * size;
    std::vector<LitRay> rays;
    for (int i = 0; i < count; ++i) {
        LitRay ray;
        ray.light = randomPoint(random.rng, lo, lo + size);
        random.next(ray.origin, ray.dir, ray.t1);
        ray.t0 = 0.0f;
        rays.push_back(ray);
    }
    return rays;
}

// Distance from t to the nearest end of any triangle's shadow interval on the ray (brute force over the BVH's
// triangles): where two shadows meet, the lit pieces have no end, but the two shadow-ray tests may disagree there.
float distanceToShadowEnd(const Bvh& bvh, const LitRay& ray, float t) {
    float d = std::numeric_limits<float>::infinity();
    for (const BvhTriangle& tri : bvh.triangles) {
        vec2 shadow;
        if (shader::litShadowInterval(tri, ray.light, ray.origin, ray.dir, ray.t0, ray.t1, shadow))
            d = std::min(d, distanceToEnd(t, &shadow, 1));
    }
    return d;
}

// Disagreements of the lit pieces with a shadow-ray test at dense samples, by where they lie.
struct Disagreements {
    int nearEnd = 0;    // within kEndEpsilon t1 of a lit piece's end
    int nearSeam = 0;   // within kEndEpsilon t1 of an end of some triangle's shadow (a seam between shadows)
    int elsewhere = 0;  // unexplained
    void add(const Bvh& bvh, const LitRay& ray, float t, float distance) {
        if (distance < kEndEpsilon * ray.t1) {
            ++nearEnd;
        } else if (distanceToShadowEnd(bvh, ray, t) < kEndEpsilon * ray.t1) {
            ++nearSeam;
        } else {
            ++elsewhere;
            ADD_FAILURE() << "disagreement at t = " << t << " of [" << ray.t0 << ", " << ray.t1 << "]";
        }
    }
    int total() const { return nearEnd + nearSeam + elsewhere; }
};

std::ostream& operator<<(std::ostream& out, const Disagreements& d) {
    return out << d.nearEnd << " near an end, " << d.nearSeam << " at a seam, " << d.elsewhere << " elsewhere";
}

TEST(LitIntervals, AgreeWithShadowRaysOnBundledProjects) {
    constexpr int kRays = 10000;
    for (const BundledScene& scene : bundledScenes()) {
        SCOPED_TRACE(scene.name);
        Bvh bvh = buildBvh(scene.meshes);
        BvhScope scope(bvh);
        EmbreeTriangles embree(scene.meshes);
        int samples = 0, lit = 0, overflows = 0, maxCount = 0, pieces = 0;
        Disagreements withBvh, withEmbree;
        for (const LitRay& ray : litRays(scene.meshes, 41u, kRays)) {
            LitIntervals intervals;
            int count = shader::litIntervals(ray.light, ray.origin, ray.dir, ray.t0, ray.t1, intervals);
            if (count == kLitOverflow) {
                ++overflows;
                continue;
            }
            ASSERT_GE(count, 0);
            maxCount = std::max(maxCount, count);
            pieces += count;
            for (int k = 0; k < count; ++k) {
                EXPECT_GE(intervals.pieces[k].x, ray.t0);
                EXPECT_LT(intervals.pieces[k].x, intervals.pieces[k].y);
                EXPECT_LE(intervals.pieces[k].y, ray.t1);
                if (k > 0) {
                    EXPECT_LT(intervals.pieces[k - 1].y, intervals.pieces[k].x);
                }
            }
            for (int s = 0; s < kSamples; ++s) {
                float t = ray.t0 + (float(s) + 0.5f) / float(kSamples) * (ray.t1 - ray.t0);
                vec3 x = ray.origin + t * ray.dir;
                bool ours = false;
                for (int k = 0; k < count; ++k)
                    ours = ours || (intervals.pieces[k].x <= t && t <= intervals.pieces[k].y);
                ++samples;
                lit += ours ? 1 : 0;
                float distance = distanceToEnd(t, intervals.pieces, count);
                // The any-hit traversal over the same BVH, and Embree's watertight test, from the light to x.
                if (ours == shader::bvhOccluded(ray.light, x - ray.light, 0.0f, 1.0f))
                    withBvh.add(bvh, ray, t, distance);
                float length = glm::length(x - ray.light);
                if (ours == embree.occluded(ray.light, (x - ray.light) / length, length))
                    withEmbree.add(bvh, ray, t, distance);
            }
        }
        std::cout << "[ LitIntervals ] " << scene.name << ": " << kRays << " rays, " << pieces
                  << " lit pieces (at most " << maxCount << " on a ray), " << overflows << " overflows; " << lit
                  << " of " << samples << " samples lit; disagreements with bvhOccluded: " << withBvh
                  << "; with Embree: " << withEmbree << "\n";
        EXPECT_EQ(overflows, 0);
        // Both outcomes well represented, or the comparison says little.
        EXPECT_GT(lit, samples / 20);
        EXPECT_LT(lit, samples - samples / 20);
        // A sample lands within kEndEpsilon t1 of one of the ~2 ends of a ray with probability ~4e-4, and then the
        // tests disagree only within rounding of the end: a few in a million samples.
        EXPECT_LE(withBvh.total(), samples / 100000);
        EXPECT_LE(withEmbree.total(), samples / 100000);
    }
}

// What the GLSL side of litIntervals gives for each ray (lit_intervals.comp.glsl).
struct GpuLitIntervals {
    std::vector<int> counts;
    std::vector<vec2> pieces;  // kMaxLitIntervals per ray
};

GpuLitIntervals litIntervalsOnGpu(Context& context, const Bvh& bvh, const std::vector<LitRay>& rays) {
    std::vector<vec4> packed;
    for (const LitRay& ray : rays) {
        packed.push_back(vec4(ray.origin, ray.t0));
        packed.push_back(vec4(ray.dir, ray.t1));
        packed.push_back(vec4(ray.light, 0.0f));
    }
    const std::uint32_t count = std::uint32_t(rays.size());
    Buffer nodes(context, bvh.nodes.size() * sizeof(shader::BvhNode));
    Buffer triangles(context, std::max<std::size_t>(bvh.triangles.size(), 1) * sizeof(BvhTriangle));
    Buffer rayBuffer(context, packed.size() * sizeof(vec4));
    Buffer countBuffer(context, count * sizeof(int));
    Buffer pieceBuffer(context, count * kMaxLitIntervals * sizeof(vec2));
    nodes.upload(bvh.nodes);
    triangles.upload(bvh.triangles);
    rayBuffer.upload(packed);
    ComputeKernel kernel(context, test::loadSpirv("lit_intervals"), 5, sizeof(std::uint32_t), "lit_intervals");
    context.submitAndWait([&](VkCommandBuffer cmd) {
        kernel.record(cmd, {&nodes, &triangles, &rayBuffer, &countBuffer, &pieceBuffer}, &count, (count + 63) / 64);
    });
    kernel.resetDescriptors();
    return {countBuffer.download<int>(count), pieceBuffer.download<vec2>(std::size_t(count) * kMaxLitIntervals)};
}

// Endpoints may differ by the GPU's rounding (fma contraction, division): this, relative to t1.
constexpr float kGpuEndTolerance = 1e-4f;

class LitIntervalsGpu : public test::GpuTest {};

TEST_F(LitIntervalsGpu, GlslAgreesWithCpp) {
    struct Case {
        std::string name;
        Bvh bvh;
        std::vector<LitRay> rays;
    };
    std::vector<Case> cases;
    for (const BundledScene& scene : bundledScenes())
        cases.push_back({scene.name, buildBvh(scene.meshes), litRays(scene.meshes, 43u, 1 << 14)});
    // Combs whose ray fits (11 pieces) and overflows.
    for (int teeth : {10, kMaxLitIntervals + 4}) {
        Comb comb(teeth);
        cases.push_back({"comb of " + std::to_string(teeth),
                         comb.bvh,
                         {LitRay{comb.light, comb.origin, comb.dir, 0.0f, 2.0f * comb.reach}}});
    }
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        BvhScope scope(c.bvh);
        GpuLitIntervals gpu = litIntervalsOnGpu(context(), c.bvh, c.rays);
        int countMismatches = 0, overflows = 0, pieces = 0;
        float worst = 0.0f;
        for (std::size_t i = 0; i < c.rays.size(); ++i) {
            const LitRay& ray = c.rays[i];
            LitIntervals cpu;
            int count = shader::litIntervals(ray.light, ray.origin, ray.dir, ray.t0, ray.t1, cpu);
            overflows += count == kLitOverflow ? 1 : 0;
            if (count != gpu.counts[i]) {
                ++countMismatches;
                ADD_FAILURE() << "ray " << i << ": " << count << " pieces on the CPU, " << gpu.counts[i]
                              << " on the GPU";
                continue;
            }
            for (int k = 0; k < count; ++k) {
                vec2 diff = glm::abs(gpu.pieces[i * kMaxLitIntervals + std::size_t(k)] - cpu.pieces[k]) / ray.t1;
                worst = std::max({worst, diff.x, diff.y});
                ++pieces;
            }
        }
        std::cout << "[ LitIntervalsGpu ] " << c.name << " on " << context().device().name << ": " << c.rays.size()
                  << " rays, " << pieces << " pieces, " << overflows << " overflows, " << countMismatches
                  << " count mismatches, endpoints within " << worst << " t1\n";
        EXPECT_LE(worst, kGpuEndTolerance);
    }
}

}  // namespace
}  // namespace tyndall::gpu
