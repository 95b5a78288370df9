// FLIP's cost at 1920 x 1080 (issue 35's target: an HDR-FLIP in a few seconds on two cores), all threads:
//   build/renderers/bench/tyndall_flip_bench
// BM_LdrFlip: one LDR-FLIP (the counter ms_per_megapixel). BM_HdrFlip: HDR-FLIP with the automatic exposure range of
// a synthetic HDR image (a smooth gradient over four decades with noise in the test), the counters exposures and
// ms_per_exposure.
#include "tyndall/image/flip.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <random>

namespace {

using namespace tyndall;

// A gradient over `decades` of luminance, and the same with multiplicative noise of `noise`.
void images(int w, int h, double decades, double noise, Image& reference, Image& test) {
    reference = Image(w, h, {"R", "G", "B"});
    test = reference;
    std::mt19937 rng(5u);
    std::normal_distribution<float> n(0.0f, float(noise));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float v = float(std::pow(10.0, decades * (double(x) / w - 0.5)));
            for (int c = 0; c < 3; ++c) {
                reference.at(x, y, c) = v * (1.0f + 0.1f * float(c));
                test.at(x, y, c) = std::max(0.0f, reference.at(x, y, c) * (1.0f + n(rng)));
            }
        }
}

void BM_LdrFlip(benchmark::State& state) {
    Image reference, test;
    images(1920, 1080, 0.5, 0.05, reference, test);
    double ms = 0.0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(ldrFlip(reference, test));
        ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    state.counters["ms_per_megapixel"] = ms / double(state.iterations()) / (1920.0 * 1080.0 / 1e6);
}
BENCHMARK(BM_LdrFlip)->Unit(benchmark::kMillisecond)->Iterations(2)->UseRealTime();

void BM_HdrFlip(benchmark::State& state) {
    Image reference, test;
    images(1920, 1080, 4.0, 0.05, reference, test);
    int exposures = 0;
    double ms = 0.0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        const HdrFlipResult r = hdrFlip(reference, test);
        ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        exposures = r.exposures;
        benchmark::DoNotOptimize(r.error.data());
    }
    state.counters["exposures"] = exposures;
    state.counters["ms_per_exposure"] = ms / double(state.iterations()) / std::max(exposures, 1);
    state.counters["ms_per_megapixel_and_exposure"] = state.counters["ms_per_exposure"] / (1920.0 * 1080.0 / 1e6);
}
BENCHMARK(BM_HdrFlip)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
