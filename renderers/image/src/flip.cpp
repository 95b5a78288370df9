#include "tyndall/image/flip.h"

#include "tyndall/core/error.h"
#include "tyndall/image/colour_map.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>

namespace tyndall {

namespace {

using Rgb3 = std::array<float, 3>;

// D65 white in XYZ, and the linear Rec. 709 <-> XYZ matrices (exact rationals of the sRGB primaries).
constexpr double kWhite[3] = {0.950428545, 1.0, 1.088900371};
constexpr double kRgbToXyz[3][3] = {{10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0},
                                    {2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0},
                                    {1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0}};
constexpr double kXyzToRgb[3][3] = {{3.241003275, -1.537398934, -0.498615861},
                                    {-0.969224334, 1.875930071, 0.041554224},
                                    {0.055639423, -0.204011202, 1.057148933}};

double srgbToLinear(double v) {
    return v > 0.04045 ? std::pow((v + 0.055) / 1.055, 2.4) : v / 12.92;
}

void multiply(const double m[3][3], const double in[3], double out[3]) {
    for (int r = 0; r < 3; ++r)
        out[r] = m[r][0] * in[0] + m[r][1] * in[1] + m[r][2] * in[2];
}

// YCxCz: the linearised CIELAB, the opponent space where FLIP filters (Sec. 3.1 of the FLIP paper).
void xyzToYcxcz(const double xyz[3], double out[3]) {
    const double x = xyz[0] / kWhite[0], y = xyz[1] / kWhite[1], z = xyz[2] / kWhite[2];
    out[0] = 116.0 * y - 16.0;
    out[1] = 500.0 * (x - y);
    out[2] = 200.0 * (y - z);
}
void ycxczToXyz(const double in[3], double xyz[3]) {
    const double y = (in[0] + 16.0) / 116.0;
    xyz[0] = (y + in[1] / 500.0) * kWhite[0];
    xyz[1] = y * kWhite[1];
    xyz[2] = (y - in[2] / 200.0) * kWhite[2];
}

// The cube root of t > 0 to ~1e-12: two steps of Halley's iteration y <- y (y^3 + 2t) / (2y^3 + t), whose error
// cubes at each step, from fdlibm's estimate (the exponent divided by three on the bit pattern: within ~4 %). The
// colour pipeline takes six per pixel, and glibc's cbrt (which splits the exponent with frexp and scalbn) was a fifth
// of HDR-FLIP's time.
inline double cubeRoot(double t) {
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(t);
    double y = std::bit_cast<double>(bits / 3 + (std::uint64_t(715094163) << 32));
    for (int i = 0; i < 2; ++i) {
        const double y3 = y * y * y;
        y *= (y3 + 2.0 * t) / (2.0 * y3 + t);
    }
    return y;
}

// CIELAB of linear RGB, with the Hunt adjustment (a and b scaled by 0.01 L).
void huntLab(const double rgb[3], double out[3]) {
    double xyz[3];
    multiply(kRgbToXyz, rgb, xyz);
    constexpr double delta = 6.0 / 29.0;
    double f[3];
    for (int i = 0; i < 3; ++i) {
        const double t = xyz[i] / kWhite[i];
        f[i] = t > delta * delta * delta ? cubeRoot(t) : t / (3.0 * delta * delta) + 4.0 / 29.0;
    }
    const double l = 116.0 * f[1] - 16.0;
    out[0] = l;
    out[1] = 0.01 * l * 500.0 * (f[0] - f[1]);
    out[2] = 0.01 * l * 200.0 * (f[1] - f[2]);
}

double hyab(const double a[3], const double b[3]) {
    const double da = a[1] - b[1], db = a[2] - b[2];  // bounded (CIELAB of [0, 1] RGB): no need for hypot's care
    return std::abs(a[0] - b[0]) + std::sqrt(da * da + db * db);
}

// A separable filter: one 1-D kernel along x and one along y (odd lengths, centred).
struct Separable {
    std::vector<float> x, y;
};

// Convolves one channel (w x h, row-major) along x with `k`, the borders clamped (replicated). The taps are the outer
// loop and the pixels the inner one, so that the compiler vectorises it.
std::vector<float> convolveX(const std::vector<float>& in, int w, int h, const std::vector<float>& k) {
    std::vector<float> out(in.size());
    const int r = int(k.size() / 2);
    tbb::parallel_for(0, h, [&](int y) {
        std::vector<float> padded(std::size_t(w + 2 * r));
        const float* row = in.data() + std::size_t(y) * w;
        for (int x = -r; x < w + r; ++x)
            padded[std::size_t(x + r)] = row[std::clamp(x, 0, w - 1)];
        float* o = out.data() + std::size_t(y) * w;
        std::fill(o, o + w, 0.0f);
        for (int i = 0; i <= 2 * r; ++i) {
            const float ki = k[std::size_t(i)];
            const float* p = padded.data() + i;
            for (int x = 0; x < w; ++x)
                o[x] += ki * p[x];
        }
    });
    return out;
}

// The same along y.
std::vector<float> convolveY(const std::vector<float>& in, int w, int h, const std::vector<float>& k) {
    std::vector<float> out(in.size(), 0.0f);
    const int r = int(k.size() / 2);
    tbb::parallel_for(0, h, [&](int y) {
        float* o = out.data() + std::size_t(y) * w;
        for (int i = -r; i <= r; ++i) {
            const float ki = k[std::size_t(i + r)];
            const float* row = in.data() + std::size_t(std::clamp(y + i, 0, h - 1)) * w;
            for (int x = 0; x < w; ++x)
                o[x] += ki * row[x];
        }
    });
    return out;
}

std::vector<float> convolve(const std::vector<float>& in, int w, int h, const Separable& k) {
    return convolveY(convolveX(in, w, h, k.x), w, h, k.y);
}

// The contrast sensitivity filters (Sec. 3.1): per channel a sum of Gaussians a_k sqrt(pi / b_k)
// exp(-pi^2 r^2 / b_k), r in degrees, normalised to sum to 1 over the 2-D kernel; each term is separable. The radius
// covers three standard deviations of the widest Gaussian of all channels (b = 0.04).
struct CsfTerm {
    double a, b;
};
constexpr CsfTerm kCsf[3][2] = {{{1.0, 0.0047}, {0.0, 1e-5}},    // achromatic
                                {{1.0, 0.0053}, {0.0, 1e-5}},    // red-green
                                {{34.1, 0.04}, {13.5, 0.025}}};  // blue-yellow

std::vector<Separable> csfTerms(int channel, double ppd) {
    const int radius = int(std::ceil(3.0 * std::sqrt(0.04 / (2.0 * std::numbers::pi * std::numbers::pi)) * ppd));
    std::vector<std::vector<double>> g;
    double total = 0.0;
    for (const CsfTerm& t : kCsf[channel]) {
        std::vector<double> k(std::size_t(2 * radius + 1));
        for (int i = -radius; i <= radius; ++i) {
            const double d = double(i) / ppd;
            k[std::size_t(i + radius)] = std::exp(-std::numbers::pi * std::numbers::pi * d * d / t.b);
        }
        const double s = std::accumulate(k.begin(), k.end(), 0.0);
        total += t.a * std::sqrt(std::numbers::pi / t.b) * s * s;
        g.push_back(std::move(k));
    }
    // A narrow term's taps far out are below 1e-8 of its centre (the achromatic and red-green terms reach it at about
    // 6 of the 10 pixels at 67 pixels per degree): they are left out, which changes no result in float and saves a
    // third of those passes.
    std::vector<Separable> terms;
    for (std::size_t i = 0; i < g.size(); ++i) {
        const CsfTerm& t = kCsf[channel][i];
        if (t.a == 0.0) continue;
        const double scale = t.a * std::sqrt(std::numbers::pi / t.b) / total;
        int trim = 0;
        while (trim < radius && g[i][std::size_t(trim)] < 1e-8 * g[i][std::size_t(radius)])
            ++trim;
        Separable s;
        for (std::size_t j = std::size_t(trim); j + std::size_t(trim) < g[i].size(); ++j) {
            s.x.push_back(float(g[i][j] * scale));
            s.y.push_back(float(g[i][j]));
        }
        terms.push_back(std::move(s));
    }
    return terms;
}

// The feature detectors (Sec. 3.2): the first (edges) and second (points) derivative of a Gaussian of standard
// deviation 0.5 w ppd, w = 0.082 degrees, radius three deviations, the positive weights normalised to sum to 1 and the
// negative ones to -1 over the 2-D kernel. Both are separable: the derivative along x times the Gaussian along y.
Separable featureKernel(bool points, double ppd) {
    const double sd = 0.5 * 0.082 * ppd;
    const int radius = int(std::ceil(3.0 * sd));
    std::vector<double> g(std::size_t(2 * radius + 1)), d(g.size());
    for (int i = -radius; i <= radius; ++i) {
        const double x = double(i);
        g[std::size_t(i + radius)] = std::exp(-x * x / (2.0 * sd * sd));
        d[std::size_t(i + radius)] = (points ? x * x / (sd * sd) - 1.0 : -x) * g[std::size_t(i + radius)];
    }
    double positive = 0.0, negative = 0.0;
    for (double v : d)
        (v > 0.0 ? positive : negative) += v;
    for (double& v : d)
        v = v > 0.0 ? v / positive : v / -negative;
    const double gs = std::accumulate(g.begin(), g.end(), 0.0);
    Separable k;
    for (std::size_t i = 0; i < g.size(); ++i) {
        k.x.push_back(float(d[i]));
        k.y.push_back(float(g[i] / gs));
    }
    return k;
}

void requireSameSize(const Image& reference, const Image& test) {
    if (reference.width() != test.width() || reference.height() != test.height())
        throw InputError(InputLocation{"", 0, 0, "test"},
                         "is " + std::to_string(test.width()) + " x " + std::to_string(test.height()) +
                             ", the reference " + std::to_string(reference.width()) + " x " +
                             std::to_string(reference.height()) + ": FLIP compares images of one size");
}

int channelOrThrow(const Image& image, const char* name, const char* which) {
    const int c = image.channelIndex(name);
    if (c < 0)
        throw InputError(InputLocation{"", 0, 0, which},
                         std::string("has no channel ") + name + " (FLIP compares RGB)");
    return c;
}

// LDR-FLIP of two images given as linear RGB triples in [0, 1] (the display-encoded values already decoded: by the
// sRGB curve for LDR-FLIP, or straight from the tone mapper for HDR-FLIP, whose sRGB encoding and decoding cancel).
std::vector<float> ldrFlipOf(const std::vector<Rgb3>& reference, const std::vector<Rgb3>& test, int w, int h,
                             double ppd) {
    constexpr double qc = 0.7, qf = 0.5, pc = 0.4, pt = 0.95;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    // Opponent space and the achromatic feature channel (Y / Y_n) of both images.
    auto opponent = [&](const std::vector<Rgb3>& image, std::array<std::vector<float>, 3>& ycc, std::vector<float>& y) {
        for (auto& c : ycc)
            c.resize(n);
        y.resize(n);
        tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
            const double rgb[3] = {image[i][0], image[i][1], image[i][2]};
            double xyz[3], o[3];
            multiply(kRgbToXyz, rgb, xyz);
            xyzToYcxcz(xyz, o);
            for (int c = 0; c < 3; ++c)
                ycc[std::size_t(c)][i] = float(o[c]);
            y[i] = float((o[0] + 16.0) / 116.0);
        });
    };
    std::array<std::vector<float>, 3> refOpp, testOpp;
    std::vector<float> refY, testY;
    opponent(reference, refOpp, refY);
    opponent(test, testOpp, testY);

    // Colour pipeline: each channel filtered by its CSF, back to linear RGB clamped to [0, 1], Hunt-adjusted CIELAB,
    // HyAB, and the redistribution of the error to [0, 1] against the largest difference (green against blue).
    auto filtered = [&](const std::array<std::vector<float>, 3>& opp) {
        std::array<std::vector<float>, 3> out;
        for (int c = 0; c < 3; ++c) {
            std::vector<float>& sum = out[std::size_t(c)];
            for (const Separable& term : csfTerms(c, ppd)) {
                std::vector<float> part = convolve(opp[std::size_t(c)], w, h, term);
                if (sum.empty()) {
                    sum = std::move(part);
                } else {
                    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { sum[i] += part[i]; });
                }
            }
        }
        return out;
    };
    std::array<std::vector<float>, 3> refFiltered, testFiltered;
    tbb::parallel_invoke([&] { refFiltered = filtered(refOpp); }, [&] { testFiltered = filtered(testOpp); });
    double green[3], blue[3];
    const double greenRgb[3] = {0.0, 1.0, 0.0}, blueRgb[3] = {0.0, 0.0, 1.0};
    huntLab(greenRgb, green);
    huntLab(blueRgb, blue);
    const double cmax = std::pow(hyab(green, blue), qc);
    std::vector<double> colour(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        double lab[2][3];
        for (int k = 0; k < 2; ++k) {
            const auto& f = k == 0 ? refFiltered : testFiltered;
            const double o[3] = {f[0][i], f[1][i], f[2][i]};
            double xyz[3], rgb[3];
            ycxczToXyz(o, xyz);
            multiply(kXyzToRgb, xyz, rgb);
            for (double& v : rgb)
                v = std::clamp(v, 0.0, 1.0);
            huntLab(rgb, lab[k]);
        }
        const double e = std::pow(hyab(lab[0], lab[1]), qc);
        colour[i] = e < pc * cmax ? pt / (pc * cmax) * e : pt + (e - pc * cmax) / (cmax - pc * cmax) * (1.0 - pt);
    });

    // Feature pipeline: edges and points of the achromatic channel, their magnitudes' difference.
    // Each detector is a derivative along one axis times the same Gaussian along the other: the Gaussian passes are
    // shared by the edge and the point detector.
    const Separable edge = featureKernel(false, ppd), point = featureKernel(true, ppd);
    auto magnitudes = [&](const std::vector<float>& y, std::vector<float>& edges, std::vector<float>& points) {
        const std::vector<float> smoothY = convolveY(y, w, h, edge.y), smoothX = convolveX(y, w, h, edge.y);
        const std::vector<float> ex = convolveX(smoothY, w, h, edge.x), ey = convolveY(smoothX, w, h, edge.x);
        const std::vector<float> px = convolveX(smoothY, w, h, point.x), py = convolveY(smoothX, w, h, point.x);
        edges.resize(n);
        points.resize(n);
        tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
            edges[i] = std::sqrt(ex[i] * ex[i] + ey[i] * ey[i]);
            points[i] = std::sqrt(px[i] * px[i] + py[i] * py[i]);
        });
    };
    std::vector<float> refEdges, testEdges, refPoints, testPoints;
    tbb::parallel_invoke([&] { magnitudes(refY, refEdges, refPoints); },
                         [&] { magnitudes(testY, testEdges, testPoints); });
    std::vector<float> error(n);
    static_assert(qf == 0.5, "the feature difference's power qf is taken as a square root");
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        const double feature = std::sqrt(
            std::max(std::abs(refEdges[i] - testEdges[i]), std::abs(refPoints[i] - testPoints[i])) / std::sqrt(2.0));
        // The magnitudes' difference is at most sqrt(2) (each normalised detector answers at most 1 per axis), so the
        // feature term is at most 1; rounding may pass it, and colour^(negative) would leave [0, 1] (or be infinite at
        // 0).
        error[i] = float(std::pow(colour[i], std::max(0.0, 1.0 - feature)));
    });
    return error;
}

// The rational polynomial's coefficients k0..k5 of each tone mapper (HDR-FLIP, Sec. 3): ACES with its pre-exposure of
// 0.6 folded in, Hable's filmic curve with its white point 11.2 and exposure bias 2 folded in, Reinhard's x / (1 + x).
std::array<double, 6> toneMapperCoefficients(FlipToneMapper t) {
    if (t == FlipToneMapper::Reinhard) return {0.0, 1.0, 0.0, 0.0, 1.0, 1.0};
    if (t == FlipToneMapper::Hable) {
        const double A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30, W = 11.2;
        const double k0 = A * F - A * E, k1 = C * B * F - B * E, k3 = A * F, k4 = B * F, k5 = D * F * F;
        const double white = (k3 * W * W + k4 * W + k5) / (k0 * W * W + k1 * W);
        return {4.0 * k0 * white, 2.0 * k1 * white, 0.0, 4.0 * k3, 2.0 * k4, k5};
    }
    return {0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14};
}

// The tone mapper of coefficients k at x (negative x counts as 0, +inf maps to 1), clamped to [0, 1].
double toneMapped(const std::array<double, 6>& k, double x) {
    x = std::max(x, 0.0);
    if (!std::isfinite(x)) return 1.0;
    return std::clamp((k[0] * x * x + k[1] * x + k[2]) / (k[3] * x * x + k[4] * x + k[5]), 0.0, 1.0);
}

}  // namespace

double flipCubeRoot(double t) {
    return cubeRoot(t);
}

double flipPixelsPerDegree(double distance, double resolution, double width) {
    return distance * (resolution / width) * std::numbers::pi / 180.0;
}

std::vector<float> ldrFlip(const Image& reference, const Image& test, double pixelsPerDegree) {
    requireSameSize(reference, test);
    const int w = reference.width(), h = reference.height();
    auto triples = [&](const Image& image, const char* which) {
        const int r = channelOrThrow(image, "R", which), g = channelOrThrow(image, "G", which),
                  b = channelOrThrow(image, "B", which);
        std::vector<Rgb3> out(std::size_t(w) * std::size_t(h));
        tbb::parallel_for(0, h, [&](int y) {
            for (int x = 0; x < w; ++x) {
                const int channels[3] = {r, g, b};
                for (int c = 0; c < 3; ++c)
                    out[std::size_t(y) * w + x][std::size_t(c)] =
                        float(srgbToLinear(std::clamp(double(image.at(x, y, channels[c])), 0.0, 1.0)));
            }
        });
        return out;
    };
    return ldrFlipOf(triples(reference, "reference"), triples(test, "test"), w, h, pixelsPerDegree);
}

FlipToneMapper flipToneMapperFromName(const std::string& name) {
    if (name == "aces") return FlipToneMapper::Aces;
    if (name == "hable") return FlipToneMapper::Hable;
    if (name == "reinhard") return FlipToneMapper::Reinhard;
    throw InputError(InputLocation{"", 0, 0, "toneMapper"}, "must be aces, hable or reinhard, got '" + name + "'");
}

double flipToneMap(FlipToneMapper toneMapper, double x) {
    return toneMapped(toneMapperCoefficients(toneMapper), x);
}

double flipToneMapperInverse(FlipToneMapper toneMapper, double t) {
    const std::array<double, 6> k = toneMapperCoefficients(toneMapper);
    // (k0 - k3 t) x^2 + (k1 - k4 t) x + (k2 - k5 t) = 0: the positive root (a linear equation for Reinhard).
    const double a = k[0] - k[3] * t, b = k[1] - k[4] * t, c = k[2] - k[5] * t;
    if (std::abs(a) < 1e-12) return -c / b;
    const double c0 = b / a, c1 = c / a;
    return -0.5 * c0 + std::sqrt(0.25 * c0 * c0 - c1);
}

void flipExposureRange(const Image& reference, FlipToneMapper toneMapper, double& start, double& stop) {
    const int r = channelOrThrow(reference, "R", "reference"), g = channelOrThrow(reference, "G", "reference"),
              b = channelOrThrow(reference, "B", "reference");
    std::vector<double> luminance;
    for (int y = 0; y < reference.height(); ++y)
        for (int x = 0; x < reference.width(); ++x)
            luminance.push_back(0.2126 * std::max(0.0f, reference.at(x, y, r)) +
                                0.7152 * std::max(0.0f, reference.at(x, y, g)) +
                                0.0722 * std::max(0.0f, reference.at(x, y, b)));
    start = stop = 0.0;
    if (luminance.empty()) return;
    const double hi = *std::max_element(luminance.begin(), luminance.end());
    if (!(hi > 0.0)) return;
    auto median = [](std::vector<double> v) {
        std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
        return v[v.size() / 2];
    };
    double lo = median(luminance);
    if (!(lo > 0.0)) {
        std::vector<double> positive;
        for (double v : luminance)
            if (v > 0.0) positive.push_back(v);
        lo = median(positive);
    }
    const double knee = flipToneMapperInverse(toneMapper, 0.85);
    start = std::log2(knee / hi);
    stop = std::log2(knee / lo);
}

// hdrFlip's work, in whatever arena the caller set up.
static HdrFlipResult hdrFlipIsolated(const Image& reference, const Image& test, const HdrFlipSettings& settings);

HdrFlipResult hdrFlip(const Image& reference, const Image& test, const HdrFlipSettings& settings) {
    TY_CHECK(settings.threads >= 0, "hdrFlip: threads >= 0");
    if (settings.threads > 0) {
        tbb::task_arena arena(settings.threads);
        HdrFlipSettings inside = settings;
        inside.threads = 0;
        return arena.execute([&] { return hdrFlip(reference, test, inside); });
    }
    HdrFlipResult result;
    tbb::this_task_arena::isolate([&] { result = hdrFlipIsolated(reference, test, settings); });
    return result;
}

static HdrFlipResult hdrFlipIsolated(const Image& reference, const Image& test, const HdrFlipSettings& settings) {
    requireSameSize(reference, test);
    HdrFlipResult result;
    if (settings.automaticExposures)
        flipExposureRange(reference, settings.toneMapper, result.startExposure, result.stopExposure);
    else
        result.startExposure = settings.startExposure, result.stopExposure = settings.stopExposure;
    result.exposures = settings.exposures > 0
                           ? settings.exposures
                           : int(std::max(2.0, std::ceil(result.stopExposure - result.startExposure)));
    const int w = reference.width(), h = reference.height();
    const std::size_t n = std::size_t(w) * std::size_t(h);
    result.error.assign(n, 0.0f);
    result.exposureIndex.assign(n, 0);
    const double step = (result.stopExposure - result.startExposure) / double(std::max(result.exposures - 1, 1));
    auto exposed = [&](const Image& image, double exposure, const char* which) {
        const int r = channelOrThrow(image, "R", which), g = channelOrThrow(image, "G", which),
                  b = channelOrThrow(image, "B", which);
        const double scale = std::exp2(exposure);
        const std::array<double, 6> k = toneMapperCoefficients(settings.toneMapper);
        std::vector<Rgb3> out(n);
        tbb::parallel_for(0, h, [&](int y) {
            for (int x = 0; x < w; ++x) {
                Rgb3& v = out[std::size_t(y) * w + x];
                const int channels[3] = {r, g, b};
                for (int c = 0; c < 3; ++c)
                    v[std::size_t(c)] = float(toneMapped(k, scale * double(image.at(x, y, channels[c]))));
            }
        });
        return out;
    };
    for (int e = 0; e < result.exposures; ++e) {
        const double exposure = result.startExposure + double(e) * step;
        const std::vector<float> error = ldrFlipOf(exposed(reference, exposure, "reference"),
                                                   exposed(test, exposure, "test"), w, h, settings.pixelsPerDegree);
        tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
            if (e == 0 || error[i] > result.error[i]) {
                result.error[i] = error[i];
                result.exposureIndex[i] = e;
            }
        });
    }
    return result;
}

std::vector<FlipHistogramBin> flipHistogram(const std::vector<float>& error, int bins) {
    TY_CHECK(bins >= 1, "flipHistogram: at least one bin");
    std::vector<FlipHistogramBin> out(static_cast<std::size_t>(bins));
    double total = 0.0;
    for (int b = 0; b < bins; ++b) {
        out[std::size_t(b)].low = double(b) / bins;
        out[std::size_t(b)].high = double(b + 1) / bins;
    }
    for (float e : error) {
        const double v = e >= 0.0f ? std::min(double(e), 1.0) : 0.0;  // a NaN counts in the first bin
        const int b = std::min(int(v * bins), bins - 1);
        ++out[std::size_t(b)].pixels;
        out[std::size_t(b)].weightedShare += e;
        total += e;
    }
    if (total > 0.0)
        for (FlipHistogramBin& b : out)
            b.weightedShare /= total;
    return out;
}

double flipRegionMean(const std::vector<float>& error, int mapWidth, int x, int y, int width, int height) {
    TY_CHECK(width > 0 && height > 0 && x >= 0 && y >= 0 && x + width <= mapWidth &&
                 std::size_t(y + height) * std::size_t(mapWidth) <= error.size(),
             "flipRegionMean: a region inside the map");
    double sum = 0.0;
    for (int row = y; row < y + height; ++row)
        for (int column = x; column < x + width; ++column)
            sum += error[std::size_t(row) * std::size_t(mapWidth) + std::size_t(column)];
    return sum / (double(width) * height);
}

Image flipColourMap(const std::vector<float>& error, int width, int height) {
    TY_CHECK(error.size() == std::size_t(width) * std::size_t(height), "flipColourMap: one error per pixel");
    Image map = Image::rgb(width, height);
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const Rgb c = magma(error[std::size_t(y) * std::size_t(width) + std::size_t(x)]);
            for (int k = 0; k < 3; ++k)
                map.at(x, y, k) = float(c[k]);
        }
    });
    return map;
}

FlipStatistics flipStatistics(const std::vector<float>& error) {
    FlipStatistics s;
    if (error.empty()) return s;
    std::vector<float> sorted = error;
    std::sort(sorted.begin(), sorted.end());
    double total = 0.0;
    for (float v : sorted)
        total += v;
    s.mean = total / double(sorted.size());
    s.minimum = sorted.front();
    s.maximum = sorted.back();
    // The value below which a fraction p of the summed error lies.
    auto weighted = [&](double p) {
        if (!(total > 0.0)) return 0.0;
        double cumulative = 0.0;
        for (float v : sorted) {
            cumulative += v;
            if (cumulative >= p * total) return double(v);
        }
        return double(sorted.back());
    };
    s.weightedFirstQuartile = weighted(0.25);
    s.weightedMedian = weighted(0.5);
    s.weightedThirdQuartile = weighted(0.75);
    return s;
}

}  // namespace tyndall
