#include "reference/reference.h"

#include "reference/integrator.h"
#include "shared/singular_pixel.h"
#include "tyndall/core/error.h"
#include "tyndall/framework/progressive.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <optional>

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
        i.name = "equiangular";
        i.type = ParamType::Enum;
        i.doc =
            "the light-targeted distances: shaped, towards point lights in homogeneous media by a 16-bin table of "
            "the rest of the single-scattering integrand along the ray (both transmittances, the phase function, a "
            "spot's profile), and about area lights softened by the light's size (the inverse square of the distance "
            "to the centroid plus area / (4 pi)); or plain equiangular (Kulla & Fajardo) for both";
        i.enumValues = {"shaped", "plain"};
        i.defaultValue = std::string("shaped");
        p.push_back(i);
    }
    {
        ParamInfo i;
        i.name = "lightSampling";
        i.type = ParamType::Enum;
        i.doc =
            "how directions to area lights are chosen: auto adds phase sampling to light sampling in media with a "
            "peaked phase function (4 pi p >= 80, HG |g| >= 0.848) and BSDF sampling on glossy surfaces; mis: MIS of "
            "both everywhere; light sampling only; or phase/BSDF sampling only";
        i.enumValues = {"auto", "mis", "light", "phase"};
        i.defaultValue = std::string("auto");
        p.push_back(i);
    }
    {
        ParamInfo i;
        i.name = "pixelJitter";
        i.type = ParamType::Enum;
        i.doc =
            "where in a pixel the camera rays go: auto jitters the pixels within 4 px of a point light's image (in a "
            "scene with a medium) with a density proportional to 1 / (distance to the image), which cancels the 1/h "
            "peak of the light scattered towards the camera; uniform jitters every pixel uniformly. Both are "
            "unbiased box-filter estimates";
        i.enumValues = {"auto", "uniform"};
        i.defaultValue = std::string("auto");
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
    o.shapedEquiangular = params.getEnum("equiangular") == "shaped";
    const std::string& l = params.getEnum("lightSampling");
    o.light = l == "light"   ? reference::LightStrategy::LightSampling
              : l == "phase" ? reference::LightStrategy::PhaseSampling
              : l == "mis"   ? reference::LightStrategy::Mis
                             : reference::LightStrategy::Auto;
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
    Image image(acc.width, acc.height, estimateChannels());
    int nA = (spp + 1) / 2, nB = spp / 2;
    for (int y = 0; y < acc.height; ++y) {
        for (int x = 0; x < acc.width; ++x) {
            size_t i = size_t(y) * acc.width + x;
            glm::dvec3 mean = (acc.sumA[i] + acc.sumB[i]) / double(std::max(spp, 1));
            const glm::dvec3 variance =
                nA > 0 && nB > 0 ? varianceOfMean(acc.sumA[i] / double(nA), acc.sumB[i] / double(nB)) : glm::dvec3(0.0);
            writeEstimate(image, x, y, glm::vec3(mean), glm::vec3(variance));  // finite: non-finite samples are dropped
        }
    }
    return image;
}

// The image points of the point lights, when the scene has a medium (the 1/h peak of the light scattered towards the
// camera is there wherever the light is inside one). The pixels within kReach of such a point are jittered with a
// density proportional to 1 / (distance to the point) (singularPixelTry), which cancels the peak: uniform jitter
// has an infinite variance in the pixel that holds the point and a large one in its neighbours (docs/reference.md).
struct SingularPoints {
    std::vector<glm::vec2> points;
    // Beyond 4 px, 1/r varies by at most a quarter across a pixel and uniform jitter does nearly as well (fog-point,
    // 128 x 128, 64 spp, two pairs of seeds: a reach of 2 and 8 px gave 1.16 and 0.97 times the RMSE at 4 px, 0 px
    // (only the pixels that hold the point) 2.5 times).
    static constexpr float kReach = 4.0f;

    SingularPoints(const reference::RenderScene& scene, bool enabled) {
        if (!enabled) return;
        for (const reference::PreparedPointLight& l : scene.pointLights) {
            glm::vec2 p;
            if (!shader::cameraProject(scene.camera, l.position, p)) continue;
            if (!(p.x > -kReach - 1.0f && p.y > -kReach - 1.0f && p.x < float(scene.width) + kReach + 1.0f &&
                  p.y < float(scene.height) + kReach + 1.0f))
                continue;
            points.push_back(p);
        }
    }

    // Pixel (x, y) prepared for jittering about the nearest point within kReach, or nothing for uniform jitter.
    std::optional<shader::SingularPixel> near(int x, int y) const {
        float best = kReach;
        const glm::vec2* nearest = nullptr;
        for (const glm::vec2& p : points) {
            const glm::vec2 q = glm::clamp(p, glm::vec2(float(x), float(y)), glm::vec2(float(x + 1), float(y + 1)));
            const float d = glm::length(q - p);
            if (d <= best) {
                best = d;
                nearest = &p;
            }
        }
        if (!nearest) return std::nullopt;
        const shader::SingularPixel pixel = shader::singularPixelSetup(x, y, *nearest);
        if (!(shader::singularPixelMeasure(pixel) > 0.0f)) return std::nullopt;
        return pixel;
    }
};

// The image point of a sample of pixel (x, y) and its weight: uniform jitter, or about a singular point by rejection
// (the first try takes the sample's Sobol pair; further tries, needed only outside the point's own pixel, take the
// stream's extra numbers: about 54 % of the tries land just beside the point, 14 % 4 px away diagonally).
glm::vec3 jitter(int x, int y, const glm::vec2& u, const std::optional<shader::SingularPixel>& singular,
                 reference::SampleStream& samples) {
    if (!singular) return glm::vec3(float(x) + u.x, float(y) + u.y, 1.0f);
    const float measure = shader::singularPixelMeasure(*singular);
    glm::vec2 v = u;
    for (int attempt = 0; attempt < 256; ++attempt) {
        const glm::vec2 q = shader::singularPixelTry(*singular, v);
        if (shader::singularPixelContains(*singular, q)) return glm::vec3(q, measure * glm::length(q - singular->p));
        v = glm::vec2(samples.extra(), samples.extra());
    }
    return glm::vec3(float(x) + u.x, float(y) + u.y, 1.0f);  // 0.86^256 = 2^-56 at worst: no measurable bias
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
    const SingularPoints singular(*scene, request.params.getEnum("pixelJitter") == "auto" &&
                                              !(scene->media.empty()));

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
                            const std::optional<shader::SingularPixel> warped = singular.near(x, y);
                            for (int s = begin; s < end; ++s) {
                                const uint32_t stream = uint32_t(s) & 1u;
                                reference::SampleStream samples(shader::hashCombine(pixelSeed, stream),
                                                                uint32_t(s) >> 1u);
                                const glm::vec2 u = samples.next2D();
                                const glm::vec3 image = jitter(x, y, u, warped, samples);
                                glm::vec3 origin, dir;
                                shader::cameraRay(scene->camera, image.x, image.y, origin, dir);
                                glm::vec3 L = image.z * integrator.radiance(origin, dir, samples);
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
