// Complex arithmetic for shared GLSL/C++ code: a complex number is a vec2 (float) or dvec2 (double) holding
// (re, im). The functions are written once (complex_impl.h) and instantiated here for both real types; GLSL and C++
// pick the overload by argument type. Functions: cMul, cInv, cDiv, cAbs, cExp, cLog (principal branch), and the real
// realExp, realLog, realSin, realCos, realAtan2, realSignBit that resolve to the built-ins in float and to
// double_math.h in double.
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

// TY_HAS_DOUBLE: defined where the double versions exist (for headers built on this one, like expint.h).
#if defined(__cplusplus) || defined(TY_ENABLE_DOUBLE)
#define TY_HAS_DOUBLE 1
#include "double_math.h"
#endif

TY_BEGIN

// Float versions of what double_math.h provides for double, where the GLSL built-in does not do.
TY_FUNC bool floatSignBit(float x) {
    return (floatBitsToUint(x) >> 31) != 0u;
}

// GLSL leaves the sign of atan(+-0, x < 0) open; the negative real axis follows the sign bit of the zero, as in C.
TY_FUNC float floatAtan2(float y, float x) {
    if (y == 0.0f && x < 0.0f) return floatSignBit(y) ? -kPi : kPi;
    return atan(y, x);
}

TY_END

// complex_impl.h's parameters (it undefines them): the types and the real functions it builds on.
#define TY_R float
#define TY_R2 vec2
#define TY_REAL_EXP exp
#define TY_REAL_LOG log
#define TY_REAL_SIN sin
#define TY_REAL_COS cos
#define TY_REAL_ATAN2 floatAtan2
#define TY_REAL_SIGN_BIT floatSignBit
#include "complex_impl.h"

#ifdef TY_HAS_DOUBLE
#define TY_R double
#define TY_R2 dvec2
#define TY_REAL_EXP dExp
#define TY_REAL_LOG dLog
#define TY_REAL_SIN dSin
#define TY_REAL_COS dCos
#define TY_REAL_ATAN2 dAtan2
#define TY_REAL_SIGN_BIT dSignBit
#include "complex_impl.h"
#endif

#endif  // TY_SHARED_COMPLEX_H
