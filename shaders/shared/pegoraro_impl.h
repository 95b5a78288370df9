// The closed form of pegoraro.h for one precision. No include guard: pegoraro.h includes this file once per
// precision, with TY_R (float or double), TY_R2 (vec2 or dvec2, a complex number re + i im) and TY_R_EPSILON (the
// unit roundoff) defined. Structs get a precision suffix (PegoraroSeries_float,
// PegoraroSeries_double); functions overload.
// Derivations: docs/pegoraro.md.

#undef TY_RS
#define TY_RS(name) TY_RS_PASTE(name, TY_R)
#ifndef TY_RS_PASTE
#define TY_RS_PASTE(name, real) TY_RS_PASTE2(name, real)
#define TY_RS_PASTE2(name, real) name##_##real
#endif

TY_BEGIN

// A polynomial in a cosine, sum_k c[k] x^k, k < terms: a phase function Phi_c (Eq. 9) or a light distribution I_c
// (Eq. 10).
struct TY_RS(PegoraroPolynomial) {
    int terms;
    TY_R c[kPegoraroMaxTerms];
};

// Phi_c(mu(v)) I_c(s(v)) / (v^2 + 1) as partial fractions at the poles v = +-i (docs/pegoraro.md, Sec. 3):
//   sum_{j=1}^{N} b_j / (v - i)^j + conj(b_j) / (v + i)^j.
// bAbs[j] bounds the magnitudes that rounding acts on while b[j] is computed: the same sums with every term replaced
// by its absolute value. It drives the error bound of pegoraroIntegral.
struct TY_RS(PegoraroSeries) {
    int terms;  // N = N_phi + N_I - 1; 0 when that exceeds kPegoraroMaxTerms
    TY_R2 b[kPegoraroMaxTerms];
    TY_R bAbs[kPegoraroMaxTerms];
};

TY_FUNC TY_R pegoraroHorner(TY_IN(TY_RS(PegoraroPolynomial)) p, TY_R x) {
    TY_R sum = TY_R(0.0f);
    for (int k = p.terms - 1; k >= 0; --k)
        sum = sum * x + p.c[k];
    return sum;
}

// v = u + sqrt(1 + u^2) (Eq. 7), without cancellation for u < 0.
TY_FUNC TY_R pegoraroV(TY_R u) {
    TY_R r = sqrt(TY_R(1.0f) + u * u);
    return u >= TY_R(0.0f) ? u + r : TY_R(1.0f) / (r - u);
}

// Eq. 17-21: the product Phi_c(mu) I_c(s) with mu = (1 - v^2) / (1 + v^2) and s = (del (v^2 - 1) + 2 dc v) / (1 + v^2)
// is P(v) / (1 + v^2)^(N-1) with P = A(v) L(v),
//   A(v) = sum_m cPhi(m) (1 - v^2)^m (1 + v^2)^(N_phi-1-m),  L(v) = sum_n cI(n) (del (v^2-1) + 2 dc v)^n (1 +
//   v^2)^(N_I-1-n).
// The paper expands these by the binomial theorem into d(n, k); here homogeneous Horner schemes build the same
// coefficients in O(N^2). The partial fractions of P(v) / (1 + v^2)^N at v = i (z = v - i) are
//   b_j = [z^(N-j)] P(z + i) (z + 2i)^(-N),
// a Taylor shift of P by i followed by a truncated product with the binomial series of (z + 2i)^(-N).
// pegoraroSeriesScaled computes the same with the phase coefficients multiplied by phaseScale, the light's by
// lightScale and the binomial series by sigmaScale: b_j times their product (see pegoraroSeriesRefine).
TY_FUNC void pegoraroSeriesScaled(TY_R del, TY_R dc, TY_IN(TY_RS(PegoraroPolynomial)) phase,
                                  TY_IN(TY_RS(PegoraroPolynomial)) light, TY_R phaseScale, TY_R lightScale,
                                  TY_R sigmaScale, TY_OUT(TY_RS(PegoraroSeries)) s) {
    int nPhi = phase.terms;
    int nI = light.terms;
    int N = nPhi + nI - 1;
    s.terms = 0;
    if (nPhi < 1 || nI < 1 || N > kPegoraroMaxTerms) return;
    s.terms = N;

    TY_R zero = TY_R(0.0f);
    TY_R one = TY_R(1.0f);
    if (kPegoraroMaxTerms == 1) {
        // A shader variant for isotropic phase and light (N = 1): P = cPhi_0 cI_0 and b_1 = P (2i)^(-1), what the
        // general path below gives. Its loops would each run once on lavapipe, which does not skip a loop of no trip.
        TY_R p = phaseScale * phase.c[0] * lightScale * light.c[0] * sigmaScale;
        s.b[0] = TY_R2(zero, -TY_R(0.5f) * p);
        s.bAbs[0] = TY_R(0.5f) * abs(p);
        return;
    }
    TY_R a[kPegoraroMaxDegree + 1];
    TY_R aAbs[kPegoraroMaxDegree + 1];
    TY_R y[kPegoraroMaxDegree + 1];  // (1 + v^2)^k
    TY_R l[kPegoraroMaxDegree + 1];
    TY_R lAbs[kPegoraroMaxDegree + 1];
    for (int k = 0; k <= kPegoraroMaxDegree; ++k) {
        a[k] = zero;
        aAbs[k] = zero;
        y[k] = zero;
        l[k] = zero;
        lAbs[k] = zero;
    }

    // A: start from the top coefficient; each step multiplies by x = 1 - v^2 and adds c_m (1 + v^2)^(N_phi-1-m).
    a[0] = phaseScale * phase.c[nPhi - 1];
    aAbs[0] = abs(a[0]);
    y[0] = one;
    for (int m = nPhi - 2; m >= 0; --m) {
        int degree = 2 * (nPhi - 2 - m);  // degree of a and y before this step
        for (int k = degree + 2; k >= 2; --k) {
            a[k] = -a[k - 2] + (k <= degree ? a[k] : zero);
            aAbs[k] = aAbs[k - 2] + (k <= degree ? aAbs[k] : zero);
            y[k] = y[k - 2] + (k <= degree ? y[k] : zero);
        }
        TY_R cm = phaseScale * phase.c[m];
        for (int k = 0; k <= degree + 2; ++k) {
            a[k] += cm * y[k];
            aAbs[k] += abs(cm) * y[k];
        }
    }
    int degreeA = 2 * (nPhi - 1);

    // L: the same with x = del v^2 + 2 dc v - del.
    for (int k = 0; k <= kPegoraroMaxDegree; ++k)
        y[k] = zero;
    l[0] = lightScale * light.c[nI - 1];
    lAbs[0] = abs(l[0]);
    y[0] = one;
    TY_R x0 = -del, x1 = TY_R(2.0f) * dc, x2 = del;
    for (int n = nI - 2; n >= 0; --n) {
        int degree = 2 * (nI - 2 - n);
        for (int k = degree + 2; k >= 0; --k) {
            TY_R lk = k <= degree ? l[k] : zero;
            TY_R lk1 = k >= 1 && k - 1 <= degree ? l[k - 1] : zero;
            TY_R lk2 = k >= 2 ? l[k - 2] : zero;
            TY_R ak = k <= degree ? lAbs[k] : zero;
            TY_R ak1 = k >= 1 && k - 1 <= degree ? lAbs[k - 1] : zero;
            TY_R ak2 = k >= 2 ? lAbs[k - 2] : zero;
            l[k] = x0 * lk + x1 * lk1 + x2 * lk2;
            lAbs[k] = abs(x0) * ak + abs(x1) * ak1 + abs(x2) * ak2;
            if (k >= 2) y[k] = y[k - 2] + (k <= degree ? y[k] : zero);
        }
        TY_R cn = lightScale * light.c[n];
        for (int k = 0; k <= degree + 2; ++k) {
            l[k] += cn * y[k];
            lAbs[k] += abs(cn) * y[k];
        }
    }
    int degreeL = 2 * (nI - 1);

    // P = A L, then its Taylor shift P(z + i) by repeated synthetic division: after pass k, q[k] is final. Only the
    // coefficients of z^0 .. z^(N-1) are needed.
    int degreeP = degreeA + degreeL;
    TY_R2 q[kPegoraroMaxDegree + 1];
    TY_R qAbs[kPegoraroMaxDegree + 1];
    for (int k = 0; k <= degreeP; ++k) {
        TY_R sum = zero, sumAbs = zero;
        for (int i = max(0, k - degreeL); i <= min(k, degreeA); ++i) {
            sum += a[i] * l[k - i];
            sumAbs += aAbs[i] * lAbs[k - i];
        }
        q[k] = TY_R2(sum, zero);
        qAbs[k] = sumAbs;
    }
    for (int k = 0; k < N; ++k) {
        for (int r = degreeP - 1; r >= k; --r) {
            q[r] += TY_R2(-q[r + 1].y, q[r + 1].x);  // i * q[r + 1]
            qAbs[r] += qAbs[r + 1];
        }
    }

    // (z + 2i)^(-N) = sum_p sigma_p z^p: sigma_0 = (2i)^(-N) = 2^(-N) (-i)^N, sigma_(p+1) = sigma_p (N + p) / (p + 1) i
    // / 2.
    TY_R2 sigma[kPegoraroMaxTerms];
    TY_R scale = sigmaScale;
    for (int k = 0; k < N; ++k)
        scale *= TY_R(0.5f);
    int phase4 = N - 4 * (N / 4);
    sigma[0] = phase4 == 0
                   ? TY_R2(scale, zero)
                   : (phase4 == 1 ? TY_R2(zero, -scale) : (phase4 == 2 ? TY_R2(-scale, zero) : TY_R2(zero, scale)));
    for (int p = 0; p + 1 < N; ++p) {
        TY_R f = TY_R(0.5f) * TY_R(N + p) / TY_R(p + 1);
        sigma[p + 1] = TY_R2(-sigma[p].y * f, sigma[p].x * f);
    }
    for (int j = 1; j <= N; ++j) {
        TY_R2 sum = TY_R2(zero, zero);
        TY_R sumAbs = zero;
        for (int k = 0; k <= N - j; ++k) {
            TY_R2 sg = sigma[N - j - k];
            sum += cMul(q[k], sg);
            sumAbs += qAbs[k] * (abs(sg.x) + abs(sg.y));
        }
        s.b[j - 1] = sum;
        s.bAbs[j - 1] = sumAbs;
    }
    for (int j = N; j < kPegoraroMaxTerms; ++j) {
        s.b[j] = TY_R2(zero, zero);
        s.bAbs[j] = zero;
    }
}

TY_FUNC void pegoraroSeries(TY_R del, TY_R dc, TY_IN(TY_RS(PegoraroPolynomial)) phase,
                            TY_IN(TY_RS(PegoraroPolynomial)) light, TY_OUT(TY_RS(PegoraroSeries)) s) {
    pegoraroSeriesScaled(del, dc, phase, light, TY_R(1.0f), TY_R(1.0f), TY_R(1.0f), s);
}

// A second opinion on the rounding error of the b_j (docs/pegoraro.md, Sec. 4), for where the a priori bound of
// pegoraroSeries (bAbs: every term's magnitude, as if every rounding added up) is too pessimistic to use the closed
// form. The series is computed again with the phase coefficients scaled by 3, the light's by 5 and the binomial series
// by 3: in exact arithmetic 45 times the same b_j, but every rounding on the way falls differently (the scales are not
// powers of two), so |b_j - b'_j / 45| measures the rounding error of b_j itself. bAbs_j becomes
// kPegoraroRefineWeight times that, plus kPegoraroRefineFloor units of roundoff of |b_j|, in units of roundoff, the
// quantity pegoraroIntegral's bound weighs with kPegoraroCoefficientWeight.
TY_FUNC void pegoraroSeriesRefine(TY_R del, TY_R dc, TY_IN(TY_RS(PegoraroPolynomial)) phase,
                                  TY_IN(TY_RS(PegoraroPolynomial)) light, TY_INOUT(TY_RS(PegoraroSeries)) s) {
    TY_RS(PegoraroSeries) second;
    pegoraroSeriesScaled(del, dc, phase, light, TY_R(3.0f), TY_R(5.0f), TY_R(3.0f), second);
    TY_R unscale = TY_R(1.0f) / TY_R(45.0f);
    for (int j = 0; j < s.terms; ++j) {
        TY_R2 difference = s.b[j] - second.b[j] * unscale;
        s.bAbs[j] = (TY_R(kPegoraroRefineWeight) * cAbs(difference) +
                     TY_R(kPegoraroRefineFloor) * TY_R(TY_R_EPSILON) * cAbs(s.b[j])) /
                    TY_R(TY_R_EPSILON);
    }
}

// One term b_j z^(1-j) G_j of pegoraroEnd's sum, with its magnitudes.
TY_FUNC void pegoraroAccumulate(TY_IN(TY_R2) b, TY_R bAbs, TY_IN(TY_R2) power, TY_R powerAbs, TY_IN(TY_R2) g,
                                TY_INOUT(TY_R) sum, TY_INOUT(TY_R) sumAbs, TY_INOUT(TY_R) coefficientAbs) {
    TY_R gAbs = powerAbs * cAbs(g);
    sum += cMul(cMul(b, power), g).x;
    sumAbs += cAbs(b) * gAbs;
    coefficientAbs += bAbs * gAbs;
}

// The antiderivative at one end v, without its factor e^(-H v): Re sum_j b_j z^(1-j) G_j(H z), z = v - i. Its
// rounding error has two parts: the sum itself cancels, so its error scales with sumAbs = sum_j |b_j| |z|^(1-j) |G_j|;
// and each b_j carries the rounding of the sums that made it, which scales with coefficientAbs =
// sum_j bAbs_j |z|^(1-j) |G_j|.
TY_FUNC TY_R pegoraroEnd(TY_IN(TY_RS(PegoraroSeries)) s, TY_R H, TY_R v, TY_OUT(TY_R) sumAbs,
                         TY_OUT(TY_R) coefficientAbs) {
    TY_R2 z = TY_R2(v, TY_R(-1.0f));
    TY_R2 zInverse = TY_R2(v, TY_R(1.0f)) / (v * v + TY_R(1.0f));
    // G_j = e^t E_j(t), t = H z, for j = 1 .. N: one direct evaluation at the pivot order ~|t| and the recurrence in
    // its stable direction on each side (expint.h), streamed without an array (arrays live in slow memory on lavapipe).
    TY_R2 t = H * z;
    if (kPegoraroMaxTerms == 1) {  // the N = 1 variant (see pegoraroSeries): G_1 alone, the pivot and no recurrence
        TY_R sum = TY_R(0.0f);
        sumAbs = TY_R(0.0f);
        coefficientAbs = TY_R(0.0f);
        pegoraroAccumulate(s.b[0], s.bAbs[0], TY_R2(TY_R(1.0f), TY_R(0.0f)), TY_R(1.0f), expintEnScaled(1, t), sum,
                           sumAbs, coefficientAbs);
        return sum;
    }
    TY_R zInverseAbs = TY_R(1.0f) / sqrt(v * v + TY_R(1.0f));
    TY_R zAbs = TY_R(1.0f) / zInverseAbs;
    int pivot = expintRecurrencePivot(s.terms, t);
    TY_R2 gPivot = expintEnScaled(pivot, t);
    TY_R2 powerPivot = TY_R2(TY_R(1.0f), TY_R(0.0f));  // z^(1 - pivot)
    TY_R powerAbsPivot = TY_R(1.0f);
    for (int k = 1; k < pivot; ++k) {
        powerPivot = cMul(powerPivot, zInverse);
        powerAbsPivot *= zInverseAbs;
    }
    TY_R sum = TY_R(0.0f);
    sumAbs = TY_R(0.0f);
    coefficientAbs = TY_R(0.0f);
    TY_R2 g = gPivot, power = powerPivot;
    TY_R powerAbs = powerAbsPivot;
    for (int j = pivot; j >= 1; --j) {
        if (j < pivot) {
            g = expintEnScaledDown(j, t, g);
            power = cMul(power, z);
            powerAbs *= zAbs;
        }
        pegoraroAccumulate(s.b[j - 1], s.bAbs[j - 1], power, powerAbs, g, sum, sumAbs, coefficientAbs);
    }
    g = gPivot;
    power = powerPivot;
    powerAbs = powerAbsPivot;
    for (int j = pivot + 1; j <= s.terms; ++j) {
        g = expintEnScaledUp(j - 1, t, g);
        power = cMul(power, zInverse);
        powerAbs *= zInverseAbs;
        pegoraroAccumulate(s.b[j - 1], s.bAbs[j - 1], power, powerAbs, g, sum, sumAbs, coefficientAbs);
    }
    return sum;
}

// Eq. 22 with Eq. 29-30: I = int_{ua}^{ub} e^(-H (u + sqrt(1 + u^2) - ua)) Phi_c I_c du / (1 + u^2)
//                          = 2 e^(H ua) int_{va}^{vb} e^(-H v) P(v) / (v^2 + 1)^N dv,
// and the antiderivative of e^(-H v) / (v - i)^j is -e^(-H v) (v - i)^(1-j) G_j(H (v - i)). The prefactor e^(H ua)
// is folded into each end, e^(H (ua - v)) <= e^(-H sqrt(1 + ua^2)) <= 1, so nothing overflows. ub >= kInfinity means
// the ray never ends. errorBound bounds the rounding error of the result (absolute), from the magnitudes of the sums.
// With farEnd = false the end at ub is left out, as for ub >= kInfinity: pegoraroIntegralToInfinity passes a constant
// false, so that its caller has no code for that end (lavapipe would run it for every evaluation, taken or not).
TY_FUNC TY_R pegoraroIntegralEnds(TY_IN(TY_RS(PegoraroSeries)) s, TY_R H, TY_R ua, TY_R ub, bool farEnd,
                                  TY_OUT(TY_R) errorBound) {
    TY_R zero = TY_R(0.0f);
    errorBound = zero;
    if (s.terms < 1 || !(ub > ua)) return zero;
    // Below this exponent e^x underflows to zero in this precision.
    TY_R smallestExponent = TY_R_EPSILON < 1.0e-10f ? TY_R(-740.0f) : TY_R(-104.0f);
    TY_R result = zero, sumAbs = zero, coefficientAbs = zero;
    TY_R exponentA = -H * sqrt(TY_R(1.0f) + ua * ua);  // H (ua - va)
    if (exponentA > smallestExponent) {
        TY_R m1, m2;
        TY_R e = realExp(exponentA);
        result += e * pegoraroEnd(s, H, pegoraroV(ua), m1, m2);
        sumAbs += e * m1 * (TY_R(kPegoraroExpintUlps) + abs(exponentA));
        coefficientAbs += e * m2;
    }
    if (farEnd && ub < TY_R(kInfinity)) {
        TY_R exponentB = H * (ua - ub) - H * sqrt(TY_R(1.0f) + ub * ub);  // H (ua - vb)
        if (exponentB > smallestExponent) {
            TY_R m1, m2;
            TY_R e = realExp(exponentB);
            result -= e * pegoraroEnd(s, H, pegoraroV(ub), m1, m2);
            sumAbs += e * m1 * (TY_R(kPegoraroExpintUlps) + abs(exponentB));
            coefficientAbs += e * m2;
        }
    }
    // F(v) = -2 Re sum ..., so I = 2 (F(vb) e^(...) - F(va) e^(...)) = 4 (end(va) e^(...) - end(vb) e^(...)).
    // The error estimate (docs/pegoraro.md, "Error estimate"): each end's sum carries the relative error of the
    // exponential integrals (kPegoraroExpintUlps units of roundoff) and of its exponential (|exponent| units), scaled
    // by the magnitude it cancels from; the coefficients b_j carry kPegoraroCoefficientWeight units per unit of the
    // magnitudes that made them.
    errorBound = TY_R(4.0f) * TY_R(TY_R_EPSILON) * (sumAbs + TY_R(kPegoraroCoefficientWeight) * coefficientAbs);
    return TY_R(4.0f) * result;
}

TY_FUNC TY_R pegoraroIntegral(TY_IN(TY_RS(PegoraroSeries)) s, TY_R H, TY_R ua, TY_R ub, TY_OUT(TY_R) errorBound) {
    return pegoraroIntegralEnds(s, H, ua, ub, true, errorBound);
}

// I over [ua, infinity): a ray that never ends.
TY_FUNC TY_R pegoraroIntegralToInfinity(TY_IN(TY_RS(PegoraroSeries)) s, TY_R H, TY_R ua, TY_OUT(TY_R) errorBound) {
    return pegoraroIntegralEnds(s, H, ua, TY_R(kInfinity), false, errorBound);
}

// The integrand of I in the angle theta = atan(u) (du / (1 + u^2) = dtheta): with v = tan(theta) + sec(theta),
//   f(theta) = e^(-H (v - ua)) Phi_c(-sin theta) I_c(dc cos theta + del sin theta).
TY_FUNC TY_R pegoraroIntegrand(TY_R H, TY_R ua, TY_R del, TY_R dc, TY_IN(TY_RS(PegoraroPolynomial)) phase,
                               TY_IN(TY_RS(PegoraroPolynomial)) light, TY_R theta) {
    TY_R sn = realSin(theta), cs = realCos(theta);
    if (cs <= TY_R(0.0f)) return TY_R(0.0f);  // theta = pi/2: v is infinite
    TY_R v = sn >= TY_R(0.0f) ? (TY_R(1.0f) + sn) / cs : cs / (TY_R(1.0f) - sn);
    return realExp(-H * (v - ua)) * pegoraroHorner(phase, -sn) * pegoraroHorner(light, dc * cs + del * sn);
}

// The fallback: I by adaptive Simpson quadrature in theta (Eq. 3 after u = tan theta), to relative tolerance relTol,
// over 32 initial panels (a spot's lobe or a Mie peak is narrow in theta). No recursion: each panel refines with an
// explicit stack. `panels` returns the number of accepted panels; reaching kPegoraroQuadratureMaxPanels stops the
// refinement (the result is then less accurate than asked, never a hang).
TY_FUNC TY_R pegoraroQuadrature(TY_R H, TY_R ua, TY_R ub, TY_R del, TY_R dc, TY_IN(TY_RS(PegoraroPolynomial)) phase,
                                TY_IN(TY_RS(PegoraroPolynomial)) light, TY_R relTol, TY_OUT(int) panels) {
    TY_R zero = TY_R(0.0f);
    panels = 0;
    if (!(ub > ua)) return zero;
    relTol = max(relTol, TY_R(64.0f) * TY_R(TY_R_EPSILON));  // float cannot do better than ~4e-6
    TY_R thetaA = realAtan2(ua, TY_R(1.0f));
    TY_R thetaB = ub < TY_R(kInfinity) ? realAtan2(ub, TY_R(1.0f)) : realAtan2(TY_R(1.0f), TY_R(0.0f));  // pi / 2
    // A first estimate by composite Simpson on the initial panels sets the absolute tolerance.
    const int kInitial = 32;
    TY_R h0 = (thetaB - thetaA) / TY_R(kInitial);
    TY_R coarse = zero;
    for (int i = 0; i <= 2 * kInitial; ++i) {
        TY_R w = (i == 0 || i == 2 * kInitial) ? TY_R(1.0f) : (i % 2 == 1 ? TY_R(4.0f) : TY_R(2.0f));
        coarse += w * abs(pegoraroIntegrand(H, ua, del, dc, phase, light, thetaA + TY_R(0.5f) * h0 * TY_R(i)));
    }
    coarse *= h0 / TY_R(6.0f);
    if (!(coarse > zero)) return zero;
    TY_R tolerance = relTol * coarse;

    TY_R total = zero;
    TY_R sa[kPegoraroQuadratureDepth], sb[kPegoraroQuadratureDepth], sfa[kPegoraroQuadratureDepth];
    TY_R sfm[kPegoraroQuadratureDepth], sfb[kPegoraroQuadratureDepth], sTol[kPegoraroQuadratureDepth];
    for (int i = 0; i < kInitial; ++i) {
        TY_R a0 = thetaA + h0 * TY_R(i);
        TY_R b0 = i + 1 == kInitial ? thetaB : a0 + h0;
        int top = 0;
        sa[0] = a0;
        sb[0] = b0;
        sfa[0] = pegoraroIntegrand(H, ua, del, dc, phase, light, a0);
        sfm[0] = pegoraroIntegrand(H, ua, del, dc, phase, light, TY_R(0.5f) * (a0 + b0));
        sfb[0] = pegoraroIntegrand(H, ua, del, dc, phase, light, b0);
        sTol[0] = tolerance / TY_R(kInitial);
        while (top >= 0) {
            TY_R a = sa[top], b = sb[top], fa = sfa[top], fm = sfm[top], fb = sfb[top], tol = sTol[top];
            --top;
            TY_R m = TY_R(0.5f) * (a + b);
            TY_R fl = pegoraroIntegrand(H, ua, del, dc, phase, light, TY_R(0.5f) * (a + m));
            TY_R fr = pegoraroIntegrand(H, ua, del, dc, phase, light, TY_R(0.5f) * (m + b));
            TY_R whole = (b - a) / TY_R(6.0f) * (fa + TY_R(4.0f) * fm + fb);
            TY_R halves = (b - a) / TY_R(12.0f) * (fa + TY_R(4.0f) * fl + TY_R(2.0f) * fm + TY_R(4.0f) * fr + fb);
            bool full = top + 2 >= kPegoraroQuadratureDepth || panels >= kPegoraroQuadratureMaxPanels;
            if (abs(halves - whole) <= TY_R(15.0f) * tol || full || b - a <= TY_R(4.0f) * TY_R(TY_R_EPSILON) * abs(m)) {
                total += halves + (halves - whole) / TY_R(15.0f);
                ++panels;
            } else {
                // Push the right half, then the left (processed next).
                for (int side = 0; side < 2; ++side) {
                    bool right = side == 0;
                    ++top;
                    sa[top] = right ? m : a;
                    sb[top] = right ? b : m;
                    sfa[top] = right ? fm : fa;
                    sfm[top] = right ? fr : fl;
                    sfb[top] = right ? fb : fm;
                    sTol[top] = TY_R(0.5f) * tol;
                }
            }
        }
    }
    return total;
}

TY_END
