#include "fit.h"
#include "minimise.h"

#include "tyndall/core/error.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

namespace tyndall::tables {

namespace {

constexpr double kPi = 3.14159265358979323846;

// HG's CDF in mu from -1, F(mu) = (1 - g^2) / (2g) [(1 + g^2 - 2g mu)^(-1/2) - 1 / (1 + g)], inverted.
double hgInverseCdf(double g, double F) {
    if (std::abs(g) < 1e-6) return 2.0 * F - 1.0;
    const double q = 2.0 * g * F / (1.0 - g * g) + 1.0 / (1.0 + g);
    return std::clamp((1.0 + g * g - 1.0 / (q * q)) / (2.0 * g), -1.0, 1.0);
}

// The sliced Wasserstein loss of 002 (Sec. 4, Eq. 10) between the target's samples and the transformed source's, on
// fixed quasi-random samples (stratified in the polar CDF, golden-ratio azimuths) and Fibonacci-sphere directions.
class SlicedWasserstein {
public:
    // targetZ(j, n): z of the target's sample j of n, stratified in its polar CDF.
    template <typename TargetZ>
    SlicedWasserstein(const TargetZ& targetZ, int source, const FitSettings& s) : source_(source), n_(s.swSamples) {
        const int k = s.swDirections;
        for (int i = 0; i < k; ++i) {
            const double z = 1.0 - (2.0 * i + 1.0) / k, r = std::sqrt(std::max(0.0, 1.0 - z * z));
            const double phi = 2.39996322972865332 * i;
            directions_.push_back(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z));
        }
        std::vector<glm::dvec3> target(static_cast<size_t>(n_));
        for (int j = 0; j < n_; ++j) target[size_t(j)] = direction(targetZ(j, n_), j);
        for (const glm::dvec3& d : directions_) {
            std::vector<double> p(static_cast<size_t>(n_));
            for (int j = 0; j < n_; ++j) p[size_t(j)] = glm::dot(target[size_t(j)], d);
            std::sort(p.begin(), p.end());
            targetProjections_.push_back(std::move(p));
        }
        for (int j = 0; j < n_; ++j) {
            const double u = (j + 0.5) / n_;
            sourceSamples_.push_back(direction(source_ == shader::kLtsdSourceClampedCosine ? std::sqrt(u)
                                                                                          : 1.0 - std::sqrt(u), j));
        }
    }

    double operator()(double y) const {
        const double m = std::exp(y);
        std::vector<glm::dvec3> moved(sourceSamples_.size());
        for (size_t j = 0; j < moved.size(); ++j) {
            const glm::dvec3& s = sourceSamples_[j];
            moved[j] = glm::normalize(glm::dvec3(m * s.x, m * s.y, s.z));
        }
        double sum = 0.0;
        std::vector<double> p(moved.size());
        for (size_t k = 0; k < directions_.size(); ++k) {
            for (size_t j = 0; j < moved.size(); ++j) p[j] = glm::dot(moved[j], directions_[k]);
            std::sort(p.begin(), p.end());
            for (size_t j = 0; j < p.size(); ++j) sum += std::abs(p[j] - targetProjections_[k][j]);
        }
        return sum / double(moved.size() * directions_.size());
    }

private:
    static glm::dvec3 direction(double z, int j) {
        const double phi = 2.0 * kPi * std::fmod(j * kGoldenFraction, 1.0);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        return {r * std::cos(phi), r * std::sin(phi), z};
    }

    int source_;
    int n_;
    std::vector<glm::dvec3> directions_;
    std::vector<std::vector<double>> targetProjections_;
    std::vector<glm::dvec3> sourceSamples_;
};

// z of sample j of n of a lobe's hemisphere (side +1: upper, mu = -z; -1: lower mirrored, mu = z), stratified in the
// lobe's CDF restricted to the hemisphere and inverted by bisection in mu (deterministic, to double precision).
double lobeHemisphereZ(const std::string& type, int side, int j, int n) {
    const double f0 = ltsdLobeCdf(type, 0.0, 0.0);
    const double u = (j + 0.5) / n;
    const double target = side > 0 ? u * f0 : f0 + u * (1.0 - f0);
    double lo = side > 0 ? -1.0 : 0.0, hi = side > 0 ? 0.0 : 1.0;
    for (int i = 0; i < 80; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (ltsdLobeCdf(type, 0.0, mid) < target)
            lo = mid;
        else
            hi = mid;
    }
    return double(-side) * 0.5 * (lo + hi);
}

struct ScaleFit {
    double m;
    double loss;
};

// Fits M = diag(m, m, 1) for one hemisphere of a parameterless lobe with the given source.
ScaleFit fitLobeScale(const std::string& type, int side, int source, const FitSettings& settings) {
    if (settings.loss == "tv") {
        const auto f = [&](double y) { return ltsdLobeTotalVariation(type, 0.0, side, source, std::exp(y)); };
        const double y = minimise1D(f, -12.0, 6.0, 0.05);
        return {std::exp(y), f(y)};
    }
    if (settings.loss == "sw") {
        const SlicedWasserstein f([&](int j, int n) { return lobeHemisphereZ(type, side, j, n); }, source, settings);
        const double y = minimise1D(f, -12.0, 6.0, 0.25);
        return {std::exp(y), f(y)};
    }
    throw InputError(InputLocation{"", 0, 0, "--loss"}, "'" + settings.loss + "' is not a loss: tv or sw");
}

}  // namespace

nlohmann::json settingsToJson(const FitSettings& s) {
    nlohmann::json j = {{"phase", s.phase}, {"loss", s.loss}, {"entriesPerHalf", s.entriesPerHalf}, {"gMax", s.gMax}};
    if (s.loss == "sw") j["swSamples"] = s.swSamples, j["swDirections"] = s.swDirections;
    return j;
}

double fitEntryScale(double g, int source, const FitSettings& settings) {
    // y = ln m over [-12, 6]: m from 6e-6 (a lobe far sharper than HG at |g| = 0.99) to 400 (flatter than isotropic).
    if (settings.loss == "tv")
        return std::exp(minimise1D([&](double y) { return ltsdTotalVariation(g, source, std::exp(y)); }, -12.0, 6.0,
                                 0.05));
    if (settings.loss == "sw") {
        const double aU = hgUpperAmplitude(g);
        const auto targetZ = [&](int j, int n) { return -hgInverseCdf(g, aU * (j + 0.5) / n); };
        return std::exp(minimise1D(SlicedWasserstein(targetZ, source, settings), -12.0, 6.0, 0.25));
    }
    throw InputError(InputLocation{"", 0, 0, "--loss"}, "'" + settings.loss + "' is not a loss: tv or sw");
}

shader::LtsdEntry fitEntry(int index, const FitSettings& settings) {
    if (settings.phase != "hg") {
        // A parameterless lobe: entry 0 fits its upper hemisphere, entry 1 its lower one mirrored (the T of
        // M_l = diag(1, 1, -1) T). Both sources are fitted; the one with the smaller loss is kept.
        TY_CHECK(index == 0 || index == 1, "a parameterless table has two entries");
        const int side = index == 0 ? 1 : -1;
        const ScaleFit clamped = fitLobeScale(settings.phase, side, shader::kLtsdSourceClampedCosine, settings);
        const ScaleFit inverse = fitLobeScale(settings.phase, side, shader::kLtsdSourceInverseClampedCosine, settings);
        const bool useClamped = clamped.loss <= inverse.loss;
        const float m = float(useClamped ? clamped.m : inverse.m);
        const double upperShare = ltsdLobeCdf(settings.phase, 0.0, 0.0);
        shader::LtsdEntry e{};
        e.m[0] = m, e.m[4] = m, e.m[8] = 1.0f;
        e.amplitude = float(ltsdLobeWeight(settings.phase) * (side > 0 ? upperShare : 1.0 - upperShare));
        e.source = useClamped ? shader::kLtsdSourceClampedCosine : shader::kLtsdSourceInverseClampedCosine;
        e.g = 0.0f;
        return e;
    }
    LtsdTable layout;
    layout.entriesPerHalf = settings.entriesPerHalf;
    layout.gMax = settings.gMax;
    const double g = layout.entryG(index);
    const int source =
        index < settings.entriesPerHalf ? shader::kLtsdSourceClampedCosine : shader::kLtsdSourceInverseClampedCosine;
    const float m = float(fitEntryScale(g, source, settings));
    shader::LtsdEntry e{};
    e.m[0] = m, e.m[4] = m, e.m[8] = 1.0f;
    e.amplitude = float(hgUpperAmplitude(g));
    e.source = source;
    e.g = float(g);
    return e;
}

std::vector<shader::LtsdEntry> fitEntries(const FitSettings& settings, const std::vector<int>& indices,
                                          const std::function<void(int, int)>& progress) {
    const int total = settings.phase == "hg" ? 2 * settings.entriesPerHalf : 2;
    std::vector<int> todo = indices;
    if (todo.empty())
        for (int i = 0; i < total; ++i) todo.push_back(i);
    std::vector<shader::LtsdEntry> entries(size_t(total), shader::LtsdEntry{});
    std::atomic<int> next{0}, done{0};
    const auto work = [&] {
        for (int k = next++; k < int(todo.size()); k = next++) {
            entries[size_t(todo[size_t(k)])] = fitEntry(todo[size_t(k)], settings);
            ++done;
        }
    };
    const int threads = std::max(1, settings.threads > 0 ? settings.threads : int(std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(work);
    while (done.load() < int(todo.size())) {
        if (progress) progress(done.load(), int(todo.size()));
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    for (std::thread& t : pool) t.join();
    if (progress) progress(int(todo.size()), int(todo.size()));
    return entries;
}

}  // namespace tyndall::tables
