#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace tyndall::cli {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), enabled_(isatty(STDERR_FILENO) != 0), start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(double fraction) {
    if (!enabled_ || finished_) return;
    auto now = std::chrono::steady_clock::now();
    if (fraction < 1.0 && now - lastDraw_ < std::chrono::milliseconds(100)) return;
    lastDraw_ = now;
    fraction = std::clamp(fraction, 0.0, 1.0);
    double elapsed = std::chrono::duration<double>(now - start_).count();
    constexpr int kWidth = 30;
    int filled = int(fraction * kWidth + 0.5);
    std::string bar(size_t(filled), '#');
    bar.resize(kWidth, ' ');
    char eta[32] = "--";
    if (fraction > 0.0) std::snprintf(eta, sizeof eta, "%.0fs", elapsed * (1.0 - fraction) / fraction);
    std::fprintf(stderr, "\r%s [%s] %3d%%  ETA %s   ", label_.c_str(), bar.c_str(), int(fraction * 100.0), eta);
    std::fflush(stderr);
}

void ProgressBar::finish() {
    if (!enabled_ || finished_) return;
    finished_ = true;
    std::fprintf(stderr, "\n");
}

}  // namespace tyndall::cli
