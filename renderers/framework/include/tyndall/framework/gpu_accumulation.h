// The GPU side of a technique that accumulates camera samples per pixel (WVDS, Volume-RIS), written once: accumulators
// that stay on the GPU from pass to pass (and render to render at the same size), one dispatch per sample index over
// the pixels (shared/accumulation.h) in slices of about 10 ms (tyndall/gpu/slicer.h), so that a progressive render can
// be cancelled between slices and read back at every pass (framework/progressive.h). A technique keeps its kernel
// variants, its scene buffers and its push constants.
#pragma once

#include "shared/accumulation.h"
#include "tyndall/framework/technique.h"
#include "tyndall/gpu/context.h"
#include "tyndall/gpu/resources.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <vector>

namespace tyndall {

class GpuAccumulation {
public:
    explicit GpuAccumulation(gpu::Context& context) : context_(context) {}

    // Starts a render of width x height pixels with vec4sPerPixel zeroed accumulators per pixel.
    void begin(int width, int height, std::size_t vec4sPerPixel);

    // What a dispatch of one slice of one sample index covers: the first fields of every accumulating kernel's push
    // constants. A dispatch covers each pixel at most once, so the read-modify-write of its accumulators never races.
    struct Slice {
        std::uint32_t first;       // the slice's first work item
        std::uint32_t end;         // one past its last (its groups may reach beyond: they must not add)
        std::uint32_t width;       // of the image
        std::uint32_t index;       // the camera sample
        std::uint32_t pixels;      // of the image
        std::uint32_t bandGroups;  // groups of 64 pixels in each band (shared/accumulation.h)
    };

    // Adds camera samples [first, end) to every pixel with `kernel`, bound to `inputs` and the accumulators after
    // them; push(slice) gives the kernel's push constants for a slice. Throws Cancelled between slices.
    template <typename MakePush>
    void addSamples(gpu::ComputeKernel& kernel, const std::vector<const gpu::Buffer*>& inputs, std::uint32_t first,
                    std::uint32_t end, const RenderCallbacks& callbacks, MakePush&& push) {
        dispatch(kernel, inputs, first, end, callbacks, [&](VkCommandBuffer cmd, const Slice& slice) {
            const auto constants = push(slice);
            kernel.record(cmd, bindings_, &constants,
                          (slice.end - slice.first + shader::kAccumulationGroup - 1) / shader::kAccumulationGroup);
        });
    }

    // Reads the accumulators back, into storage kept from pass to pass and render to render.
    const std::vector<glm::vec4>& read();

    double longestSliceMs() const { return longestSliceMs_; }  // of the render so far
    double gpuMs() const { return gpuMs_; }                    // of the render so far

private:
    void dispatch(gpu::ComputeKernel& kernel, const std::vector<const gpu::Buffer*>& inputs, std::uint32_t first,
                  std::uint32_t end, const RenderCallbacks& callbacks,
                  const std::function<void(VkCommandBuffer, const Slice&)>& record);

    gpu::Context& context_;
    // Per kernel variant, the slice size (in work items, one pixel each) its last dispatch measured: each sample of a
    // render, and the next render of the variant, start there instead of ramping up from a small first slice again
    // (each slice is a submission and a wait, ~0.2-0.5 ms on lavapipe; a 512 x 512 sample took 8 slices to reach its
    // size).
    std::map<const gpu::ComputeKernel*, std::uint64_t> sliceSizes_;
    std::unique_ptr<gpu::Buffer> accumulators_;
    std::vector<const gpu::Buffer*> bindings_;  // of the current dispatch
    std::vector<glm::vec4> readback_;
    std::uint32_t width_ = 0, pixels_ = 0;
    std::size_t vec4sPerPixel_ = 0;
    double longestSliceMs_ = 0.0, gpuMs_ = 0.0;
};

}  // namespace tyndall
