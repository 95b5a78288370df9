#include "tyndall/gpu/slicer.h"

#include "tyndall/core/error.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace tyndall::gpu {

SliceStats runSliced(Context& context, std::uint64_t total, const SliceRecorder& record,
                     const std::atomic<bool>* cancel, double targetMs, std::uint64_t firstSlice) {
    SliceStats stats;
    double recentPerItem[3] = {0.0, 0.0, 0.0};  // ms per item of the last three slices
    std::uint64_t begin = 0;
    std::uint64_t planned = std::max<std::uint64_t>(1, firstSlice);  // the next slice's size, before the end cuts it
    while (begin < total) {
        if (cancel && cancel->load(std::memory_order_relaxed)) throw Cancelled();
        const std::uint64_t count = std::min(planned, total - begin);
        auto start = std::chrono::steady_clock::now();
        double ms = context.submitTimed([&](VkCommandBuffer cmd) { record(cmd, begin, count); });
        if (ms < 0.0) ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        stats.slices += 1;
        stats.longestMs = std::max(stats.longestMs, ms);
        stats.totalMs += ms;
        begin += count;
        // A last slice that the end cut short measures mostly the fixed cost of a submission: it says little of the
        // cost per item and does not resize (unless it is all there is to go by).
        if (2 * count < planned && stats.slices > 1) break;
        // Size the next slice from the dearest cost per item of the last three slices, for 60 % of the target, and
        // grow at most 2x at a time: work is rarely uniform (an image's rows with a medium or a sphere cost twice its
        // sky's on lavapipe), and a slice sized from cheaper predecessors overshoots by that ratio (WVDS's longest
        // slice at 512 x 512 went from 21 to 10 ms). Shrinking is immediate. One item is never split: a slice is never
        // shorter than its dearest item (a Pegoraro sample that falls back to quadrature takes up to ~13 ms).
        recentPerItem[stats.slices % 3] = ms / double(count);
        const double perItem = std::max(recentPerItem[0], std::max(recentPerItem[1], recentPerItem[2]));
        const std::uint64_t next = perItem > 0.0 ? std::uint64_t(std::floor(0.6 * targetMs / perItem)) : count * 2;
        planned = std::clamp<std::uint64_t>(next, 1, count * 2);
    }
    stats.nextSlice = planned;
    return stats;
}

}  // namespace tyndall::gpu
