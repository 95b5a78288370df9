// Double-precision exp, log, sin, cos, atan2 and pow for GLSL (which has double arithmetic, sqrt, floor, abs and fma
// but none of these) and C++. Each is argument reduction plus a Taylor polynomial on the reduced interval, evaluated
// so that the large terms are exact and only the small correction carries rounding error.
// Accuracy against the C library (test/test_double_math.cpp): relative error below 2.8e-16, i.e. within 2 ulp, for
// exp, log, atan2, and sin and cos with |x| <= kDSinCosMaxArg; dPow within 2 (1 + |y ln x|) ulp. On the GPU this also
// assumes IEEE double division and fma (fma used once, in dAtan2), which the Vulkan precision tables do not require;
// the GPU-vs-CPU harness measures it.
//
// Double constants in shared code: GLSL needs the lf suffix for a double literal (an unsuffixed literal is a float,
// rounded to 24 bits) and C++ rejects it; glslang's ## only pastes identifiers and operators, so x##lf is not an
// option. Hence:
//  - TY_DOUBLE(x): only for literals exactly representable as a float (0.5, 710.0); GLSL converts them exactly.
//    Beware double(0.6f) with a literal that is not: glslang folds it to the decimal value (0.6 in double), C++ to the
//    float's value (0.6000000238...), so the two sides differ by ~1e-8. Write such constants as ratios (3.0 / 5.0).
//  - Rational constants (Taylor coefficients) are written as double(p) / double(q), folded at compile time and
//    correctly rounded on both sides.
//  - Irrational constants are written by their bits, TY_DOUBLE_BITS(high word, low word), with the decimal value in
//    a comment. GLSL does not fold packDouble2x32 in a constant expression, so these are locals inside functions.
#ifndef TY_SHARED_DOUBLE_MATH_H
#define TY_SHARED_DOUBLE_MATH_H

#include "compat.h"

#ifdef __cplusplus

#include <bit>

namespace tyndall::shader {
using glm::fma;  // std::fma (one rounding) with a C++11 library
using glm::packDouble2x32;
using glm::unpackDouble2x32;
}  // namespace tyndall::shader

#define TY_DOUBLE(x) (x)
#define TY_DOUBLE_BITS(hi, lo) std::bit_cast<double>((std::uint64_t(hi) << 32) | std::uint64_t(lo))

#else  // GLSL

#define TY_DOUBLE(x) double(x)
#define TY_DOUBLE_BITS(hi, lo) packDouble2x32(uvec2(lo, hi))

#endif

TY_BEGIN

// Taylor coefficients 1/n! for exp.
TY_CONST double kDExpC2 = double(1) / double(2);
TY_CONST double kDExpC3 = double(1) / double(6);
TY_CONST double kDExpC4 = double(1) / double(24);
TY_CONST double kDExpC5 = double(1) / double(120);
TY_CONST double kDExpC6 = double(1) / double(720);
TY_CONST double kDExpC7 = double(1) / double(5040);
TY_CONST double kDExpC8 = double(1) / double(40320);
TY_CONST double kDExpC9 = double(1) / double(362880);
TY_CONST double kDExpC10 = double(1) / double(3628800);
TY_CONST double kDExpC11 = double(1) / double(39916800);
TY_CONST double kDExpC12 = double(1) / double(479001600);
TY_CONST double kDExpC13 = double(1) / (double(479001600) * double(13));
TY_CONST double kDExpC14 = double(1) / (double(479001600) * double(13 * 14));

// Taylor coefficients (-1)^n / (2n+1)! for sin and (-1)^n / (2n)! for cos.
TY_CONST double kDSinC3 = double(-1) / double(6);
TY_CONST double kDSinC5 = double(1) / double(120);
TY_CONST double kDSinC7 = double(-1) / double(5040);
TY_CONST double kDSinC9 = double(1) / double(362880);
TY_CONST double kDSinC11 = double(-1) / double(39916800);
TY_CONST double kDSinC13 = double(1) / (double(479001600) * double(13));
TY_CONST double kDSinC15 = double(-1) / (double(479001600) * double(13 * 14 * 15));
TY_CONST double kDSinC17 = double(1) / (double(479001600) * double(13 * 14 * 15) * double(16 * 17));
TY_CONST double kDCosC4 = double(1) / double(24);
TY_CONST double kDCosC6 = double(-1) / double(720);
TY_CONST double kDCosC8 = double(1) / double(40320);
TY_CONST double kDCosC10 = double(-1) / double(3628800);
TY_CONST double kDCosC12 = double(1) / double(479001600);
TY_CONST double kDCosC14 = double(-1) / (double(479001600) * double(13 * 14));
TY_CONST double kDCosC16 = double(1) / (double(479001600) * double(13 * 14 * 15) * double(16));
TY_CONST double kDCosC18 = double(-1) / (double(479001600) * double(13 * 14 * 15) * double(16 * 17 * 18));

// sin and cos reduce exactly (k * kPio2Part1 and k * kPio2Part2 exact) while |k| < 2^20, i.e. |x| < 1.6e6; past that
// the result degrades gradually. Tested to 1e5.
TY_CONST double kDSinCosMaxArg = TY_DOUBLE(1.0e5);

// +inf and a quiet NaN, built at run time (GLSL has no literal for either).
TY_FUNC double dInfinity() { return packDouble2x32(uvec2(0u, 0x7FF00000u)); }
TY_FUNC double dNaN() { return packDouble2x32(uvec2(0u, 0x7FF80000u)); }

// True for negative numbers, -0 and NaNs with the sign bit set.
TY_FUNC bool dSignBit(double x) { return (unpackDouble2x32(x).y >> 31) != 0u; }

// 2^n for -1022 <= n <= 1023, by writing the exponent field.
TY_FUNC double dPow2(int n) { return packDouble2x32(uvec2(0u, uint(n + 1023) << 20)); }

// exp(x) = 2^k exp(r), k = round(x / ln 2), r = x - k ln 2 in [-ln2/2, ln2/2]. ln 2 is split Cody-Waite style
// (ln2Hi has 42 significant bits, so k * ln2Hi is exact for |k| < 2^11). exp(r) = 1 + r + r^2 sum_{n>=2} r^(n-2)/n!,
// truncated after r^14 (remainder below 2^-60 relative). 2^k is applied as two factors so that results in the
// subnormal range are rounded once and results past the largest double overflow to +inf.
TY_FUNC double dExp(double x) {
    if (isnan(x)) return x;
    if (x > TY_DOUBLE(710.0)) return dInfinity();
    if (x < TY_DOUBLE(-746.0)) return TY_DOUBLE(0.0);
    double invLn2 = TY_DOUBLE_BITS(0x3FF71547u, 0x652B82FEu);  // 1.4426950408889634
    double ln2Hi = TY_DOUBLE_BITS(0x3FE62E42u, 0xFEFA3800u);   // 0.6931471805598903
    double ln2Lo = TY_DOUBLE_BITS(0x3D2EF357u, 0x93C76730u);   // 5.497923018708371e-14
    double k = floor(x * invLn2 + TY_DOUBLE(0.5));
    double r = (x - k * ln2Hi) - k * ln2Lo;
    double p = kDExpC14;
    p = p * r + kDExpC13;
    p = p * r + kDExpC12;
    p = p * r + kDExpC11;
    p = p * r + kDExpC10;
    p = p * r + kDExpC9;
    p = p * r + kDExpC8;
    p = p * r + kDExpC7;
    p = p * r + kDExpC6;
    p = p * r + kDExpC5;
    p = p * r + kDExpC4;
    p = p * r + kDExpC3;
    p = p * r + kDExpC2;
    double expR = TY_DOUBLE(1.0) + (r + r * r * p);
    int n = int(k);
    int n1 = n >> 1;  // floor(n / 2): both factors stay within the normal exponent range
    return expR * dPow2(n1) * dPow2(n - n1);
}

// log(x) = e ln 2 + log(1 + f) with x = 2^e (1 + f), 1 + f in [sqrt(1/2), sqrt(2)). With s = f / (2 + f),
// log(1 + f) = 2 atanh(s) = 2s + s R, R = 2 s^2 (1/3 + s^2/5 + ...), and 2s = f - s f, so
// log(1 + f) = f - s (f - R): f is exact and only the correction s (f - R), at most 0.2 of the result, is rounded.
// |s| <= 0.172, so R up to s^20 leaves a remainder below 2^-60 relative.
TY_FUNC double dLog(double x) {
    if (isnan(x)) return x;
    if (x < TY_DOUBLE(0.0)) return dNaN();
    if (x == TY_DOUBLE(0.0)) return -dInfinity();
    if (isinf(x)) return x;
    double ln2Hi = TY_DOUBLE_BITS(0x3FE62E42u, 0xFEFA3800u);  // 0.6931471805598903
    double ln2Lo = TY_DOUBLE_BITS(0x3D2EF357u, 0x93C76730u);  // 5.497923018708371e-14
    double sqrt2 = TY_DOUBLE_BITS(0x3FF6A09Eu, 0x667F3BCDu);  // 1.4142135623730951
    int e = 0;
    if (x < dPow2(-1022)) {  // subnormal: scale into the normal range first
        x *= dPow2(54);
        e = -54;
    }
    uvec2 bits = unpackDouble2x32(x);
    e += int((bits.y >> 20) & 0x7FFu) - 1023;
    double m = packDouble2x32(uvec2(bits.x, (bits.y & 0x000FFFFFu) | 0x3FF00000u));  // in [1, 2)
    if (m > sqrt2) {
        m *= TY_DOUBLE(0.5);
        e += 1;
    }
    double f = m - TY_DOUBLE(1.0);  // exact (Sterbenz)
    double s = f / (TY_DOUBLE(2.0) + f);
    double z = s * s;
    double q = double(2) / double(21);
    q = q * z + double(2) / double(19);
    q = q * z + double(2) / double(17);
    q = q * z + double(2) / double(15);
    q = q * z + double(2) / double(13);
    q = q * z + double(2) / double(11);
    q = q * z + double(2) / double(9);
    q = q * z + double(2) / double(7);
    q = q * z + double(2) / double(5);
    q = q * z + double(2) / double(3);
    double R = z * q;
    double de = double(e);
    return de * ln2Hi + (f - (s * (f - R) - de * ln2Lo));
}

// sin r on |r| <= pi/4 (plus the reduction's slack): r + r^3 sum_n (-1)^n r^(2n-2) / (2n+1)!, through r^17.
TY_FUNC double dSinKernel(double r) {
    double z = r * r;
    double p = kDSinC17;
    p = p * z + kDSinC15;
    p = p * z + kDSinC13;
    p = p * z + kDSinC11;
    p = p * z + kDSinC9;
    p = p * z + kDSinC7;
    p = p * z + kDSinC5;
    p = p * z + kDSinC3;
    return r + r * z * p;
}

// cos r on |r| <= pi/4: 1 - r^2/2 + r^4 sum_n (-1)^n r^(2n-4) / (2n)!, through r^18. 1 - r^2/2 is summed with its
// rounding error recovered (Fast2Sum, |1| >= |r^2/2|), since r^2/2 reaches 0.31.
TY_FUNC double dCosKernel(double r) {
    double z = r * r;
    double p = kDCosC18;
    p = p * z + kDCosC16;
    p = p * z + kDCosC14;
    p = p * z + kDCosC12;
    p = p * z + kDCosC10;
    p = p * z + kDCosC8;
    p = p * z + kDCosC6;
    p = p * z + kDCosC4;
    double halfZ = TY_DOUBLE(0.5) * z;
    double head = TY_DOUBLE(1.0) - halfZ;
    double headError = (TY_DOUBLE(1.0) - head) - halfZ;
    return head + (headError + z * z * p);
}

// x = k pi/2 + r with k = round(2x / pi), |r| <= pi/4; returns r and k mod 4. pi/2 is split in three (Cody-Waite):
// two 33-bit parts, whose products with k are exact for |k| < 2^20, and the 53-bit rest.
TY_FUNC double dReduceHalfPi(double x, TY_OUT(int) quadrant) {
    double twoOverPi = TY_DOUBLE_BITS(0x3FE45F30u, 0x6DC9C883u);  // 0.6366197723675814
    double pio2Part1 = TY_DOUBLE_BITS(0x3FF921FBu, 0x54400000u);  // 1.5707963267341256
    double pio2Part2 = TY_DOUBLE_BITS(0x3DD0B461u, 0x1A600000u);  // 6.077100506303966e-11
    double pio2Part3 = TY_DOUBLE_BITS(0x3BA3198Au, 0x2E037073u);  // 2.0222662487959506e-21
    double k = floor(x * twoOverPi + TY_DOUBLE(0.5));
    quadrant = int(k - TY_DOUBLE(4.0) * floor(k * TY_DOUBLE(0.25)));  // k mod 4 without integer overflow
    double r = ((x - k * pio2Part1) - k * pio2Part2) - k * pio2Part3;
    // A no-op within the supported range; far past it keeps the kernels on a bounded (meaningless) argument.
    return clamp(r, TY_DOUBLE(-0.875), TY_DOUBLE(0.875));
}

// sin(k pi/2 + r) = sin r, cos r, -sin r, -cos r for k mod 4 = 0, 1, 2, 3.
// For |x| < 2^-26, x^3/6 is below half an ulp of x and sin x = x (which also keeps the sign of -0).
TY_FUNC double dSin(double x) {
    if (isnan(x) || isinf(x)) return dNaN();
    if (abs(x) < dPow2(-26)) return x;
    int quadrant;
    double r = dReduceHalfPi(x, quadrant);
    double v = (quadrant & 1) == 0 ? dSinKernel(r) : dCosKernel(r);
    return quadrant >= 2 ? -v : v;
}

// cos(k pi/2 + r) = cos r, -sin r, -cos r, sin r for k mod 4 = 0, 1, 2, 3.
TY_FUNC double dCos(double x) {
    if (isnan(x) || isinf(x)) return dNaN();
    int quadrant;
    double r = dReduceHalfPi(x, quadrant);
    double v = (quadrant & 1) == 0 ? dCosKernel(r) : dSinKernel(r);
    return (quadrant == 1 || quadrant == 2) ? -v : v;
}

// atan u on |u| <= tan(pi/8) = 0.414: u + u^3 sum_n (-1)^n u^(2n-2) / (2n+1), through u^41 (remainder below 2^-58
// relative).
TY_FUNC double dAtanKernel(double u) {
    double z = u * u;
    double p = double(1) / double(41);
    p = p * z + double(-1) / double(39);
    p = p * z + double(1) / double(37);
    p = p * z + double(-1) / double(35);
    p = p * z + double(1) / double(33);
    p = p * z + double(-1) / double(31);
    p = p * z + double(1) / double(29);
    p = p * z + double(-1) / double(27);
    p = p * z + double(1) / double(25);
    p = p * z + double(-1) / double(23);
    p = p * z + double(1) / double(21);
    p = p * z + double(-1) / double(19);
    p = p * z + double(1) / double(17);
    p = p * z + double(-1) / double(15);
    p = p * z + double(1) / double(13);
    p = p * z + double(-1) / double(11);
    p = p * z + double(1) / double(9);
    p = p * z + double(-1) / double(7);
    p = p * z + double(1) / double(5);
    p = p * z + double(-1) / double(3);
    return u + u * z * p;
}

// atan2(y, x). With t = min(|x|, |y|) / max(|x|, |y|) in [0, 1]: atan t directly for t <= tan(pi/8), else
// atan t = pi/4 + atan((t - 1) / (t + 1)). The first octant angle a = j pi/4 + atan(u) then maps to the quadrant by
// atan(1/t) = pi/2 - atan t and atan2(y, -x) = pi - atan2(y, x); the multiple of pi/4 is added as hi + lo last, so
// the result is rounded once on top of the error in atan(u). Signs of zero follow C's atan2.
TY_FUNC double dAtan2(double y, double x) {
    if (isnan(x) || isnan(y)) return x + y;
    double ax = abs(x);
    double ay = abs(y);
    bool swapped = ay > ax;
    double t;
    if (isinf(ax) && isinf(ay)) t = TY_DOUBLE(1.0);
    else if (ay == TY_DOUBLE(0.0)) t = TY_DOUBLE(0.0);
    else t = swapped ? ax / ay : ay / ax;
    double tanPiOver8 = TY_DOUBLE_BITS(0x3FDA8279u, 0x99FCEF32u);  // 0.41421356237309503
    int j = 0;  // a = j pi/4 + atan(u)
    double u = t;
    if (t > tanPiOver8) {
        j = 1;
        // Near t = tan(pi/8), atan(u) is about half the result, so u is computed to about 0.5 ulp: t - 1 and t + 1
        // with their rounding errors (Fast2Sum, |1| >= t), then one correction of the quotient with an exact fma
        // residual.
        double num = t - TY_DOUBLE(1.0);
        double numError = t - (num + TY_DOUBLE(1.0));
        double den = t + TY_DOUBLE(1.0);
        double denError = t - (den - TY_DOUBLE(1.0));
        u = num / den;
        u += (fma(-u, den, num) + (numError - u * denError)) / den;
    }
    double small = dAtanKernel(u);
    // result = n pi/4 + sign * (small), by quadrant.
    int n = j;
    if (swapped) {
        n = 2 - j;
        small = -small;
    }
    if (dSignBit(x)) {
        n = 4 - n;
        small = -small;
    }
    double hi = TY_DOUBLE(0.0);
    double lo = TY_DOUBLE(0.0);
    if (n == 1) {
        hi = TY_DOUBLE_BITS(0x3FE921FBu, 0x54442D18u);  // pi/4 = 0.7853981633974483
        lo = TY_DOUBLE_BITS(0x3C81A626u, 0x33145C07u);  //   + 3.061616997868383e-17
    } else if (n == 2) {
        hi = TY_DOUBLE_BITS(0x3FF921FBu, 0x54442D18u);  // pi/2 = 1.5707963267948966
        lo = TY_DOUBLE_BITS(0x3C91A626u, 0x33145C07u);  //   + 6.123233995736766e-17
    } else if (n == 3) {
        hi = TY_DOUBLE_BITS(0x4002D97Cu, 0x7F3321D2u);  // 3pi/4 = 2.356194490192345
        lo = TY_DOUBLE_BITS(0x3C9A7939u, 0x4C9E8A0Au);  //   + 9.184850993605148e-17
    } else if (n == 4) {
        hi = TY_DOUBLE_BITS(0x400921FBu, 0x54442D18u);  // pi = 3.141592653589793
        lo = TY_DOUBLE_BITS(0x3CA1A626u, 0x33145C07u);  //   + 1.2246467991473532e-16
    }
    double a = n == 0 ? small : hi + (lo + small);
    return dSignBit(y) ? -a : a;
}

// x^y = exp(y log x) for x > 0; for x < 0 and integer y, (-1)^y |x|^y. The rounding error of log x is multiplied by
// y log x, so the result is within 2 (1 + |y ln x|) ulp. pow(x, 0) = 1 and pow(1, y) = 1, also for NaN.
TY_FUNC double dPow(double x, double y) {
    if (y == TY_DOUBLE(0.0) || x == TY_DOUBLE(1.0)) return TY_DOUBLE(1.0);
    if (isnan(x) || isnan(y)) return x + y;
    if (x == TY_DOUBLE(0.0)) return y > TY_DOUBLE(0.0) ? TY_DOUBLE(0.0) : dInfinity();
    if (x > TY_DOUBLE(0.0)) return dExp(y * dLog(x));
    if (floor(y) != y) return dNaN();
    double magnitude = dExp(y * dLog(-x));
    bool odd = abs(y) < TY_DOUBLE(9007199254740992.0) && floor(y * TY_DOUBLE(0.5)) * TY_DOUBLE(2.0) != y;
    return odd ? -magnitude : magnitude;
}

TY_END

#endif  // TY_SHARED_DOUBLE_MATH_H
