// The core of the WVDS technique for one precision (TY_R, TY_R3 and TY_RS defined by wvds.h, which includes this file
// once per precision): the pieces of the light's path length along a camera ray, their closed-form integrals, and the
// samplers. Derivations in docs/wvds.md.

TY_BEGIN

// (1 - e^-x) / x for x >= 0, without the cancellation of the direct form near 0: below 1/2 its Taylor series
// sum_k (-x)^k / (k + 1)!, to k = TY_WVDS_PHI_TERMS - 1 (wvds.h), by Horner's rule with constant reciprocals.
TY_FUNC TY_R TY_RS(wvdsPhi)(TY_R x) {
    if (x < TY_R(0.5f)) {
        TY_R sum = TY_R(1.0f);
        for (int k = TY_WVDS_PHI_TERMS; k >= 2; --k)
            sum = TY_R(1.0f) - x * sum * (TY_R(1.0f) / TY_R(float(k)));
        return sum;
    }
    return (TY_R(1.0f) - realExp(-x)) / x;
}

// log(q) for q = 1 - y in (0, 1], given both: the series -sum_k y^k / k (to k = TY_WVDS_LOG_TERMS, by Horner's rule)
// where y is small (where 1 - y would round), else the logarithm.
TY_FUNC TY_R TY_RS(wvdsLogOneMinus)(TY_R y, TY_R q) {
    if (y < TY_R(0.0625f)) {
        TY_R sum = TY_R(0.0f);
        for (int k = TY_WVDS_LOG_TERMS; k >= 1; --k)
            sum = y * (TY_R(1.0f) / TY_R(float(k)) + sum);
        return -sum;
    }
    return realLog(q);
}

// Eq. 6, WVDS paper (001): integral over s in [0, len] of e^{-sigma (p0 + c s)}, the transmittance of one trapezoid
// segment; written with phi so that the small-slope limit (c -> 0) and negative slopes need no special case and
// nothing overflows: the exponential is taken at the end where the path is shortest. One exponential and one phi
// whatever the sign (a SIMD device such as lavapipe would otherwise evaluate both branches).
TY_FUNC TY_R TY_RS(wvdsPieceIntegral)(TY_R sigma, TY_R p0, TY_R c, TY_R len) {
    TY_R x = sigma * c * len;
    TY_R shortest = x >= TY_R(0.0f) ? p0 : p0 + c * len;
    return realExp(-sigma * shortest) * len * TY_RS(wvdsPhi)(abs(x));
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

// The line d_f(t) = alpha + beta t of the face `plane` along the camera ray o + t d (docs/wvds.md); false, with the
// line that never counts (alpha = kInfinity, beta = 0), when the light ray (towards l) cannot leave through the face.
TY_FUNC bool TY_RS(wvdsFaceLine)(TY_IN(vec4) plane, TY_IN(TY_R3) o, TY_IN(TY_R3) d, TY_IN(TY_R3) l, TY_OUT(TY_R) alpha,
                                 TY_OUT(TY_R) beta) {
    TY_R3 n = TY_R3(vec3(plane));
    TY_R nl = dot(n, l);
    alpha = TY_R(kInfinity);
    beta = TY_R(0.0f);
    if (nl <= TY_R(0.0f)) return false;
    alpha = (TY_R(plane.w) - dot(n, o)) / nl;
    beta = -dot(n, d) / nl;
    return true;
}

// No pieces: every slot empty, at b.
TY_FUNC void TY_RS(wvdsClearPieces)(TY_R b, TY_OUT(TY_RS(WvdsPieces)) pieces) {
    pieces.count = 0;
    for (int k = 0; k < kWvdsMaxSegments; ++k) {
        pieces.t0[k] = b;
        pieces.len[k] = TY_R(0.0f);
        pieces.p0[k] = TY_R(0.0f);
        pieces.c[k] = TY_R(1.0f);
    }
}

// Where line j (slope betaJ <= betaI) drops below line i, as t grows: a crossing, or +-kInfinity for parallel lines
// (never, when line i is the lower or they coincide; always, when line j is the lower).
TY_FUNC TY_R TY_RS(wvdsCrossing)(TY_R alphaI, TY_R betaI, TY_R alphaJ, TY_R betaJ) {
    TY_R slopes = betaI - betaJ;
    TY_R parallel = alphaI <= alphaJ ? TY_R(kInfinity) : -TY_R(kInfinity);
    return slopes > TY_R(0.0f) ? (alphaJ - alphaI) / slopes : parallel;
}

// Orders lines i and j by decreasing slope (the order in which a lower envelope meets them as t grows).
TY_FUNC void TY_RS(wvdsOrderLines)(TY_INOUT(TY_R) alphaI, TY_INOUT(TY_R) betaI, TY_INOUT(TY_R) alphaJ,
                                   TY_INOUT(TY_R) betaJ) {
    bool swap = betaJ > betaI;
    TY_R alpha = alphaI, beta = betaI;
    alphaI = swap ? alphaJ : alphaI;
    betaI = swap ? betaJ : betaI;
    alphaJ = swap ? alpha : alphaJ;
    betaJ = swap ? beta : betaJ;
}

// Piece k of the pieces: t in [t0, t1] on the line alpha + beta t (docs/wvds.md).
TY_FUNC void TY_RS(wvdsSetPiece)(TY_INOUT(TY_RS(WvdsPieces)) pieces, int k, TY_R tIn, TY_R t0, TY_R t1, TY_R alpha,
                                 TY_R beta) {
    pieces.t0[k] = t0;
    pieces.len[k] = t1 - t0;
    pieces.p0[k] = t0 - tIn + max(alpha + beta * t0, TY_R(0.0f));
    pieces.c[k] = TY_R(1.0f) + beta;
}

// The lower envelope of three lines alpha_i + beta_i t over [a, b] in closed form, with no loop and no branch (what a
// box needs: one face per pair of opposite faces can be left towards the light). Sorted by decreasing slope, the lines
// L1, L2, L3 are met in that order; L2 is on the envelope exactly when L1 -> L2 comes before L2 -> L3, else the
// envelope goes from L1 to L3 directly. Always three pieces, some of them possibly empty (len = 0), each on its line, so
// that sums, samples and path lengths over them equal those over the non-empty pieces. Lines that do not count are
// alpha = kInfinity, beta = 0, as in wvdsPieces.
TY_FUNC int TY_RS(wvdsEnvelope3)(TY_R3 alpha, TY_R3 beta, TY_R tIn, TY_R a, TY_R b,
                                 TY_OUT(TY_RS(WvdsPieces)) pieces) {
    TY_R a1 = alpha.x, b1 = beta.x, a2 = alpha.y, b2 = beta.y, a3 = alpha.z, b3 = beta.z;
    TY_RS(wvdsOrderLines)(a1, b1, a2, b2);
    TY_RS(wvdsOrderLines)(a2, b2, a3, b3);
    TY_RS(wvdsOrderLines)(a1, b1, a2, b2);
    TY_R t12 = TY_RS(wvdsCrossing)(a1, b1, a2, b2);
    TY_R t23 = TY_RS(wvdsCrossing)(a2, b2, a3, b3);
    TY_R t13 = TY_RS(wvdsCrossing)(a1, b1, a3, b3);
    bool middle = t12 < t23;
    TY_R u1 = clamp(middle ? t12 : t13, a, b);
    TY_R u2 = clamp(middle ? t23 : t13, a, b);
    TY_RS(wvdsSetPiece)(pieces, 0, tIn, a, u1, a1, b1);
    TY_RS(wvdsSetPiece)(pieces, 1, tIn, u1, u2, middle ? a2 : a3, middle ? b2 : b3);
    TY_RS(wvdsSetPiece)(pieces, 2, tIn, u2, b, a3, b3);
    pieces.count = 3;
    return 3;
}

// wvdsPieces for a box: its planes [first, first + 6) in pairs of opposite normals (boxHalfSpaces). Of each pair only
// the face towards the light can be left, which gives three lines and wvdsEnvelope3's three pieces (some possibly
// empty). What the box variant of the GPU renderer runs; the general walk below gives the same P(t).
TY_FUNC int TY_RS(wvdsBoxPieces)(int first, TY_IN(TY_R3) o, TY_IN(TY_R3) d, TY_IN(TY_R3) l, TY_R tIn, TY_R a, TY_R b,
                                 TY_OUT(TY_RS(WvdsPieces)) pieces) {
    TY_R3 alpha, beta;
    bool any = false;
    for (int i = 0; i < 3; ++i) {
        vec4 plane = wvdsPlane(first + 2 * i);
        if (dot(TY_R3(vec3(plane)), l) <= TY_R(0.0f)) plane = wvdsPlane(first + 2 * i + 1);
        TY_R lineAlpha, lineBeta;  // no line when the light ray is parallel to both faces of the pair
        any = TY_RS(wvdsFaceLine)(plane, o, d, l, lineAlpha, lineBeta) || any;
        alpha[i] = lineAlpha;
        beta[i] = lineBeta;
    }
    TY_RS(wvdsClearPieces)(b, pieces);
    if (!any || !(b > a)) return 0;
    return TY_RS(wvdsEnvelope3)(alpha, beta, tIn, a, b, pieces);
}

// Sec. 4.2-4.4 without the traversal of the box outline: d_m(t) is the lower envelope of one line per face that the
// light ray can leave through, d_f(t) = (w_f - n_f.(o + t d)) / (n_f.l), walked from a to b. The medium is the planes
// [first, first + count); o + t d is the camera ray (d of unit length), tIn where it enters the medium, l the unit
// direction towards the light. Returns the number of pieces: 0 when [a, b] is empty. A shader that defines
// TY_WVDS_BOX gets wvdsBoxPieces instead.
// Every array here is indexed by a loop counter with a constant bound (faces that do not count get the line
// alpha = +max, beta = 0, which is never lowest and never crossed within [a, b]), so that shaders keep them in
// registers; the current and the next line are carried as values.
TY_FUNC int TY_RS(wvdsPieces)(int first, int count, TY_IN(TY_R3) o, TY_IN(TY_R3) d, TY_IN(TY_R3) l, TY_R tIn, TY_R a,
                              TY_R b, TY_OUT(TY_RS(WvdsPieces)) pieces) {
#ifdef TY_WVDS_BOX
    return TY_RS(wvdsBoxPieces)(first, o, d, l, tIn, a, b, pieces);
#else
    TY_R alpha[kWvdsLines];
    TY_R beta[kWvdsLines];
    bool any = false;
    for (int i = 0; i < kWvdsLines; ++i) {
        alpha[i] = TY_R(kInfinity);
        beta[i] = TY_R(0.0f);
        if (i >= count) continue;
        TY_R lineAlpha, lineBeta;
        any = TY_RS(wvdsFaceLine)(wvdsPlane(first + i), o, d, l, lineAlpha, lineBeta) || any;
        alpha[i] = lineAlpha;
        beta[i] = lineBeta;
    }
    TY_RS(wvdsClearPieces)(b, pieces);
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
#endif
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
