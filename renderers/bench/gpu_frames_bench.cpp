// Frame time of every GPU technique at 512 x 512 and 1920 x 1080, the cases and targets of issue 37 (docs/gpu.md):
//   build/renderers/bench/tyndall_gpu_frames_bench [--benchmark_filter=ltsd] [--benchmark_out=f.json ...]
// The time of an iteration is the frame's GPU time from the device's timestamps (metadata gpu:totalMs); the first
// render, which compiles the pipelines, is not timed. Counters: each pass's GPU time as the technique records it
// (metadata gpu:<pass>Ms: camera hits, air-light, ratios, shadow maps, sort, particles ...), the wall time of a frame
// (wallMs: uploads, readback and the CPU's share included), where that wall time goes (the stages of
// framework/stage_times.h: prepare, upload, kernel, readback, resolve ..., ms) and the target (targetMs; 0 where there
// is none).
// tyndall-gpu-check (packaging/gpu-check.sh) runs it and compares each case with its target.
#include "stage_counters.h"

#include "tyndall/core/resources.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace tyndall;

namespace {

struct FrameCase {
    const char* name;     // the benchmark's name: BM_Frame/<name>/<width>x<height>
    const char* project;  // under resourceRoot()/projects
    const char* view;
    std::vector<std::string> parameters;  // the view's parameters, "name=value"
    std::vector<std::string> overrides;   // other --set overrides
    double targetMs;                      // at 1920 x 1080 (issue 37); 0: no target, reported only
};

const std::vector<FrameCase>& frameCases() {
    static const std::vector<FrameCase> cases = {
        // The paper's LTSD: N = 8 nodes, one area light, the analytic air-light without the ratio estimators' shadows.
        {"ltsd",
         "examples/ltsd-room.json",
         "ltsd",
         {"nodes=8", "shadows=off"},
         {"views[ltsd].lights=[\"ceiling panel\"]", "views[ltsd].media=[\"fog\"]"},
         8.0},
        // The same with the ratio estimators' shadows (16 samples, denoised): what the studio shows by default.
        {"ltsd-shadowed",
         "examples/ltsd-room.json",
         "ltsd",
         {"nodes=8", "shadows=ratio-denoised"},
         {"views[ltsd].lights=[\"ceiling panel\"]", "views[ltsd].media=[\"fog\"]"},
         0.0},
        {"isv",
         "isv/smoke.json",
         "isv",
         {"steps=2", "integration=simpson"},
         {"particleMedia[0].generator.count=5000"},
         8.0},
        {"wvds", "examples/wvds-box.json", "analytic", {"samplesPerPixel=1"}, {}, 4.0},
        // The isotropic lamp of the street scene (its view renders that light alone), one ray per pixel.
        {"pegoraro", "examples/pegoraro-street.json", "lamp only", {"supersampling=1"}, {}, 3.0},
        {"volume-ris", "examples/volume-ris-shaft.json", "shaft", {"candidates=32", "samplesPerPixel=1"}, {}, 10.0},
    };
    return cases;
}

RenderJob frameJob(const FrameCase& c, int width, int height) {
    const std::string path = (resourceRoot() / "projects" / c.project).string();
    const std::string view = std::string("views[") + c.view + "]";
    std::vector<std::string> overrides = c.overrides;
    overrides.push_back("camera.width=" + std::to_string(width));
    overrides.push_back("camera.height=" + std::to_string(height));
    overrides.push_back(view + ".parameters.device=gpu");
    for (const std::string& p : c.parameters)
        overrides.push_back(view + ".parameters." + p);
    const Project project = loadProject(techniqueCatalogue(), path, overrides);
    JobOptions options;
    options.spp = 1;
    return makeViewJob(project, path, c.view, options);
}

void BM_Frame(benchmark::State& state, const FrameCase& c, int width, int height) {
    RenderJob job = frameJob(c, width, height);
    const RenderResult first = runJob(job);  // compiles the pipelines
    if (first.image.metadata.count("gpu:totalMs") == 0) {
        state.SkipWithError(("the view did not run on the GPU (device " +
                             (first.image.metadata.count("device") ? first.image.metadata.at("device") : "?") + ")")
                                .c_str());
        return;
    }
    std::map<std::string, double> passes;
    bench::StageCounters stages;
    double wallMs = 0.0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        const RenderResult r = runJob(job);
        wallMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        state.SetIterationTime(std::stod(r.image.metadata.at("gpu:totalMs")) * 1e-3);
        stages.add(r.image, "stage");
        for (const auto& [key, value] : r.image.metadata) {
            if (key.starts_with("gpu:") && key.ends_with("Ms") && key != "gpu:totalMs" && key != "gpu:longestSliceMs")
                passes[key.substr(4)] += std::stod(value);
        }
    }
    const double frames = double(state.iterations());
    for (const auto& [pass, sum] : passes)
        state.counters[pass] = sum / frames;
    state.counters["wallMs"] = wallMs / frames;
    stages.report(state);
    state.counters["targetMs"] = width == 1920 && height == 1080 ? c.targetMs : 0.0;
    state.SetLabel(first.image.metadata.count("device") ? first.image.metadata.at("device") : "");
}

// The frame sizes: 512 x 512 and 1920 x 1080, or $TYNDALL_BENCH_SIZES ("64x64,128x96": gpu-check's quick run on
// lavapipe). A malformed list is refused before anything runs.
std::vector<std::pair<int, int>> frameSizes() {
    const char* list = std::getenv("TYNDALL_BENCH_SIZES");
    if (!list || !*list) return {{512, 512}, {1920, 1080}};
    std::vector<std::pair<int, int>> sizes;
    std::stringstream in(list);
    for (std::string item; std::getline(in, item, ',');) {
        int width = 0, height = 0;
        char x = 0, extra = 0;
        if (std::sscanf(item.c_str(), "%d%c%d%c", &width, &x, &height, &extra) != 3 || x != 'x' || width < 1 ||
            height < 1 || width > 8192 || height > 8192) {
            std::fprintf(stderr, "TYNDALL_BENCH_SIZES: '%s' is not a list of WIDTHxHEIGHT (1 to 8192 each)\n", list);
            std::exit(2);
        }
        sizes.emplace_back(width, height);
    }
    return sizes;
}

// Timed frames per case: 10, or $TYNDALL_BENCH_FRAMES. A fixed count, not a minimum time: a frame's GPU time can be a
// small part of its wall time (the CPU's share of Pegoraro's frame is ~200 ms), and Google Benchmark would add frames
// until the GPU time alone reached the minimum.
int timedFrames() {
    const char* text = std::getenv("TYNDALL_BENCH_FRAMES");
    if (!text || !*text) return 10;
    char* end = nullptr;
    const long frames = std::strtol(text, &end, 10);
    if (*end != '\0' || frames < 1 || frames > 10000) {
        std::fprintf(stderr, "TYNDALL_BENCH_FRAMES: '%s' is not a whole number of frames in [1, 10000]\n", text);
        std::exit(2);
    }
    return int(frames);
}

// Registered at start-up, one benchmark per case and size.
const bool kRegistered = [] {
    const std::vector<std::pair<int, int>> sizes = frameSizes();
    const int frames = timedFrames();
    for (const FrameCase& c : frameCases()) {
        for (const auto& [width, height] : sizes) {
            const std::string name =
                std::string("BM_Frame/") + c.name + "/" + std::to_string(width) + "x" + std::to_string(height);
            benchmark::RegisterBenchmark(name.c_str(), [&c, width = width, height = height](
                                                           benchmark::State& s) { BM_Frame(s, c, width, height); })
                ->UseManualTime()
                ->Iterations(frames)
                ->Unit(benchmark::kMillisecond);
        }
    }
    return true;
}();

}  // namespace

BENCHMARK_MAIN();
