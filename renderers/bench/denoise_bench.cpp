// Time to denoise a 512x512 RGB image with 5 a-trous levels (renderers/src/denoise.cpp), all threads:
//   build/renderers/bench/tyndall_denoise_bench
// Variants: all three guides and a given variance; no variance (estimated locally from the image); and the ratio of
// Eq. 22-23 (numerator and denominator filtered together, the weight on their ratio) with all guides.
#include "tyndall/image/denoise.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

namespace {

using tyndall::Image;

constexpr int kSize = 512;

struct Inputs {
    Image noisy, variance, depth, normal, guide, numerator, denominator;
};

// A plane split into two depths with a sinusoidal guide, Gaussian noise of sigma 0.1, fixed seed.
const Inputs& inputs() {
    static const Inputs in = [] {
        Inputs r{Image::rgb(kSize, kSize),   Image(kSize, kSize, {"variance.R", "variance.G", "variance.B"}),
                 Image(kSize, kSize, {"Z"}), Image(kSize, kSize, {"N.X", "N.Y", "N.Z"}),
                 Image::rgb(kSize, kSize),   Image::rgb(kSize, kSize),
                 Image::rgb(kSize, kSize)};
        std::mt19937 rng(3);
        std::normal_distribution<float> noise(0.0f, 0.1f);
        std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                const float u = 1.0f + 0.5f * std::sin(0.02f * float(x + y));
                r.depth.at(x, y, 0) = x < kSize / 2 ? 2.0f : 3.0f;
                r.normal.at(x, y, 2) = 1.0f;
                for (int c = 0; c < 3; ++c) {
                    r.noisy.at(x, y, c) = 0.5f * u + noise(rng);
                    r.variance.at(x, y, c) = 0.01f;
                    r.guide.at(x, y, c) = u;
                    const float d = u * 2.0f * uniform(rng);
                    r.denominator.at(x, y, c) = d;
                    r.numerator.at(x, y, c) = uniform(rng) < 0.6f ? d : 0.0f;
                }
            }
        return r;
    }();
    return in;
}

void BM_Denoise(benchmark::State& state) {
    const Inputs& in = inputs();
    const bool withVariance = state.range(0) != 0;
    for (auto _ : state) {
        Image out =
            tyndall::denoise(in.noisy, withVariance ? &in.variance : nullptr, {&in.depth, &in.normal, &in.guide}, {});
        benchmark::DoNotOptimize(out.data());
    }
    state.SetLabel(withVariance ? "512x512 RGB, 5 levels, given variance"
                                : "512x512 RGB, 5 levels, estimated variance");
}
BENCHMARK(BM_Denoise)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_DenoiseRatio(benchmark::State& state) {
    const Inputs& in = inputs();
    for (auto _ : state) {
        Image out =
            tyndall::denoiseRatio(in.numerator, in.denominator, &in.variance, {&in.depth, &in.normal, &in.guide}, {});
        benchmark::DoNotOptimize(out.data());
    }
    state.SetLabel("512x512 RGB ratio, 5 levels, given variance");
}
BENCHMARK(BM_DenoiseRatio)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
