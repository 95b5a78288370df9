// Shadow-query throughput of the reference against Embree's raw rtcOccluded1 on the same rays, in the same run.
//   build/renderers/bench/tyndall_reference_bench
// Target (issue "Reference renderer"): the renderer's occlusion-only queries reach >= 50 % of the raw rate. The full
// query (occlusion plus exact transmittance through the media) is reported beside it.
#include "reference/integrator.h"

#include "tyndall/core/resources.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"

#include <benchmark/benchmark.h>

#include <random>

namespace {

using namespace tyndall;

struct ShadowRays {
    std::unique_ptr<reference::RenderScene> scene;
    std::vector<glm::vec3> origins, dirs;
    std::vector<float> distances;
};

// Rays from random points in the default project's room towards random points of its area light and its lamp.
const ShadowRays& shadowRays() {
    static ShadowRays rays = [] {
        ShadowRays r;
        Project project =
            loadProject(techniqueCatalogue(), (tyndall::resourceRoot() / "projects/default.json").string());
        r.scene = reference::prepareScene(project.scene, (tyndall::resourceRoot() / "projects").string());
        std::mt19937 rng(1);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        const glm::vec3 lamp = r.scene->pointLights.at(0).position;
        const auto& panel = r.scene->areaLights.at(0).vertices;
        for (int i = 0; i < 1 << 16; ++i) {
            glm::vec3 x(-1.9f + 3.8f * u(rng), 0.05f + 2.85f * u(rng), -1.9f + 3.8f * u(rng));
            glm::vec3 target = (i & 1) ? lamp : glm::mix(glm::mix(panel[0], panel[1], u(rng)), glm::mix(panel[3], panel[2], u(rng)), u(rng));
            glm::vec3 d = target - x;
            float len = glm::length(d);
            r.origins.push_back(x);
            r.dirs.push_back(d / len);
            r.distances.push_back(len);
        }
        return r;
    }();
    return rays;
}

void BM_EmbreeRawOccluded(benchmark::State& state) {
    const ShadowRays& r = shadowRays();
    RTCScene scene = r.scene->embree->surfaceScene();
    size_t i = 0, blocked = 0;
    for (auto _ : state) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay ray{};
        ray.org_x = r.origins[i].x;
        ray.org_y = r.origins[i].y;
        ray.org_z = r.origins[i].z;
        ray.dir_x = r.dirs[i].x;
        ray.dir_y = r.dirs[i].y;
        ray.dir_z = r.dirs[i].z;
        ray.tnear = 0.0f;
        ray.tfar = r.distances[i] * (1.0f - 1e-5f);
        ray.mask = 0xffffffffu;
        rtcOccluded1(scene, &context, &ray);
        blocked += ray.tfar < 0.0f;
        i = (i + 1) & (r.origins.size() - 1);
    }
    benchmark::DoNotOptimize(blocked);
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EmbreeRawOccluded);

void BM_ReferenceOcclusionQuery(benchmark::State& state) {
    const ShadowRays& r = shadowRays();
    size_t i = 0, blocked = 0;
    for (auto _ : state) {
        blocked += r.scene->embree->occluded(r.origins[i], r.dirs[i], 0.0f, r.distances[i] * (1.0f - 1e-5f));
        i = (i + 1) & (r.origins.size() - 1);
    }
    benchmark::DoNotOptimize(blocked);
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ReferenceOcclusionQuery);

void BM_ReferenceShadowTransmittance(benchmark::State& state) {
    const ShadowRays& r = shadowRays();
    reference::Integrator integrator(*r.scene, reference::IntegratorOptions{});
    size_t i = 0;
    glm::vec3 sum(0.0f);
    for (auto _ : state) {
        sum += integrator.shadowTransmittance(r.origins[i], r.dirs[i], r.distances[i], 0.0f);
        i = (i + 1) & (r.origins.size() - 1);
    }
    benchmark::DoNotOptimize(sum);
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ReferenceShadowTransmittance);

}  // namespace

BENCHMARK_MAIN();
