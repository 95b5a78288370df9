#include "tyndall/gpu/slicer.h"

#include "tyndall/error.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace tyndall::gpu {

SliceStats runSliced(Context& context, std::uint64_t total, const SliceRecorder& record,
                     const std::atomic<bool>* cancel, double targetMs, std::uint64_t firstSlice) {
    SliceStats stats;
    std::uint64_t begin = 0;
    std::uint64_t count = std::max<std::uint64_t>(1, std::min(firstSlice, total));
    while (begin < total) {
        if (cancel && cancel->load(std::memory_order_relaxed)) throw Cancelled();
        count = std::min(count, total - begin);
        auto start = std::chrono::steady_clock::now();
        double ms = context.submitTimed([&](VkCommandBuffer cmd) { record(cmd, begin, count); });
        if (ms < 0.0) ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        stats.slices += 1;
        stats.longestMs = std::max(stats.longestMs, ms);
        stats.totalMs += ms;
        begin += count;
        // Size the next slice from this one's cost per item; grow at most 4x at a time so that one cheap slice
        // (caches warm, empty tiles) cannot produce a runaway long one.
        const double perItem = ms / double(count);
        std::uint64_t next = perItem > 0.0 ? std::uint64_t(std::floor(targetMs / perItem)) : count * 4;
        count = std::clamp<std::uint64_t>(next, 1, count * 4);
    }
    return stats;
}

}  // namespace tyndall::gpu
