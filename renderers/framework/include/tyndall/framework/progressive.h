// The progressive schedule of a technique that accumulates samples per pixel (WVDS, Volume-RIS): passes of 1, 1, 2,
// 4, ... samples, so that an image arrives at every power of two, until the request's spp or its time limit; a pass is
// cut to the time that is left at the previous pass's cost per sample. Written once here, so that every accumulating
// technique reports progress, delivers intermediate images and honours time limits the same way, and so that a later
// schedule (a reduced resolution first) has one place to plug in.
#pragma once

#include "tyndall/framework/technique.h"

#include <glm/glm.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

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

// Every progressive technique keeps two independent halves of each pixel's samples (even and odd sample indices, or
// two scrambled streams). Their means differ only by noise, so (meanA - meanB)^2 / 4 estimates the variance of the
// pixel's mean (derivation in docs/reference.md); the image holds it next to the value.
template <typename Real>
glm::vec<3, Real> varianceOfMean(const glm::vec<3, Real>& meanA, const glm::vec<3, Real>& meanB) {
    const glm::vec<3, Real> d = meanA - meanB;
    return d * d * Real(0.25);
}

// R, G, B, variance.R, variance.G, variance.B, then the technique's further channels.
std::vector<std::string> estimateChannels(const std::vector<std::string>& further = {});

// Writes a pixel's value and the variance of its mean into channels 0-5. A non-finite pair (a sample that overflowed
// or divided by zero) is written as zeros and counted by the caller: returns false then.
inline bool writeEstimate(Image& image, int x, int y, const glm::vec3& value, const glm::vec3& variance) {
    const bool finite = std::isfinite(value.x + value.y + value.z + variance.x + variance.y + variance.z);
    for (int c = 0; c < 3; ++c) {
        image.at(x, y, c) = finite ? value[c] : 0.0f;
        image.at(x, y, 3 + c) = finite ? variance[c] : 0.0f;
    }
    return finite;
}

}  // namespace tyndall
