// The WVDS technique on the GPU: uploads a prepared scene once, then adds camera samples to per-pixel accumulators
// that stay on the GPU (framework/gpu_accumulation.h), so that a progressive render can be cancelled between slices
// and read back at every pass.
#pragma once

#include "wvds/prepared.h"

#include "tyndall/framework/gpu_accumulation.h"
#include "tyndall/framework/kernel_cache.h"
#include "tyndall/framework/technique.h"
#include "tyndall/gpu/context.h"
#include "tyndall/gpu/resources.h"

#include <memory>
#include <string>
#include <vector>

namespace tyndall::wvds {

class GpuRenderer {
public:
    GpuRenderer();  // on gpu::sharedContext(); throws GpuError without Vulkan

    // Starts a render: uploads the scene and zeroes `stride` vec4 accumulators per pixel and half.
    void begin(const PreparedScene& scene, int width, int height, int stride, int ratioLights);
    // Adds camera samples [first, end) to every pixel. Throws Cancelled between slices.
    void addSamples(std::uint32_t first, std::uint32_t end, const RenderCallbacks& callbacks);
    // Reads the accumulators back, into storage kept from pass to pass and render to render.
    const std::vector<glm::vec4>& readAccumulators();

    gpu::Context& context() { return *context_; }
    double longestSliceMs() const { return accumulation_.longestSliceMs(); }
    double gpuMs() const { return accumulation_.gpuMs(); }
    double compileSeconds() const { return compileSeconds_; }  // of the current render's variant (0 when cached)

private:
    // The variant for an estimator, a number of faces (or a box), a phase function, a number of lights and of
    // planes in all (the medium's and the gobos'), compiled on first use.
    gpu::ComputeKernel& kernel(int estimator, int planeCount, int planeTotal, bool box, int phaseKind, int lightCount,
                               const GpuSurfaces& surfaces, bool grey, bool gobos);

    std::shared_ptr<gpu::Context> context_;
    KernelCache kernels_;                   // by variant
    gpu::ComputeKernel* kernel_ = nullptr;  // the current render's
    std::vector<std::unique_ptr<gpu::Buffer>> buffers_;  // bindings 0-6; the accumulators are binding 7
    GpuAccumulation accumulation_;
    std::uint32_t stride_ = 1, ratioLights_ = 0;
    double compileSeconds_ = 0.0;
};

}  // namespace tyndall::wvds
