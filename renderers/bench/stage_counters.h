// A render's stages (framework/stage_times.h: the image metadata "time:<stage>", ms) summed over a benchmark's frames
// and reported as counters "<variant>:<stage>" in ms per frame, so that every frame bench shows where its wall time
// goes (issue 31's profile).
#pragma once

#include "tyndall/image/image.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <string>

namespace tyndall::bench {

class StageCounters {
public:
    // The stages of one frame of `variant` (empty: no prefix).
    void add(const Image& image, const std::string& variant = "") {
        ++frames_[variant];
        for (const auto& [key, value] : image.metadata)
            if (key.rfind("time:", 0) == 0) sums_[{variant, key.substr(5)}] += std::stod(value);
    }

    void report(benchmark::State& state) const {
        for (const auto& [name, ms] : sums_) {
            std::string counter = (name.first.empty() ? "" : name.first + ":") + name.second;
            std::replace(counter.begin(), counter.end(), ' ', '_');
            state.counters[counter] = ms / std::max(frames_.at(name.first), 1);
        }
    }

private:
    std::map<std::pair<std::string, std::string>, double> sums_;
    std::map<std::string, int> frames_;
};

}  // namespace tyndall::bench
