#include "tyndall/framework/stage_times.h"

#include <algorithm>
#include <cstdio>

namespace tyndall {

void StageTimes::mark(const std::string& stage) {
    const Clock::time_point now = Clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    const auto it = std::find_if(stages_.begin(), stages_.end(), [&](const auto& s) { return s.first == stage; });
    if (it != stages_.end())
        it->second += ms;
    else
        stages_.emplace_back(stage, ms);
}

double StageTimes::ms(const std::string& stage) const {
    const auto it = std::find_if(stages_.begin(), stages_.end(), [&](const auto& s) { return s.first == stage; });
    return it != stages_.end() ? it->second : 0.0;
}

double StageTimes::totalMs() const {
    double total = 0.0;
    for (const auto& s : stages_)
        total += s.second;
    return total;
}

void StageTimes::writeTo(std::map<std::string, std::string>& metadata) const {
    for (const auto& [stage, ms] : stages_) {
        char text[32];
        std::snprintf(text, sizeof text, "%.3g", ms);
        metadata["time:" + stage] = text;
    }
}

}  // namespace tyndall
