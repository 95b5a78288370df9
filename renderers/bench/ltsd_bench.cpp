// Frame time of the LTSD technique at 512 x 512 on the example room (projects/examples/ltsd-room.json), for N = 1, 8,
// 64 quadrature nodes with one light (the ceiling panel) and with four (the room's two and two more panels):
//   build/renderers/bench/tyndall_ltsd_technique_bench
// - BM_LtsdGpu/N/lights: wall time of the render on the Vulkan device (lavapipe here), preparation, uploads, camera
//   hits and readback included; the device's own timestamps in the counter gpuTimestampMs (lavapipe's read far too
//   low once a kernel has run in the process). The first render compiles the pipeline and is not timed. Target
//   (issue 18) on lavapipe: N = 8, one light, >= 20 frames/s (<= 50 ms).
// - BM_LtsdCpu/N/lights: wall time of the CPU path (every core).
// - BM_LtsdGpuTransmittancePolygon/N: one light with the polygon-averaged transmittance instead of Eq. 10.
// - BM_LtsdGpuRatio1/denoised: N = 8, one light, one ratio sample per pixel for the shadows (wall time, the CPU
//   denoiser included).
// - BM_LtsdGpuPrimaryVisibility/medium: N = 8, one light, the room with (1) and without (0) its fog, the camera hits
//   rasterised (framework/primary_hits.h) and traced (TYNDALL_RASTER_PRIMARY=0), alternately frame by frame: the wall
//   time of each render in the counters rasterMs and tracedMs (the raster pass, preparation and readback included).
//   Target (issue 31) without the medium on lavapipe: <= 15 ms.
// - BM_LtsdSMethod/device: N = 8, one light, the accurate S (the default) and the paper's alternately, on the GPU (0)
//   and the CPU (1): wall time per render in the counters accurateMs and paperMs (issue 32).
// Every case but BM_LtsdGpuRatio1 is unshadowed (shadows = off); every case but BM_LtsdSMethod uses the default S.
#include "stage_counters.h"

#include "tyndall/core/resources.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

using namespace tyndall;

namespace {

const std::string kProject = (tyndall::resourceRoot() / "projects/examples/ltsd-room.json").string();

RenderJob frameJob(int nodes, int lights, const std::string& device, const std::string& transmittance = "min-distance",
                   const std::string& shadows = "off", const std::string& sMethod = "accurate") {
    std::vector<std::string> overrides = {"camera.width=512",
                                          "camera.height=512",
                                          "views[ltsd].parameters.sMethod=" + sMethod,
                                          "views[ltsd].parameters.device=" + device,
                                          "views[ltsd].parameters.shadows=" + shadows,
                                          "views[ltsd].parameters.ratioSamples=1",
                                          "views[ltsd].parameters.nodes=" + std::to_string(nodes),
                                          "views[ltsd].parameters.transmittance=" + transmittance};
    if (lights == 1) {
        overrides.push_back("views[ltsd].lights=[\"ceiling panel\"]");
        overrides.push_back("views[ltsd].media=[\"fog\"]");
    }
    if (lights == 4) {
        overrides.push_back(R"(lights[+]={"name": "panel 3", "type": "area", "radiance": [5, 5, 5],
            "vertices": [[0.6, 2.9, -1.3], [1.2, 2.9, -1.3], [1.2, 2.9, -0.7], [0.6, 2.9, -0.7]]})");
        overrides.push_back(R"(lights[+]={"name": "panel 4", "type": "area", "radiance": [5, 5, 5],
            "vertices": [[-1.2, 2.9, 0.2], [-0.6, 2.9, 0.2], [-0.6, 2.9, 0.8], [-1.2, 2.9, 0.8]]})");
    }
    const Project project = loadProject(techniqueCatalogue(), kProject, overrides);
    return makeViewJob(project, kProject, "ltsd", {});
}

// Two variants of a frame measured alternately (the machine's speed drifts), each run once first untimed (pipeline
// compilation): `timed` (ms) is the iteration time, and the counters `timedName` and `baselineName` hold the means.
void alternate(benchmark::State& state, const std::function<double()>& timed, const std::function<double()>& baseline,
               const char* timedName, const char* baselineName) {
    timed();
    baseline();
    double timedMs = 0.0, baselineMs = 0.0;
    int frames = 0;
    for (auto _ : state) {
        baselineMs += baseline();
        const double t = timed();
        timedMs += t;
        ++frames;
        state.SetIterationTime(t * 1e-3);
    }
    state.counters[timedName] = timedMs / frames;
    state.counters[baselineName] = baselineMs / frames;
}

void BM_LtsdGpu(benchmark::State& state) {
    RenderJob job = frameJob(int(state.range(0)), int(state.range(1)), "gpu");
    runJob(job);  // compiles the pipeline
    double longest = 0.0, timestamps = 0.0;
    for (auto _ : state) {
        const RenderResult r = runJob(job);
        state.SetIterationTime(std::stod(r.image.metadata.at("renderTime")));
        longest = std::stod(r.image.metadata.at("gpu:longestSliceMs"));
        timestamps += std::stod(r.image.metadata.at("gpu:totalMs"));
    }
    state.counters["longestSliceMs"] = longest;
    state.counters["gpuTimestampMs"] = timestamps / double(state.iterations());
}
BENCHMARK(BM_LtsdGpu)
    ->ArgsProduct({{1, 8, 64}, {1, 4}})
    ->UseManualTime()
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

void BM_LtsdGpuTransmittancePolygon(benchmark::State& state) {
    RenderJob job = frameJob(int(state.range(0)), 1, "gpu", "polygon");
    runJob(job);
    for (auto _ : state) {
        const RenderResult r = runJob(job);
        state.SetIterationTime(std::stod(r.image.metadata.at("renderTime")));
    }
}
BENCHMARK(BM_LtsdGpuTransmittancePolygon)->Arg(8)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

// One ratio sample per pixel (Sec. 6), raw and denoised, N = 8, one light: the shadowed frame's cost.
void BM_LtsdGpuRatio1(benchmark::State& state) {
    RenderJob job = frameJob(8, 1, "gpu", "min-distance", state.range(0) != 0 ? "ratio-denoised" : "ratio");
    runJob(job);
    for (auto _ : state) {
        const RenderResult r = runJob(job);
        state.SetIterationTime(std::stod(r.image.metadata.at("renderTime")));
    }
}
BENCHMARK(BM_LtsdGpuRatio1)->Arg(0)->Arg(1)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

void BM_LtsdGpuPrimaryVisibility(benchmark::State& state) {
    const bool medium = state.range(0) != 0;
    RenderJob job = frameJob(8, 1, "gpu");
    if (!medium) {
        const Project project = loadProject(
            techniqueCatalogue(), kProject,
            {"camera.width=512", "camera.height=512", "views[ltsd].parameters.device=gpu",
             "views[ltsd].parameters.shadows=off", "views[ltsd].lights=[\"ceiling panel\"]", "views[ltsd].media=[]"});
        job = makeViewJob(project, kProject, "ltsd", {});
    }
    bench::StageCounters stages;
    bool warm[2] = {false, false};  // per variant (traced, raster): the untimed first frame (compilation) is left out
    const auto frame = [&](bool raster) {
        setenv("TYNDALL_RASTER_PRIMARY", raster ? "1" : "0", 1);
        const RenderResult r = runJob(job);
        if (warm[raster]) stages.add(r.image, raster ? "raster" : "traced");
        warm[raster] = true;
        if (r.image.metadata.at("primaryVisibility") != (raster ? "raster" : "traced: TYNDALL_RASTER_PRIMARY=0"))
            state.SkipWithError(("primaryVisibility: " + r.image.metadata.at("primaryVisibility")).c_str());
        // Wall time of the whole render (preparation, uploads, passes, readback): lavapipe's timestamps of the compute
        // slices read far too low once a kernel has run in the process (0.8 ms for a frame that takes 360 ms).
        return 1e3 * std::stod(r.image.metadata.at("renderTime"));
    };
    alternate(
        state, [&] { return frame(true); }, [&] { return frame(false); }, "rasterMs", "tracedMs");
    unsetenv("TYNDALL_RASTER_PRIMARY");
    stages.report(state);  // where each variant's frame goes, ms per timed frame
}
BENCHMARK(BM_LtsdGpuPrimaryVisibility)->Arg(0)->Arg(1)->UseManualTime()->Iterations(5)->Unit(benchmark::kMillisecond);

// An edit's frame as the studio and the CLI render it: a new job (and so a new technique object) per frame, N = 8, one
// light, without the medium (range 0) and with it (1); wall time of the render, its stages in the counters.
void BM_LtsdGpuNewJobPerFrame(benchmark::State& state) {
    std::vector<std::string> overrides = {"camera.width=512", "camera.height=512", "views[ltsd].parameters.device=gpu",
                                          "views[ltsd].parameters.shadows=off",
                                          "views[ltsd].lights=[\"ceiling panel\"]"};
    if (state.range(0) == 0) overrides.push_back("views[ltsd].media=[]");
    const Project project = loadProject(techniqueCatalogue(), kProject, overrides);
    bench::StageCounters stages;
    for (auto _ : state) {
        RenderJob job = makeViewJob(project, kProject, "ltsd", {});
        const RenderResult r = runJob(job);
        state.SetIterationTime(std::stod(r.image.metadata.at("renderTime")));
        stages.add(r.image);
    }
    stages.report(state);
}
BENCHMARK(BM_LtsdGpuNewJobPerFrame)->Arg(0)->Arg(1)->UseManualTime()->Iterations(4)->Unit(benchmark::kMillisecond);

// The cost of the accurate S against the paper's: N = 8, one light, the polygon-averaged transmittance, on the GPU
// (range 0; lavapipe here) and the CPU path (1), the two methods alternately frame by frame; the wall time of each
// render in the counters paperMs and accurateMs.
void BM_LtsdSMethod(benchmark::State& state) {
    const std::string device = state.range(0) == 0 ? "gpu" : "cpu";
    RenderJob paper = frameJob(8, 1, device, "polygon", "off", "paper");
    RenderJob accurate = frameJob(8, 1, device, "polygon", "off", "accurate");
    const auto frame = [](RenderJob& job) { return 1e3 * std::stod(runJob(job).image.metadata.at("renderTime")); };
    alternate(
        state, [&] { return frame(accurate); }, [&] { return frame(paper); }, "accurateMs", "paperMs");
}
BENCHMARK(BM_LtsdSMethod)->Arg(0)->Arg(1)->UseManualTime()->Iterations(4)->Unit(benchmark::kMillisecond);

void BM_LtsdCpu(benchmark::State& state) {
    RenderJob job = frameJob(int(state.range(0)), int(state.range(1)), "cpu");
    for (auto _ : state)
        benchmark::DoNotOptimize(runJob(job));
}
BENCHMARK(BM_LtsdCpu)->ArgsProduct({{1, 8, 64}, {1, 4}})->Iterations(2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
