#include "tyndall/image/denoise.h"

#include "tyndall/core/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace tyndall {

namespace {

// The B3-spline kernel of the a-trous transform (Dammertz et al. 2010), 5 taps per axis.
constexpr float kKernel[5] = {1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f};

std::string sizeText(const Image& image) {
    return std::to_string(image.width()) + "x" + std::to_string(image.height());
}

void checkSize(const Image& image, const Image& reference, const std::string& what, const std::string& field) {
    if (image.width() != reference.width() || image.height() != reference.height())
        throw InputError(InputLocation{.field = field}, what + " is " + sizeText(image) + ", the noisy image " +
                                                            sizeText(reference) + ": they must be the same size");
}

void checkFinite(const Image& image, int c, const std::string& field, bool allowInfinite = false) {
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x) {
            const float v = image.at(x, y, c);
            if (std::isnan(v) || (!allowInfinite && !std::isfinite(v)))
                throw InputError(InputLocation{.field = field}, "must be finite, got " + std::to_string(v) +
                                                                    " at pixel (" + std::to_string(x) + ", " +
                                                                    std::to_string(y) + ")");
        }
}

std::string channelList(const Image& image) {
    std::string out;
    for (const std::string& name : image.channels())
        out += (out.empty() ? "" : ", ") + name;
    return out.empty() ? "none" : out;
}

// The guides, checked and flattened to per-pixel arrays (empty when absent).
struct Guides {
    int width = 0, height = 0;
    std::vector<float> depth, depthDx, depthDy;  // depth and its smaller one-sided slope per axis (0 at edges)
    std::vector<float> normal;                   // 3 per pixel
    std::vector<float> guide;                    // mean of the guide's channels
};

Guides readGuides(const DenoiseGuides& in, const Image& noisy) {
    Guides g;
    g.width = noisy.width();
    g.height = noisy.height();
    const std::size_t n = std::size_t(g.width) * g.height;
    if (in.depth) {
        const Image& d = *in.depth;
        checkSize(d, noisy, "the depth guide", "guides.depth");
        int c = d.channelIndex("Z");
        if (c < 0 && d.channelCount() == 1) c = 0;
        if (c < 0)
            throw InputError(InputLocation{.field = "guides.depth"},
                             "needs a channel \"Z\" (or exactly one channel); it has " + channelList(d));
        checkFinite(d, c, "guides.depth." + d.channels()[c], true);
        g.depth.resize(n);
        for (int y = 0; y < g.height; ++y)
            for (int x = 0; x < g.width; ++x)
                g.depth[std::size_t(y) * g.width + x] = d.at(x, y, c);
        // The slope toward the side that continues the surface: the smaller one-sided difference, so that a pixel
        // beside a depth step does not take the step for its slope.
        auto slope = [&](int x, int y, int dx, int dy) {
            const float z = d.at(x, y, c);
            float best = 0.0f;
            bool found = false;
            for (int s = -1; s <= 1; s += 2) {
                const int qx = x + s * dx, qy = y + s * dy;
                if (qx < 0 || qy < 0 || qx >= g.width || qy >= g.height) continue;
                const float zq = d.at(qx, qy, c);
                if (!std::isfinite(zq) || !std::isfinite(z)) continue;
                const float diff = (zq - z) * float(s);
                if (!found || std::fabs(diff) < std::fabs(best)) best = diff;
                found = true;
            }
            return best;
        };
        g.depthDx.resize(n);
        g.depthDy.resize(n);
        for (int y = 0; y < g.height; ++y)
            for (int x = 0; x < g.width; ++x) {
                g.depthDx[std::size_t(y) * g.width + x] = slope(x, y, 1, 0);
                g.depthDy[std::size_t(y) * g.width + x] = slope(x, y, 0, 1);
            }
    }
    if (in.normal) {
        const Image& m = *in.normal;
        checkSize(m, noisy, "the normal guide", "guides.normal");
        int c[3] = {m.channelIndex("N.X"), m.channelIndex("N.Y"), m.channelIndex("N.Z")};
        if ((c[0] < 0 || c[1] < 0 || c[2] < 0) && m.channelCount() == 3) c[0] = 0, c[1] = 1, c[2] = 2;
        if (c[0] < 0 || c[1] < 0 || c[2] < 0)
            throw InputError(
                InputLocation{.field = "guides.normal"},
                "needs channels \"N.X\", \"N.Y\", \"N.Z\" (or exactly three channels); it has " + channelList(m));
        g.normal.resize(3 * n);
        for (int k = 0; k < 3; ++k) {
            checkFinite(m, c[k], "guides.normal." + m.channels()[c[k]]);
            for (int y = 0; y < g.height; ++y)
                for (int x = 0; x < g.width; ++x)
                    g.normal[3 * (std::size_t(y) * g.width + x) + k] = m.at(x, y, c[k]);
        }
    }
    if (in.guide) {
        const Image& m = *in.guide;
        checkSize(m, noisy, "the guide image", "guides.guide");
        std::vector<int> cs;
        if (m.channelIndex("R") >= 0 && m.channelIndex("G") >= 0 && m.channelIndex("B") >= 0)
            cs = {m.channelIndex("R"), m.channelIndex("G"), m.channelIndex("B")};
        else
            for (int c = 0; c < m.channelCount(); ++c)
                cs.push_back(c);
        if (cs.empty()) throw InputError(InputLocation{.field = "guides.guide"}, "has no channels");
        g.guide.assign(n, 0.0f);
        for (int c : cs) {
            checkFinite(m, c, "guides.guide." + m.channels()[c]);
            for (int y = 0; y < g.height; ++y)
                for (int x = 0; x < g.width; ++x)
                    g.guide[std::size_t(y) * g.width + x] += m.at(x, y, c) / float(cs.size());
        }
    }
    return g;
}

void checkSettings(const DenoiseSettings& s) {
    if (s.iterations < 0 || s.iterations > 12)
        throw InputError(InputLocation{.field = "denoise.iterations"},
                         "must be in [0, 12], got " + std::to_string(s.iterations));
    const std::pair<const char*, float> values[] = {
        {"sigmaDepth", s.sigmaDepth},   {"normalExponent", s.normalExponent}, {"sigmaGuide", s.sigmaGuide},
        {"sigmaColour", s.sigmaColour}, {"minDenominator", s.minDenominator}, {"ratioFallback", s.ratioFallback}};
    for (const auto& [name, v] : values)
        if (!std::isfinite(v))
            throw InputError(InputLocation{.field = std::string("denoise.") + name},
                             "must be finite, got " + std::to_string(v));
    if (s.minDenominator < 0.0f)
        throw InputError(InputLocation{.field = "denoise.minDenominator"},
                         "must be >= 0, got " + std::to_string(s.minDenominator));
}

// Channels of `variance` for each channel of `of`: "variance.<name>", else "<name>".
std::vector<float> readVariance(const Image& variance, const Image& of, const std::string& ofName) {
    checkSize(variance, of, "the variance image", "variance");
    const std::size_t n = std::size_t(of.width()) * of.height();
    const int C = of.channelCount();
    std::vector<float> out(n * C);
    for (int c = 0; c < C; ++c) {
        const std::string& name = of.channels()[c];
        int v = variance.channelIndex("variance." + name);
        if (v < 0) v = variance.channelIndex(name);
        if (v < 0)
            throw InputError(InputLocation{.field = "variance"}, "has no channel \"variance." + name + "\" or \"" +
                                                                     name + "\" for the " + ofName + "'s channel \"" +
                                                                     name + "\"; it has " + channelList(variance));
        for (int y = 0; y < of.height(); ++y)
            for (int x = 0; x < of.width(); ++x) {
                const float value = variance.at(x, y, v);
                if (!(value >= 0.0f) || !std::isfinite(value))
                    throw InputError(InputLocation{.field = "variance." + variance.channels()[v]},
                                     "must be finite and >= 0, got " + std::to_string(value) + " at pixel (" +
                                         std::to_string(x) + ", " + std::to_string(y) + ")");
                out[(std::size_t(y) * of.width() + x) * C + c] = value;
            }
    }
    return out;
}

// The noise variance per pixel and channel when none is given, estimated robustly from the signal itself: the median
// absolute difference of the 40 horizontal and vertical neighbour pairs in the 5x5 window around the pixel, scaled to
// a standard deviation for Gaussian noise (1.4826 MAD) and halved since a difference carries two pixels' noise. The
// median ignores the few pairs that straddle an edge; exact zeros count, so a noise-free region (a ratio that is
// exactly 1 where everything is lit) is left alone. Pairs with an unknown end (a zero denominator) are skipped.
std::vector<float> estimateVariance(const std::vector<float>& signal, const std::vector<unsigned char>& known,
                                    int width, int height, int C) {
    std::vector<float> out(std::size_t(width) * height * C);
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 4), [&](const tbb::blocked_range<int>& rows) {
        std::vector<float> diffs;
        diffs.reserve(40);
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < width; ++x)
                for (int c = 0; c < C; ++c) {
                    diffs.clear();
                    for (int qy = std::max(0, y - 2); qy <= std::min(height - 1, y + 2); ++qy)
                        for (int qx = std::max(0, x - 2); qx <= std::min(width - 1, x + 2); ++qx) {
                            const std::size_t q = std::size_t(qy) * width + qx;
                            if (!known[q]) continue;
                            if (qx + 1 <= std::min(width - 1, x + 2) && known[q + 1])
                                diffs.push_back(std::fabs(signal[q * C + c] - signal[(q + 1) * C + c]));
                            if (qy + 1 <= std::min(height - 1, y + 2) && known[q + width])
                                diffs.push_back(std::fabs(signal[q * C + c] - signal[(q + width) * C + c]));
                        }
                    float variance = 0.0f;
                    if (!diffs.empty()) {
                        auto mid = diffs.begin() + std::ptrdiff_t(diffs.size() / 2);
                        std::nth_element(diffs.begin(), mid, diffs.end());
                        const float sigma = 1.4826f * *mid;
                        variance = 0.5f * sigma * sigma;
                    }
                    out[(std::size_t(y) * width + x) * C + c] = variance;
                }
    });
    return out;
}

// 3x3 Gaussian blur of the variance used in the colour weight (SVGF does the same: a per-pixel variance from few
// samples is itself very noisy).
std::vector<float> blurVariance(const std::vector<float>& var, int width, int height, int C) {
    std::vector<float> out(var.size());
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 8), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < width; ++x)
                for (int c = 0; c < C; ++c) {
                    float sum = 0.0f, weight = 0.0f;
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            const int qx = x + dx, qy = y + dy;
                            if (qx < 0 || qy < 0 || qx >= width || qy >= height) continue;
                            const float k = (dx == 0 ? 0.5f : 0.25f) * (dy == 0 ? 0.5f : 0.25f);
                            sum += k * var[(std::size_t(qy) * width + qx) * C + c];
                            weight += k;
                        }
                    out[(std::size_t(y) * width + x) * C + c] = sum / weight;
                }
    });
    return out;
}

// The working state of the filter: `values` (V per pixel) are averaged; the colour weight compares `signal` (C per
// pixel) in units of the standard deviation from `variance`. For denoise() values == signal; for denoiseRatio()
// values are numerator and denominator and the signal is their ratio. `known` marks pixels whose signal means
// something (a ratio with a zero denominator does not): the colour weight is 1 where either end is unknown.
struct State {
    int V = 0, C = 0;
    std::vector<float> values, signal, variance;
    std::vector<unsigned char> known;
};

// One a-trous level with taps `step` pixels apart; the result's variance is sum w^2 var / (sum w)^2.
void atrousLevel(const Guides& g, const DenoiseSettings& s, int step, const State& in, State& out) {
    const int width = g.width, height = g.height, V = in.V, C = in.C;
    const std::vector<float> varW = blurVariance(in.variance, width, height, C);
    const bool useDepth = !g.depth.empty() && s.sigmaDepth > 0.0f;
    const bool useNormal = !g.normal.empty() && s.normalExponent > 0.0f;
    const bool useGuide = !g.guide.empty() && s.sigmaGuide > 0.0f;
    const bool useColour = s.sigmaColour > 0.0f;
    const float colourFactor = useColour ? -0.5f / (s.sigmaColour * s.sigmaColour) : 0.0f;
    const float guideFactor = useGuide ? -1.0f / (s.sigmaGuide * s.sigmaGuide) : 0.0f;
    const float invC = 1.0f / float(C);
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 4), [&](const tbb::blocked_range<int>& rows) {
        std::vector<float> sum(V), varSum(C);
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < width; ++x) {
                const std::size_t p = std::size_t(y) * width + x;
                std::fill(sum.begin(), sum.end(), 0.0f);
                std::fill(varSum.begin(), varSum.end(), 0.0f);
                float weightSum = 0.0f;
                // What the taps compare against, read once per pixel.
                const float zp = useDepth ? g.depth[p] : 0.0f;
                const bool zpFinite = std::isfinite(zp);
                const float dzdx = useDepth ? g.depthDx[p] * s.sigmaDepth : 0.0f;
                const float dzdy = useDepth ? g.depthDy[p] * s.sigmaDepth : 0.0f;
                const float depthFloor = 1e-3f * std::fabs(zp) + 1e-30f;
                const float* np = useNormal ? &g.normal[3 * p] : nullptr;
                const bool zeroP = np && np[0] == 0.0f && np[1] == 0.0f && np[2] == 0.0f;
                const float gp = useGuide ? g.guide[p] : 0.0f;
                const bool colourHere = useColour && in.known[p];
                const float* signalP = &in.signal[p * C];
                const float* varP = &varW[p * C];
                const float* valuesP = &in.values[p * V];
                for (int ky = 0; ky < 5; ++ky) {
                    const int qy = y + (ky - 2) * step;
                    if (qy < 0 || qy >= height) continue;
                    for (int kx = 0; kx < 5; ++kx) {
                        const int qx = x + (kx - 2) * step;
                        if (qx < 0 || qx >= width) continue;
                        const std::size_t q = std::size_t(qy) * width + qx;
                        float w = kKernel[kx] * kKernel[ky];
                        if (q != p) {
                            // The edge-stopping weights multiply: their exponents add, and one exp serves all.
                            float exponent = 0.0f;
                            if (useDepth) {
                                const float zq = g.depth[q];
                                if (zpFinite != std::isfinite(zq)) continue;
                                if (zpFinite) {
                                    const float along =
                                        std::fabs(dzdx * float((kx - 2) * step) + dzdy * float((ky - 2) * step));
                                    exponent -= std::fabs(zp - zq) / (along + depthFloor);
                                }
                            }
                            if (useGuide) {
                                const float gq = g.guide[q];
                                const float m = std::max(std::fabs(gp), std::fabs(gq));
                                if (m > 0.0f) {
                                    const float rel = std::fabs(gp - gq) / m;
                                    exponent += guideFactor * rel * rel;
                                }
                            }
                            if (colourHere && in.known[q]) {
                                const float* signalQ = &in.signal[q * C];
                                const float* varQ = &varW[q * C];
                                float d2 = 0.0f;
                                for (int c = 0; c < C; ++c) {
                                    const float diff = signalP[c] - signalQ[c];
                                    if (diff == 0.0f) continue;
                                    const float v = varP[c] + varQ[c];
                                    d2 += v > 0.0f ? diff * diff / v : std::numeric_limits<float>::infinity();
                                }
                                exponent += colourFactor * d2 * invC;
                            }
                            if (useNormal) {
                                const float* nq = &g.normal[3 * q];
                                const bool zeroQ = nq[0] == 0.0f && nq[1] == 0.0f && nq[2] == 0.0f;
                                if (zeroP != zeroQ) continue;
                                if (!zeroP) {
                                    const float d = np[0] * nq[0] + np[1] * nq[1] + np[2] * nq[2];
                                    if (!(d > 0.0f)) continue;
                                    // max(0, n_p . n_q)^e; equal normals (the common case) cost nothing.
                                    if (d < 1.0f) exponent += s.normalExponent * std::log(d);
                                }
                            }
                            // Below e^-30 a tap cannot matter next to the centre's (3/8)^2: skip the exp.
                            if (!(exponent > -30.0f)) continue;
                            if (exponent < 0.0f) w *= std::exp(exponent);
                        }
                        // Sums of differences to the centre: a constant image stays exactly constant.
                        const float* valuesQ = &in.values[q * V];
                        for (int v = 0; v < V; ++v)
                            sum[v] += w * (valuesQ[v] - valuesP[v]);
                        for (int c = 0; c < C; ++c)
                            varSum[c] += w * w * in.variance[q * C + c];
                        weightSum += w;
                    }
                }
                // The centre tap always counts, so weightSum >= (3/8)^2.
                for (int v = 0; v < V; ++v)
                    out.values[p * V + v] = in.values[p * V + v] + sum[v] / weightSum;
                for (int c = 0; c < C; ++c)
                    out.variance[p * C + c] = varSum[c] / (weightSum * weightSum);
            }
    });
}

// The safe ratio: the fallback where the denominator is ~0 or the quotient is not finite.
float safeRatio(float num, float den, const DenoiseSettings& s) {
    if (!(std::fabs(den) > s.minDenominator)) return s.ratioFallback;
    const float r = num / den;
    return std::isfinite(r) ? r : s.ratioFallback;
}

void updateRatioSignal(State& st, const DenoiseSettings& s) {
    const std::size_t n = st.known.size();
    for (std::size_t p = 0; p < n; ++p) {
        bool known = false;
        for (int c = 0; c < st.C; ++c) {
            const float num = st.values[p * st.V + c], den = st.values[p * st.V + st.C + c];
            st.signal[p * st.C + c] = safeRatio(num, den, s);
            known = known || std::fabs(den) > s.minDenominator;
        }
        st.known[p] = known ? 1 : 0;
    }
}

// Runs the levels. `isRatio`: the signal is recomputed from the values after each level.
void runFilter(const Guides& g, const DenoiseSettings& s, State& st, bool isRatio) {
    State next = st;
    for (int level = 0; level < s.iterations; ++level) {
        // The variance falls level by level, so the same difference counts as more standard deviations: coarse
        // levels only average what the fine levels left flat.
        atrousLevel(g, s, 1 << level, st, next);
        if (isRatio)
            updateRatioSignal(next, s);
        else
            next.signal = next.values;
        std::swap(st, next);
    }
}

}  // namespace

Image denoise(const Image& noisy, const Image* variance, const DenoiseGuides& guides, const DenoiseSettings& settings) {
    checkSettings(settings);
    if (noisy.channelCount() == 0) throw InputError(InputLocation{.field = "noisy"}, "has no channels");
    for (int c = 0; c < noisy.channelCount(); ++c)
        checkFinite(noisy, c, "noisy." + noisy.channels()[c]);
    const Guides g = readGuides(guides, noisy);
    const int C = noisy.channelCount();
    const std::size_t n = std::size_t(noisy.width()) * noisy.height();
    State st;
    st.V = st.C = C;
    st.values.assign(noisy.data(), noisy.data() + n * C);
    st.signal = st.values;
    st.known.assign(n, 1);
    st.variance = variance ? readVariance(*variance, noisy, "noisy image")
                           : estimateVariance(st.signal, st.known, noisy.width(), noisy.height(), C);
    runFilter(g, settings, st, false);
    Image out(noisy.width(), noisy.height(), noisy.channels());
    std::copy(st.values.begin(), st.values.end(), out.data());
    out.metadata = noisy.metadata;
    return out;
}

Image denoiseRatio(const Image& numerator, const Image& denominator, const Image* variance, const DenoiseGuides& guides,
                   const DenoiseSettings& settings, bool denoised) {
    checkSettings(settings);
    if (numerator.channelCount() == 0) throw InputError(InputLocation{.field = "numerator"}, "has no channels");
    checkSize(denominator, numerator, "the denominator", "denominator");
    if (denominator.channels() != numerator.channels())
        throw InputError(InputLocation{.field = "denominator"}, "has channels " + channelList(denominator) +
                                                                    ", the numerator " + channelList(numerator) +
                                                                    ": they must be the same");
    for (int c = 0; c < numerator.channelCount(); ++c) {
        checkFinite(numerator, c, "numerator." + numerator.channels()[c]);
        checkFinite(denominator, c, "denominator." + denominator.channels()[c]);
    }
    const Guides g = readGuides(guides, numerator);
    const int C = numerator.channelCount();
    const std::size_t n = std::size_t(numerator.width()) * numerator.height();
    State st;
    st.C = C;
    st.V = 2 * C;
    st.values.resize(n * st.V);
    for (std::size_t p = 0; p < n; ++p)
        for (int c = 0; c < C; ++c) {
            st.values[p * st.V + c] = numerator.data()[p * C + c];
            st.values[p * st.V + C + c] = denominator.data()[p * C + c];
        }
    st.signal.resize(n * C);
    st.known.resize(n);
    updateRatioSignal(st, settings);
    if (denoised) {
        st.variance = variance ? readVariance(*variance, numerator, "numerator")
                               : estimateVariance(st.signal, st.known, numerator.width(), numerator.height(), C);
        runFilter(g, settings, st, true);
    } else if (variance) {
        readVariance(*variance, numerator, "numerator");  // the same checks either way
    }
    Image out(numerator.width(), numerator.height(), numerator.channels());
    std::copy(st.signal.begin(), st.signal.end(), out.data());
    out.metadata = numerator.metadata;
    return out;
}

}  // namespace tyndall
