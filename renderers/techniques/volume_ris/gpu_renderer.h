// The Volume-RIS technique on the GPU: uploads a prepared scene once, then adds camera samples to per-pixel
// accumulators that stay on the GPU (framework/gpu_accumulation.h), so that a progressive render can be cancelled
// between slices and read back at every pass.
#pragma once

#include "volume_ris/prepared.h"

#include "tyndall/framework/gpu_accumulation.h"
#include "tyndall/framework/kernel_cache.h"
#include "tyndall/framework/technique.h"
#include "tyndall/gpu/context.h"
#include "tyndall/gpu/resources.h"

#include <memory>
#include <string>
#include <vector>

namespace tyndall::volume_ris {

class GpuRenderer {
public:
    GpuRenderer();  // on gpu::sharedContext(); throws GpuError without Vulkan

    // Starts a render: uploads the scene and zeroes the accumulators: per pixel and half, two vec4s (medium with the
    // sample count in w, surface).
    void begin(const PreparedScene& scene, int width, int height);
    // Adds camera samples [first, end) to every pixel. Throws Cancelled between slices.
    void addSamples(std::uint32_t first, std::uint32_t end, const RenderCallbacks& callbacks);
    // Reads the accumulators back, into storage kept from pass to pass and render to render.
    const std::vector<glm::vec4>& readAccumulators();

    double gpuMs() const { return accumulation_.gpuMs(); }
    double compileSeconds() const { return compileSeconds_; }  // of the current render's variant (0 when cached)

private:
    // The variant for a scene, compiled on first use.
    gpu::ComputeKernel& kernel(const PreparedScene& scene);

    std::shared_ptr<gpu::Context> context_;
    KernelCache kernels_;                   // by variant
    gpu::ComputeKernel* kernel_ = nullptr;  // the current render's
    std::vector<std::unique_ptr<gpu::Buffer>> buffers_;  // bindings 0-7; the accumulators are binding 8
    GpuAccumulation accumulation_;
    double compileSeconds_ = 0.0;
};

}  // namespace tyndall::volume_ris
