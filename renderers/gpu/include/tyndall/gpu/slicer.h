// Long GPU work split into slices of about 10 ms of GPU time (GPU framework issue, item 2), so that a render can be
// cancelled or preempted between slices and a single-queue device (lavapipe) keeps serving the display.
#pragma once

#include "tyndall/gpu/context.h"

#include <atomic>
#include <cstdint>
#include <functional>

namespace tyndall::gpu {

struct SliceStats {
    int slices = 0;
    double longestMs = 0.0;  // GPU time of the longest slice (wall time where the queue has no timestamps)
    double totalMs = 0.0;
    // The size the next slice would have had: the firstSlice for another run of the same work (the next sample of
    // an image), so that it starts at its measured size instead of growing to it again from a small first slice.
    std::uint64_t nextSlice = 1;
};

// Records work items [begin, begin + count) into the command buffer.
using SliceRecorder = std::function<void(VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t count)>;

// Runs `total` work items in slices. The first slice has `firstSlice` items; each next slice is sized from the
// measured time per item so that it takes about targetMs. Between slices `cancel` is checked, and tyndall::Cancelled
// is thrown when it is set.
SliceStats runSliced(Context& context, std::uint64_t total, const SliceRecorder& record,
                     const std::atomic<bool>* cancel = nullptr, double targetMs = 10.0, std::uint64_t firstSlice = 1);

}  // namespace tyndall::gpu
