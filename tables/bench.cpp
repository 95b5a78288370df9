// tyndall_ltsd_bench: the CPU cost of S (Eq. 21) per sample, with the entries fetched once (as a shader does, g being
// uniform per medium) and with the fetch per call, for a quad light above, straddling and below the horizon; and the
// fitting time of one table entry with each loss, measured in the same run (this machine's speed drifts).
#include "fit.h"

#include "tyndall/ltsd_table.h"

#include <benchmark/benchmark.h>

namespace {

using namespace tyndall;

const LtsdTable& table() {
    static const LtsdTable t = loadLtsdTable(ltsdTablePath("hg"));
    return t;
}

shader::SphericalPolygon quad(float z) {
    shader::SphericalPolygon p{};
    p.count = 4;
    p.v[0] = glm::vec3(0.4f, 0.3f, z), p.v[1] = glm::vec3(-0.4f, 0.3f, z + 0.3f);
    p.v[2] = glm::vec3(-0.4f, -0.3f, z + 0.3f), p.v[3] = glm::vec3(0.4f, -0.3f, z);
    return p;
}

// state.range(0): the quad's height: 0 above the horizon, 1 straddling it, 2 below it.
shader::SphericalPolygon quadFor(const benchmark::State& state) {
    const float heights[] = {0.6f, -0.15f, -0.9f};
    return quad(heights[state.range(0)]);
}

void BM_S_EntriesFetchedOnce(benchmark::State& state) {
    const shader::LtsdEntry upper = table().upper(0.6), lower = table().lower(0.6);
    shader::SphericalPolygon p = quadFor(state);
    for (auto _ : state) {
        benchmark::DoNotOptimize(p);
        benchmark::DoNotOptimize(shader::ltsdS(p, upper, lower));
    }
}
BENCHMARK(BM_S_EntriesFetchedOnce)->Arg(0)->Arg(1)->Arg(2);

void BM_S_WithFetch(benchmark::State& state) {
    shader::SphericalPolygon p = quadFor(state);
    double g = 0.6;
    for (auto _ : state) {
        benchmark::DoNotOptimize(g);
        benchmark::DoNotOptimize(table().integral(p, g));
    }
}
BENCHMARK(BM_S_WithFetch)->Arg(0)->Arg(1)->Arg(2);

// One entry of T_1 (clamped cosine, g = -0.5) and of T_2 (inverse, g = +0.5) per loss, single-threaded.
void BM_FitEntry(benchmark::State& state, const char* loss) {
    tables::FitSettings s;
    s.loss = loss;
    const int index = int(state.range(0));
    for (auto _ : state) benchmark::DoNotOptimize(tables::fitEntry(index, s));
}
BENCHMARK_CAPTURE(BM_FitEntry, sw, "sw")->Arg(32)->Arg(191)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FitEntry, tv, "tv")->Arg(32)->Arg(191)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
