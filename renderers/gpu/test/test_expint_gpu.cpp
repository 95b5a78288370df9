// The exponential integrals of shaders/shared/expint.h run on the GPU (lavapipe here) like on the CPU, in float and
// in double, through the GPU-vs-CPU harness. Each input carries 1 / |CPU value|, by which both sides scale their
// result, so that the harness's difference with a relative floor of 1 is the error relative to the complex value's
// magnitude (a component near zero would otherwise dominate).
//
// Tolerances: float 1.5e-5, about 3 times the measured worst difference (5.5e-6 for E1 and Ei, 3.4e-6 for e^z E_n).
// The CPU side is accurate to 4e-7 (test_expint.cpp); the difference comes from the GPU's float built-ins, which
// Vulkan lets be coarse: on lavapipe atan(y, x) is off by up to 3.3e-6 and log by 4.8e-7 (absolute), exp by 6 ulp,
// and the series' ln z carries that into the result. Double 1e-14: both sides run the same double_math.h functions
// in IEEE double, so only FMA contraction differs; measured 1.0e-15 (E1, Ei) and 5.6e-16 (e^z E_n).
#include "gpu_test.h"

#include "tyndall/gpu/harness.h"

#include "shared/expint.h"

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

namespace tyndall::gpu::test {
namespace {

namespace sh = tyndall::shader;

constexpr double kFloatTolerance = 1.5e-5;
constexpr double kDoubleTolerance = 1e-14;
constexpr int kInputs = 4096;

template <typename Vec2>
double magnitude(const Vec2& v) {
    return std::hypot(double(v.x), double(v.y));
}

// Arguments over the plane: |z| log-uniform in [1e-6, maxRadius], all angles; every eighth just off the negative
// real axis.
template <typename Vec4>
std::vector<Vec4> planeArguments(double maxRadius, uint32_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> logR(std::log(1e-6), std::log(maxRadius)), angle(-M_PI, M_PI), unit(0, 1);
    std::vector<Vec4> inputs(kInputs);
    for (size_t i = 0; i < inputs.size(); ++i) {
        double r = std::exp(logR(rng));
        double theta = i % 8 == 0 ? (unit(rng) < 0.5 ? 1.0 : -1.0) * (M_PI - 1e-6 * unit(rng)) : angle(rng);
        inputs[i] = Vec4(r * std::cos(theta), r * std::sin(theta), 0, 0);
    }
    return inputs;
}

// Arguments of e^z E_n(z): half Pegoraro's t = H (v - i), H in [1e-4, 50], v in [1e-4, 1e4]; half the right half
// plane with |z| in [1e-4, 1e4]; n uniform in 1 .. 40 in the third component.
template <typename Vec4>
std::vector<Vec4> rightHalfPlaneArguments(uint32_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> logH(std::log(1e-4), std::log(50.0)), logV(std::log(1e-4), std::log(1e4));
    std::uniform_real_distribution<double> logR(std::log(1e-4), std::log(1e4)), angle(-M_PI / 2, M_PI / 2);
    std::uniform_int_distribution<int> order(1, sh::kExpintMaxOrder);
    std::vector<Vec4> inputs(kInputs);
    for (size_t i = 0; i < inputs.size(); ++i) {
        if (i % 2 == 0) {
            double h = std::exp(logH(rng)), v = std::exp(logV(rng));
            inputs[i] = Vec4(h * v, -h, order(rng), 0);
        } else {
            double r = std::exp(logR(rng)), theta = angle(rng);
            inputs[i] = Vec4(r * std::cos(theta), r * std::sin(theta), order(rng), 0);
        }
    }
    return inputs;
}

// E1 in x, y and Ei in z, w, each scaled by 1 / |CPU value| (carried in the input's z and w).
template <typename Vec4>
Vec4 cpuE1Ei(const Vec4& x) {
    using Vec2 = glm::vec<2, typename Vec4::value_type>;
    Vec2 z(x.x, x.y);
    return Vec4(sh::expintE1(z) * x.z, sh::expintEi(z) * x.w);
}

// e^z E_n(z) once alone and once from the all-orders variant, both scaled by 1 / |CPU value| (in w).
template <typename Vec4, typename Orders>
Vec4 cpuEnScaled(const Vec4& x) {
    using Vec2 = glm::vec<2, typename Vec4::value_type>;
    Vec2 z(x.x, x.y);
    int n = int(x.z);
    Orders orders;
    sh::expintEnScaledAll(n, z, orders);
    return Vec4(sh::expintEnScaled(n, z) * x.w, orders.value[n - 1] * x.w);
}

const char* kE1EiBody = "return vec4(expintE1(x.xy) * x.z, expintEi(x.xy) * x.w);";
const char* kEnScaledBody =
    "int n = int(x.z);\n"
    "ExpintOrders orders;\n"
    "expintEnScaledAll(n, x.xy, orders);\n"
    "return vec4(expintEnScaled(n, x.xy) * x.w, orders.value[n - 1] * x.w);";
const char* kE1EiBodyDouble = "return dvec4(expintE1(x.xy) * x.z, expintEi(x.xy) * x.w);";
const char* kEnScaledBodyDouble =
    "int n = int(x.z);\n"
    "ExpintOrdersD orders;\n"
    "expintEnScaledAll(n, x.xy, orders);\n"
    "return dvec4(expintEnScaled(n, x.xy) * x.w, orders.value[n - 1] * x.w);";

void expectClose(const char* name, const HarnessReport& r, double tolerance) {
    std::printf("%-28s max difference relative to |value| %.3g (input %zu)\n", name, r.maxAbsDiff, r.worstIndex);
    EXPECT_LT(r.maxAbsDiff, tolerance) << name << ", input " << r.worstIndex << " component " << r.worstComponent;
    EXPECT_EQ(r.nonFiniteMismatches, 0u) << name;
}

TEST_F(GpuTest, ExpintFloatAgreesWithTheCpu) {
    // |z| <= 60 keeps every value within the normal float range (E1(60) ~ 1.5e-28, E1(-60) ~ 1.9e24).
    std::vector<glm::vec4> e1Inputs = planeArguments<glm::vec4>(60.0, 1);
    for (glm::vec4& x : e1Inputs) {
        glm::vec2 z(x.x, x.y);
        x.z = float(1.0 / magnitude(sh::expintE1(z)));
        x.w = float(1.0 / magnitude(sh::expintEi(z)));
    }
    auto gpu = evaluateOnGpu(context(), "#include \"shared/expint.h\"\n", kE1EiBody, e1Inputs);
    expectClose("float E1, Ei", compareWithCpu(e1Inputs, gpu, cpuE1Ei<glm::vec4>, 1.0), kFloatTolerance);

    std::vector<glm::vec4> enInputs = rightHalfPlaneArguments<glm::vec4>(2);
    for (glm::vec4& x : enInputs)
        x.w = float(1.0 / magnitude(sh::expintEnScaled(int(x.z), glm::vec2(x.x, x.y))));
    gpu = evaluateOnGpu(context(), "#include \"shared/expint.h\"\n", kEnScaledBody, enInputs);
    expectClose("float e^z E_n, all orders",
                compareWithCpu(enInputs, gpu, cpuEnScaled<glm::vec4, sh::ExpintOrders>, 1.0), kFloatTolerance);
}

TEST_F(GpuTest, ExpintDoubleAgreesWithTheCpu) {
    if (!context().device().shaderFloat64) GTEST_SKIP() << "the device has no float64";
    const std::string prelude = "#define TY_ENABLE_DOUBLE\n#include \"shared/expint.h\"\n";
    // |z| <= 700: E1 and Ei stay within the double range.
    std::vector<glm::dvec4> e1Inputs = planeArguments<glm::dvec4>(700.0, 3);
    for (glm::dvec4& x : e1Inputs) {
        glm::dvec2 z(x.x, x.y);
        x.z = 1.0 / magnitude(sh::expintE1(z));
        x.w = 1.0 / magnitude(sh::expintEi(z));
    }
    auto gpu = evaluateOnGpuDouble(context(), prelude, kE1EiBodyDouble, e1Inputs);
    expectClose("double E1, Ei", compareWithCpu(e1Inputs, gpu, cpuE1Ei<glm::dvec4>, 1.0), kDoubleTolerance);

    std::vector<glm::dvec4> enInputs = rightHalfPlaneArguments<glm::dvec4>(4);
    for (glm::dvec4& x : enInputs)
        x.w = 1.0 / magnitude(sh::expintEnScaled(int(x.z), glm::dvec2(x.x, x.y)));
    gpu = evaluateOnGpuDouble(context(), prelude, kEnScaledBodyDouble, enInputs);
    expectClose("double e^z E_n, all orders",
                compareWithCpu(enInputs, gpu, cpuEnScaled<glm::dvec4, sh::ExpintOrdersD>, 1.0), kDoubleTolerance);
}

// The side of the cut on the GPU: im = +0 above (-i pi), -0 below (+i pi), as on the CPU.
TEST_F(GpuTest, ExpintTakesTheSideOfTheCutFromTheSignOfZero) {
    std::vector<glm::vec4> inputs;
    for (float x : {0.5f, 3.0f, 20.0f, 40.0f}) {
        inputs.push_back(glm::vec4(-x, 0.0f, 0, 0));
        inputs.push_back(glm::vec4(-x, -0.0f, 0, 0));
    }
    auto gpu =
        evaluateOnGpu(context(), "#include \"shared/expint.h\"\n", "return vec4(expintE1(x.xy), 0.0f, 0.0f);", inputs);
    for (size_t i = 0; i < inputs.size(); ++i)
        EXPECT_FLOAT_EQ(gpu[i].y, std::signbit(inputs[i].y) ? float(M_PI) : -float(M_PI)) << inputs[i].x;
}

}  // namespace
}  // namespace tyndall::gpu::test
