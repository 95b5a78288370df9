// Where a render's wall time goes (issue 31, deliverable 3): a technique marks the end of each stage of its frame
// (scene preparation, uploads, the raster pass, the kernels, the readback, the resolve) and writes the stages into the
// image's metadata as "time:<stage>" in milliseconds (EXR headers carry it), so that benches profile a frame without a
// profiler. On lavapipe a profiler sees the kernels only as anonymous JIT code, and the timestamps of compute slices
// read far too low once a kernel has run in the process (docs/ltsd.md), so the wall clock is the measure.
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace tyndall {

class StageTimes {
public:
    using Clock = std::chrono::steady_clock;

    StageTimes() : last_(Clock::now()) {}

    // The wall time since the previous mark (or since construction) is `stage`'s; a stage marked again adds up.
    void mark(const std::string& stage);

    // Milliseconds of `stage` (0 when it was never marked), and of every stage together.
    double ms(const std::string& stage) const;
    double totalMs() const;

    // "time:<stage>" = milliseconds with three significant digits, for each stage.
    void writeTo(std::map<std::string, std::string>& metadata) const;

    const std::vector<std::pair<std::string, double>>& stages() const { return stages_; }

private:
    Clock::time_point last_;
    std::vector<std::pair<std::string, double>> stages_;  // in the order first marked
};

}  // namespace tyndall
