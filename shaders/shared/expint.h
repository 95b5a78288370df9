// The exponential integrals E1(z), Ei(z) and e^z E_n(z) for complex z, in float (vec2) and double (dvec2) from one
// source (expint_impl.h); Pegoraro's closed-form single scattering (issue #5) evaluates e^z E_n(z).
// Complex numbers are (re, im). Algorithms, regions, thresholds and measured accuracy: docs/expint.md.
//
//   vec2  expintE1(vec2 z)           E1(z) on the principal branch, cut along the negative real axis. On the cut the
//   dvec2 expintE1(dvec2 z)          sign of the zero imaginary part picks the side: im = +0 gives the value from
//                                    above, E1(-x + i0) = -Ei(x) - i pi; im = -0 the value from below, -Ei(x) + i pi
//                                    (on the GPU the sign of a zero need not survive: pass +-tiny to be sure).
//                                    E1(0) = +inf. Overflows to inf for Re z below about -716 (double) or -93 (float).
//   vec2  expintEi(vec2 z)           Ei(z) = -E1(-z) + i pi sign(Im z), as mpmath's ei: off the real axis the
//   dvec2 expintEi(dvec2 z)          analytic continuation with the cut along the negative real axis; on the real
//                                    axis (im = +-0) the real Ei(x), for x < 0 the mean of both sides, -E1(-x).
//   vec2  expintEnScaled(int n, vec2 z)     e^z E_n(z) for 1 <= n and Re z >= 0 (z != 0 for n = 1; e^0 E_n(0) =
//   dvec2 expintEnScaled(int n, dvec2 z)    1/(n-1) for n >= 2). Finite for all such z: no exp(-z) is formed for
//                                           large |z|.
//   void  expintEnScaledAll(int n, vec2 z, out ExpintOrders orders)    orders.value[j-1] = e^z E_j(z) for
//   void  expintEnScaledAll(int n, dvec2 z, out ExpintOrdersD orders)  j = 1 .. min(n, kExpintMaxOrder), Re z >= 0,
//                                           z != 0: one expintEnScaled at the pivot order and the recurrence below.
//   int   expintRecurrencePivot(int n, z)   ceil(|z|) within 1 .. n: the order from which the recurrence is stable
//   vec2  expintEnScaledUp(int j, z, g)     upwards, g_{j+1} = (1 - z g_j) / j, for j >= pivot, and
//   vec2  expintEnScaledDown(int j, z, g)   downwards, g_j = (1 - j g_{j+1}) / z, for j < pivot (g_j = e^z E_j(z);
//                                           also for dvec2). With these a caller can run over the orders without an
//                                           array, which lavapipe keeps in slow scratch memory.
//
// Accuracy against mpmath (tests/data/expint_reference.csv; docs/expint.md has the table and the regions): relative
// error at most 1.3e-15 in double and 3.8e-7 in float (where the value is within 1e-30 .. 1e30), except next to the
// real zero of Ei (x0 = 0.3725), where the error is absolute (3.5e-17, 1.6e-8). On a GPU the float functions inherit
// the device's exp, log and atan: lavapipe adds up to 5.5e-6. Arguments: |z| within 1e-150 .. 1e150 (double),
// 1e-18 .. 1e18 (float) and |Im z| <= 1e5 (double; dSin/dCos).
//
// Double precision is always there in C++; in GLSL only when TY_ENABLE_DOUBLE is defined before the include (the
// device needs shaderFloat64).
#ifndef TY_SHARED_EXPINT_H
#define TY_SHARED_EXPINT_H

#include "compat.h"
#include "complex.h"

TY_BEGIN

// The largest order expintEnScaledAll returns (Pegoraro's closed form uses up to about 33).
TY_CONST int kExpintMaxOrder = 40;

struct ExpintOrders {
    vec2 value[kExpintMaxOrder];  // e^z E_j(z) at value[j - 1]
};

#ifdef TY_HAS_DOUBLE
struct ExpintOrdersD {
    dvec2 value[kExpintMaxOrder];  // e^z E_j(z) at value[j - 1]
};
#endif

TY_END

// Float: tolerance 2^-24; the continued fraction where 32 steps suffice (|z| + Re z >= 1.93, and everywhere for
// n >= 9), the power series elsewhere; E1's asymptotic series from |z| = 30, where its branch term is exact to well
// below the tolerance. The depth constants are explained at expintCfDepth.
#define TY_R float
#define TY_R2 vec2
#define TY_EXPINT_ORDERS ExpintOrders
#define TY_EXPINT_GAMMA 0.5772156649f
#define TY_EXPINT_PI 3.1415926536f
#define TY_EXPINT_TOLERANCE 5.9604645e-8f
#define TY_EXPINT_DEPTH_A 6.2f
#define TY_EXPINT_DEPTH_B 1.1f
#define TY_EXPINT_DEPTH_P 15.5f
#define TY_EXPINT_DEPTH_Q 1.39f
#define TY_EXPINT_MAX_DEPTH 32
#define TY_EXPINT_ASYMPTOTIC 30.0f
#define TY_EXPINT_MAX_TERMS 200
#define TY_EXPINT_MAX_EXP 88.0f
#include "expint_impl.h"

// Double: tolerance 2^-53; the continued fraction where 128 steps suffice (|z| + Re z >= 1.88, and everywhere for
// n >= 14), the power series elsewhere; E1's asymptotic series from |z| = 50.
#ifdef TY_HAS_DOUBLE
#define TY_R double
#define TY_R2 dvec2
#define TY_EXPINT_ORDERS ExpintOrdersD
#define TY_EXPINT_GAMMA TY_DOUBLE_BITS(0x3FE2788Cu, 0xFC6FB619u)  // 0.5772156649015329
#define TY_EXPINT_PI TY_DOUBLE_BITS(0x400921FBu, 0x54442D18u)     // 3.141592653589793
#define TY_EXPINT_TOLERANCE TY_DOUBLE(1.1102230246251565e-16)
#define TY_EXPINT_DEPTH_A 13.0f
#define TY_EXPINT_DEPTH_B 1.8f
#define TY_EXPINT_DEPTH_P 29.7f
#define TY_EXPINT_DEPTH_Q 2.28f
#define TY_EXPINT_MAX_DEPTH 128
#define TY_EXPINT_ASYMPTOTIC TY_DOUBLE(50.0)
#define TY_EXPINT_MAX_TERMS 400
#define TY_EXPINT_MAX_EXP TY_DOUBLE(709.0)
#include "expint_impl.h"
#endif

#endif  // TY_SHARED_EXPINT_H
