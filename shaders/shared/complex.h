// Complex arithmetic for shared GLSL/C++ code: a complex number is a vec2 (float) or dvec2 (double) holding
// (re, im). The functions are written once (complex_impl.h) and instantiated here for both real types; GLSL and C++
// pick the overload by argument type.
//
// Double precision is always there in C++; in GLSL only when the includer defined TY_ENABLE_DOUBLE before including
// (the device needs shaderFloat64: any double function in a module makes glslang declare the Float64 capability).
//
// Range: cInv, cDiv and cAbs square their argument, so |z| must stay within 1e-150 .. 1e150 in double and 1e-18 ..
// 1e18 in float. cExp and cLog use the double_math.h functions in double (GLSL has no double exp, log, sin, cos);
// their argument limits apply (dSin/dCos accurate for |Im z| <= 1e5).
#ifndef TY_SHARED_COMPLEX_H
#define TY_SHARED_COMPLEX_H

#include "compat.h"
#include "constants.h"

#if defined(__cplusplus) || defined(TY_ENABLE_DOUBLE)
#define TY_HAS_DOUBLE 1
#include "double_math.h"
#endif

TY_BEGIN

// The real functions complex_impl.h needs, overloaded by type so that one source serves float and double.
TY_FUNC float realExp(float x) {
    return exp(x);
}
TY_FUNC float realLog(float x) {
    return log(x);
}
TY_FUNC float realSin(float x) {
    return sin(x);
}
TY_FUNC float realCos(float x) {
    return cos(x);
}
TY_FUNC bool realSignBit(float x) {
    return (floatBitsToUint(x) >> 31) != 0u;
}
// GLSL leaves the sign of atan(+-0, x < 0) open; the negative real axis follows the sign bit of the zero, as in C.
TY_FUNC float realAtan2(float y, float x) {
    if (y == 0.0f && x < 0.0f) return realSignBit(y) ? -kPi : kPi;
    return atan(y, x);
}

#ifdef TY_HAS_DOUBLE
TY_FUNC double realExp(double x) {
    return dExp(x);
}
TY_FUNC double realLog(double x) {
    return dLog(x);
}
TY_FUNC double realSin(double x) {
    return dSin(x);
}
TY_FUNC double realCos(double x) {
    return dCos(x);
}
TY_FUNC bool realSignBit(double x) {
    return dSignBit(x);
}
TY_FUNC double realAtan2(double y, double x) {
    return dAtan2(y, x);
}
#endif

TY_END

#define TY_R float
#define TY_R2 vec2
#include "complex_impl.h"
#undef TY_R
#undef TY_R2

#ifdef TY_HAS_DOUBLE
#define TY_R double
#define TY_R2 dvec2
#include "complex_impl.h"
#undef TY_R
#undef TY_R2
#endif

#endif  // TY_SHARED_COMPLEX_H
