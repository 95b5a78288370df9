// A progress bar with an ETA for long work on a terminal; silent when stderr is not a terminal.
#pragma once

#include <chrono>
#include <string>

namespace tyndall::cli {

class ProgressBar {
public:
    explicit ProgressBar(std::string label);
    ~ProgressBar();
    void update(double fraction);  // in [0, 1]; redraws at most ten times a second
    void finish();

private:
    std::string label_;
    bool enabled_;
    bool finished_ = false;
    std::chrono::steady_clock::time_point start_, lastDraw_;
};

}  // namespace tyndall::cli
