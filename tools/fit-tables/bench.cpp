// tyndall_fit_tables_bench: the CPU cost of S (Eq. 21) per sample, with the entries fetched once (as a shader does, g
// being uniform per medium) and with the fetch per call, for a quad light above, straddling and below the horizon; and
// the fitting time of one table entry with each loss, measured in the same run (this machine's speed drifts); and S per
// sample on the Vulkan device (lavapipe here): BM_S_Gpu evaluates S over 2^20 quads in one compute dispatch (GPU time
// from timestamps), against a dispatch that builds the same quads without S, and reports the difference per sample as
// the counter ns_per_S, for Eq. 21 (BM_S_Gpu/paper: the entries read from a buffer, as the LTSD technique's kernel
// reads its table) and for the boundary form of shared/ltsd_boundary.h (BM_S_Gpu/accurate; BM_S_Accurate on the CPU).
#include "fit.h"

#include "tyndall/gpu/context.h"
#include "tyndall/gpu/harness.h"

#include "tyndall/tables/ltsd_table.h"

#include "shared/ltsd_boundary.h"

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

// S by the boundary form (issue 32, sMethod = accurate): no table, 3 Gauss nodes per edge; the same quads and g.
void BM_S_Accurate(benchmark::State& state) {
    shader::SphericalPolygon p = quadFor(state);
    for (auto _ : state) {
        benchmark::DoNotOptimize(p);
        benchmark::DoNotOptimize(shader::ltsdLobeIntegral(p, shader::kLtsdLobeHg, 0.6f));
    }
}
BENCHMARK(BM_S_Accurate)->Arg(0)->Arg(1)->Arg(2);

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

gpu::Context& gpuContext() {
    static gpu::Context context;
    return context;
}

// Inputs 0-5: the upper and the lower entry (12 floats each, the source as a float); then one vec4 per sample: the
// quad's offsets in x and y, and its height (as quadFor: above, straddling or below the horizon).
std::vector<glm::vec4> gpuInputs(const benchmark::State& state, size_t samples) {
    std::vector<glm::vec4> inputs;
    for (const shader::LtsdEntry& e : {table().upper(0.6), table().lower(0.6)}) {
        inputs.emplace_back(e.m[0], e.m[1], e.m[2], e.m[3]);
        inputs.emplace_back(e.m[4], e.m[5], e.m[6], e.m[7]);
        inputs.emplace_back(e.m[8], e.amplitude, float(e.source), e.g);
    }
    const float heights[] = {0.6f, -0.15f, -0.9f};
    for (size_t i = 0; i < samples; ++i) {
        const float u = float(i % 1024) / 1024.0f - 0.5f, v = float(i / 1024 % 1024) / 1024.0f - 0.5f;
        inputs.emplace_back(0.2f * u, 0.2f * v, heights[state.range(0)], 0.0f);
    }
    return inputs;
}

constexpr const char* kQuadBody = R"(
    SphericalPolygon p;
    p.count = 4;
    p.v[0] = vec3(0.4 + x.x, 0.3 + x.y, x.z);
    p.v[1] = vec3(-0.4 + x.x, 0.3 + x.y, x.z + 0.3);
    p.v[2] = vec3(-0.4 + x.x, -0.3 + x.y, x.z + 0.3);
    p.v[3] = vec3(0.4 + x.x, -0.3 + x.y, x.z);
)";

constexpr const char* kSBody = R"(
    LtsdEntry e[2];
    for (int k = 0; k < 2; ++k) {
        vec4 a = inputs[3 * k], b = inputs[3 * k + 1], c = inputs[3 * k + 2];
        e[k].m = float[9](a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, c.x);
        e[k].amplitude = c.y;
        e[k].source = int(c.z);
        e[k].g = c.w;
    }
    return vec4(ltsdS(p, e[0], e[1]), 0.0, 0.0, 0.0);
)";

// S by the boundary form on the same quads: HG at g = 0.6, the lobe a compile-time constant as in the LTSD kernel.
constexpr const char* kAccurateSBody = R"(
    return vec4(ltsdLobeIntegral(p, kLtsdLobeHg, 0.6 + inputs[0].x * 0.0), 0.0, 0.0, 0.0);
)";

// The same quads, summed so that building them is not optimised away.
constexpr const char* kBaselineBody = R"(
    return vec4(p.v[0].x + p.v[1].y + p.v[2].z + p.v[3].x + inputs[0].x, 0.0, 0.0, 0.0);
)";

void BM_S_Gpu(benchmark::State& state, const char* sBody) {
    constexpr size_t kSamples = size_t(1) << 20;
    const std::vector<glm::vec4> inputs = gpuInputs(state, kSamples);
    const std::string prelude = "#include \"shared/ltsd_boundary.h\"\n";
    double withS = 0.0, baseline = 0.0;
    for (auto _ : state) {
        double ms = 0.0, base = 0.0;
        gpu::evaluateOnGpu(gpuContext(), prelude, std::string(kQuadBody) + sBody, inputs, &ms);
        gpu::evaluateOnGpu(gpuContext(), prelude, std::string(kQuadBody) + kBaselineBody, inputs, &base);
        if (ms < 0.0) {
            state.SkipWithError("the device has no timestamps");
            return;
        }
        state.SetIterationTime(ms / 1e3);
        withS += ms, baseline += base;
    }
    const double n = double(state.iterations()) * double(kSamples);
    state.counters["ns_per_S"] = (withS - baseline) * 1e6 / n;
    state.counters["ns_per_sample_with_S"] = withS * 1e6 / n;
    state.SetLabel(gpuContext().device().name);
}
// The three quads, GPU time, three dispatches each.
void gpuRuns(benchmark::internal::Benchmark* b) {
    b->Arg(0)->Arg(1)->Arg(2)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);
}
BENCHMARK_CAPTURE(BM_S_Gpu, paper, kSBody)->Apply(gpuRuns);
BENCHMARK_CAPTURE(BM_S_Gpu, accurate, kAccurateSBody)->Apply(gpuRuns);

}  // namespace

BENCHMARK_MAIN();
