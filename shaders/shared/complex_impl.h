// The complex functions of complex.h for one real type. No include guard: complex.h includes this file once per
// real type with TY_R the real type (float, double) and TY_R2 the matching complex type (vec2, dvec2). Include
// complex.h, not this file.

TY_BEGIN

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
