// Shared math runs unchanged in compute shaders: each function is evaluated on the GPU (lavapipe here) and on the CPU
// from the same header, and the largest difference is bounded per function.
#include "gpu_test.h"

#include "tyndall/gpu/harness.h"

#include "shared/double_math.h"
#include "shared/phase.h"
#include "shared/rng.h"
#include "shared/sampling.h"

#include <cmath>
#include <functional>
#include <random>

namespace tyndall::gpu::test {
namespace {

namespace sh = tyndall::shader;

// Keep components x, y (or z, w) and zero the others, to compare parts with different tolerances.
std::vector<glm::vec4> onlyXY(std::vector<glm::vec4> v) {
    for (auto& x : v) x.z = x.w = 0.0f;
    return v;
}
std::vector<glm::vec4> onlyZW(std::vector<glm::vec4> v) {
    for (auto& x : v) x.x = x.y = 0.0f;
    return v;
}

std::vector<glm::vec4> randomInputs(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<glm::vec4> out(n);
    for (auto& v : out) v = glm::vec4(u(rng), u(rng), u(rng), u(rng));
    return out;
}

TEST_F(GpuTest, HarnessReportsTheLargestDifference) {
    std::vector<glm::vec4> inputs = randomInputs(256, 1);
    auto gpu = evaluateOnGpu(context(), "", "return x * 2.0f;", inputs);
    HarnessReport same = compareWithCpu(inputs, gpu, [](const glm::vec4& x) { return x * 2.0f; });
    EXPECT_EQ(same.maxAbsDiff, 0.0);
    HarnessReport off = compareWithCpu(inputs, gpu, [](const glm::vec4& x) { return x * 2.0f + glm::vec4(0, 0, 0.5f, 0); });
    EXPECT_NEAR(off.maxAbsDiff, 0.5, 1e-6) << "a deliberate difference must be found";
    EXPECT_EQ(off.worstComponent, 2);
}

// Phase functions: x.x -> mu in [-1, 1], x.y -> the parameter.
TEST_F(GpuTest, PhaseFunctionsAgreeWithTheCpu) {
    const char* prelude = "#include \"shared/phase.h\"\n"
                          "PhaseParams params(int kind, float p) {\n"
                          "    PhaseParams q; q.kind = kind; q.g = 1.8f * p - 0.9f; q.a = p; q.b = 2.0f * p - 1.0f;\n"
                          "    q.terms = 3; q.legendre[0] = 1.0f; q.legendre[1] = 0.9f * p; q.legendre[2] = 0.3f * p;\n"
                          "    for (int i = 3; i < kMaxLegendreTerms; ++i) q.legendre[i] = 0.0f;\n"
                          "    return q;\n"
                          "}\n";
    auto cpuParams = [](int kind, float p) {
        sh::PhaseParams q{};
        q.kind = kind;
        q.g = 1.8f * p - 0.9f;
        q.a = p;
        q.b = 2.0f * p - 1.0f;
        q.terms = 3;
        q.legendre[0] = 1.0f;
        q.legendre[1] = 0.9f * p;
        q.legendre[2] = 0.3f * p;
        return q;
    };
    std::vector<glm::vec4> inputs = randomInputs(4096, 2);
    for (glm::vec4& v : inputs) v.x = 2.0f * v.x - 1.0f;
    for (int kind = 0; kind <= sh::kPhaseLegendre; ++kind) {
        std::string body = "PhaseParams q = params(" + std::to_string(kind) + ", x.y);\n"
                           "vec2 u = x.zw;\n"
                           "float pdf; vec3 w = phaseSample(q, normalize(vec3(0.3f, -0.5f, 0.8f)), u, pdf);\n"
                           "return vec4(phaseEval(q, x.x), pdf, w.x, w.z);";
        auto gpu = evaluateOnGpu(context(), prelude, body, inputs);
        auto cpu = [&](const glm::vec4& x) {
            sh::PhaseParams q = cpuParams(kind, x.y);
            float pdf;
            glm::vec3 w = sh::phaseSample(q, glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f)), glm::vec2(x.z, x.w), pdf);
            return glm::vec4(sh::phaseEval(q, x.x), pdf, w.x, w.z);
        };
        // Values (eval, pdf): float math on two compilers (GCC, and LLVM in lavapipe with FMA contraction) differs
        // by a few ulps, which pow and the Legendre bisection amplify near lobes: 1e-4 relative.
        HarnessReport values = compareWithCpu(inputs, onlyXY(gpu), [&](const glm::vec4& x) {
            return glm::vec4(glm::vec2(cpu(x)), 0.0f, 0.0f);
        }, 1e-3);
        EXPECT_LT(values.maxRelDiff, 1e-4) << "phase kind " << kind << ", input " << values.worstIndex;
        // Sampled directions: sqrt(1 - mu^2) turns an ulp of mu near +-1 (strong HG lobes) into ~1e-4 of a
        // direction component, so directions are compared absolutely at 2e-3.
        HarnessReport directions = compareWithCpu(inputs, onlyZW(gpu), [&](const glm::vec4& x) {
            glm::vec4 c = cpu(x);
            return glm::vec4(0.0f, 0.0f, c.z, c.w);
        });
        EXPECT_LT(directions.maxAbsDiff, 2e-3) << "phase kind " << kind << ", input " << directions.worstIndex;
        HarnessReport r = values;
        EXPECT_EQ(r.nonFiniteMismatches, 0u);
    }
}

// Integer code must agree bit for bit: the same seeds give the same samples on both sides.
TEST_F(GpuTest, RandomNumbersAreBitIdentical) {
    std::vector<glm::vec4> inputs(2048);
    for (size_t i = 0; i < inputs.size(); ++i) inputs[i] = glm::vec4(float(i), float(i % 7), 0.0f, 0.0f);
    auto gpu = evaluateOnGpu(context(), "#include \"shared/rng.h\"\n",
                             "uint i = uint(x.x); uint pair = uint(x.y);\n"
                             "vec2 s = sobolSample2D(12345u, i, pair);\n"
                             "Pcg32 r = pcg32Seed(i, pair); float p = pcg32NextFloat(r);\n"
                             "return vec4(s, p, uintToUnitFloat(hashUint(i)));",
                             inputs);
    HarnessReport r = compareWithCpu(inputs, gpu, [](const glm::vec4& x) {
        uint32_t i = uint32_t(x.x), pair = uint32_t(x.y);
        glm::vec2 s = sh::sobolSample2D(12345u, i, pair);
        sh::Pcg32 rng = sh::pcg32Seed(i, pair);
        float p = sh::pcg32NextFloat(rng);
        return glm::vec4(s, p, sh::uintToUnitFloat(sh::hashUint(i)));
    });
    EXPECT_EQ(r.maxAbsDiff, 0.0);
}

TEST_F(GpuTest, EquiangularAndSphericalTriangleSamplingAgree) {
    std::vector<glm::vec4> inputs = randomInputs(4096, 3);
    auto gpu = evaluateOnGpu(context(), "#include \"shared/sampling.h\"\n",
                             "Equiangular e = equiangularSetup(vec3(0.0f), normalize(vec3(0.2f, 0.1f, -1.0f)),\n"
                             "                                 vec3(1.0f, 2.0f, -3.0f), 0.5f, 6.0f);\n"
                             "float pdf; float t = equiangularSample(e, x.x, pdf);\n"
                             "float omega; vec3 d = sampleSphericalTriangle(normalize(vec3(1, 0, -2)),\n"
                             "    normalize(vec3(0, 1, -2)), normalize(vec3(-1, -1, -2)), x.yz, omega);\n"
                             "return vec4(t, pdf, d.x, d.y);",
                             inputs);
    auto cpu = [](const glm::vec4& x) {
        sh::Equiangular e = sh::equiangularSetup(glm::vec3(0.0f), glm::normalize(glm::vec3(0.2f, 0.1f, -1.0f)),
                                                 glm::vec3(1.0f, 2.0f, -3.0f), 0.5f, 6.0f);
        float pdf;
        float t = sh::equiangularSample(e, x.x, pdf);
        float omega;
        glm::vec3 d = sh::sampleSphericalTriangle(glm::normalize(glm::vec3(1, 0, -2)), glm::normalize(glm::vec3(0, 1, -2)),
                                                  glm::normalize(glm::vec3(-1, -1, -2)), glm::vec2(x.y, x.z), omega);
        return glm::vec4(t, pdf, d.x, d.y);
    };
    // Distances and pdfs to 1e-4 relative (tan/atan differ by ulps between the math libraries); directions of
    // Arvo's construction (acos, then square roots near the poles) to 1e-3 absolute.
    HarnessReport values = compareWithCpu(inputs, onlyXY(gpu), [&](const glm::vec4& x) {
        return glm::vec4(glm::vec2(cpu(x)), 0.0f, 0.0f);
    }, 1e-3);
    EXPECT_LT(values.maxRelDiff, 1e-4) << "input " << values.worstIndex;
    HarnessReport directions = compareWithCpu(inputs, onlyZW(gpu), [&](const glm::vec4& x) {
        glm::vec4 c = cpu(x);
        return glm::vec4(0.0f, 0.0f, c.z, c.w);
    });
    EXPECT_LT(directions.maxAbsDiff, 1e-3) << "input " << directions.worstIndex;
}

// Double-precision exp, log, sin, cos, atan2 written as shared code run on the GPU like on the CPU. Both sides do IEEE
// double arithmetic with exact fma, so they agree to an ulp or two (the only freedom is the GPU compiler's
// contraction of a*b+c), well inside the functions' own 2-ulp accuracy.
TEST_F(GpuTest, DoublePrecisionMathAgreesWithTheCpu) {
    if (!context().device().shaderFloat64) GTEST_SKIP() << "the device has no float64";
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> e(-700.0, 700.0), l(-690.0, 690.0), s(-1e4, 1e4);
    std::vector<glm::dvec4> inputs(4096);
    for (auto& v : inputs) v = glm::dvec4(e(rng), std::exp(l(rng)), s(rng), s(rng));
    const std::string prelude = "#include \"shared/double_math.h\"\n";
    struct Case {
        const char* glsl;
        std::function<glm::dvec4(const glm::dvec4&)> shared, libm;
    };
    const Case cases[] = {
        {"return dvec4(dExp(x.x), dLog(x.y), dSin(x.z), dCos(x.w));",
         [](const glm::dvec4& x) { return glm::dvec4(sh::dExp(x.x), sh::dLog(x.y), sh::dSin(x.z), sh::dCos(x.w)); },
         [](const glm::dvec4& x) { return glm::dvec4(std::exp(x.x), std::log(x.y), std::sin(x.z), std::cos(x.w)); }},
        {"return dvec4(dAtan2(x.z, x.w), dAtan2(x.w, -x.z), dCos(x.z), dExp(-abs(x.x)));",
         [](const glm::dvec4& x) {
             return glm::dvec4(sh::dAtan2(x.z, x.w), sh::dAtan2(x.w, -x.z), sh::dCos(x.z), sh::dExp(-std::abs(x.x)));
         },
         [](const glm::dvec4& x) {
             return glm::dvec4(std::atan2(x.z, x.w), std::atan2(x.w, -x.z), std::cos(x.z), std::exp(-std::abs(x.x)));
         }},
    };
    for (const Case& c : cases) {
        auto gpu = evaluateOnGpuDouble(context(), prelude, c.glsl, inputs);
        HarnessReport r = compareWithCpu(inputs, gpu, c.shared, 1e-300);
        EXPECT_LT(r.maxRelDiff, 1e-15) << c.glsl << " input " << r.worstIndex << " component " << r.worstComponent;
        EXPECT_EQ(r.nonFiniteMismatches, 0u);
        // And against the C library, which the functions were written to match within 2 ulp (4.4e-16).
        HarnessReport libm = compareWithCpu(inputs, gpu, c.libm, 1e-300);
        EXPECT_LT(libm.maxRelDiff, 1e-15) << c.glsl << " input " << libm.worstIndex << " component "
                                          << libm.worstComponent;
    }
}

}  // namespace
}  // namespace tyndall::gpu::test
