// The cost of the lit intervals of a camera ray for a point light (shaders/shared/lit_intervals.h) on the CPU, one
// core, on the default project: its camera's rays through random pixel positions, each up to its first surface, and
// its point light "lamp". For scale, one shadow ray (bvhOccluded) from the lamp to a random point of the same rays.
//   build/renderers/bench/tyndall_lit_intervals_bench
#include "shared/lit_intervals.h"
#include "tyndall/core/geometry.h"
#include "tyndall/core/resources.h"
#include "tyndall/gpu/bvh.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace {

using glm::vec3;
using glm::vec4;

struct CameraRays {
    tyndall::gpu::Bvh bvh;
    vec3 light;
    std::vector<vec4> rays;  // (origin, t1), (dir, 0)
    static constexpr int kCount = 1 << 14;
};

const CameraRays& cameraRays() {
    static CameraRays r = [] {
        CameraRays out;
        const std::string dir = (tyndall::resourceRoot() / "projects").string();
        tyndall::Project project = tyndall::loadProject(tyndall::techniqueCatalogue(), dir + "/default.json");
        std::vector<tyndall::TriangleMesh> meshes;
        for (const tyndall::Mesh& mesh : project.scene.meshes)
            meshes.push_back(tyndall::buildMesh(mesh, dir));
        out.bvh = tyndall::gpu::buildBvh(meshes);
        for (const tyndall::PointLight& light : project.scene.pointLights)
            if (light.name == "lamp") out.light = vec3(light.position);
        // Pinhole rays as docs/conventions.md defines them.
        const tyndall::Camera& camera = project.scene.camera;
        vec3 forward = glm::normalize(vec3(camera.target - camera.position));
        vec3 right = glm::normalize(glm::cross(forward, vec3(camera.up)));
        vec3 up = glm::cross(right, forward);
        float tanHalf = float(std::tan(glm::radians(camera.fovY) / 2.0));
        float aspect = float(camera.width) / float(camera.height);
        std::mt19937 rng(9);
        std::uniform_real_distribution<float> unit(0.0f, 1.0f);
        tyndall::gpu::BvhScope scope(out.bvh);
        for (int i = 0; i < CameraRays::kCount; ++i) {
            float x = 2.0f * unit(rng) - 1.0f, y = 1.0f - 2.0f * unit(rng);
            vec3 d = glm::normalize(forward + x * tanHalf * aspect * right + y * tanHalf * up);
            tyndall::shader::BvhHit hit;
            tyndall::shader::bvhIntersect(vec3(camera.position), d, 0.0f, 100.0f, hit);
            out.rays.push_back(vec4(vec3(camera.position), hit.t));
            out.rays.push_back(vec4(d, 0.0f));
        }
        return out;
    }();
    return r;
}

void BM_LitIntervalsPerCameraRay(benchmark::State& state) {
    const CameraRays& r = cameraRays();
    tyndall::gpu::BvhScope scope(r.bvh);
    std::size_t i = 0;
    long pieces = 0, overflows = 0, calls = 0;
    for (auto _ : state) {
        vec4 o = r.rays[2 * i], d = r.rays[2 * i + 1];
        tyndall::shader::LitIntervals lit;
        int count = tyndall::shader::litIntervals(r.light, vec3(o), vec3(d), 0.0f, o.w, lit);
        benchmark::DoNotOptimize(lit);
        pieces += count > 0 ? count : 0;
        overflows += count == tyndall::shader::kLitOverflow ? 1 : 0;
        ++calls;
        i = (i + 1) % CameraRays::kCount;
    }
    state.counters["pieces_per_ray"] = double(pieces) / double(calls);
    state.counters["overflows"] = double(overflows);
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LitIntervalsPerCameraRay);

void BM_ShadowRayForComparison(benchmark::State& state) {
    const CameraRays& r = cameraRays();
    tyndall::gpu::BvhScope scope(r.bvh);
    std::mt19937 rng(10);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<vec3> points;
    for (int i = 0; i < CameraRays::kCount; ++i)
        points.push_back(vec3(r.rays[2 * i]) + unit(rng) * r.rays[2 * i].w * vec3(r.rays[2 * i + 1]));
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(tyndall::shader::bvhOccluded(r.light, points[i] - r.light, 0.0f, 1.0f));
        i = (i + 1) % CameraRays::kCount;
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ShadowRayForComparison);

}  // namespace

BENCHMARK_MAIN();
