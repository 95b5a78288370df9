#include "reference/reference.h"

#include "reference/integrator.h"
#include "tyndall/error.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>

namespace tyndall {

using reference::IntegratorOptions;

std::vector<ParamInfo> ReferenceTechnique::parameters() const {
    std::vector<ParamInfo> p;
    {
        ParamInfo i;
        i.name = "mode";
        i.type = ParamType::Enum;
        i.doc = "single: one scattering event, what the techniques approximate; multiple: up to maxDepth events";
        i.enumValues = {"single", "multiple"};
        i.defaultValue = std::string("single");
        p.push_back(i);
    }
    {
        ParamInfo i;
        i.name = "maxDepth";
        i.type = ParamType::Int;
        i.doc = "scattering events at most in multiple-scattering mode";
        i.min = 1;
        i.max = 1024;
        i.defaultValue = std::int64_t(16);
        p.push_back(i);
    }
    {
        ParamInfo i;
        i.name = "distanceSampling";
        i.type = ParamType::Enum;
        i.doc =
            "how scattering distances for light sampling are chosen: equiangular alone for point and area lights "
            "in homogeneous media and MIS of both elsewhere, MIS of both, delta tracking only, or light-targeted "
            "where available (equiangular for point and area lights, uniform in a beam)";
        i.enumValues = {"auto", "mis", "distance", "equiangular"};
        i.defaultValue = std::string("auto");
        p.push_back(i);
    }
    {
        ParamInfo i;
        i.name = "lightSampling";
        i.type = ParamType::Enum;
        i.doc =
            "how directions to area lights are chosen: MIS of both, light sampling only, or phase/BSDF sampling "
            "only";
        i.enumValues = {"mis", "light", "phase"};
        i.defaultValue = std::string("mis");
        p.push_back(i);
    }
    return p;
}

namespace {

IntegratorOptions optionsFrom(const ParamSet& params) {
    IntegratorOptions o;
    o.multipleScattering = params.getEnum("mode") == "multiple";
    o.maxDepth = o.multipleScattering ? int(params.getInt("maxDepth")) : 1;
    const std::string& d = params.getEnum("distanceSampling");
    o.distance = d == "distance"      ? reference::DistanceStrategy::Distance
                 : d == "equiangular" ? reference::DistanceStrategy::LightTargeted
                 : d == "mis"         ? reference::DistanceStrategy::Mis
                                      : reference::DistanceStrategy::Auto;
    const std::string& l = params.getEnum("lightSampling");
    o.light = l == "light"   ? reference::LightStrategy::LightSampling
              : l == "phase" ? reference::LightStrategy::PhaseSampling
                             : reference::LightStrategy::Mis;
    return o;
}

// Per-pixel sums of the two independently scrambled sample streams (even and odd sample indices). Their means differ
// only by noise, so (meanA - meanB)^2 / 4 estimates the variance of the pixel's mean (docs/reference.md).
struct Accumulator {
    int width, height;
    std::vector<glm::dvec3> sumA, sumB;
    long nonFinite = 0;
    Accumulator(int w, int h) : width(w), height(h), sumA(size_t(w) * h), sumB(size_t(w) * h) {}
};

Image resolve(const Accumulator& acc, int spp) {
    Image image(acc.width, acc.height, {"R", "G", "B", "variance.R", "variance.G", "variance.B"});
    int nA = (spp + 1) / 2, nB = spp / 2;
    for (int y = 0; y < acc.height; ++y) {
        for (int x = 0; x < acc.width; ++x) {
            size_t i = size_t(y) * acc.width + x;
            glm::dvec3 mean = (acc.sumA[i] + acc.sumB[i]) / double(std::max(spp, 1));
            glm::dvec3 variance(0.0);
            if (nA > 0 && nB > 0) {
                glm::dvec3 d = acc.sumA[i] / double(nA) - acc.sumB[i] / double(nB);
                variance = d * d * 0.25;
            }
            for (int c = 0; c < 3; ++c) {
                image.at(x, y, c) = float(mean[c]);
                image.at(x, y, 3 + c) = float(variance[c]);
            }
        }
    }
    return image;
}

}  // namespace

void ReferenceTechnique::check(const RenderRequest& request) const {
    requireSupported(request.scene);
    (void)optionsFrom(request.params);
    (void)reference::prepareScene(request.scene, request.projectDir);
}

RenderResult ReferenceTechnique::render(const RenderRequest& request, const RenderCallbacks& callbacks) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    requireSupported(request.scene);

    auto scene = reference::prepareScene(request.scene, request.projectDir);
    const IntegratorOptions options = optionsFrom(request.params);
    const reference::Integrator integrator(*scene, options);
    const int width = scene->width, height = scene->height;
    const int targetSpp = request.spp > 0 ? request.spp : kDefaultSpp;
    const uint32_t seed = uint32_t(request.seed ^ (request.seed >> 32));
    Accumulator acc(width, height);

    tbb::task_arena arena(request.threads > 0 ? request.threads : tbb::task_arena::automatic);
    int done = 0;
    int passSize = 1;
    auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
    std::atomic<long> nonFinite{0};

    while (done < targetSpp) {
        const int begin = done, end = std::min(targetSpp, done + passSize);
        const auto passStart = Clock::now();
        arena.execute([&] {
            tbb::parallel_for(
                tbb::blocked_range2d<int>(0, height, 8, 0, width, 8), [&](const tbb::blocked_range2d<int>& r) {
                    if (callbacks.cancel && callbacks.cancel->load(std::memory_order_relaxed)) return;
                    for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
                        for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
                            const uint32_t pixelSeed =
                                shader::hashCombine(shader::hashCombine(seed, uint32_t(x)), uint32_t(y));
                            const size_t p = size_t(y) * width + x;
                            for (int s = begin; s < end; ++s) {
                                const uint32_t stream = uint32_t(s) & 1u;
                                reference::SampleStream samples(shader::hashCombine(pixelSeed, stream),
                                                                uint32_t(s) >> 1u);
                                glm::vec2 jitter = samples.next2D();
                                glm::vec3 origin, dir;
                                shader::cameraRay(scene->camera, float(x) + jitter.x, float(y) + jitter.y, origin, dir);
                                glm::vec3 L = integrator.radiance(origin, dir, samples);
                                if (!std::isfinite(L.x) || !std::isfinite(L.y) || !std::isfinite(L.z)) {
                                    nonFinite.fetch_add(1, std::memory_order_relaxed);
                                    L = glm::vec3(0.0f);
                                }
                                (stream == 0 ? acc.sumA[p] : acc.sumB[p]) += glm::dvec3(L);
                            }
                        }
                    }
                });
        });
        if (callbacks.cancel && callbacks.cancel->load()) throw Cancelled();
        done = end;
        const double passSeconds = std::chrono::duration<double>(Clock::now() - passStart).count();
        const double total = elapsed();
        if (callbacks.progress) callbacks.progress(progressFraction(done, targetSpp, total, request.timeLimit));
        if (request.timeLimit > 0.0 && total >= request.timeLimit) break;
        if (callbacks.intermediate && done < targetSpp) callbacks.intermediate(resolve(acc, done), done);
        // Grow passes while they are short, so that intermediate images come about every half second.
        const double perSample = passSeconds / double(end - begin);
        passSize = std::max(1, std::min(passSize * 2, int(0.5 / std::max(perSample, 1e-6))));
        if (request.timeLimit > 0.0) {
            int remaining = int((request.timeLimit - total) / std::max(perSample, 1e-6));
            passSize = std::max(1, std::min(passSize, remaining));
        }
    }

    RenderResult result;
    result.spp = done;
    result.image = resolve(acc, done);
    result.seconds = elapsed();
    stampMetadata(result, request);
    result.image.metadata["mode"] = request.params.getEnum("mode");
    result.image.metadata["nonFiniteSamples"] = std::to_string(nonFinite.load());
    return result;
}

}  // namespace tyndall
