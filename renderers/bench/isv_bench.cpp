// Frame time of the ISV technique at 512 x 512 on the bundled smoke scene (projects/isv/smoke.json), the analogue of
// the thesis' Sec. 4.2 plots:
//   build/renderers/bench/tyndall_isv_bench [--benchmark_filter=...]
// Every GPU benchmark reports the GPU time from the device's timestamps (lavapipe here), the first render (which
// compiles the pipelines) untimed, and the time of each pass as counters (ms): shadow = opaque shadow map, vsm =
// volumetric shadow map, surfaces, sort, particles = proxies + shading + blending. Target (issue 20) on lavapipe:
// 5000 particles at >= 10 frames/s (<= 100 ms) with Simpson 2 steps.
// - BM_IsvParticles/count: particle count (500, 5000, 50000), Simpson 2 steps
// - BM_IsvSteps/steps: Simpson steps (1, 2, 4, 10), 5000 particles
// - BM_IsvIntegration/mode: 0 analytic, 1 taylor, 2 simpson (1 step)
// - BM_IsvVsmSlices/slices, BM_IsvVsmResolution/texels: the volumetric shadow map
// - BM_IsvPcf/radius: 0 (off), 2 (5 x 5), 4 (9 x 9)
// - BM_IsvFading/on: extinction fading off (0) or on (1), 1 Simpson step
// - BM_IsvLights/lights: 1, 2 or 3 lights (one pass each), Simpson 2 steps; the wall time in the counter wallMs
// - BM_IsvCpu/count: wall time of the CPU model (every core), Simpson 2 steps
#include "tyndall/core/resources.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

using namespace tyndall;

namespace {

const std::string kProject = (tyndall::resourceRoot() / "projects/isv/smoke.json").string();

RenderJob frameJob(std::vector<std::string> parameters, int count = 5000, const std::string& device = "gpu") {
    std::vector<std::string> overrides = {"camera.width=512", "camera.height=512",
                                          "particleMedia[0].generator.count=" + std::to_string(count),
                                          "views[isv].parameters.device=" + device};
    for (const std::string& p : parameters)
        overrides.push_back("views[isv].parameters." + p);
    const Project project = loadProject(techniqueCatalogue(), kProject, overrides);
    return makeViewJob(project, kProject, "isv", {});
}

void runGpu(benchmark::State& state, RenderJob job) {
    runJob(job);  // compiles the pipelines
    const char* passes[] = {"shadowMapMs", "vsmMs", "surfacesMs", "sortMs", "particlesMs"};
    const char* names[] = {"shadow", "vsm", "surfaces", "sort", "particles"};
    double sums[5] = {}, longest = 0.0;
    int n = 0;
    for (auto _ : state) {
        const RenderResult r = runJob(job);
        state.SetIterationTime(std::stod(r.image.metadata.at("gpu:totalMs")) * 1e-3);
        for (int i = 0; i < 5; ++i)
            sums[i] += std::stod(r.image.metadata.at(std::string("gpu:") + passes[i]));
        longest = std::max(longest, std::stod(r.image.metadata.at("gpu:longestSliceMs")));
        ++n;
    }
    for (int i = 0; i < 5; ++i)
        state.counters[names[i]] = sums[i] / std::max(n, 1);
    state.counters["longestSliceMs"] = longest;
}

void BM_IsvParticles(benchmark::State& state) {
    runGpu(state, frameJob({"steps=2"}, int(state.range(0))));
}
BENCHMARK(BM_IsvParticles)->Arg(500)->Arg(5000)->Arg(50000)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_IsvSteps(benchmark::State& state) {
    runGpu(state, frameJob({"steps=" + std::to_string(state.range(0))}));
}
BENCHMARK(BM_IsvSteps)->Arg(1)->Arg(2)->Arg(4)->Arg(10)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_IsvIntegration(benchmark::State& state) {
    const char* modes[] = {"analytic", "taylor", "simpson"};
    runGpu(state, frameJob({std::string("integration=") + modes[state.range(0)]}));
}
BENCHMARK(BM_IsvIntegration)->DenseRange(0, 2)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_IsvVsmSlices(benchmark::State& state) {
    runGpu(state, frameJob({"steps=2", "vsmSlices=" + std::to_string(state.range(0))}));
}
BENCHMARK(BM_IsvVsmSlices)->Arg(4)->Arg(16)->Arg(64)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_IsvVsmResolution(benchmark::State& state) {
    runGpu(state, frameJob({"steps=2", "vsmResolution=" + std::to_string(state.range(0))}));
}
BENCHMARK(BM_IsvVsmResolution)->Arg(64)->Arg(128)->Arg(512)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_IsvPcf(benchmark::State& state) {
    runGpu(state, frameJob({"steps=2", "pcfRadius=" + std::to_string(state.range(0))}));
}
BENCHMARK(BM_IsvPcf)->Arg(0)->Arg(2)->Arg(4)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_IsvFading(benchmark::State& state) {
    runGpu(state, frameJob({std::string("fading=") + (state.range(0) != 0 ? "true" : "false")}));
}
BENCHMARK(BM_IsvFading)->Arg(0)->Arg(1)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

// The cost per added light (issue 32): one pass per light, 5000 particles, Simpson 2 steps; 1 = the smoke's sun, 2 =
// and a fill light from the other side, 3 = and a spot light above the cloud. GPU time, and the wall time of the whole
// render in the counter wallMs (preparation and readback included).
void BM_IsvLights(benchmark::State& state) {
    std::vector<std::string> overrides = {"camera.width=512", "camera.height=512", "views[isv].parameters.device=gpu",
                                          "views[isv].parameters.steps=2"};
    if (state.range(0) >= 2)
        overrides.push_back(R"(lights[+]={"name": "fill", "type": "directional", "direction": [-0.6, -0.7, 0.4],
            "irradiance": [1.0, 1.1, 1.3]})");
    if (state.range(0) >= 3)
        overrides.push_back(R"(lights[+]={"name": "spot", "type": "point", "position": [1.5, 3.5, 1.5],
            "intensity": [8, 8, 8], "distribution": {"type": "spot", "axis": [-0.5, -0.85, -0.5], "exponent": 4}})");
    const Project project = loadProject(techniqueCatalogue(), kProject, overrides);
    RenderJob job = makeViewJob(project, kProject, "isv", {});
    runJob(job);  // compiles the pipelines
    double wall = 0.0;
    int n = 0;
    for (auto _ : state) {
        const RenderResult r = runJob(job);
        if (r.image.metadata.at("isv:lights") != std::to_string(state.range(0)))
            state.SkipWithError("the view does not render every light");
        state.SetIterationTime(std::stod(r.image.metadata.at("gpu:totalMs")) * 1e-3);
        wall += 1e3 * std::stod(r.image.metadata.at("renderTime"));
        ++n;
    }
    state.counters["wallMs"] = wall / std::max(n, 1);
}
BENCHMARK(BM_IsvLights)->DenseRange(1, 3)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_IsvCpu(benchmark::State& state) {
    RenderJob job = frameJob({"steps=2"}, int(state.range(0)), "cpu");
    for (auto _ : state)
        benchmark::DoNotOptimize(runJob(job));
}
BENCHMARK(BM_IsvCpu)->Arg(500)->Arg(5000)->Arg(50000)->Iterations(2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
