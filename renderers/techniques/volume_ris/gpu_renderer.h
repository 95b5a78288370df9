// The Volume-RIS technique on the GPU: uploads a prepared scene once, then adds camera samples to per-pixel
// accumulators that stay on the GPU, one dispatch per sample index in slices of about 10 ms (tyndall/gpu/slicer.h), so
// that a progressive render can be cancelled between slices and read back at every pass. As wvds/gpu_renderer.h.
#pragma once

#include "volume_ris/prepared.h"

#include "tyndall/framework/kernel_cache.h"
#include "tyndall/framework/technique.h"
#include "tyndall/gpu/context.h"
#include "tyndall/gpu/resources.h"

#include <map>
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

    double gpuMs() const { return gpuMs_; }
    double compileSeconds() const { return compileSeconds_; }  // of the current render's variant (0 when cached)

private:
    // The variant for a scene, compiled on first use.
    gpu::ComputeKernel& kernel(const PreparedScene& scene);

    std::shared_ptr<gpu::Context> context_;
    KernelCache kernels_;                   // by variant
    gpu::ComputeKernel* kernel_ = nullptr;  // the current render's
    std::map<const gpu::ComputeKernel*, std::uint64_t> sliceSizes_;  // per variant, as in wvds/gpu_renderer.h
    std::vector<std::unique_ptr<gpu::Buffer>> buffers_;  // bindings 0-7
    std::unique_ptr<gpu::Buffer> accumulators_;          // binding 8
    std::vector<glm::vec4> readback_;
    std::uint32_t pixels_ = 0, width_ = 0;
    double gpuMs_ = 0.0, compileSeconds_ = 0.0;
};

}  // namespace tyndall::volume_ris
