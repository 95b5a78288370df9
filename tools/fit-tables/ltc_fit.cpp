#include "ltc_fit.h"
#include "minimise.h"

#include "tyndall/core/error.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numeric>
#include <thread>

namespace tyndall::tables {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Point j of n of the golden-ratio lattice on [0, 1)^2 (a Fibonacci-like rank-1 lattice for any n).
glm::dvec2 lattice(int j, int n) {
    return {(j + 0.5) / n, std::fmod(j * kGoldenFraction, 1.0)};
}

double ggxLambda(const glm::dvec3& w, double ax, double ay) {
    const double t = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / (w.z * w.z);
    return 0.5 * t / (1.0 + std::sqrt(1.0 + t));
}

double ggxD(const glm::dvec3& h, double ax, double ay) {
    if (h.z <= 0.0) return 0.0;
    const double x = h.x / ax, y = h.y / ay;
    const double s = x * x + y * y + h.z * h.z;
    return 1.0 / (kPi * ax * ay * s * s);
}

// A visible normal of GGX for wo (Heitz 2018, as shared/bsdf.h's ggxSampleVisibleNormal, in double).
glm::dvec3 sampleVisibleNormal(const glm::dvec3& wo, double ax, double ay, const glm::dvec2& u) {
    const glm::dvec3 vh = glm::normalize(glm::dvec3(ax * wo.x, ay * wo.y, wo.z));
    const double lensq = vh.x * vh.x + vh.y * vh.y;
    const glm::dvec3 t1 = lensq > 0.0 ? glm::dvec3(-vh.y, vh.x, 0.0) / std::sqrt(lensq) : glm::dvec3(1.0, 0.0, 0.0);
    const glm::dvec3 t2 = glm::cross(vh, t1);
    const double r = std::sqrt(u.x), phi = 2.0 * kPi * u.y;
    const double p1 = r * std::cos(phi);
    double p2 = r * std::sin(phi);
    const double s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
    const glm::dvec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return glm::normalize(glm::dvec3(ax * nh.x, ay * nh.y, std::max(0.0, nh.z)));
}

glm::dvec3 reflect(const glm::dvec3& wo, const glm::dvec3& h) {
    return 2.0 * glm::dot(wo, h) * h - wo;
}

// The clamped cosine's sample for lattice point u: z = sqrt(1 - u.x) (P(Z <= z) = z^2), uniform azimuth.
glm::dvec3 cosineSample(const glm::dvec2& u) {
    const double r = std::sqrt(u.x), phi = 2.0 * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u.x))};
}

// Nelder-Mead over x (reflection 1, expansion 2, contractions and shrink 1/2), deterministic: ties are broken by the
// vertex's index. Stops after maxEvaluations or when the simplex's values and extent are within the tolerances.
template <typename F>
std::vector<double> nelderMead(const F& f, std::vector<double> x0, const std::vector<double>& step, int maxEvaluations,
                               double& best) {
    const size_t n = x0.size();
    std::vector<std::vector<double>> x(n + 1, x0);
    std::vector<double> v(n + 1);
    for (size_t i = 0; i < n; ++i)
        x[i + 1][i] += step[i];
    for (size_t i = 0; i <= n; ++i)
        v[i] = f(x[i]);
    int evaluations = int(n + 1);
    std::vector<size_t> order(n + 1);
    const auto along = [&](const std::vector<double>& c, const std::vector<double>& w, double t) {
        std::vector<double> r(n);
        for (size_t k = 0; k < n; ++k)
            r[k] = c[k] + t * (w[k] - c[k]);
        return r;
    };
    while (evaluations < maxEvaluations) {
        std::iota(order.begin(), order.end(), size_t(0));
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return v[a] < v[b]; });
        const size_t lo = order[0], hi = order[n], second = order[n - 1];
        double extent = 0.0;
        for (size_t i = 0; i <= n; ++i)
            for (size_t k = 0; k < n; ++k)
                extent = std::max(extent, std::abs(x[i][k] - x[lo][k]));
        if (v[hi] - v[lo] <= 1e-10 + 1e-8 * std::abs(v[lo]) && extent <= 1e-7) break;
        std::vector<double> c(n, 0.0);
        for (size_t i = 0; i <= n; ++i)
            if (i != hi)
                for (size_t k = 0; k < n; ++k)
                    c[k] += x[i][k] / double(n);
        const std::vector<double> xr = along(c, x[hi], -1.0);
        const double fr = f(xr);
        ++evaluations;
        if (fr < v[lo]) {
            const std::vector<double> xe = along(c, x[hi], -2.0);
            const double fe = f(xe);
            ++evaluations;
            if (fe < fr)
                x[hi] = xe, v[hi] = fe;
            else
                x[hi] = xr, v[hi] = fr;
            continue;
        }
        if (fr < v[second]) {
            x[hi] = xr, v[hi] = fr;
            continue;
        }
        const bool outside = fr < v[hi];
        const std::vector<double> xc = outside ? along(c, xr, 0.5) : along(c, x[hi], 0.5);
        const double fc = f(xc);
        ++evaluations;
        if (fc < (outside ? fr : v[hi])) {
            x[hi] = xc, v[hi] = fc;
            continue;
        }
        for (size_t i = 0; i <= n; ++i) {
            if (i == lo) continue;
            x[i] = along(x[lo], x[i], 0.5);
            v[i] = f(x[i]);
            ++evaluations;
        }
    }
    const size_t lo = size_t(std::min_element(v.begin(), v.end()) - v.begin());
    best = v[lo];
    return x[lo];
}

glm::dmat3 entryMatrix(const shader::LtcEntry& e) {
    glm::dmat3 m;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            m[c][r] = double(e.m[3 * c + r]);
    return m;
}

// M_prev (I + P) with P's four free entries (0, 0), (0, 2), (1, 1), (2, 0) (row, column): the lobe's symmetry about
// the xz-plane keeps M's entries (0, 1), (1, 0), (1, 2), (2, 1) zero, and P(2, 2) = 0 fixes the scale.
glm::dmat3 perturbed(const glm::dmat3& m0, const std::vector<double>& p) {
    glm::dmat3 q(1.0);
    q[0][0] += p[0];  // row 0, column 0
    q[2][0] += p[1];  // row 0, column 2
    q[1][1] += p[2];  // row 1, column 1
    q[0][2] += p[3];  // row 2, column 0
    return m0 * q;
}

// The free entries of P for each form of M (anisotropic table), as (row, column) pairs; a second pair, when not -1,
// moves together with the first (P(0, 1) = P(1, 0) removes the rotation about z).
struct FreeEntry {
    int row, column, row2, column2;
};
const std::vector<FreeEntry> kDiagonalForm = {{0, 0, -1, -1}, {1, 1, -1, -1}};
const std::vector<FreeEntry> kXzForm = {{0, 0, -1, -1}, {0, 2, -1, -1}, {1, 1, -1, -1}, {2, 0, -1, -1}};
const std::vector<FreeEntry> kYzForm = {{0, 0, -1, -1}, {1, 1, -1, -1}, {1, 2, -1, -1}, {2, 1, -1, -1}};
const std::vector<FreeEntry> kGeneralForm = {{0, 0, -1, -1}, {0, 1, 1, 0},   {0, 2, -1, -1}, {1, 1, -1, -1},
                                             {1, 2, -1, -1}, {2, 0, -1, -1}, {2, 1, -1, -1}};

// Diagonal entries of I + P are exp(p) (orders of magnitude are a few steps: a grazing lobe at low roughness is
// thousands of times thinner across than along), the others additive.
glm::dmat3 perturbed(const glm::dmat3& m0, const std::vector<double>& p, const std::vector<FreeEntry>& form) {
    glm::dmat3 q(1.0);
    for (size_t k = 0; k < form.size(); ++k) {
        if (form[k].row == form[k].column) {
            q[form[k].column][form[k].row] = std::exp(p[k]);
            continue;
        }
        q[form[k].column][form[k].row] += p[k];
        if (form[k].row2 >= 0) q[form[k].column2][form[k].row2] += p[k];
    }
    return m0 * q;
}

// Nelder-Mead over M = m (I + P) with P of the given form, restarted from its result with a fresh simplex while a run
// improves the loss by more than 1e-5 relative (at most four runs of maxEvaluations).
glm::dmat3 refine(const LtcLoss& loss, glm::dmat3 m, const std::vector<FreeEntry>& form, int maxEvaluations) {
    const std::vector<double> zero(form.size(), 0.0);
    std::vector<double> step(form.size(), 0.05);
    for (size_t k = 0; k < form.size(); ++k)
        if (form[k].row == form[k].column) step[k] = 0.2;  // a factor e^0.2 on a diagonal entry
    const auto f = [&](const std::vector<double>& p) { return loss(perturbed(m, p, form)); };
    double best = f(zero);
    for (int run = 0; run < 4; ++run) {
        double value = 0.0;
        const std::vector<double> p = nelderMead(f, zero, step, maxEvaluations, value);
        if (!(value < best)) break;
        const bool improved = value < best * (1.0 - 1e-5);
        best = value;
        m = perturbed(m, p, form);
        if (!improved) break;
    }
    return m;
}

// The LTC's mean direction (the clamped cosine's samples transformed), unit.
glm::dvec3 ltcMeanDirection(const glm::dmat3& m) {
    constexpr int kSamples = 1024;
    glm::dvec3 sum(0.0);
    for (int j = 0; j < kSamples; ++j)
        sum += glm::normalize(m * cosineSample(lattice(j, kSamples)));
    return glm::normalize(sum);
}

// m rotated (on the left) by the smallest rotation that takes its LTC's mean direction to `target`. It keeps the
// symmetric forms: both directions in the xz- (yz-) plane make it a rotation about y (x).
glm::dmat3 rotatedTowards(const glm::dmat3& m, const glm::dvec3& target) {
    const glm::dvec3 from = ltcMeanDirection(m);
    const glm::dvec3 axis = glm::cross(from, target);
    const double s = glm::length(axis), c = glm::dot(from, target);
    if (!(s > 1e-12)) return m;
    const glm::dvec3 k = axis / s;
    // Rodrigues: R = c I + s [k]x + (1 - c) k k^T (columns).
    const glm::dmat3 kx(glm::dvec3(0.0, k.z, -k.y), glm::dvec3(-k.z, 0.0, k.x), glm::dvec3(k.y, -k.x, 0.0));
    const glm::dmat3 kk(k * k.x, k * k.y, k * k.z);
    return (c * glm::dmat3(1.0) + s * kx + (1.0 - c) * kk) * m;
}

glm::dmat3 rotationZ(double phi) {
    const double c = std::cos(phi), s = std::sin(phi);
    return glm::dmat3(glm::dvec3(c, s, 0.0), glm::dvec3(-s, c, 0.0), glm::dvec3(0.0, 0.0, 1.0));
}

// The isotropic one-parameter fit at normal incidence: m of M = diag(m, m, 1) for GGX at alpha.
double normalIncidenceScale(double alpha, const LtcFitSettings& settings) {
    const glm::dvec3 wo(0.0, 0.0, 1.0);
    const LtcLoss loss(wo, alpha, alpha, ggxMoments(wo, alpha, alpha, settings.momentSamples).norm, settings.samples);
    const auto f = [&](double y) {
        const double s = std::exp(y);
        return loss(glm::dmat3(glm::dvec3(s, 0, 0), glm::dvec3(0, s, 0), glm::dvec3(0, 0, 1)));
    };
    return std::exp(minimise1D(f, std::log(double(settings.alphaMin)) - 2.0, 1.0, 0.1));
}

shader::LtcEntry storeEntry(glm::dmat3 m, const GgxMoments& moments, double error) {
    m /= glm::length(m[2]);  // the third column of unit length (002, Sec. 7)
    shader::LtcEntry e{};
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            e.m[3 * c + r] = float(m[c][r]);
    e.norm = float(moments.norm);
    e.fresnel = float(moments.fresnel);
    e.error = float(error);
    return e;
}

}  // namespace

nlohmann::json ltcSettingsToJson(const LtcFitSettings& s) {
    if (s.anisotropic)
        return {{"table", "ggx-aniso"},
                {"thetaCount", s.thetaCount},
                {"phiCount", s.phiCount},
                {"alphaCount", s.alphaCount},
                {"ratioCount", s.ratioCount},
                {"alphaMin", s.alphaMin},
                {"ratioMin", s.ratioMin},
                {"samples", s.samples},
                {"momentSamples", s.momentSamples},
                {"loss", "tv"}};
    return {{"table", "ggx"},
            {"xCount", s.xCount},
            {"alphaCount", s.alphaCount},
            {"alphaMin", s.alphaMin},
            {"samples", s.samples},
            {"momentSamples", s.momentSamples},
            {"loss", "tv"}};
}

void ltcSettingsFromJson(const nlohmann::json& j, LtcFitSettings& s) {
    s.anisotropic = j.value("table", std::string(s.anisotropic ? "ggx-aniso" : "ggx")) == "ggx-aniso";
    s.thetaCount = j.value("thetaCount", s.thetaCount);
    s.phiCount = j.value("phiCount", s.phiCount);
    s.ratioCount = j.value("ratioCount", s.ratioCount);
    s.ratioMin = j.value("ratioMin", s.ratioMin);
    s.xCount = j.value("xCount", s.xCount);
    s.alphaCount = j.value("alphaCount", s.alphaCount);
    s.alphaMin = j.value("alphaMin", s.alphaMin);
    s.samples = j.value("samples", s.samples);
    s.momentSamples = j.value("momentSamples", s.momentSamples);
}

GgxMoments ggxMoments(const glm::dvec3& wo, double ax, double ay, int samples) {
    // f cos / pdf of the reflected visible normal = G2 / G1(wo) (F = 1), zero below the horizon.
    const double lambdaO = ggxLambda(wo, ax, ay);
    double norm = 0.0, fresnel = 0.0;
    for (int j = 0; j < samples; ++j) {
        const glm::dvec3 h = sampleVisibleNormal(wo, ax, ay, lattice(j, samples));
        const glm::dvec3 wi = reflect(wo, h);
        if (wi.z <= 0.0) continue;
        const double weight = (1.0 + lambdaO) / (1.0 + lambdaO + ggxLambda(wi, ax, ay));
        const double m = std::max(0.0, 1.0 - glm::dot(wi, h));
        norm += weight;
        fresnel += weight * (m * m) * (m * m) * m;
    }
    return {norm / samples, fresnel / samples};
}

LtcLoss::LtcLoss(const glm::dvec3& wo, double ax, double ay, double norm, int samples)
    : wo_(wo), ax_(ax), ay_(ay), norm_(norm) {
    lambdaO_ = ggxLambda(wo, ax, ay);
    g1o_ = 1.0 / (1.0 + lambdaO_);
    for (int j = 0; j < samples; ++j) {
        const glm::dvec2 u = lattice(j, samples);
        const glm::dvec3 w = reflect(wo, sampleVisibleNormal(wo, ax, ay, u));
        double p, pv;
        densities(w, p, pv);
        if (!(pv > 0.0)) continue;  // a degenerate sample (a horizontal normal): density zero, never drawn
        vndfDirections_.push_back(w);
        vndfP_.push_back(p);
        vndfPdf_.push_back(pv);
        cosineSamples_.push_back(cosineSample(u));
    }
    // The same number of LTC samples as visible-normal ones, so that the balance heuristic's counts are equal.
    cosineSamples_.resize(vndfDirections_.size());
}

void LtcLoss::densities(const glm::dvec3& w, double& p, double& pv) const {
    const glm::dvec3 sum = wo_ + w;
    const double l = glm::length(sum);
    if (!(l > 0.0)) {
        p = pv = 0.0;
        return;
    }
    const glm::dvec3 h = sum / l;
    const double d = ggxD(h, ax_, ay_);
    pv = g1o_ * d / (4.0 * wo_.z);
    p = w.z > 0.0 ? d / (4.0 * wo_.z * (1.0 + lambdaO_ + ggxLambda(w, ax_, ay_)) * norm_) : 0.0;
}

glm::dvec3 LtcLoss::targetMean() const {
    glm::dvec3 sum(0.0);
    for (size_t j = 0; j < vndfDirections_.size(); ++j)
        sum += vndfDirections_[j] * (vndfP_[j] / vndfPdf_[j]);
    return glm::normalize(sum);
}

double LtcLoss::operator()(const glm::dmat3& m) const {
    const double det = glm::determinant(m);
    if (!(det > 0.0)) return 4.0;  // beyond any distance between densities: the optimiser backs off
    const glm::dmat3 inv = glm::inverse(m);
    const double detInv = 1.0 / det;
    double sum = 0.0;
    for (size_t j = 0; j < vndfDirections_.size(); ++j) {
        const glm::dvec3 s = inv * vndfDirections_[j];
        const double l = glm::length(s);
        const double q = std::max(s.z / l, 0.0) / kPi * detInv / (l * l * l);
        sum += std::abs(vndfP_[j] - q) / (vndfPdf_[j] + q);
    }
    for (const glm::dvec3& s : cosineSamples_) {
        // w = M s / |M s|; its density is D_o(s) |det M^-1| |M s|^3, since M^-1 w = s / |M s|.
        const glm::dvec3 ms = m * s;
        const double l = glm::length(ms);
        const double q = s.z / kPi * detInv * l * l * l;
        double p, pv;
        densities(ms / l, p, pv);
        sum += std::abs(p - q) / (pv + q);
    }
    return sum / double(vndfDirections_.size());
}

LtcAlignment ltcAlignment(const glm::dmat3& m, bool allowFlips, int kSamples, double stepDegrees) {
    std::vector<glm::dvec3> samples;
    for (int j = 0; j < kSamples; ++j)
        samples.push_back(cosineSample(lattice(j, kSamples)));
    const auto transform = [](double psi, bool fx, bool fy) {
        const double c = std::cos(psi), s = std::sin(psi);
        const glm::dmat3 r(glm::dvec3(c, s, 0.0), glm::dvec3(-s, c, 0.0), glm::dvec3(0.0, 0.0, 1.0));
        const glm::dmat3 f(glm::dvec3(fx ? -1.0 : 1.0, 0.0, 0.0), glm::dvec3(0.0, fy ? -1.0 : 1.0, 0.0),
                           glm::dvec3(0.0, 0.0, 1.0));
        return r * f;
    };
    LtcAlignment best{0.0, false, false, m, 1e300};
    for (int flips = 0; flips < (allowFlips ? 4 : 1); ++flips) {
        const bool fx = flips & 1, fy = flips & 2;
        const auto cost = [&](double psi) {
            const glm::dmat3 mm = m * transform(psi, fx, fy);
            double sum = 0.0;
            for (const glm::dvec3& s : samples) {
                const glm::dvec3 d = glm::normalize(mm * s) - s;
                sum += glm::dot(d, d);
            }
            return sum / kSamples;
        };
        const double psi = minimise1D(cost, 0.0, 2.0 * kPi, stepDegrees * kPi / 180.0);
        const double value = cost(psi);
        if (value < best.cost) best = {psi, fx, fy, m * transform(psi, fx, fy), value};
    }
    return best;
}

shader::LtcEntry fitLtcEntry(int index, const LtcFitSettings& settings, const shader::LtcEntry* previous) {
    const int ix = index % settings.xCount, ia = index / settings.xCount;
    TY_CHECK(ia < settings.alphaCount, "LTC entry index out of range");
    const double alpha = LtcTable::gridAlpha(ia, settings.alphaCount, settings.alphaMin);
    const double cosTheta = LtcTable::gridCosTheta(ix, settings.xCount);
    const glm::dvec3 wo(std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta)), 0.0, cosTheta);
    const GgxMoments moments = ggxMoments(wo, alpha, alpha, settings.momentSamples);
    const LtcLoss loss(wo, alpha, alpha, moments.norm, settings.samples);

    glm::dmat3 m(1.0);
    if (ix == 0) {
        // Normal incidence: the lobe is rotationally symmetric about z, so M = diag(m, m, 1); y = ln m from well below
        // alpha (the lobe's width) to a lobe wider than the cosine.
        const auto f = [&](double y) {
            const double s = std::exp(y);
            return loss(glm::dmat3(glm::dvec3(s, 0, 0), glm::dvec3(0, s, 0), glm::dvec3(0, 0, 1)));
        };
        const double y = minimise1D(f, std::log(double(settings.alphaMin)) - 2.0, 1.0, 0.1);
        m = glm::dmat3(glm::dvec3(std::exp(y), 0, 0), glm::dvec3(0, std::exp(y), 0), glm::dvec3(0, 0, 1));
    } else {
        TY_CHECK(previous != nullptr, "an LTC entry at theta > 0 starts from the previous one");
        m = entryMatrix(*previous);
        // Nelder-Mead from the previous entry, restarted at its result with a fresh simplex until a restart no longer
        // improves the loss (at most four runs).
        const auto f = [&](const std::vector<double>& p) { return loss(perturbed(m, p)); };
        double best = f({0.0, 0.0, 0.0, 0.0});
        for (int run = 0; run < 4; ++run) {
            double value = 0.0;
            const std::vector<double> p = nelderMead(f, {0.0, 0.0, 0.0, 0.0}, {0.05, 0.05, 0.05, 0.05}, 400, value);
            if (!(value < best)) break;
            const bool improved = value < best * (1.0 - 1e-5);
            best = value;
            m = perturbed(m, p);
            if (!improved) break;
        }
    }
    m /= glm::length(m[2]);  // the third column of unit length (002, Sec. 7)

    shader::LtcEntry e{};
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            e.m[3 * c + r] = float(m[c][r]);
    // Entries that the symmetry keeps zero are exactly zero.
    e.m[1] = e.m[3] = e.m[5] = e.m[7] = 0.0f;
    e.norm = float(moments.norm);
    e.fresnel = float(moments.fresnel);
    e.error = float(LtcLoss(wo, alpha, alpha, moments.norm, settings.momentSamples)(entryMatrix(e)));
    return e;
}

// An anisotropic fit whose loss stays above this is retried by continuation (fitLtcAnisotropicEntry).
constexpr double kContinuationThreshold = 0.5;
constexpr int kContinuationSteps = 16;

shader::LtcEntry fitLtcAnisotropicEntry(int index, const LtcFitSettings& s,
                                        const std::function<const shader::LtcEntry&(int)>& stored) {
    const int nt = s.thetaCount, np = s.phiCount, na = s.alphaCount, nr = s.ratioCount;
    const int it = index % nt, ip = (index / nt) % np, ia = (index / (nt * np)) % na, ir = index / (nt * np * na);
    TY_CHECK(ir < nr, "LTC entry index out of range");
    const double theta = LtcTable::gridTheta(it, nt), phi = LtcTable::gridPhi(ip, np);
    const double alphaX = LtcTable::gridAlpha(ia, na, s.alphaMin);
    const double alphaY = std::max(LtcTable::gridRatio(ir, nr, s.ratioMin) * alphaX, double(s.alphaMin));
    const glm::dvec3 wo(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    const auto at = [&](int t, int p) { return index + (t - it) + (p - ip) * nt; };

    // theta = 0: every phi is the phi = 0 entry (002 Eq. 16).
    if (it == 0 && ip > 0) return stored(at(0, 0));
    GgxMoments moments{};
    glm::dmat3 m(1.0);
    if (ir == nr - 1 && it > 0 && ip > 0) {
        // Isotropic GGX: the phi = 0 entry rotated about z (the lobe's rotation), with its moments.
        const shader::LtcEntry& e0 = stored(at(it, 0));
        m = rotationZ(phi) * entryMatrix(e0) * rotationZ(-phi);
        moments = {double(e0.norm), double(e0.fresnel)};
    } else {
        moments = ggxMoments(wo, alphaX, alphaY, s.momentSamples);
        const LtcLoss loss(wo, alphaX, alphaY, moments.norm, s.samples);
        if (it == 0) {
            const double a = normalIncidenceScale(alphaX, s), c = normalIncidenceScale(alphaY, s);
            m = glm::dmat3(glm::dvec3(a, 0, 0), glm::dvec3(0, c, 0), glm::dvec3(0, 0, 1));
            // Isotropic GGX (r = 1) keeps diag(a, a, 1), exactly symmetric under the swap of x and y.
            if (ir < nr - 1) m = refine(loss, m, kDiagonalForm, 400);
        } else {
            // Candidate starts, each rotated towards the lobe's mean direction; the one of smallest loss is refined.
            // The previous theta at this phi and the normal-incidence entry keep the symmetric forms; the general
            // entries also try the previous phi and phi = 0 at this theta.
            const bool general = ip > 0 && ip < np - 1;
            std::vector<int> candidates = {at(it - 1, ip), at(0, 0)};
            if (general) candidates.insert(candidates.end(), {at(it, ip - 1), at(it, 0)});
            const glm::dvec3 mean = loss.targetMean();
            double best = 1e300;
            glm::dmat3 m0(1.0);
            // Each also wider and narrower along x, y or both (the loss is flat where the lobes do not overlap).
            const double scales[] = {1.0, 0.25, 4.0, 1.0 / 16.0, 16.0, 1.0 / 256.0, 256.0};
            for (int c : candidates)
                for (double sx : scales)
                    for (double sy : scales) {
                        if (sx != sy && sx != 1.0 && sy != 1.0) continue;
                        const glm::dmat3 widened =
                            entryMatrix(stored(c)) *
                            glm::dmat3(glm::dvec3(sx, 0.0, 0.0), glm::dvec3(0.0, sy, 0.0), glm::dvec3(0.0, 0.0, 1.0));
                        const glm::dmat3 start = rotatedTowards(widened, mean);
                        const double value = loss(start);
                        if (value < best) best = value, m0 = start;
                    }
            const std::vector<FreeEntry>& form = ip == 0 ? kXzForm : ip == np - 1 ? kYzForm : kGeneralForm;
            m = refine(loss, m0, form, general ? 800 : 400);
            if (!general && loss(m) > kContinuationThreshold) {
                // Continuation (the symmetric forms): walk from the previous theta's view to this one in
                // kContinuationSteps steps, fitting at each, and keep the better result. (Where a general entry stays
                // above the threshold, its lobe is a thin arc off a great circle, which no LTC follows, 002 Sec. 10;
                // walking does not help there.)
                const int from = general ? at(it, ip - 1) : at(it - 1, ip);
                const double theta0 = general ? theta : LtcTable::gridTheta(it - 1, nt);
                const double phi0 = general ? LtcTable::gridPhi(ip - 1, np) : phi;
                glm::dmat3 walk = entryMatrix(stored(from));
                // Uniform steps in x = sqrt(1 - cos theta) (dense towards grazing, as the isotropic table) and phi.
                const double x0 = std::sqrt(1.0 - std::cos(theta0)), x1 = std::sqrt(1.0 - std::cos(theta));
                for (int k = 1; k <= kContinuationSteps; ++k) {
                    const double t = double(k) / kContinuationSteps, x = x0 + t * (x1 - x0);
                    const double th = std::acos(1.0 - x * x), ph = phi0 + t * (phi - phi0);
                    const glm::dvec3 w(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
                    const LtcLoss step =
                        k == kContinuationSteps
                            ? loss
                            : LtcLoss(w, alphaX, alphaY, ggxMoments(w, alphaX, alphaY, s.samples).norm, s.samples);
                    const glm::dmat3 rotated = rotatedTowards(walk, step.targetMean());
                    walk = refine(step, step(rotated) < step(walk) ? rotated : walk, form, general ? 800 : 400);
                }
                if (loss(walk) < loss(m)) m = walk;
            }
            if (general) m = ltcAlignment(m, false, 256, 2.0).aligned;
        }
    }
    shader::LtcEntry e = storeEntry(m, moments, 0.0);
    // The symmetries' zeros, exact (002 Eq. 16): phi = 0 keeps the xz-plane, phi = pi / 2 the yz-plane, theta = 0 both.
    if (ip == 0 || it == 0) e.m[1] = e.m[3] = e.m[5] = e.m[7] = 0.0f;
    if (ip == np - 1 || it == 0) e.m[1] = e.m[3] = e.m[2] = e.m[6] = 0.0f;
    e.error = float(LtcLoss(wo, alphaX, alphaY, moments.norm, s.momentSamples)(entryMatrix(e)));
    return e;
}

int ltcEntryCount(const LtcFitSettings& s) {
    return s.anisotropic ? s.thetaCount * s.phiCount * s.alphaCount * s.ratioCount : s.xCount * s.alphaCount;
}

int ltcRowLength(const LtcFitSettings& s) {
    return s.anisotropic ? s.thetaCount * s.phiCount : s.xCount;
}

std::vector<shader::LtcEntry> fitLtcRows(const LtcFitSettings& settings, const std::vector<int>& rows,
                                         const std::function<void(int, int)>& progress) {
    const int rowLength = ltcRowLength(settings), rowCount = ltcEntryCount(settings) / rowLength;
    std::vector<int> todo = rows;
    if (todo.empty())
        for (int i = 0; i < rowCount; ++i)
            todo.push_back(i);
    std::vector<shader::LtcEntry> entries(size_t(ltcEntryCount(settings)), shader::LtcEntry{});
    const int total = int(todo.size()) * rowLength;
    std::atomic<int> next{0}, done{0};
    const auto stored = [&](int i) -> const shader::LtcEntry& { return entries[size_t(i)]; };
    const auto work = [&] {
        for (int k = next++; k < int(todo.size()); k = next++) {
            const int base = todo[size_t(k)] * rowLength;
            for (int j = 0; j < rowLength; ++j) {
                entries[size_t(base + j)] =
                    settings.anisotropic
                        ? fitLtcAnisotropicEntry(base + j, settings, stored)
                        : fitLtcEntry(base + j, settings, j > 0 ? &entries[size_t(base + j - 1)] : nullptr);
                ++done;
            }
        }
    };
    const int threads = std::max(1, settings.threads > 0 ? settings.threads : int(std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back(work);
    while (done.load() < total) {
        if (progress) progress(done.load(), total);
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    for (std::thread& t : pool)
        t.join();
    if (progress) progress(total, total);
    return entries;
}

}  // namespace tyndall::tables
