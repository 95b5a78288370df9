// The Pegoraro technique on the GPU: uploads a prepared scene and runs shaders/pegoraro/pegoraro.comp.glsl in slices
// of about 10 ms (tyndall/gpu/slicer.h), so that a render can be cancelled between slices.
#pragma once

#include "pegoraro/prepared.h"

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

namespace tyndall::pegoraro {

struct GpuOutput {
    std::vector<glm::vec4> radiance;       // rgb, closed-form evaluations that fell back
    std::vector<std::uint32_t> overflows;  // rays whose shadow boundaries did not fit
    std::string deviceName;
    double longestSliceMs = 0.0;
    double gpuMs = 0.0;           // GPU time of all slices
    double primaryHitsMs = 0.0;   // of gpuMs: the camera hits (raster or traced)
    double compileSeconds = 0.0;  // building the pipeline (0 when it was cached)
    // The camera hits: "raster" or "traced: <why>" (framework/primary_hits.h); empty without surfaces.
    std::string primaryVisibility;
};

class GpuRenderer {
public:
    GpuRenderer();  // on gpu::sharedContext(); throws GpuError without Vulkan

    // Throws Cancelled, GpuError, ShaderError, and InputError for double precision on a device without it.
    GpuOutput render(const PreparedScene& scene, bool useDouble, int width, int height,
                     const RenderCallbacks& callbacks, StageTimes& times);

    gpu::Context& context() { return *context_; }

private:
    // One compiled variant of the shader (see the top of pegoraro.comp.glsl).
    struct Variant {
        int maxTerms = 1;
        bool useDouble = false;
        bool shadows = true;
        bool surfaces = true;
        bool grey = false;
        bool deferredFallback = false;
        bool raster = false;  // camera hits from the rasterised records (TY_PRIMARY_HITS)
    };
    gpu::ComputeKernel& kernel(const Variant& variant, double& compileSeconds);

    std::shared_ptr<gpu::Context> context_;
    KernelCache kernels_;  // by variant
    RasterPrimaryHits primaryHits_;
};

}  // namespace tyndall::pegoraro
