// CPU time per call of e^z E_n(z) (shaders/shared/expint.h) in float and double, the function Pegoraro's closed form
// evaluates at two endpoints per pixel and light:
//   build/renderers/bench/tyndall_expint_bench
// Arguments t = H (v - i) with H log-uniform in [1e-4, 50] and v log-uniform in [1e-4, 1e4] ("mixed"), or only those
// in the power-series region (|t| + Re t < 1.9, "series") or with |t| + Re t > 20 ("far"). The counter s/call is the
// time of one evaluation (for the all-orders variant, of all orders together).
#include "shared/expint.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

namespace {

namespace sh = tyndall::shader;

enum class Region { Mixed, Series, Far };

// 4096 arguments per region, drawn from one stream.
template <typename Vec2>
const std::vector<Vec2>& arguments(Region region) {
    static const std::vector<std::vector<Vec2>> sets = [] {
        std::vector<std::vector<Vec2>> all(3);
        std::mt19937_64 rng(1);
        std::uniform_real_distribution<double> logH(std::log(1e-4), std::log(50.0));
        std::uniform_real_distribution<double> logV(std::log(1e-4), std::log(1e4));
        while (all[0].size() < 4096 || all[1].size() < 4096 || all[2].size() < 4096) {
            double h = std::exp(logH(rng)), v = std::exp(logV(rng));
            double s = std::hypot(h * v, h) + h * v;
            Vec2 t(h * v, -h);
            if (all[0].size() < 4096) all[0].push_back(t);
            if (s < 1.9 && all[1].size() < 4096) all[1].push_back(t);
            if (s > 20.0 && all[2].size() < 4096) all[2].push_back(t);
        }
        return all;
    }();
    return sets[int(region)];
}

// Time per evaluation: the rate counter inverted, over all arguments of all iterations.
benchmark::Counter perCall(const benchmark::State& state, size_t calls) {
    return benchmark::Counter(double(state.iterations()) * double(calls),
                              benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

template <typename Vec2>
void BM_ExpintEnScaled(benchmark::State& state) {
    const int n = int(state.range(0));
    const std::vector<Vec2>& ts = arguments<Vec2>(Region(state.range(1)));
    for (auto _ : state) {
        Vec2 sum(0);
        for (const Vec2& t : ts)
            sum += sh::expintEnScaled(n, t);
        benchmark::DoNotOptimize(sum);
    }
    state.counters["s/call"] = perCall(state, ts.size());
}

template <typename Vec2, typename Orders>
void BM_ExpintEnScaledAll(benchmark::State& state) {
    const int n = int(state.range(0));
    const std::vector<Vec2>& ts = arguments<Vec2>(Region(state.range(1)));
    Orders orders;
    for (auto _ : state) {
        Vec2 sum(0);
        for (const Vec2& t : ts) {
            sh::expintEnScaledAll(n, t, orders);
            sum += orders.value[n - 1];
        }
        benchmark::DoNotOptimize(sum);
    }
    state.counters["s/call"] = perCall(state, ts.size());
}

void orders(benchmark::internal::Benchmark* b) {
    b->ArgNames({"n", "region"});
    for (int region : {0, 1, 2})
        for (int n : {1, 4, 9, 33})
            b->Args({n, region});
}

void allOrders(benchmark::internal::Benchmark* b) {
    b->ArgNames({"n", "region"});
    for (int region : {0, 1, 2})
        for (int n : {9, 33})
            b->Args({n, region});
}

BENCHMARK_TEMPLATE(BM_ExpintEnScaled, glm::vec2)->Apply(orders);
BENCHMARK_TEMPLATE(BM_ExpintEnScaled, glm::dvec2)->Apply(orders);
BENCHMARK_TEMPLATE(BM_ExpintEnScaledAll, glm::vec2, sh::ExpintOrders)->Apply(allOrders);
BENCHMARK_TEMPLATE(BM_ExpintEnScaledAll, glm::dvec2, sh::ExpintOrdersD)->Apply(allOrders);

}  // namespace

BENCHMARK_MAIN();
