// Frame time of each WVDS estimator on the Fig. 6 project (projects/examples/wvds-box.json) at 512 x 512, one camera
// sample per pixel:
//   build/renderers/bench/tyndall_wvds_bench
// - BM_WvdsGpu/estimator: GPU time of the render on the Vulkan device (lavapipe here), from its timestamps; the first
//   render compiles the pipeline and is not timed. Target on lavapipe: mcwvds <= 100 ms.
// - BM_WvdsGpuMediumOnly/estimator: the same without the scene's meshes (no camera hits, no shadow rays), so that the
//   frame is the medium's single scattering alone: for the analytic estimator, the unoccluded integral over the image,
//   the technique's own pass as the paper times it (Sec. 7). Target on lavapipe: analytic <= 10 ms. (docs/wvds.md,
//   Measured, has the numbers and what the full frame adds.)
// - BM_WvdsCpu/estimator: wall time of the CPU path (every core).
#include "stage_counters.h"

#include "tyndall/core/resources.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

using namespace tyndall;

namespace {

const std::string kProject = (tyndall::resourceRoot() / "projects/examples/wvds-box.json").string();
const char* kEstimators[] = {"analytic", "mcwvds", "reds", "rees", "rm", "mcds"};

RenderJob frameJob(const std::string& estimator, const std::string& device, bool meshes = true) {
    std::vector<std::string> overrides = {"camera.width=512", "camera.height=512",
                                          "views[mcwvds].parameters.device=" + device,
                                          "views[mcwvds].parameters.estimator=" + estimator};
    if (!meshes) overrides.push_back("meshes=[]");
    const Project project = loadProject(techniqueCatalogue(), kProject, overrides);
    JobOptions options;
    options.spp = 1;
    return makeViewJob(project, kProject, "mcwvds", options);
}

void gpuFrames(benchmark::State& state, bool meshes) {
    const std::string estimator = kEstimators[state.range(0)];
    RenderJob job = frameJob(estimator, "gpu", meshes);
    runJob(job);  // compiles the pipeline
    double longest = 0.0;
    bench::StageCounters stages;
    for (auto _ : state) {
        const RenderResult r = runJob(job);
        state.SetIterationTime(std::stod(r.image.metadata.at("gpu:totalMs")) * 1e-3);
        longest = std::stod(r.image.metadata.at("gpu:longestSliceMs"));
        stages.add(r.image);
    }
    state.counters["longestSliceMs"] = longest;
    stages.report(state);
    state.SetLabel(estimator);
}

void BM_WvdsGpu(benchmark::State& state) { gpuFrames(state, true); }
BENCHMARK(BM_WvdsGpu)->DenseRange(0, 5)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_WvdsGpuMediumOnly(benchmark::State& state) { gpuFrames(state, false); }
BENCHMARK(BM_WvdsGpuMediumOnly)->DenseRange(0, 1)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_WvdsCpu(benchmark::State& state) {
    const std::string estimator = kEstimators[state.range(0)];
    RenderJob job = frameJob(estimator, "cpu");
    for (auto _ : state)
        benchmark::DoNotOptimize(runJob(job));
    state.SetLabel(estimator);
}
BENCHMARK(BM_WvdsCpu)->DenseRange(0, 5)->Iterations(5)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
