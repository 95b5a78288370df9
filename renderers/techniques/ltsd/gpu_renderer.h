// The LTSD technique on the GPU: uploads a prepared scene and runs shaders/ltsd/ltsd.comp.glsl, one invocation per
// pixel, in slices of about 10 ms (tyndall/gpu/slicer.h) so that a render can be cancelled between slices.
#pragma once

#include "ltsd/prepared.h"

#include "tyndall/framework/kernel_cache.h"
#include "tyndall/framework/primary_hits.h"
#include "tyndall/framework/stage_times.h"
#include "tyndall/framework/technique.h"
#include "tyndall/gpu/context.h"
#include "tyndall/gpu/resources.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace tyndall::ltsd {

struct GpuOutput {
    // Per pixel: A-bar and T L_c-bar (analytic pass), or the four ratio sums; kept by the renderer until its next pass
    // of the same kind.
    const std::vector<glm::vec4>* values = nullptr;
    std::string deviceName;
    double longestSliceMs = 0.0;
    double gpuMs = 0.0;
    double primaryHitsMs = 0.0;   // of gpuMs: the camera hits (raster or traced)
    double compileSeconds = 0.0;  // building the pipeline (0 when it was cached)
    // The analytic pass's camera hits: "raster", "traced: <why>" (framework/primary_hits.h); empty for the ratio pass.
    std::string primaryVisibility;
};

class GpuRenderer {
public:
    GpuRenderer();  // on gpu::sharedContext(); throws GpuError without Vulkan

    // The analytic pass: per pixel A-bar then T L_c-bar. Throws Cancelled, GpuError, ShaderError. Each pass marks its
    // stages in `times` (upload, camera hits, kernel, readback; the ratio pass's prefixed "ratio ").
    GpuOutput render(const PreparedScene& scene, int width, int height, const RenderCallbacks& callbacks,
                     StageTimes& times);
    // The ratio estimators' pass: per pixel the sums over `samples` camera samples of the four LtsdRatioTerms.
    GpuOutput renderRatio(const PreparedScene& scene, int width, int height, int samples, std::uint32_t seed,
                          const RenderCallbacks& callbacks, StageTimes& times);

private:
    gpu::ComputeKernel& kernel(const PreparedScene& scene, bool ratio, bool raster, double& compileSeconds);
    GpuOutput run(const PreparedScene& scene, bool ratio, int width, int height, int samples, std::uint32_t seed,
                  const RenderCallbacks& callbacks, StageTimes& times);

    std::shared_ptr<gpu::Context> context_;
    KernelCache kernels_;  // by variant
    RasterPrimaryHits primaryHits_;
    // Per pass (analytic, ratio): the output buffer and its readback, kept from render to render (gpu::keptBuffer).
    std::unique_ptr<gpu::Buffer> outputs_[2];
    std::vector<glm::vec4> values_[2];
};

}  // namespace tyndall::ltsd
