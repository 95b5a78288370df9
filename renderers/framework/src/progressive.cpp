#include "tyndall/framework/progressive.h"

#include <algorithm>

namespace tyndall {

ProgressiveResult renderProgressively(
    const RenderRequest& request, int spp, const RenderCallbacks& callbacks,
    std::chrono::steady_clock::time_point start,
    const std::function<void(std::uint32_t first, std::uint32_t end, const RenderCallbacks& pass)>& addSamples,
    const std::function<Image()>& resolve) {
    using Clock = std::chrono::steady_clock;
    auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
    ProgressiveResult result;
    int done = 0;
    double secondsPerSample = 0.0;  // of the last pass; bounds a pass by the time that is left
    while (done < spp) {
        int passSize = std::min(spp - done, std::max(done, 1));
        if (request.timeLimit > 0.0 && secondsPerSample > 0.0)
            passSize = std::clamp(int((request.timeLimit - elapsed()) / secondsPerSample), 1, passSize);
        const auto passStart = Clock::now();
        const RenderCallbacks pass{
            [&](double f) {
                if (callbacks.progress)
                    callbacks.progress(progressFraction(done + f * passSize, spp, elapsed(), request.timeLimit));
            },
            nullptr, callbacks.cancel};
        addSamples(std::uint32_t(done), std::uint32_t(done + passSize), pass);
        done += passSize;
        secondsPerSample = std::chrono::duration<double>(Clock::now() - passStart).count() / passSize;
        result.image = resolve();
        if (callbacks.progress) callbacks.progress(progressFraction(done, spp, elapsed(), request.timeLimit));
        if (request.timeLimit > 0.0 && elapsed() >= request.timeLimit) break;
        if (callbacks.intermediate && done < spp) callbacks.intermediate(result.image, done);
    }
    result.spp = done;
    return result;
}

std::vector<std::string> estimateChannels(const std::vector<std::string>& further) {
    std::vector<std::string> channels = {"R", "G", "B", "variance.R", "variance.G", "variance.B"};
    channels.insert(channels.end(), further.begin(), further.end());
    return channels;
}

}  // namespace tyndall
