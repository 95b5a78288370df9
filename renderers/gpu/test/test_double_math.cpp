// The double-precision exp/log/sin/cos/atan2/pow of shaders/shared/double_math.h, compiled as C++, against the C
// library. Errors are measured in ulps of the reference (which also covers subnormal results) and as relative error.
// The C library's own error (< 1 ulp in glibc) is part of what is measured, so the bounds allow 2 ulp and a relative
// error of 4e-16 (1.8 ulp at the bottom of a binade); measured: at most 2.8e-16 (atan2), 2.3e-16 for the others.
#include "shared/double_math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

namespace {

namespace sh = tyndall::shader;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxUlp = 2.0;           // see the file comment
constexpr double kMaxRelative = 4e-16;    // see the file comment

// |a - r| in units of the spacing of doubles at r (the gap above |r|; a subnormal gap for subnormal r).
double ulpError(double a, double r) {
    if (a == r) return 0.0;
    double gap = std::nextafter(std::abs(r), kInf) - std::abs(r);
    return std::abs(a - r) / gap;
}

struct ErrorStats {
    double maxUlp = 0.0;
    double maxRelative = 0.0;
    double worstArgument = 0.0;

    void add(double argument, double a, double r) {
        double ulp = ulpError(a, r);
        if (ulp > maxUlp) {
            maxUlp = ulp;
            worstArgument = argument;
        }
        if (r != 0.0 && std::abs(r) >= std::numeric_limits<double>::min())
            maxRelative = std::max(maxRelative, std::abs(a - r) / std::abs(r));
    }
};

// Prints the measured accuracy and checks it against the bounds.
void expectAccurate(const char* name, const ErrorStats& s, double maxUlp = kMaxUlp,
                    double maxRelative = kMaxRelative) {
    std::printf("%-28s max %.3f ulp, max relative %.3e (worst at %.17g)\n", name, s.maxUlp, s.maxRelative,
                s.worstArgument);
    EXPECT_LE(s.maxUlp, maxUlp) << name << ", worst at " << s.worstArgument;
    EXPECT_LE(s.maxRelative, maxRelative) << name;
}

double logUniform(std::mt19937_64& rng, double lo, double hi) {
    std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
    return std::exp(u(rng));
}

constexpr int kSamples = 200000;

}  // namespace

TEST(DoubleMath, ExpMatchesStd) {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> wide(-700.0, 700.0);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    ErrorStats s;
    for (int i = 0; i < kSamples; ++i) {
        double x = wide(rng);
        s.add(x, sh::dExp(x), std::exp(x));
        x = unit(rng);
        s.add(x, sh::dExp(x), std::exp(x));
        x = (i & 1 ? 1.0 : -1.0) * logUniform(rng, 1e-300, 1.0);
        s.add(x, sh::dExp(x), std::exp(x));
    }
    expectAccurate("dExp, |x| <= 700", s);
}

TEST(DoubleMath, ExpNearOverflowAndIntoSubnormals) {
    std::mt19937_64 rng(2);
    std::uniform_real_distribution<double> high(700.0, 709.78);
    std::uniform_real_distribution<double> low(-745.0, -700.0);
    ErrorStats s;
    for (int i = 0; i < kSamples / 4; ++i) {
        double x = high(rng);
        s.add(x, sh::dExp(x), std::exp(x));
        x = low(rng);
        s.add(x, sh::dExp(x), std::exp(x));
    }
    // Subnormal results have fewer significant bits: the ulp bound still holds, the relative one does not apply
    // (ErrorStats only tracks relative error for normal results).
    expectAccurate("dExp, 700 <= |x| <= 745", s);
}

TEST(DoubleMath, ExpSpecialValues) {
    EXPECT_EQ(sh::dExp(0.0), 1.0);
    EXPECT_EQ(sh::dExp(-0.0), 1.0);
    EXPECT_EQ(sh::dExp(710.0), kInf);
    EXPECT_EQ(sh::dExp(709.8), kInf);  // just past log(DBL_MAX) = 709.78
    EXPECT_EQ(sh::dExp(1e300), kInf);
    EXPECT_EQ(sh::dExp(kInf), kInf);
    EXPECT_EQ(sh::dExp(-746.0), 0.0);
    EXPECT_EQ(sh::dExp(-1e300), 0.0);
    EXPECT_EQ(sh::dExp(-kInf), 0.0);
    EXPECT_EQ(sh::dExp(-745.0), std::exp(-745.0));  // the smallest subnormal
    EXPECT_TRUE(std::isnan(sh::dExp(std::nan(""))));
    EXPECT_EQ(sh::dExp(709.78), std::exp(709.78));
}

TEST(DoubleMath, LogMatchesStd) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> nearOne(0.5, 2.0);
    ErrorStats s;
    for (int i = 0; i < kSamples; ++i) {
        double x = logUniform(rng, 1e-300, 1e300);
        s.add(x, sh::dLog(x), std::log(x));
        x = nearOne(rng);
        s.add(x, sh::dLog(x), std::log(x));
        x = 1.0 + (i & 1 ? 1.0 : -1.0) * logUniform(rng, 1e-16, 1e-2);
        s.add(x, sh::dLog(x), std::log(x));
    }
    expectAccurate("dLog, [1e-300, 1e300]", s);
}

TEST(DoubleMath, LogOfSubnormals) {
    std::mt19937_64 rng(4);
    ErrorStats s;
    for (int i = 0; i < kSamples / 4; ++i) {
        double x = logUniform(rng, 5e-324, 2.2e-308);
        s.add(x, sh::dLog(x), std::log(x));
    }
    expectAccurate("dLog, subnormal x", s);
}

TEST(DoubleMath, LogSpecialValues) {
    EXPECT_EQ(sh::dLog(1.0), 0.0);
    EXPECT_EQ(sh::dLog(0.0), -kInf);
    EXPECT_EQ(sh::dLog(-0.0), -kInf);
    EXPECT_EQ(sh::dLog(kInf), kInf);
    EXPECT_TRUE(std::isnan(sh::dLog(-1.0)));
    EXPECT_TRUE(std::isnan(sh::dLog(-kInf)));
    EXPECT_TRUE(std::isnan(sh::dLog(std::nan(""))));
    EXPECT_EQ(sh::dLog(std::numeric_limits<double>::max()), std::log(std::numeric_limits<double>::max()));
    EXPECT_NEAR(sh::dLog(std::numeric_limits<double>::denorm_min()), -744.44007192138126, 1e-12);
}

TEST(DoubleMath, SinCosMatchStd) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> wide(-1e4, 1e4);
    std::uniform_real_distribution<double> small(-4.0, 4.0);
    ErrorStats sinStats;
    ErrorStats cosStats;
    for (int i = 0; i < kSamples; ++i) {
        for (double x : {wide(rng), small(rng), (i & 1 ? 1.0 : -1.0) * logUniform(rng, 1e-300, 1e4)}) {
            sinStats.add(x, sh::dSin(x), std::sin(x));
            cosStats.add(x, sh::dCos(x), std::cos(x));
        }
    }
    expectAccurate("dSin, |x| <= 1e4", sinStats);
    expectAccurate("dCos, |x| <= 1e4", cosStats);
}

// Up to kDSinCosMaxArg = 1e5 the reduction is still exact; measured in ulps only, since near a zero of sin or cos
// the absolute error of the reduced argument (about 2^-106 k) becomes relatively larger.
TEST(DoubleMath, SinCosUpToTheirStatedLimit) {
    std::mt19937_64 rng(6);
    std::uniform_real_distribution<double> wide(-sh::kDSinCosMaxArg, sh::kDSinCosMaxArg);
    ErrorStats sinStats;
    ErrorStats cosStats;
    for (int i = 0; i < kSamples; ++i) {
        double x = wide(rng);
        sinStats.add(x, sh::dSin(x), std::sin(x));
        cosStats.add(x, sh::dCos(x), std::cos(x));
    }
    expectAccurate("dSin, |x| <= 1e5", sinStats);
    expectAccurate("dCos, |x| <= 1e5", cosStats);
}

// Arguments closest to multiples of pi/2, where the reduction cancels most: x = the double nearest k pi/2.
TEST(DoubleMath, SinCosNearMultiplesOfHalfPi) {
    ErrorStats sinStats;
    ErrorStats cosStats;
    for (int k = -6400; k <= 6400; ++k) {
        double x = double(k) * 1.5707963267948966;
        for (double y : {std::nextafter(x, -kInf), x, std::nextafter(x, kInf)}) {
            sinStats.add(y, sh::dSin(y), std::sin(y));
            cosStats.add(y, sh::dCos(y), std::cos(y));
        }
    }
    expectAccurate("dSin, near k pi/2", sinStats, kMaxUlp, 1.0);
    expectAccurate("dCos, near k pi/2", cosStats, kMaxUlp, 1.0);
}

TEST(DoubleMath, SinCosSpecialValues) {
    EXPECT_EQ(sh::dSin(0.0), 0.0);
    EXPECT_TRUE(std::signbit(sh::dSin(-0.0)));
    EXPECT_EQ(sh::dCos(0.0), 1.0);
    EXPECT_EQ(sh::dSin(1e-300), 1e-300);
    EXPECT_TRUE(std::signbit(sh::dSin(-1e-300)));
    EXPECT_TRUE(std::isnan(sh::dSin(kInf)));
    EXPECT_TRUE(std::isnan(sh::dCos(-kInf)));
    EXPECT_TRUE(std::isnan(sh::dSin(std::nan(""))));
    EXPECT_TRUE(std::isnan(sh::dCos(std::nan(""))));
    // Far past the stated limit the value is inaccurate but still a sine.
    EXPECT_LE(std::abs(sh::dSin(1e300)), 1.0);
    EXPECT_LE(std::abs(sh::dCos(-1e20)), 1.0);
}

TEST(DoubleMath, Atan2MatchesStdInAllQuadrants) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    ErrorStats s;
    for (int i = 0; i < kSamples; ++i) {
        double y = unit(rng);
        double x = unit(rng);
        s.add(y, sh::dAtan2(y, x), std::atan2(y, x));
        // Magnitudes far apart: angles near the axes.
        y = (i & 1 ? 1.0 : -1.0) * logUniform(rng, 1e-200, 1e200);
        x = (i & 2 ? 1.0 : -1.0) * logUniform(rng, 1e-200, 1e200);
        s.add(y, sh::dAtan2(y, x), std::atan2(y, x));
        // Near the octant boundaries t = tan(pi/8) and t = 1.
        double t = (i & 4 ? 0.41421356237309503 : 1.0) * (1.0 + 1e-3 * unit(rng));
        x = i & 8 ? 1.0 : -1.0;
        s.add(t, sh::dAtan2(t * x, x), std::atan2(t * x, x));
    }
    expectAccurate("dAtan2, all quadrants", s);
}

TEST(DoubleMath, Atan2SpecialValues) {
    const double pi = 3.141592653589793;
    const double values[] = {0.0, -0.0, 1.0, -1.0, 1e-310, -1e-310, 1e308, -1e308, kInf, -kInf};
    for (double y : values) {
        for (double x : values) {
            double a = sh::dAtan2(y, x);
            double r = std::atan2(y, x);
            EXPECT_EQ(a, r) << "atan2(" << y << ", " << x << ")";
            EXPECT_EQ(std::signbit(a), std::signbit(r)) << "atan2(" << y << ", " << x << ")";
        }
    }
    EXPECT_EQ(sh::dAtan2(0.0, -1.0), pi);
    EXPECT_EQ(sh::dAtan2(-0.0, -1.0), -pi);
    EXPECT_TRUE(std::isnan(sh::dAtan2(std::nan(""), 1.0)));
    EXPECT_TRUE(std::isnan(sh::dAtan2(1.0, std::nan(""))));
}

// pow inherits the rounding errors of log x and of the product y log x (each up to 1 ulp), amplified by |y ln x|;
// within 2 (1 + |y ln x|) ulp.
TEST(DoubleMath, PowMatchesStd) {
    std::mt19937_64 rng(8);
    std::uniform_real_distribution<double> exponent(-4.0, 4.0);
    double worst = 0.0;
    for (int i = 0; i < kSamples; ++i) {
        double x = logUniform(rng, 1e-30, 1e30);
        double y = exponent(rng);
        double r = std::pow(x, y);
        double bound = 2.0 * (1.0 + std::abs(y * std::log(x)));
        double e = ulpError(sh::dPow(x, y), r);
        worst = std::max(worst, e / bound);
        EXPECT_LE(e, bound) << "pow(" << x << ", " << y << ")";
        if (e > bound) break;
    }
    std::printf("%-28s max error / (2 (1 + |y ln x|)) ulp = %.3f\n", "dPow", worst);
}

TEST(DoubleMath, PowSpecialValues) {
    EXPECT_DOUBLE_EQ(sh::dPow(2.0, 10.0), 1024.0);
    EXPECT_DOUBLE_EQ(sh::dPow(-2.0, 3.0), -8.0);
    EXPECT_DOUBLE_EQ(sh::dPow(-2.0, 2.0), 4.0);
    EXPECT_TRUE(std::isnan(sh::dPow(-2.0, 0.5)));
    EXPECT_EQ(sh::dPow(0.0, 2.0), 0.0);
    EXPECT_EQ(sh::dPow(0.0, -2.0), kInf);
    EXPECT_EQ(sh::dPow(std::nan(""), 0.0), 1.0);
    EXPECT_EQ(sh::dPow(1.0, std::nan("")), 1.0);
    EXPECT_TRUE(std::isnan(sh::dPow(2.0, std::nan(""))));
    EXPECT_DOUBLE_EQ(sh::dPow(4.0, 0.5), 2.0);
}
