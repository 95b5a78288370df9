#include "resolution_schedule.h"

#include <algorithm>

namespace tyndall::studio {

namespace {

// The reduced stages of a sequence may delay the full-resolution image by at most this fraction of its own time (the
// issue's target: full resolution within 1.2x of a render without them).
constexpr double kMaxOverhead = 0.2;

}  // namespace

ResolutionSchedule::ResolutionSchedule(std::function<double()> clock, double budgetSeconds)
    : clock_(std::move(clock)), budget_(budgetSeconds) {}

int ResolutionSchedule::indexOf(int factor) {
    for (std::size_t i = 0; i < kFactors.size(); ++i)
        if (kFactors[i] == factor) return int(i);
    return -1;
}

std::optional<double> ResolutionSchedule::predicted(int factor) const {
    // The measurements nearest full resolution and farthest from it: they separate the fixed cost best.
    int lo = -1, hi = -1;
    for (int i = 0; i < int(kFactors.size()); ++i) {
        if (!measured_[std::size_t(i)]) continue;
        if (lo < 0) lo = i;
        hi = i;
    }
    if (lo < 0) return std::nullopt;
    auto inverseArea = [](int i) { return 1.0 / (double(kFactors[std::size_t(i)]) * kFactors[std::size_t(i)]); };
    double full, fixed;
    if (lo == hi) {
        fixed = 0.0;
        full = *measured_[std::size_t(lo)] / inverseArea(lo);
    } else {
        const double tLo = *measured_[std::size_t(lo)], tHi = *measured_[std::size_t(hi)];
        full = std::max(0.0, (tLo - tHi) / (inverseArea(lo) - inverseArea(hi)));
        fixed = std::max(0.0, tHi - full * inverseArea(hi));
    }
    return fixed + full / (double(factor) * factor);
}

int ResolutionSchedule::begin() {
    started_ = clock_();
    spent_ = 0.0;
    shown_ = false;
    current_ = 1;
    const std::optional<double> fullTime = predicted(1);
    if (!fullTime || *fullTime <= budget_) return current_;
    // The smallest reduction that fits the budget and costs little against the full-resolution render it comes
    // before; when none fits the budget, the largest, if it costs little.
    const double affordable = kMaxOverhead * *fullTime;
    for (int f : kFactors) {
        const double t = *predicted(f);
        if (f > 1 && t <= budget_ && t <= affordable) {
            current_ = f;
            return current_;
        }
    }
    if (*predicted(kFactors.back()) > budget_ && *predicted(kFactors.back()) <= affordable) current_ = kFactors.back();
    return current_;
}

int ResolutionSchedule::delivered(int factor, double renderSeconds) {
    if (factor != current_ || current_ == 0) return 0;
    const double now = clock_(), seconds = renderSeconds >= 0.0 ? renderSeconds : now - started_;
    measured_[std::size_t(indexOf(factor))] = seconds;
    started_ = now;
    shown_ = true;
    if (factor == 1) {
        current_ = 0;
        return 0;
    }
    spent_ += seconds;
    // Halve the reduction, unless that stage would push the full-resolution image back by more than kMaxOverhead:
    // then straight to full resolution (a smaller reduction costs more still).
    int next = factor / 2;
    const double fullTime = *predicted(1);
    if (next > 1 && spent_ + *predicted(next) > kMaxOverhead * fullTime) next = 1;
    current_ = next;
    return next;
}

}  // namespace tyndall::studio
