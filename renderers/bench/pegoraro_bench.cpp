// The cost of the Pegoraro closed form against the order of the angular distributions (the analogue of the paper's
// Table 4), and against adaptive quadrature of the same integral:
//   build/renderers/bench/tyndall_pegoraro_bench
// - BM_ClosedFormCpu/order/double: one evaluation (series + integral, one light, one channel) on one CPU core, averaged
//   over random configurations (H in [1e-2, 20]); BM_QuadratureCpu/order: the fallback quadrature to 1e-6 on the same
//   configurations. The order where the quadrature becomes cheaper is where the closed form stops paying.
// - BM_AutoCpu/terms/measured: fallback = auto on one evaluation for Henyey-Greenstein g = 0.7, deciding with the a
//   priori error bound (0, as before) or with the measured one (1, pegoraroSeriesRefine), with the fallback rates.
// - BM_TechniqueGpu/order/size: the technique on the GPU (lavapipe here) on a scene with nothing but an infinite
//   medium (chromatic extinction) whose phase function has that order and an isotropic point light, size x size, one
//   sample per pixel, shadows off: GPU time per pixel per light (ns) and frames per second, from the renders'
//   timestamps (the first render compiles the pipeline and is not timed), and the pixels that fell back.
// - BM_QuadratureGpu/order/size: the same with fallback = always (every evaluation by the quadrature), for the order
//   where the quadrature would become the cheaper way on the GPU.
#include "pegoraro/coefficients.h"
#include "pegoraro/test/closed_form_cases.h"

#include "tyndall/framework/technique.h"
#include "tyndall/gpu/context.h"
#include "tyndall/techniques/registry.h"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

using namespace tyndall;
using namespace tyndall::pegoraro::test;

namespace {

std::vector<Case> cases(int order) {
    sh::Pcg32 rng = sh::pcg32Seed(42u, std::uint32_t(order));
    std::vector<Case> out;
    for (int i = 0; i < 256; ++i)
        out.push_back(randomCase(rng, order, 1e-2, 20.0, 20.0));
    return out;
}

void BM_ClosedFormCpu(benchmark::State& state) {
    const int order = int(state.range(0));
    const bool useDouble = state.range(1) != 0;
    const std::vector<Case> cs = cases(order);
    std::size_t i = 0;
    for (auto _ : state) {
        const Case& c = cs[i++ % cs.size()];
        benchmark::DoNotOptimize(useDouble ? closedFormDouble(c).value : closedFormFloat(c).value);
    }
    state.SetLabel(useDouble ? "double" : "float");
}
BENCHMARK(BM_ClosedFormCpu)->ArgsProduct({{0, 1, 2, 4, 8, 12, 16, 24, 32}, {0, 1}})->Unit(benchmark::kMicrosecond);

void BM_QuadratureCpu(benchmark::State& state) {
    const int order = int(state.range(0));
    const std::vector<Case> cs = cases(order);
    std::size_t i = 0;
    for (auto _ : state) {
        const Case& c = cs[i++ % cs.size()];
        int panels = 0;
        benchmark::DoNotOptimize(sh::pegoraroQuadrature(c.H, c.ua, c.ub, c.del, c.dc, toPolynomialD(c.phase),
                                                        toPolynomialD(c.lightPoly), 1e-6, panels));
    }
}
BENCHMARK(BM_QuadratureCpu)->DenseRange(0, 32, 4)->Unit(benchmark::kMicrosecond);

// fallback = auto on one evaluation, the case: Henyey-Greenstein g = 0.7 truncated to `terms` Legendre terms,
// isotropic light. measured = 0: the a priori bound decides, as before pegoraroSeriesRefine; 1: the measured bound
// decides where the a priori one fails. Past the deciding bound, the quadrature to 1e-6. Interleaved in one run, so
// that the machine's drift affects both alike; the counter is the fraction that fell back.
void BM_AutoCpu(benchmark::State& state) {
    const int terms = int(state.range(0));
    const bool measured = state.range(1) != 0;
    tyndall::PhaseFunction phase;
    phase.kind = tyndall::PhaseKind::HenyeyGreenstein;
    phase.g = 0.7;
    tyndall::pegoraro::HgSettings hg;
    hg.terms = terms;
    const std::vector<double> polynomial = tyndall::pegoraro::phasePolynomial(phase, hg).c;
    std::vector<Case> cs = cases(0);
    for (Case& c : cs) {
        c.phase = polynomial;
        c.lightPoly = {1.0};
    }
    std::size_t i = 0, fellBack = 0, evaluations = 0;
    for (auto _ : state) {
        const Case& c = cs[i++ % cs.size()];
        const sh::PegoraroPolynomial_double p = toPolynomialD(c.phase), l = toPolynomialD(c.lightPoly);
        sh::PegoraroSeries_double s;
        sh::pegoraroSeries(c.del, c.dc, p, l, s);
        double bound = 0.0;
        double value = sh::pegoraroIntegral(s, c.H, c.ua, c.ub, bound);
        if (measured && bound > 1e-4 * std::abs(value)) {
            sh::pegoraroSeriesRefine(c.del, c.dc, p, l, s);
            value = sh::pegoraroIntegral(s, c.H, c.ua, c.ub, bound);
        }
        if (bound > 1e-4 * std::abs(value)) {
            int panels = 0;
            value = sh::pegoraroQuadrature(c.H, c.ua, c.ub, c.del, c.dc, p, l, 1e-6, panels);
            ++fellBack;
        }
        ++evaluations;
        benchmark::DoNotOptimize(value);
    }
    state.counters["fallback"] = double(fellBack) / double(std::max<std::size_t>(evaluations, 1));
    state.SetLabel(measured ? "measured bound" : "a priori bound");
}
BENCHMARK(BM_AutoCpu)->ArgsProduct({{8, 12, 16, 20}, {0, 1}})->Unit(benchmark::kMicrosecond);

Scene mediumOnlyScene(int order, int size = 256) {
    Scene scene;
    scene.camera.position = {0.0, 1.0, 4.0};
    scene.camera.target = {0.0, 1.0, 0.0};
    scene.camera.width = scene.camera.height = size;
    HomogeneousMedium m;
    m.name = "haze";
    m.sigma_s = Rgb(0.1, 0.12, 0.15);
    m.sigma_a = Rgb(0.01);
    m.phase.kind = PhaseKind::Legendre;
    for (int n = 0; n <= order; ++n)
        m.phase.legendre.push_back((2.0 * n + 1.0) * std::pow(0.5, n));
    scene.media.push_back(m);
    PointLight l;
    l.name = "lamp";
    l.position = {0.3, 1.2, 0.0};
    l.intensity = Rgb(2.0);
    scene.pointLights.push_back(l);
    return scene;
}

void techniqueGpu(benchmark::State& state, const std::string& fallback) {
    const int order = int(state.range(0));
    const int size = int(state.range(1));
    auto technique = createTechnique("pegoraro");
    RenderRequest request;
    request.scene = mediumOnlyScene(order, size);
    request.params = technique->defaultParams();
    request.params.set("device", std::string("gpu"));
    request.params.set("fallback", fallback);
    request.params.set("supersampling", std::int64_t(1));
    request.params.set("shadows", false);
    request.params.set("hgTerms", std::int64_t(1));
    technique->render(request, {});  // compiles the pipeline
    double gpuMs = 0.0, fallbackPixels = 0.0;
    std::string precision;
    for (auto _ : state) {
        const RenderResult r = technique->render(request, {});
        const double ms = std::stod(r.image.metadata.at("gpu:totalMs"));
        state.SetIterationTime(ms * 1e-3);
        gpuMs = ms;
        precision = r.image.metadata.at("pegoraro:precision");
        fallbackPixels = std::stod(r.image.metadata.at("pegoraro:fallbackPixels"));
    }
    state.counters["ns/pixel/light"] = gpuMs * 1e6 / (double(size) * double(size));
    state.counters["frames/s"] = 1e3 / gpuMs;
    state.counters["fallbackPixels"] = fallbackPixels;
    state.SetLabel(precision);
}

void BM_TechniqueGpu(benchmark::State& state) {
    techniqueGpu(state, "auto");
}
BENCHMARK(BM_TechniqueGpu)
    ->Args({0, 256})
    ->Args({1, 256})
    ->Args({2, 256})
    ->Args({4, 256})
    ->Args({8, 256})
    ->Args({12, 256})
    ->Args({16, 256})
    ->Args({0, 512})  // the target: isotropic at >= 30 frames/s at 512 x 512 on lavapipe
    ->UseManualTime()
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

// The same scene with every evaluation by the fallback quadrature (to quadratureTolerance, 1e-6), at 64 x 64: where
// it would become cheaper than the closed form on the GPU.
void BM_QuadratureGpu(benchmark::State& state) {
    techniqueGpu(state, "always");
}
BENCHMARK(BM_QuadratureGpu)
    ->Args({0, 64})
    ->Args({4, 64})
    ->Args({8, 64})
    ->Args({16, 64})
    ->UseManualTime()
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
