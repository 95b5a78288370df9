// The cost of a display transform (colour_management.h) on a 1920 x 1080 linear image, all at once and on every
// thread, as the studio's viewport (compositor.cpp, toDisplay) and a PNG apply it:
//   build/renderers/bench/tyndall_display_bench
// Each case: Tyndall's own sRGB operator, and the shipped OpenColorIO config's sRGB / Standard and
// sRGB / ACES 1.0 - SDR Video views; the counter ms_per_megapixel.
#include "tyndall/image/colour_management.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace {

using namespace tyndall;

void BM_Display(benchmark::State& state, const char* display, const char* view) {
    constexpr int kWidth = 1920, kHeight = 1080;
    std::vector<float> linear(std::size_t(kWidth) * kHeight * 3);
    for (std::size_t i = 0; i < linear.size(); ++i)
        linear[i] = float(std::pow(10.0, 3.0 * double(i % 7919) / 7919.0 - 2.0));  // 1e-2 .. 10
    const DisplayTransform transform =
        *display ? DisplayTransform(ColourConfig::fromFile(ColourConfig::shippedConfigPath().string()), display, view)
                 : DisplayTransform(Tonemap::Srgb);
    std::vector<float> shown(linear.size());
    double ms = 0.0;
    for (auto _ : state) {
        std::copy(linear.begin(), linear.end(), shown.begin());
        const auto start = std::chrono::steady_clock::now();
        transform.apply(shown.data(), std::size_t(kWidth) * kHeight, 0.5);
        benchmark::DoNotOptimize(shown.data());
        ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    state.counters["ms_per_megapixel"] = ms / double(state.iterations()) / (kWidth * kHeight * 1e-6);
}

BENCHMARK_CAPTURE(BM_Display, tyndall_srgb, "", "")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Display, ocio_srgb_standard, "sRGB", "Standard")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Display, ocio_srgb_aces, "sRGB", "ACES 1.0 - SDR Video")->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
