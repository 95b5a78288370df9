// The core of the WVDS technique for one precision (TY_R, TY_R3 and TY_RS defined by wvds.h, which includes this file
// once per precision): the pieces of the light's path length along a camera ray, their closed-form integrals, and the
// samplers. Derivations in docs/wvds.md.

TY_BEGIN

// (1 - e^-x) / x for x >= 0, without the cancellation of the direct form near 0: below 1/2 its Taylor series
// sum_k (-x)^k / (k + 1)!, to k = 12 (good to 1e-12 relative), by Horner's rule with constant reciprocals.
TY_FUNC TY_R TY_RS(wvdsPhi)(TY_R x) {
    if (x < TY_R(0.5f)) {
        TY_R sum = TY_R(1.0f);
        for (int k = 13; k >= 2; --k)
            sum = TY_R(1.0f) - x * sum * (TY_R(1.0f) / TY_R(float(k)));
        return sum;
    }
    return (TY_R(1.0f) - realExp(-x)) / x;
}

// log(q) for q = 1 - y in (0, 1], given both: the series -sum_k y^k / k (to k = 14, by Horner's rule) where y is small
// (where 1 - y would round), else the logarithm.
TY_FUNC TY_R TY_RS(wvdsLogOneMinus)(TY_R y, TY_R q) {
    if (y < TY_R(0.0625f)) {
        TY_R sum = TY_R(0.0f);
        for (int k = 14; k >= 1; --k)
            sum = y * (TY_R(1.0f) / TY_R(float(k)) + sum);
        return -sum;
    }
    return realLog(q);
}

// Eq. 6, WVDS paper (001): integral over s in [0, len] of e^{-sigma (p0 + c s)}, the transmittance of one trapezoid
// segment; written with phi so that the small-slope limit (c -> 0) and negative slopes need no special case and
// nothing overflows: the exponential is taken at the end where the path is shortest.
TY_FUNC TY_R TY_RS(wvdsPieceIntegral)(TY_R sigma, TY_R p0, TY_R c, TY_R len) {
    TY_R x = sigma * c * len;
    if (x >= TY_R(0.0f)) return realExp(-sigma * p0) * len * TY_RS(wvdsPhi)(x);
    return realExp(-sigma * (p0 + c * len)) * len * TY_RS(wvdsPhi)(-x);
}

// Sec. 5.1: the offset s in [0, len] with density proportional to e^{-sigma c s}, by inversion of its CDF at u. A
// negative slope is the mirror image of a positive one (s -> len - s).
TY_FUNC TY_R TY_RS(wvdsPieceSample)(TY_R sigma, TY_R c, TY_R len, TY_R u) {
    TY_R x = sigma * c * len;
    TY_R ax = abs(x);
    TY_R v = x >= TY_R(0.0f) ? u : TY_R(1.0f) - u;
    TY_R frac = v;
    if (ax > TY_R(0.0f)) {
        // s / len = -log(1 - v (1 - e^-ax)) / ax; 1 - v (1 - e^-ax) = (1 - v) + v e^-ax without cancellation.
        TY_R y = v * ax * TY_RS(wvdsPhi)(ax);
        TY_R q = (TY_R(1.0f) - v) + v * realExp(-ax);
        frac = -TY_RS(wvdsLogOneMinus)(y, q) / ax;
    }
    frac = clamp(frac, TY_R(0.0f), TY_R(1.0f));
    return (x >= TY_R(0.0f) ? frac : TY_R(1.0f) - frac) * len;
}

// The pieces of the path length P(t) = t - tIn + d_m(t) over [a, b] of a camera ray (docs/wvds.md): on piece k,
// t in [t0, t0 + len] and P = p0 + c (t - t0). For a box these are the paper's trapezoid segments (at most 3).
struct TY_RS(WvdsPieces) {
    int count;
    TY_R t0[kWvdsMaxSegments];   // m, start along the camera ray
    TY_R len[kWvdsMaxSegments];  // m, length along the camera ray
    TY_R p0[kWvdsMaxSegments];   // m, P at the start
    TY_R c[kWvdsMaxSegments];    // dP/dt on the piece: the paper's slope c = 1 + (d_E,E - d_E,S) / (t_C,E - t_C,S)
};

// Sec. 4.2-4.4 without the traversal of the box outline: d_m(t) is the lower envelope of one line per face that the
// light ray can leave through, d_f(t) = (w_f - n_f.(o + t d)) / (n_f.l), walked from a to b. The medium is the planes
// [first, first + count); o + t d is the camera ray (d of unit length), tIn where it enters the medium, l the unit
// direction towards the light. Returns the number of pieces: 0 when [a, b] is empty.
// Every array here is indexed by a loop counter with a constant bound (faces that do not count get the line
// alpha = +max, beta = 0, which is never lowest and never crossed within [a, b]), so that shaders keep them in
// registers; the current and the next line are carried as values.
TY_FUNC int TY_RS(wvdsPieces)(int first, int count, TY_IN(TY_R3) o, TY_IN(TY_R3) d, TY_IN(TY_R3) l, TY_R tIn, TY_R a,
                              TY_R b, TY_OUT(TY_RS(WvdsPieces)) pieces) {
    TY_R alpha[kWvdsLines];
    TY_R beta[kWvdsLines];
    bool any = false;
    for (int i = 0; i < kWvdsLines; ++i) {
        alpha[i] = TY_R(kInfinity);
        beta[i] = TY_R(0.0f);
#ifdef TY_WVDS_BOX
        // The face of pair i that faces the light (the other's normal is the opposite).
        vec4 plane = wvdsPlane(first + 2 * i);
        vec4 opposite = wvdsPlane(first + 2 * i + 1);
        if (dot(TY_R3(vec3(plane)), l) <= TY_R(0.0f)) plane = opposite;
#else
        if (i >= count) continue;
        vec4 plane = wvdsPlane(first + i);
#endif
        TY_R3 n = TY_R3(vec3(plane));
        TY_R nl = dot(n, l);
        if (nl <= TY_R(0.0f)) continue;  // the light ray cannot leave through this face
        alpha[i] = (TY_R(plane.w) - dot(n, o)) / nl;
        beta[i] = -dot(n, d) / nl;
        any = true;
    }
    pieces.count = 0;
    for (int k = 0; k < kWvdsMaxSegments; ++k) {
        pieces.t0[k] = b;
        pieces.len[k] = TY_R(0.0f);
        pieces.p0[k] = TY_R(0.0f);
        pieces.c[k] = TY_R(1.0f);
    }
    if (!any || !(b > a)) return 0;

    // The lowest line at a (ties: the one that stays lowest, the smaller slope).
    TY_R curAlpha = alpha[0], curBeta = beta[0];
    TY_R best = alpha[0] + beta[0] * a;
    for (int i = 1; i < kWvdsLines; ++i) {
        TY_R v = alpha[i] + beta[i] * a;
        if (v < best || (v == best && beta[i] < curBeta)) {
            best = v;
            curAlpha = alpha[i];
            curBeta = beta[i];
        }
    }
    TY_R t = a;
    bool done = false;
    for (int k = 0; k < kWvdsMaxSegments; ++k) {
        if (done) continue;
        // The next corner: the first line with a smaller slope to cross the current one after t.
        TY_R next = b, nextAlpha = curAlpha, nextBeta = curBeta;
        bool turns = false;
        for (int i = 0; i < kWvdsLines; ++i) {
            if (!(beta[i] < curBeta)) continue;
            TY_R tx = (alpha[i] - curAlpha) / (curBeta - beta[i]);
            if (tx > t && (tx < next || (tx == next && turns && beta[i] < nextBeta))) {
                next = tx;
                nextAlpha = alpha[i];
                nextBeta = beta[i];
                turns = true;
            }
        }
        pieces.t0[k] = t;
        pieces.len[k] = next - t;
        pieces.p0[k] = t - tIn + max(curAlpha + curBeta * t, TY_R(0.0f));
        pieces.c[k] = TY_R(1.0f) + curBeta;
        pieces.count = k + 1;
        done = !turns;
        t = next;
        curAlpha = nextAlpha;
        curBeta = nextBeta;
    }
    return pieces.count;
}

// The path length P(t) at a point t of the pieces (clamped to their range).
TY_FUNC TY_R TY_RS(wvdsPathLength)(TY_IN(TY_RS(WvdsPieces)) pieces, TY_R t) {
    TY_R t0 = pieces.t0[0], len = pieces.len[0], p0 = pieces.p0[0], c = pieces.c[0];
    for (int k = 1; k < kWvdsMaxSegments; ++k) {
        if (k < pieces.count && t >= pieces.t0[k]) {
            t0 = pieces.t0[k];
            len = pieces.len[k];
            p0 = pieces.p0[k];
            c = pieces.c[k];
        }
    }
    return p0 + c * clamp(t - t0, TY_R(0.0f), len);
}

// T_total = Tbox (Sec. 4.2, Eq. 6 summed over the segments): the unoccluded integral over t of e^{-sigma P(t)}.
TY_FUNC TY_R TY_RS(wvdsTotal)(TY_IN(TY_RS(WvdsPieces)) pieces, TY_R sigma) {
    TY_R total = TY_R(0.0f);
    for (int k = 0; k < kWvdsMaxSegments; ++k)
        if (k < pieces.count) total += TY_RS(wvdsPieceIntegral)(sigma, pieces.p0[k], pieces.c[k], pieces.len[k]);
    return total;
}

// Eq. 9-10, WVDS paper (001): whole-volume distance sampling. Chooses a segment with probability T_k / T_total, maps
// u into it, and inverts the segment's integral. Returns t; `pdf` receives Eq. 11, which is e^{-sigma P(t)} / T_total
// (0 when T_total underflows: then the ray carries no light either), and `path` the path length P(t).
TY_FUNC TY_R TY_RS(wvdsSample)(TY_IN(TY_RS(WvdsPieces)) pieces, TY_R sigma, TY_R u, TY_OUT(TY_R) pdf,
                               TY_OUT(TY_R) path) {
    TY_R integrals[kWvdsMaxSegments];
    TY_R total = TY_R(0.0f);
    for (int k = 0; k < kWvdsMaxSegments; ++k) {
        integrals[k] = k < pieces.count ? TY_RS(wvdsPieceIntegral)(sigma, pieces.p0[k], pieces.c[k], pieces.len[k])
                                        : TY_R(0.0f);
        total += integrals[k];
    }
    pdf = TY_R(0.0f);
    path = TY_R(0.0f);
    if (!(total > TY_R(0.0f))) return pieces.t0[0];
    TY_R target = u * total, below = TY_R(0.0f);
    TY_R t0 = pieces.t0[0], len = pieces.len[0], p0 = pieces.p0[0], c = pieces.c[0], segment = integrals[0];
    TY_R chosenBelow = TY_R(0.0f);
    bool found = false;
    for (int k = 0; k < kWvdsMaxSegments; ++k) {
        if (found || k >= pieces.count) continue;
        if (target < below + integrals[k] || k == pieces.count - 1) {
            found = true;
            t0 = pieces.t0[k];
            len = pieces.len[k];
            p0 = pieces.p0[k];
            c = pieces.c[k];
            segment = integrals[k];
            chosenBelow = below;
        }
        below += integrals[k];
    }
    TY_R r = segment > TY_R(0.0f) ? clamp((target - chosenBelow) / segment, TY_R(0.0f), TY_R(1.0f)) : TY_R(0.5f);
    TY_R s = TY_RS(wvdsPieceSample)(sigma, c, len, r);
    path = p0 + c * s;
    pdf = realExp(-sigma * path) / total;
    return t0 + s;
}

// Eq. 11: the pdf of wvdsSample at t (0 outside the pieces).
TY_FUNC TY_R TY_RS(wvdsPdf)(TY_IN(TY_RS(WvdsPieces)) pieces, TY_R sigma, TY_R t) {
    if (pieces.count == 0) return TY_R(0.0f);
    TY_R end = pieces.t0[0];
    for (int k = 0; k < kWvdsMaxSegments; ++k)
        if (k < pieces.count) end = pieces.t0[k] + pieces.len[k];
    if (t < pieces.t0[0] || t > end) return TY_R(0.0f);
    TY_R total = TY_RS(wvdsTotal)(pieces, sigma);
    return total > TY_R(0.0f) ? realExp(-sigma * TY_RS(wvdsPathLength)(pieces, t)) / total : TY_R(0.0f);
}

// Classic distance sampling along the camera ray, truncated to [a, b]: density sigma e^{-sigma (t - a)} normalised
// over the interval (what REDS and MCDS use). Returns t and its pdf.
TY_FUNC TY_R TY_RS(wvdsDistanceSample)(TY_R sigma, TY_R a, TY_R b, TY_R u, TY_OUT(TY_R) pdf) {
    TY_R len = b - a;
    TY_R s = TY_RS(wvdsPieceSample)(sigma, TY_R(1.0f), len, u);
    pdf = realExp(-sigma * s) / TY_RS(wvdsPieceIntegral)(sigma, TY_R(0.0f), TY_R(1.0f), len);
    return a + s;
}

TY_FUNC TY_R TY_RS(wvdsDistancePdf)(TY_R sigma, TY_R a, TY_R b, TY_R t) {
    if (t < a || t > b) return TY_R(0.0f);
    return realExp(-sigma * (t - a)) / TY_RS(wvdsPieceIntegral)(sigma, TY_R(0.0f), TY_R(1.0f), b - a);
}

// App. B's slab test generalised to convex media: clips [a, b] of o + t d to the planes [first, first + count).
// Returns false (and leaves a >= b) when nothing is left.
TY_FUNC bool TY_RS(wvdsClip)(int first, int count, TY_IN(TY_R3) o, TY_IN(TY_R3) d, TY_INOUT(TY_R) a,
                             TY_INOUT(TY_R) b) {
    for (int i = 0; i < count; ++i) {
        vec4 plane = wvdsPlane(first + i);
        TY_R3 n = TY_R3(vec3(plane));
        TY_R nd = dot(n, d);
        TY_R room = TY_R(plane.w) - dot(n, o);  // inside where t nd <= room
        if (nd > TY_R(0.0f))
            b = min(b, room / nd);
        else if (nd < TY_R(0.0f))
            a = max(a, room / nd);
        else if (room < TY_R(0.0f))
            b = a;
    }
    return a < b;
}

// d_m at the point x inside the medium: the distance to its boundary towards the light, by a slab test per point
// (what RM and MCDS do at every step).
TY_FUNC TY_R TY_RS(wvdsExitDistance)(int first, int count, TY_IN(TY_R3) x, TY_IN(TY_R3) l) {
    TY_R a = TY_R(0.0f), b = TY_R(kInfinity);
    TY_RS(wvdsClip)(first, count, x, l, a, b);
    return max(b, TY_R(0.0f));
}

TY_END
