// Frame time of Volume-RIS on its bundled project (projects/examples/volume-ris-shaft.json, view "shaft": a box of fog, a quad
// light, an occluding plate, a diffuse ground and a GGX ball) at 512 x 512, one camera sample per pixel, for
// M = 8 and 32 candidates, light points by solid angle (the default, second argument 0) or by area (1):
//   build/renderers/bench/tyndall_volume_ris_bench
// - BM_VolumeRisGpu/M/sampling: GPU time of the render on the Vulkan device (lavapipe here), from its timestamps; the first
//   render compiles the pipeline and is not timed.
// - BM_VolumeRisCpu/M/sampling: wall time of the CPU path (every core).
// docs/volume-ris.md, Measured, has the numbers.
#include "tyndall/core/resources.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

using namespace tyndall;

namespace {

const std::string kProject = (tyndall::resourceRoot() / "projects/examples/volume-ris-shaft.json").string();

RenderJob frameJob(int candidates, bool area, const std::string& device) {
    const std::vector<std::string> overrides = {
        "camera.width=512", "camera.height=512", "views[shaft].parameters.device=" + device,
        "views[shaft].parameters.candidates=" + std::to_string(candidates),
        std::string("views[shaft].parameters.lightSampling=") + (area ? "area" : "solidAngle")};
    const Project project = loadProject(techniqueCatalogue(), kProject, overrides);
    JobOptions options;
    options.spp = 1;
    return makeViewJob(project, kProject, "shaft", options);
}

void BM_VolumeRisGpu(benchmark::State& state) {
    RenderJob job = frameJob(int(state.range(0)), state.range(1) != 0, "gpu");
    runJob(job);  // compiles the pipeline
    for (auto _ : state) {
        const RenderResult r = runJob(job);
        state.SetIterationTime(std::stod(r.image.metadata.at("gpu:totalMs")) * 1e-3);
    }
    state.SetLabel("M = " + std::to_string(state.range(0)) + (state.range(1) ? ", area" : ", solid angle"));
}
BENCHMARK(BM_VolumeRisGpu)->ArgsProduct({{8, 32}, {0, 1}})->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_VolumeRisCpu(benchmark::State& state) {
    RenderJob job = frameJob(int(state.range(0)), state.range(1) != 0, "cpu");
    for (auto _ : state)
        benchmark::DoNotOptimize(runJob(job));
    state.SetLabel("M = " + std::to_string(state.range(0)) + (state.range(1) ? ", area" : ", solid angle"));
}
BENCHMARK(BM_VolumeRisCpu)->ArgsProduct({{8, 32}, {0, 1}})->Iterations(3)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
