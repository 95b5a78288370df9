#include "tyndall/framework/gpu_accumulation.h"

#include "tyndall/core/error.h"
#include "tyndall/gpu/slicer.h"

#include <algorithm>

namespace tyndall {

void GpuAccumulation::begin(int width, int height, std::size_t vec4sPerPixel) {
    width_ = std::uint32_t(width);
    pixels_ = std::uint32_t(width) * std::uint32_t(height);
    vec4sPerPixel_ = vec4sPerPixel;
    // The accumulators stay from render to render at the same size (an edit re-renders the view at its size), zeroed
    // in place: a fresh 8-32 MB buffer and a host array of zeros for it cost page faults, ~8 ms per 8 MB here.
    const VkDeviceSize bytes = VkDeviceSize(pixels_) * vec4sPerPixel_ * sizeof(glm::vec4);
    if (!accumulators_ || accumulators_->size() != bytes)
        accumulators_ = std::make_unique<gpu::Buffer>(context_, bytes);
    accumulators_->fill(0u);
    longestSliceMs_ = gpuMs_ = 0.0;
}

void GpuAccumulation::dispatch(gpu::ComputeKernel& kernel, const std::vector<const gpu::Buffer*>& inputs,
                               std::uint32_t first, std::uint32_t end, const RenderCallbacks& callbacks,
                               const std::function<void(VkCommandBuffer, const Slice&)>& record) {
    TY_CHECK(accumulators_ != nullptr, "GpuAccumulation::begin before addSamples");
    bindings_ = inputs;
    bindings_.push_back(accumulators_.get());
    std::uint64_t& sliceSize = sliceSizes_.try_emplace(&kernel, 1024).first->second;
    const std::uint32_t bandGroups = shader::accumulationBandGroups(pixels_);
    try {
        for (std::uint32_t index = first; index < end; ++index) {
            const gpu::SliceStats stats = gpu::runSliced(
                context_, std::uint64_t(shader::kAccumulationBands) * bandGroups * shader::kAccumulationGroup,
                [&](VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t count) {
                    record(cmd,
                           {std::uint32_t(begin), std::uint32_t(begin + count), width_, index, pixels_, bandGroups});
                    gpu::computeToComputeBarrier(cmd);
                },
                callbacks.cancel, 10.0, sliceSize);
            sliceSize = stats.nextSlice;
            longestSliceMs_ = std::max(longestSliceMs_, stats.longestMs);
            gpuMs_ += stats.totalMs;
            kernel.resetDescriptors();
        }
    } catch (...) {
        kernel.resetDescriptors();
        throw;
    }
}

const std::vector<glm::vec4>& GpuAccumulation::read() {
    accumulators_->download(readback_, std::size_t(pixels_) * vec4sPerPixel_);
    return readback_;
}

}  // namespace tyndall
