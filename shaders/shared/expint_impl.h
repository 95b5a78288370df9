// The exponential integrals of expint.h for one real type. No include guard: expint.h includes this file once per
// real type, with
//   TY_R, TY_R2                   the real type and the complex type (float, vec2 or double, dvec2);
//   TY_EXPINT_ORDERS              the name of the struct that holds e^z E_j(z) for j = 1 .. kExpintMaxOrder;
//   TY_EXPINT_GAMMA, TY_EXPINT_PI Euler's constant and pi in the real type (usable inside functions only);
//   TY_EXPINT_TOLERANCE           where the power and asymptotic series stop: the relative size of the next term;
//   TY_EXPINT_DEPTH_A, _B, _P, _Q the constants of the continued fraction's depth bound (expintCfDepth, in float);
//   TY_EXPINT_MAX_DEPTH           the deepest continued fraction used; where more is needed the power series is;
//   TY_EXPINT_ASYMPTOTIC          the radius beyond which E1 uses its asymptotic series near the negative axis;
//   TY_EXPINT_MAX_TERMS           an upper bound on the terms of the power and asymptotic series;
//   TY_EXPINT_MAX_EXP             an integer x with exp(x) finite, below the overflow threshold.
// It undefines them at its end. Include expint.h, not this file. docs/expint.md explains the regions and the
// thresholds.

TY_BEGIN

// E_n(z) by its power series, A&S 5.1.12 (5.1.11 for n = 1), with ln z supplied by the caller (Ei passes the
// logarithm of the other side of the cut):
//   E_n(z) = (-z)^(n-1) / (n-1)! (psi(n) - ln z) - sum_{k >= 0, k != n-1} (-z)^k / ((k - n + 1) k!),
//   psi(n) = -gamma + sum_{m=1}^{n-1} 1/m (A&S 6.3.2).
// The terms grow until k ~ |z| and then fall; the sum stops once k > |z| and the next term is below the tolerance
// relative to the value so far.
TY_FUNC TY_R2 expintEnSeriesLog(int n, TY_R2 z, TY_R2 logZ) {
    TY_R r = cAbs(z);
    TY_R tolerance2 = TY_EXPINT_TOLERANCE * TY_EXPINT_TOLERANCE;
    TY_R psi = -TY_EXPINT_GAMMA;
    TY_R2 term = TY_R2(TY_R(1.0f), TY_R(0.0f));  // (-z)^k / k!
    TY_R2 sum = TY_R2(TY_R(0.0f));               // over k != n - 1
    TY_R2 logPart = TY_R2(TY_R(0.0f));           // the k = n - 1 term
    for (int k = 0; k < TY_EXPINT_MAX_TERMS; ++k) {
        if (k == n - 1) {
            logPart = cMul(term, TY_R2(psi - logZ.x, -logZ.y));
        } else {
            sum += term / TY_R(k - n + 1);
            if (k < n - 1) psi += TY_R(1.0f) / TY_R(k + 1);
        }
        term = cMul(term, -z) / TY_R(k + 1);
        TY_R2 value = logPart - sum;
        if (k >= n - 1 && TY_R(k) > r && dot(term, term) <= tolerance2 * dot(value, value)) break;
    }
    return logPart - sum;
}

TY_FUNC TY_R2 expintEnSeries(int n, TY_R2 z) {
    return expintEnSeriesLog(n, z, cLog(z));
}

// The depth of the continued fraction below that reaches the tolerance: an upper bound on the depth needed, fitted
// to the depths measured in extended precision (docs/expint.md), with s = |z| + Re z = 2 (Re sqrt z)^2. For every n
// the error falls like exp(-sqrt(8 k s)) (Laguerre-type convergence), so sqrt(depth) ~ A / sqrt(s) + B; for n >= 2
// the fraction also converges at z = 0, within exp(P / (n - 1) + Q) steps whatever s. Computed in float for both
// types. Past TY_EXPINT_MAX_DEPTH the caller uses a series instead.
TY_FUNC int expintCfDepth(int n, TY_R s) {
    float root = TY_EXPINT_DEPTH_A / sqrt(max(float(s), 1.0e-30f)) + TY_EXPINT_DEPTH_B;
    float depth = root * root;
    if (n > 1) depth = min(depth, 1.1f * exp(TY_EXPINT_DEPTH_P / float(n - 1) + TY_EXPINT_DEPTH_Q));
    return int(min(depth, float(TY_EXPINT_MAX_DEPTH))) + 1;
}

// e^z E_n(z) by the even part of the continued fraction A&S 5.1.22 (DLMF 6.9.1 for n = 1; 8.9.2 with 8.19.1),
//   e^z E_n(z) = 1 / (z + n - 1 n / (z + n + 2 - 2 (n + 1) / (z + n + 4 - ...))),
// a_k = -k (n + k - 1), b_k = z + n + 2k, cut after `depth` steps and evaluated from the bottom up: one complex
// division a step and a rounding error of a few ulps whatever the depth (forward evaluation, Lentz's method, gathers
// one rounding error a step).
TY_FUNC TY_R2 expintEnScaledCf(int n, TY_R2 z, int depth) {
    TY_R2 f = z + TY_R2(TY_R(n + 2 * depth), TY_R(0.0f));
    for (int k = min(depth, TY_EXPINT_MAX_DEPTH + 1); k >= 1; --k) {
        f = z + TY_R2(TY_R(n + 2 * k - 2), TY_R(0.0f)) - (TY_R(k) * TY_R(n + k - 1)) * cInv(f);
    }
    return cInv(f);
}

// e^z E_1(z) by the asymptotic series A&S 5.1.51, (1/z) sum_k (-1)^k k! / z^k, summed until the terms stop falling
// (k ~ |z|) or fall below the tolerance. Only the part that dominates near the negative real axis: the caller adds
// the branch term.
TY_FUNC TY_R2 expintE1ScaledAsymptotic(TY_R2 z) {
    TY_R r = cAbs(z);
    TY_R tolerance2 = TY_EXPINT_TOLERANCE * TY_EXPINT_TOLERANCE;
    TY_R2 w = cInv(z);
    TY_R2 term = w;
    TY_R2 sum = w;
    for (int k = 1; k < TY_EXPINT_MAX_TERMS && TY_R(k) < r; ++k) {
        term = -TY_R(k) * cMul(term, w);
        sum += term;
        if (dot(term, term) <= tolerance2 * dot(sum, sum)) break;
    }
    return sum;
}

// e^(-z) g without overflowing early: e^(-Re z / 2) is applied twice, so the product is finite whenever the result
// is, and overflows to inf (not NaN: zero components stay zero) when it is not.
TY_FUNC TY_R2 expintTimesExpMinus(TY_R2 g, TY_R2 z) {
    TY_R scale = realExp(min(TY_R(-0.5f) * z.x, TY_R(TY_EXPINT_MAX_EXP)));
    TY_R2 rotated = cMul(g, TY_R2(realCos(z.y), -realSin(z.y)));
    return (rotated * scale) * scale;
}

// The branch term of E1 across the negative real axis: E1(-x +- i0) = -Ei(x) -+ i pi (A&S 5.1.7). Above the axis
// (im > 0 or +0) -i pi, below (im < 0 or -0) +i pi. On the axis the asymptotic series sums to the real -Ei(x); off it
// the true branch term switches on smoothly across the Stokes line (DLMF 8.20.3, 2.11(iii)), so the full step is off
// by at most pi there, relative to |E1| ~ e^(-Re z) / |z| at most pi |z| e^(Re z) < 1e-18 (double) and 1e-9 (float)
// where expintE1 uses it.
TY_FUNC TY_R2 expintE1BranchTerm(TY_R2 z) {
    TY_R pi = TY_EXPINT_PI;
    return TY_R2(TY_R(0.0f), realSignBit(z.y) ? pi : -pi);
}

// E1(z), principal branch; see expint.h.
TY_FUNC TY_R2 expintE1(TY_R2 z) {
    TY_R r = cAbs(z);
    int depth = expintCfDepth(1, r + z.x);
    if (depth <= TY_EXPINT_MAX_DEPTH) return expintTimesExpMinus(expintEnScaledCf(1, z, depth), z);
    if (r < TY_EXPINT_ASYMPTOTIC) return expintEnSeries(1, z);
    return expintTimesExpMinus(expintE1ScaledAsymptotic(z), z) + expintE1BranchTerm(z);
}

// Ei(z) = -E1(-z) + i pi sign(Im z): both are gamma + ln +- sum z^k / (k k!) (A&S 5.1.10, 5.1.11) and
// ln z - ln(-z) = i pi sign(Im z). On the real axis the real Ei; see expint.h.
// Each region evaluates the form without cancelling branch terms: the series is gamma + ln z + sum z^k / (k k!)
// directly, and near the positive real axis the two branch terms cancel exactly and are left out.
TY_FUNC TY_R2 expintEi(TY_R2 z) {
    TY_R pi = TY_EXPINT_PI;
    TY_R2 w = -z;
    TY_R r = cAbs(z);
    int depth = expintCfDepth(1, r + w.x);
    if (depth <= TY_EXPINT_MAX_DEPTH) {
        TY_R2 value = -expintTimesExpMinus(expintEnScaledCf(1, w, depth), w);
        if (z.y == TY_R(0.0f)) return TY_R2(value.x, TY_R(0.0f));
        return value + TY_R2(TY_R(0.0f), z.y > TY_R(0.0f) ? pi : -pi);
    }
    if (r < TY_EXPINT_ASYMPTOTIC) {
        TY_R2 logZ = cLog(z);
        if (z.y == TY_R(0.0f)) logZ.y = TY_R(0.0f);
        return -expintEnSeriesLog(1, w, logZ);
    }
    return -expintTimesExpMinus(expintE1ScaledAsymptotic(w), w);
}

// e^z E_n(z) for n >= 1, Re z >= 0; see expint.h.
TY_FUNC TY_R2 expintEnScaled(int n, TY_R2 z) {
    TY_R r = cAbs(z);
    int depth = expintCfDepth(n, r + z.x);
    if (depth <= TY_EXPINT_MAX_DEPTH) return expintEnScaledCf(n, z, depth);
    if (r == TY_R(0.0f) && n > 1) return TY_R2(TY_R(1.0f) / TY_R(n - 1), TY_R(0.0f));
    return cMul(cExp(z), expintEnSeries(n, z));
}

// The three-term recurrence n E_{n+1}(z) = e^(-z) - z E_n(z) (A&S 5.1.14), for g_n = e^z E_n(z):
//   upwards   g_{j+1} = (1 - z g_j) / j,        which multiplies an error in g_j by |z| / j,
//   downwards g_j = (1 - j g_{j+1}) / z,        which multiplies an error in g_{j+1} by j / |z|.
// So upwards is stable for j >= |z| and downwards for j < |z|. expintRecurrencePivot is the order ceil(|z|) (within
// 1 .. n) from which both directions are stable: evaluate it with expintEnScaled and step away from it.
TY_FUNC int expintRecurrencePivot(int n, TY_R2 z) {
    return max(int(min(ceil(cAbs(z)), TY_R(n))), 1);
}

TY_FUNC TY_R2 expintEnScaledUp(int j, TY_R2 z, TY_R2 g) {
    return (TY_R2(TY_R(1.0f), TY_R(0.0f)) - cMul(z, g)) / TY_R(j);
}

TY_FUNC TY_R2 expintEnScaledDown(int j, TY_R2 z, TY_R2 gNext) {
    return cDiv(TY_R2(TY_R(1.0f), TY_R(0.0f)) - TY_R(j) * gNext, z);
}

// e^z E_j(z) for j = 1 .. n; see expint.h.
TY_FUNC void expintEnScaledAll(int n, TY_R2 z, TY_OUT(TY_EXPINT_ORDERS) orders) {
    n = min(n, kExpintMaxOrder);
    int pivot = expintRecurrencePivot(n, z);
    orders.value[pivot - 1] = expintEnScaled(pivot, z);
    for (int j = pivot - 1; j >= 1; --j)
        orders.value[j - 1] = expintEnScaledDown(j, z, orders.value[j]);
    for (int j = pivot; j < n; ++j)
        orders.value[j] = expintEnScaledUp(j, z, orders.value[j - 1]);
}

TY_END

#undef TY_R
#undef TY_R2
#undef TY_EXPINT_ORDERS
#undef TY_EXPINT_GAMMA
#undef TY_EXPINT_PI
#undef TY_EXPINT_TOLERANCE
#undef TY_EXPINT_DEPTH_A
#undef TY_EXPINT_DEPTH_B
#undef TY_EXPINT_DEPTH_P
#undef TY_EXPINT_DEPTH_Q
#undef TY_EXPINT_MAX_DEPTH
#undef TY_EXPINT_ASYMPTOTIC
#undef TY_EXPINT_MAX_TERMS
#undef TY_EXPINT_MAX_EXP
