// With TYNDALL_STUDIO_TRACE set, the studio prints to stderr the milestones of each render's way from an edit to the
// screen (edit, job made, worker start, image posted, image received, composed, presented) with the time since the
// start of the process, to find where latency goes.
#pragma once

#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>

namespace tyndall::studio {

inline bool tracing() {
    static const bool on = std::getenv("TYNDALL_STUDIO_TRACE") != nullptr;
    return on;
}

inline double traceClockMs() {
    using Clock = std::chrono::steady_clock;
    static const Clock::time_point start = Clock::now();
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

__attribute__((format(printf, 1, 2))) inline void trace(const char* format, ...) {
    if (!tracing()) return;
    char line[256];
    va_list args;
    va_start(args, format);
    std::vsnprintf(line, sizeof(line), format, args);
    va_end(args);
    std::fprintf(stderr, "[%9.1f ms] %s\n", traceClockMs(), line);
}

}  // namespace tyndall::studio
