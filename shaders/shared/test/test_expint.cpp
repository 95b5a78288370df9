// The exponential integrals of shaders/shared/expint.h (E1, Ei, e^z E_n and its all-orders variant), compiled as
// C++, against mpmath (tests/data/expint_reference.csv, made by tests/data/gen_expint_reference.py: 30+ digits).
// Errors are relative to the complex value, |computed - reference| / |reference|. Every argument in the file is a
// float, so the float and double functions are measured at the same points.
//
// Tolerances, with the worst errors measured on this file (docs/expint.md has the table):
//  - double: 4e-15 (about 18 ulp); measured at most 1.3e-15 (E1), 6.2e-16 (Ei), 1.1e-15 (e^z E_n), 4.2e-16 (all
//    orders). The series regions lose up to a factor e^(|z| + Re z) < 7 to cancellation; the rest is rounding.
//  - float: 1.5e-6 (about 25 ulp) where the value lies in [1e-30, 1e30]; measured at most 3.8e-7 (E1), 2.6e-7 (Ei),
//    3.5e-7 (e^z E_n), 2.0e-7 (all orders). A denser random sample (10^4 points) reaches 9.6e-7 next to the series
//    boundary.
//  - Ei next to its real zero x0 = 0.3725 (where |Ei| is below 1e-3): an absolute error of 2e-16 (double) and 1e-7
//    (float), as ln z and gamma are summed to a value near zero and only an absolute accuracy can be expected;
//    measured 3.5e-17 and 1.6e-8.
#include "shared/expint.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace tyndall {
namespace {

namespace sh = tyndall::shader;
using Complex = std::complex<double>;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;
constexpr double kDoubleTolerance = 4e-15;
constexpr double kFloatTolerance = 1.5e-6;
constexpr double kFloatRange = 1e30;  // float values are compared where 1/kFloatRange <= |value| <= kFloatRange
constexpr double kEiZero = 0.37250741078136663;

struct Reference {
    std::string function;  // E1, Ei or EnScaled
    int n = 1;
    double x = 0.0, y = 0.0;  // the argument, a float value
    Complex value;
};

const std::vector<Reference>& references() {
    static const std::vector<Reference> rows = [] {
        std::vector<Reference> out;
        std::ifstream in(std::string(TYNDALL_SOURCE_DIR) + "/tests/data/expint_reference.csv");
        std::string line;
        while (std::getline(in, line)) {
            if (line.empty() || line[0] == '#' || line.rfind("function,", 0) == 0) continue;
            std::stringstream fields(line);
            std::string f[6];
            for (std::string& field : f)
                std::getline(fields, field, ',');
            Reference r;
            r.function = f[0];
            r.n = std::stoi(f[1]);
            r.x = std::strtod(f[2].c_str(), nullptr);
            r.y = std::strtod(f[3].c_str(), nullptr);
            r.value = Complex(std::strtod(f[4].c_str(), nullptr), std::strtod(f[5].c_str(), nullptr));
            out.push_back(r);
        }
        return out;
    }();
    return rows;
}

template <typename Vec2>
Complex toComplex(const Vec2& v) {
    return Complex(double(v.x), double(v.y));
}

// The function a row names, in the precision of Vec2 (glm::vec2 or glm::dvec2).
template <typename Vec2>
Complex evaluate(const Reference& r) {
    using Real = typename Vec2::value_type;
    Vec2 z(Real(r.x), Real(r.y));
    if (r.function == "E1") return toComplex(sh::expintE1(z));
    if (r.function == "Ei") return toComplex(sh::expintEi(z));
    return toComplex(sh::expintEnScaled(r.n, z));
}

bool nearEiZero(const Reference& r) {
    return r.function == "Ei" && std::abs(Complex(r.x, r.y) - kEiZero) < 1e-3;
}

struct Worst {
    double error = 0.0;
    const Reference* at = nullptr;
    size_t count = 0;

    void add(double e, const Reference& r) {
        ++count;
        if (!(e <= error)) {  // NaN counts as worst
            error = e;
            at = &r;
        }
    }
};

// Errors by function for one precision: relative to |reference|, except next to the zero of Ei, where they are
// absolute. Rows with |reference| outside [1/range, range] are skipped.
template <typename Vec2>
void expectAccurate(const char* precision, double range, double relativeTolerance, double absoluteNearEiZero) {
    std::map<std::string, Worst> worst;
    for (const Reference& r : references()) {
        double magnitude = std::abs(r.value);
        if (magnitude > range || magnitude < 1.0 / range) continue;
        double error = std::abs(evaluate<Vec2>(r) - r.value);
        if (nearEiZero(r))
            worst["Ei near its zero, absolute"].add(error, r);
        else
            worst[r.function].add(error / magnitude, r);
    }
    for (const auto& [function, w] : worst) {
        ASSERT_NE(w.at, nullptr);
        bool absolute = function.find("absolute") != std::string::npos;
        std::printf("%s %-28s %5zu values, worst error %.3g at n = %d, z = %.9g %+.9gi\n", precision, function.c_str(),
                    w.count, w.error, w.at->n, w.at->x, w.at->y);
        EXPECT_LE(w.error, absolute ? absoluteNearEiZero : relativeTolerance)
            << precision << " " << function << " at n = " << w.at->n << ", z = " << w.at->x << " + " << w.at->y << "i";
    }
}

TEST(ExpInt, ReferenceFileCoversEveryFunction) {
    std::map<std::string, size_t> counts;
    for (const Reference& r : references())
        counts[r.function] += 1;
    EXPECT_GT(counts["E1"], 1000u);
    EXPECT_GT(counts["Ei"], 300u);
    EXPECT_GT(counts["EnScaled"], 2500u);
}

TEST(ExpInt, DoubleMatchesMpmath) {
    expectAccurate<glm::dvec2>("double", 1e300, kDoubleTolerance, 2e-16);
}

TEST(ExpInt, FloatMatchesMpmath) {
    expectAccurate<glm::vec2>("float ", kFloatRange, kFloatTolerance, 1e-7);
}

// On the negative real axis the sign of the zero imaginary part picks the side of the cut; just off the axis the
// imaginary part is -pi above and +pi below, plus a part that vanishes with Im z.
TEST(ExpInt, E1TakesTheSideOfTheCut) {
    for (double x : {1e-6, 0.5, 3.0, 29.5, 31.0, 49.0, 51.0, 200.0}) {
        Complex above = toComplex(sh::expintE1(glm::dvec2(-x, 0.0)));
        Complex below = toComplex(sh::expintE1(glm::dvec2(-x, -0.0)));
        EXPECT_EQ(above.imag(), -kPi) << x;
        EXPECT_EQ(below.imag(), kPi) << x;
        EXPECT_EQ(above.real(), below.real()) << x;
        Complex aboveF = toComplex(sh::expintE1(glm::vec2(float(-x), 0.0f)));
        Complex belowF = toComplex(sh::expintE1(glm::vec2(float(-x), -0.0f)));
        EXPECT_FLOAT_EQ(float(aboveF.imag()), -float(kPi)) << x;
        EXPECT_FLOAT_EQ(float(belowF.imag()), float(kPi)) << x;
        for (double y : {1e-12, 1e-6}) {
            double offAxis = y * std::exp(x) / x;  // the size of the imaginary part that is not the branch term
            if (offAxis > 1.0) continue;
            EXPECT_NEAR(sh::expintE1(glm::dvec2(-x, y)).y, -kPi, 2.0 * offAxis + 1e-15) << x;
            EXPECT_NEAR(sh::expintE1(glm::dvec2(-x, -y)).y, kPi, 2.0 * offAxis + 1e-15) << x;
        }
    }
}

// mpmath's convention for Ei: real on the real axis (for x < 0 the mean of both sides), +-i pi off it.
TEST(ExpInt, EiIsRealOnTheRealAxis) {
    for (double x : {-40.0, -2.0, -1e-3, 1e-3, 2.0, 40.0, 60.0}) {
        EXPECT_EQ(sh::expintEi(glm::dvec2(x, 0.0)).y, 0.0) << x;
        EXPECT_EQ(sh::expintEi(glm::dvec2(x, -0.0)).y, 0.0) << x;
        EXPECT_EQ(sh::expintEi(glm::vec2(float(x), 0.0f)).y, 0.0f) << x;
    }
    EXPECT_NEAR(sh::expintEi(glm::dvec2(-2.0, 1e-9)).y, kPi, 1e-9);
    EXPECT_NEAR(sh::expintEi(glm::dvec2(-2.0, -1e-9)).y, -kPi, 1e-9);
}

// E1(conj z) = conj E1(z): every step of the evaluation is symmetric, so the values are exactly conjugate.
TEST(ExpInt, E1OfTheConjugateIsTheConjugate) {
    for (double logR = -6.0; logR <= 2.8; logR += 0.2) {
        for (double theta = 0.05; theta < kPi; theta += 0.1) {
            double r = std::pow(10.0, logR);
            glm::dvec2 z(r * std::cos(theta), r * std::sin(theta));
            glm::dvec2 a = sh::expintE1(z);
            glm::dvec2 b = sh::expintE1(glm::dvec2(z.x, -z.y));
            EXPECT_EQ(a.x, b.x) << z.x << " " << z.y;
            EXPECT_EQ(a.y, -b.y) << z.x << " " << z.y;
            glm::vec2 zf(z);
            glm::vec2 af = sh::expintE1(zf);
            glm::vec2 bf = sh::expintE1(glm::vec2(zf.x, -zf.y));
            EXPECT_EQ(af.x, bf.x) << z.x << " " << z.y;
            EXPECT_EQ(af.y, -bf.y) << z.x << " " << z.y;
        }
    }
}

// All orders at once: the rows that hold n = 1 .. 40 at one argument (Pegoraro's t = H (v - i) samples).
template <typename Vec2, typename Orders>
double worstOfAllOrders(size_t& points) {
    using Real = typename Vec2::value_type;
    std::map<std::pair<double, double>, std::map<int, Complex>> byArgument;
    for (const Reference& r : references())
        if (r.function == "EnScaled") byArgument[{r.x, r.y}][r.n] = r.value;
    double worst = 0.0;
    points = 0;
    for (const auto& [z, values] : byArgument) {
        if (values.size() != size_t(sh::kExpintMaxOrder)) continue;
        ++points;
        Orders orders;
        sh::expintEnScaledAll(sh::kExpintMaxOrder, Vec2(Real(z.first), Real(z.second)), orders);
        for (const auto& [n, value] : values) {
            double error = std::abs(toComplex(orders.value[n - 1]) - value) / std::abs(value);
            worst = std::max(worst, std::isnan(error) ? kInf : error);
        }
    }
    return worst;
}

TEST(ExpInt, AllOrdersMatchMpmath) {
    size_t points = 0;
    double worstDouble = worstOfAllOrders<glm::dvec2, sh::ExpintOrdersD>(points);
    EXPECT_GE(points, 40u);
    double worstFloat = worstOfAllOrders<glm::vec2, sh::ExpintOrders>(points);
    std::printf("expintEnScaledAll, n = 1 .. 40 at %zu arguments: worst relative error %.3g (double), %.3g (float)\n",
                points, worstDouble, worstFloat);
    EXPECT_LE(worstDouble, kDoubleTolerance);
    EXPECT_LE(worstFloat, kFloatTolerance);
}

// Fewer orders than the maximum fill exactly those, with the same values.
TEST(ExpInt, AllOrdersAgreeWithSingleOrders) {
    for (glm::dvec2 z : {glm::dvec2(0.3, -0.2), glm::dvec2(2.5, -1.0), glm::dvec2(7.0, -30.0), glm::dvec2(1e3, -5.0)}) {
        sh::ExpintOrdersD orders;
        sh::expintEnScaledAll(9, z, orders);
        for (int n = 1; n <= 9; ++n) {
            Complex single = toComplex(sh::expintEnScaled(n, z));
            EXPECT_LE(std::abs(toComplex(orders.value[n - 1]) - single), kDoubleTolerance * std::abs(single))
                << "n = " << n << ", z = " << z.x << " " << z.y;
        }
    }
}

TEST(ExpInt, SpecialValues) {
    EXPECT_EQ(sh::expintE1(glm::dvec2(0.0)).x, kInf);
    EXPECT_EQ(sh::expintEi(glm::dvec2(0.0)).x, -kInf);
    for (int n = 2; n <= 40; ++n) {
        EXPECT_EQ(sh::expintEnScaled(n, glm::dvec2(0.0)).x, 1.0 / double(n - 1));
        EXPECT_EQ(sh::expintEnScaled(n, glm::vec2(0.0f)).x, 1.0f / float(n - 1));
    }
    // Overflow to inf, not NaN, past the largest double / float; underflow to 0.
    for (glm::dvec2 z : {glm::dvec2(-720.0, 0.0), glm::dvec2(-2000.0, 0.0), glm::dvec2(-720.0, 5.0)}) {
        glm::dvec2 v = sh::expintE1(z);
        EXPECT_TRUE(std::isinf(v.x)) << z.x;
        EXPECT_FALSE(std::isnan(v.y)) << z.x;
    }
    EXPECT_TRUE(std::isinf(sh::expintE1(glm::vec2(-100.0f, 0.0f)).x));
    EXPECT_FALSE(std::isnan(sh::expintE1(glm::vec2(-100.0f, 0.0f)).y));
    EXPECT_TRUE(std::isfinite(sh::expintE1(glm::dvec2(-712.0, 0.0)).x));  // e^712 / 712 is still a double
    EXPECT_EQ(sh::expintE1(glm::dvec2(800.0, 0.0)).x, 0.0);
    // e^z E_n(z) stays finite for large |z|, where it is (1/z) (1 - n/z + n (n+1) / z^2) to O(n^3 / z^3) (A&S 5.1.51).
    for (int n : {1, 9, 40}) {
        glm::dvec2 z(5e5, -50.0);
        Complex w = 1.0 / Complex(z.x, z.y);
        Complex expected = w * (1.0 - double(n) * w + double(n * (n + 1)) * w * w);
        double truncation = double(n * (n + 1) * (n + 2)) * std::pow(std::abs(w), 3.0);
        EXPECT_LE(std::abs(toComplex(sh::expintEnScaled(n, z)) - expected), (truncation + 1e-15) * std::abs(expected));
        glm::vec2 zf(5e5f, -50.0f);
        EXPECT_LE(std::abs(toComplex(sh::expintEnScaled(n, zf)) - expected), 1e-6 * std::abs(expected));
    }
}

}  // namespace
}  // namespace tyndall
