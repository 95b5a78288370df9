// The progressive schedule of a technique that accumulates samples per pixel (WVDS, Volume-RIS): passes of 1, 1, 2,
// 4, ... samples, so that an image arrives at every power of two, until the request's spp or its time limit; a pass is
// cut to the time that is left at the previous pass's cost per sample. Written once here, so that every accumulating
// technique reports progress, delivers intermediate images and honours time limits the same way, and so that a later
// schedule (a reduced resolution first) has one place to plug in.
#pragma once

#include "tyndall/framework/technique.h"

#include <chrono>
#include <cstdint>
#include <functional>

namespace tyndall {

struct ProgressiveResult {
    Image image;  // the last pass's image
    int spp = 0;  // samples per pixel reached
};

// addSamples(first, end, passCallbacks) adds the samples [first, end) of every pixel (the pass's callbacks carry the
// render's cancel flag and map the pass's progress onto the render's); resolve() turns what has been accumulated into
// the image. Runs until `spp` samples, or until request.timeLimit (s) has passed since `start`; delivers every image
// but the last through callbacks.intermediate. Cancellation throws Cancelled from addSamples.
ProgressiveResult renderProgressively(
    const RenderRequest& request, int spp, const RenderCallbacks& callbacks,
    std::chrono::steady_clock::time_point start,
    const std::function<void(std::uint32_t first, std::uint32_t end, const RenderCallbacks& pass)>& addSamples,
    const std::function<Image()>& resolve);

}  // namespace tyndall
