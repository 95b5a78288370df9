// The complex functions of complex.h for one real type. No include guard: complex.h includes this file once per
// real type with
//   TY_R, TY_R2        the real type and the complex type (float, vec2 or double, dvec2);
//   TY_REAL_EXP, ...   the real exp, log, sin, cos, atan2 and sign bit of that type (the GLSL built-ins for float,
//                      double_math.h's for double),
// and undefines them at its end. Include complex.h, not this file.

TY_BEGIN

// The real functions, overloaded by type so that code written once for both types (expint_impl.h) can call them.
TY_FUNC TY_R realExp(TY_R x) {
    return TY_REAL_EXP(x);
}
TY_FUNC TY_R realLog(TY_R x) {
    return TY_REAL_LOG(x);
}
TY_FUNC TY_R realSin(TY_R x) {
    return TY_REAL_SIN(x);
}
TY_FUNC TY_R realCos(TY_R x) {
    return TY_REAL_COS(x);
}
TY_FUNC TY_R realAtan2(TY_R y, TY_R x) {
    return TY_REAL_ATAN2(y, x);
}
TY_FUNC bool realSignBit(TY_R x) {
    return TY_REAL_SIGN_BIT(x);
}

TY_FUNC TY_R2 cMul(TY_R2 a, TY_R2 b) {
    return TY_R2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

// 1 / b = conj(b) / |b|^2.
TY_FUNC TY_R2 cInv(TY_R2 b) {
    return TY_R2(b.x, -b.y) / dot(b, b);
}

TY_FUNC TY_R2 cDiv(TY_R2 a, TY_R2 b) {
    return cMul(a, cInv(b));
}

TY_FUNC TY_R cAbs(TY_R2 z) {
    return sqrt(dot(z, z));
}

TY_FUNC TY_R2 cExp(TY_R2 z) {
    return realExp(z.x) * TY_R2(realCos(z.y), realSin(z.y));
}

// Principal logarithm, arg in [-pi, pi]: on the negative real axis +pi for im = +0 and -pi for im = -0.
TY_FUNC TY_R2 cLog(TY_R2 z) {
    return TY_R2(realLog(cAbs(z)), realAtan2(z.y, z.x));
}

TY_END

#undef TY_R
#undef TY_R2
#undef TY_REAL_EXP
#undef TY_REAL_LOG
#undef TY_REAL_SIN
#undef TY_REAL_COS
#undef TY_REAL_ATAN2
#undef TY_REAL_SIGN_BIT
