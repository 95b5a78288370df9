#include "wvds/wvds.h"

#include "wvds/gpu_renderer.h"
#include "wvds/prepared.h"

#include "tyndall/core/error.h"
#include "tyndall/core/text.h"
#include "tyndall/framework/progressive.h"
#include "tyndall/framework/renderer_pool.h"
#include "tyndall/framework/row_loop.h"
#include "tyndall/framework/stage_times.h"
#include "tyndall/image/denoise.h"
#include "tyndall/image/metrics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace tyndall {

using wvds::PreparedScene;
using wvds::Settings;

WvdsTechnique::WvdsTechnique() = default;
WvdsTechnique::~WvdsTechnique() = default;

std::vector<ParamInfo> WvdsTechnique::parameters() const {
    std::vector<ParamInfo> p;
    p.push_back({"estimator",
                 ParamType::Enum,
                 "mcwvds: whole-volume distance sampling (Sec. 6); reds / rees: ratio estimators with distance / "
                 "jittered equidistant samples (Eq. 3); rm: jittered ray marching; mcds: distance sampling; analytic: "
                 "the unoccluded integral alone (Sec. 4, no shadows)",
                 "",
                 0,
                 0,
                 std::string("mcwvds"),
                 wvds::estimatorNames()});
    p.push_back({"samplesPerPixel", ParamType::Int,
                 "Camera rays per pixel, jittered in the pixel (a box filter like the reference's), when the render "
                 "does not ask for a number",
                 "spp", 1, 65536, std::int64_t(16), {}, true});
    p.push_back({"raySamples", ParamType::Int, "Distance samples along each camera ray, each with a shadow ray (N_sample)",
                 "", 1, 64, std::int64_t(1)});
    p.push_back({"shadows", ParamType::Bool,
                 "Visibility of the light by shadow rays through the BVH; off: the unoccluded image", "", 0, 1, true});
    p.push_back({"lightSelection",
                 ParamType::Enum,
                 "With several lights, mcwvds and mcds pick one light per sample with probability proportional to its "
                 "unoccluded radiance (unoccluded) or sample every light (all); the other estimators sample every light",
                 "",
                 0,
                 0,
                 std::string("unoccluded"),
                 {"unoccluded", "all"}});
    p.push_back(deviceParameter(
        "Where the estimators run: the GPU (Vulkan compute) or the CPU; auto takes the GPU unless the only "
        "Vulkan device is a software one (lavapipe)"));
    p.push_back({"pdfScale", ParamType::Float,
                 "Scales the pdf of the Monte Carlo estimators (the analytic term of the ratio estimators): 1 is "
                 "unbiased; other values bias the image by 1 / pdfScale, to show that a convergence test detects it",
                 "", 0.5, 2.0, 1.0});
    p.push_back({"denoise", ParamType::Bool,
                 "Ratio estimators (reds, rees): denoise each light's numerator and denominator separately, with the "
                 "same edge-aware weights guided by depth, before the ratio (docs/denoise.md); the variance channels "
                 "stay those of the raw estimate. Other estimators ignore it",
                 "", 0, 1, false});
    return p;
}

Support WvdsTechnique::supports(const HomogeneousMedium& medium) const {
    if (medium.shape == MediumShape::Infinite)
        return Support::no("the medium '" + medium.name +
                           "' is infinite; WVDS integrates collimated light in a bounded convex medium (an infinite one "
                           "extinguishes it completely)");
    if (medium.shape == MediumShape::ConvexPolyhedron && int(medium.planes.size()) > shader::kWvdsMaxPlanes)
        return Support::no("the medium '" + medium.name + "' has more than " + std::to_string(shader::kWvdsMaxPlanes) +
                           " faces");
    return Support::yes();
}

Support WvdsTechnique::supports(const ParticleMedium& medium) const {
    return Support::no("the particle medium '" + medium.name + "' is heterogeneous; WVDS needs a homogeneous one");
}

Support WvdsTechnique::supports(const PointLight& light) const {
    return Support::no("the point light '" + light.name + "' is not collimated; WVDS takes directional lights");
}

Support WvdsTechnique::supports(const DirectionalLight& light) const {
    if (int(light.gobo.size()) > shader::kWvdsMaxGoboPlanes)
        return Support::no("the gobo of '" + light.name + "' has more than " +
                           std::to_string(shader::kWvdsMaxGoboPlanes) + " vertices");
    return Support::yes();
}

Support WvdsTechnique::supports(const AreaLight& light) const {
    return Support::no("the area light '" + light.name + "' is not collimated; WVDS takes directional lights");
}

namespace {

// Accumulators: per pixel and half (even, odd camera samples), `stride` vec4s: the direct sum (w counts the samples),
// then per light of a ratio estimator its analytic term, numerator and denominator.
struct Layout {
    int width = 0, height = 0, stride = 1, ratioLights = 0;
    std::size_t size() const { return std::size_t(width) * height * 2 * stride; }
};

void addSamplesCpu(const PreparedScene& scene, const Layout& layout, std::vector<glm::vec4>& acc, std::uint32_t first,
                   std::uint32_t end, int threads, const RenderCallbacks& callbacks, std::atomic<long>& nonFinite) {
    RowLoop(layout.height, threads, callbacks.cancel)
        .run<wvds::SceneScope>(
            [&](int y) {
                for (int x = 0; x < layout.width; ++x) {
                    const std::size_t pixel = std::size_t(y) * layout.width + x;
                    for (std::uint32_t s = first; s < end; ++s) {
                        const shader::WvdsTerms t = shader::wvdsSample(scene.frame, x, y, s);
                        glm::vec4* a = &acc[(pixel * 2 + (s & 1u)) * layout.stride];
                        bool finite = std::isfinite(t.direct.x + t.direct.y + t.direct.z);
                        for (int l = 0; l < layout.ratioLights; ++l)
                            finite = finite && std::isfinite(glm::dot(t.analytic[l] + t.numerator[l] + t.denominator[l],
                                                                      glm::vec3(1.0f)));
                        a[0].w += 1.0f;
                        if (!finite) {
                            nonFinite.fetch_add(1, std::memory_order_relaxed);
                            continue;
                        }
                        a[0] += glm::vec4(t.direct, 0.0f);
                        for (int l = 0; l < layout.ratioLights; ++l) {
                            a[1 + 3 * l] += glm::vec4(t.analytic[l], 0.0f);
                            a[2 + 3 * l] += glm::vec4(t.numerator[l], 0.0f);
                            a[3 + 3 * l] += glm::vec4(t.denominator[l], 0.0f);
                        }
                    }
                }
            },
            scene);
}

// The pixel's value from accumulators of one half (h = 0, 1) or both (h = 2). Ratio estimators divide the sums of all
// samples, not per-sample ratios (Eq. 3 accumulated progressively).
// With `ratios` (h = 2 only), each light's ratio is read from its denoised image instead of the pixel's sums.
glm::vec3 pixelValue(const glm::vec4* a0, const glm::vec4* a1, int ratioLights, int h,
                     const std::vector<Image>* ratios = nullptr, int x = 0, int y = 0) {
    auto sum = [&](int i) {
        return h == 0 ? glm::vec4(a0[i]) : h == 1 ? glm::vec4(a1[i]) : glm::vec4(a0[i]) + glm::vec4(a1[i]);
    };
    const glm::vec4 direct = sum(0);
    const float n = direct.w;
    if (!(n > 0.0f)) return glm::vec3(0.0f);
    glm::vec3 value = glm::vec3(direct) / n;
    for (int l = 0; l < ratioLights; ++l) {
        const glm::vec3 analytic = glm::vec3(sum(1 + 3 * l)) / n;
        if (ratios) {
            for (int c = 0; c < 3; ++c) value[c] += analytic[c] * (*ratios)[std::size_t(l)].at(x, y, c);
            continue;
        }
        const glm::vec3 numerator = glm::vec3(sum(2 + 3 * l)), denominator = glm::vec3(sum(3 + 3 * l));
        for (int c = 0; c < 3; ++c)
            if (denominator[c] > 0.0f) value[c] += analytic[c] * numerator[c] / denominator[c];
    }
    return value;
}

// R, G, B and the variance of each pixel's mean from its two halves, (A - B)^2 / 4, as the reference writes it. Rows in
// parallel: this runs after every progressive pass, so it is on the way from an edit to its first image.
// Each light's ratio of separately denoised numerator and denominator sums (Eq. 22-23 of the LTSD paper (000), as
// issue 18 asks of the ratio estimators), guided by `depth`; the ratio's variance from the two halves.
std::vector<Image> denoisedRatios(const std::vector<glm::vec4>& acc, const Layout& layout, const Image& depth) {
    std::vector<Image> ratios;
    for (int l = 0; l < layout.ratioLights; ++l) {
        Image num = Image::rgb(layout.width, layout.height), den = Image::rgb(layout.width, layout.height);
        Image variance(layout.width, layout.height, {"variance.R", "variance.G", "variance.B"});
        for (int y = 0; y < layout.height; ++y)
            for (int x = 0; x < layout.width; ++x) {
                const std::size_t pixel = std::size_t(y) * layout.width + x;
                const glm::vec4* a0 = &acc[(pixel * 2) * layout.stride];
                const glm::vec4* a1 = &acc[(pixel * 2 + 1) * layout.stride];
                for (int c = 0; c < 3; ++c) {
                    const float n0 = a0[2 + 3 * l][c], n1 = a1[2 + 3 * l][c];
                    const float d0 = a0[3 + 3 * l][c], d1 = a1[3 + 3 * l][c];
                    const bool ok = std::isfinite(n0 + n1 + d0 + d1);
                    num.at(x, y, c) = ok ? n0 + n1 : 0.0f;
                    den.at(x, y, c) = ok ? d0 + d1 : 0.0f;
                    const float r0 = d0 > 0.0f ? n0 / d0 : 0.0f, r1 = d1 > 0.0f ? n1 / d1 : 0.0f;
                    const float v = (r0 - r1) * (r0 - r1) * 0.25f;
                    variance.at(x, y, c) = ok && std::isfinite(v) ? v : 0.0f;
                }
            }
        ratios.push_back(denoiseRatio(num, den, &variance, {&depth, nullptr, nullptr}, DenoiseSettings{}));
    }
    return ratios;
}

Image resolve(const std::vector<glm::vec4>& acc, const Layout& layout, int threads, long& nonFinitePixels,
              const Image* denoiseDepth = nullptr) {
    Image image(layout.width, layout.height, estimateChannels());
    std::atomic<long> nonFinite{0};
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    std::vector<Image> ratios;
    if (denoiseDepth && layout.ratioLights > 0)
        arena.execute([&] { ratios = denoisedRatios(acc, layout, *denoiseDepth); });
    const std::vector<Image>* ratioImages = ratios.empty() ? nullptr : &ratios;
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, layout.height, 8), [&](const tbb::blocked_range<int>& rows) {
            long bad = 0;
            for (int y = rows.begin(); y < rows.end(); ++y) {
                for (int x = 0; x < layout.width; ++x) {
                    const std::size_t pixel = std::size_t(y) * layout.width + x;
                    const glm::vec4* a0 = &acc[(pixel * 2) * layout.stride];
                    const glm::vec4* a1 = &acc[(pixel * 2 + 1) * layout.stride];
                    const glm::vec3 v = pixelValue(a0, a1, layout.ratioLights, 2, ratioImages, x, y);
                    const glm::vec3 variance = a0[0].w > 0.0f && a1[0].w > 0.0f
                                                   ? varianceOfMean(pixelValue(a0, a1, layout.ratioLights, 0),
                                                                    pixelValue(a0, a1, layout.ratioLights, 1))
                                                   : glm::vec3(0.0f);
                    if (!writeEstimate(image, x, y, v, variance)) ++bad;
                }
            }
            nonFinite.fetch_add(bad, std::memory_order_relaxed);
        });
    });
    nonFinitePixels = nonFinite.load();
    return image;
}

}  // namespace

void WvdsTechnique::check(const RenderRequest& request) const {
    requireSupported(request.scene);
    (void)wvds::prepareScene(request.scene, wvds::settingsFrom(request.params), request.seed, request.projectDir);
}

RenderResult WvdsTechnique::render(const RenderRequest& request, const RenderCallbacks& callbacks) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    StageTimes times;
    requireSupported(request.scene);
    const Settings settings = wvds::settingsFrom(request.params);
    const PreparedScene scene = wvds::prepareScene(request.scene, settings, request.seed, request.projectDir);
    times.mark("prepare");
    const int spp = request.spp > 0 ? request.spp : settings.samplesPerPixel;

    Layout layout;
    layout.width = request.scene.camera.width;
    layout.height = request.scene.camera.height;
    layout.ratioLights = shader::wvdsIsRatio(settings.estimator) ? scene.frame.lightCount : 0;
    layout.stride = 1 + 3 * layout.ratioLights;

    const bool onGpu = runsOnGpu(settings.device, AutoDevice::HardwareGpu);
    // The denoiser's depth guide, once per render.
    const bool denoise = settings.denoise && layout.ratioLights > 0;
    const Image depth =
        denoise ? centreRayGuides(scene.surfaces, scene.frame.camera, layout.width, layout.height).depth : Image();
    std::vector<glm::vec4> acc;  // the CPU path's accumulators
    RendererPool<wvds::GpuRenderer>::Lease renderer;  // the process's renderers (framework/renderer_pool.h)
    if (onGpu) renderer = RendererPool<wvds::GpuRenderer>::lease();
    if (onGpu) {
        renderer->begin(scene, layout.width, layout.height, layout.stride, layout.ratioLights);
    } else {
        acc.assign(layout.size(), glm::vec4(0.0f));
    }

    times.mark("upload");

    // Passes of 1, 1, 2, 4, ... camera samples until spp or the time limit (framework/progressive.h). Each stage's time
    // sums over the passes.
    std::atomic<long> nonFiniteSamples{0};
    long nonFinitePixels = 0;
    auto addSamples = [&](std::uint32_t first, std::uint32_t end, const RenderCallbacks& pass) {
        if (onGpu)
            renderer->addSamples(first, end, pass);
        else
            addSamplesCpu(scene, layout, acc, first, end, request.threads, pass, nonFiniteSamples);
        times.mark("samples");
    };
    ProgressiveResult progressive = renderProgressively(request, spp, callbacks, start, addSamples, [&] {
        const std::vector<glm::vec4>& values = onGpu ? renderer->readAccumulators() : acc;
        times.mark("readback");
        Image image = resolve(values, layout, request.threads, nonFinitePixels, denoise ? &depth : nullptr);
        times.mark("resolve");
        return image;
    });
    RenderResult result;
    result.image = std::move(progressive.image);
    result.spp = progressive.spp;
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    stampMetadata(result, request);
    auto& meta = result.image.metadata;
    times.writeTo(meta);
    meta["device"] = onGpu ? renderer->context().device().name : "cpu";
    meta["wvds:estimator"] = wvds::estimatorNames()[std::size_t(settings.estimator)];
    if (denoise) meta["wvds:denoise"] = "numerator and denominator denoised separately (variance channels: raw)";
    meta["nonFiniteSamples"] = std::to_string(nonFiniteSamples.load() + nonFinitePixels);
    if (onGpu) {
        meta["gpu:longestSliceMs"] = formatShort(renderer->longestSliceMs());
        meta["gpu:totalMs"] = formatShort(renderer->gpuMs());
        meta["gpu:compileSeconds"] = formatShort(renderer->compileSeconds());
    }
    return result;
}

// ---------------------------------------------------------------------------------------------------------------------
// Probes

std::vector<ProbeInfo> WvdsTechnique::probes() const {
    return {{"distances",
             "Histograms (256 bins) of the distances that whole-volume distance sampling, distance sampling and "
             "equidistant sampling draw along the pixel's centre ray, with their analytic pdfs (Fig. 4, 5)"},
            {"convergence",
             "relMSE of each estimator against a converged MCWVDS image at 1, 2, 4, ... spp (Fig. 7); the pixel is "
             "ignored"}};
}

namespace {

ProbeResult distanceProbe(const PreparedScene& scene, const Scene& sceneModel, int px, int py) {
    wvds::SceneScope scope(scene);
    const shader::WvdsFrame& f = scene.frame;
    ProbeResult r;
    r.xLabel = "distance along the camera ray t (m)";
    r.yLabel = "probability density (1/m)";
    glm::vec3 origin, dir;
    shader::cameraRay(f.camera, float(px) + 0.5f, float(py) + 0.5f, origin, dir);
    shader::BvhHit hit;
    const float tEnd = shader::bvhIntersect(origin, dir, 0.0f, shader::kInfinity, hit) ? hit.t : shader::kInfinity;
    float tIn = 0.0f, tOut = shader::kInfinity;
    const bool inMedium = shader::wvdsClip_float(0, f.planeCount, origin, dir, tIn, tOut) && tIn < tEnd;
    // The light that scatters the most along this ray.
    int best = -1;
    float bestWeight = 0.0f, a = 0.0f, b = 0.0f;
    shader::WvdsPieces_float pieces{};
    for (int i = 0; i < f.lightCount && inMedium; ++i) {
        const shader::WvdsLight light = shader::wvdsLight(i);
        float la, lb;
        if (!shader::wvdsLitInterval(light, origin, dir, tIn, std::min(tOut, tEnd), la, lb)) continue;
        shader::WvdsPieces_float p;
        shader::wvdsPieces_float(0, f.planeCount, origin, dir, light.toLight, tIn, la, lb, p);
        const float weight = shader::wvdsMean(light.irradiance) * shader::wvdsTotal_float(p, f.sigmaSample);
        if (weight > bestWeight) {
            best = i;
            bestWeight = weight;
            pieces = p;
            a = la;
            b = lb;
        }
    }
    char title[160];
    if (best < 0) {
        std::snprintf(title, sizeof title, "Pixel (%d, %d): the centre ray crosses no lit part of the medium", px, py);
        r.title = title;
        return r;
    }
    std::snprintf(title, sizeof title, "Sampled distances at pixel (%d, %d), light '%s', %d segment(s)", px, py,
                  sceneModel.directionalLights[std::size_t(best)].name.c_str(), pieces.count);
    r.title = title;

    constexpr int kBins = 256, kSamples = 1 << 16;
    const double width = double(b - a) / kBins;
    std::vector<double> centres(kBins);
    for (int i = 0; i < kBins; ++i)
        centres[i] = a + (i + 0.5) * width;
    auto histogram = [&](const std::string& label, auto&& sample) {
        ProbeSeries s{label + " samples", centres, std::vector<double>(kBins, 0.0)};
        for (int k = 0; k < kSamples; ++k) {
            // Stratified, jittered uniforms, as the paper's Fig. 4 and 5 use.
            const float jitter = shader::uintToUnitFloat(shader::hashUint(std::uint32_t(k) * 747796405u + 1u));
            const double t = sample((float(k) + jitter) / float(kSamples));
            const int bin = int((t - a) / width);
            if (bin >= 0 && bin < kBins) s.y[std::size_t(bin)] += 1.0;
        }
        for (double& y : s.y)
            y /= double(kSamples) * width;
        r.series.push_back(std::move(s));
    };
    auto density = [&](const std::string& label, auto&& pdf) {
        ProbeSeries s{label, centres, {}};
        for (double t : centres)
            s.y.push_back(pdf(float(t)));
        r.series.push_back(std::move(s));
    };
    const float sigma = f.sigmaSample;
    histogram("whole-volume distance sampling", [&](float u) {
        float pdf, path;
        return shader::wvdsSample_float(pieces, sigma, u, pdf, path);
    });
    density("whole-volume pdf (Eq. 11)", [&](float t) { return shader::wvdsPdf_float(pieces, sigma, t); });
    histogram("distance sampling", [&](float u) {
        float pdf;
        return shader::wvdsDistanceSample_float(sigma, a, b, u, pdf);
    });
    density("distance sampling pdf", [&](float t) { return shader::wvdsDistancePdf_float(sigma, a, b, t); });
    histogram("equidistant", [&](float u) { return a + u * (b - a); });
    density("equidistant pdf", [&](float) { return 1.0f / (b - a); });
    return r;
}

}  // namespace

ProbeResult WvdsTechnique::probe(const RenderRequest& request, const std::string& probeName, int x, int y) {
    requireSupported(request.scene);
    const Settings settings = wvds::settingsFrom(request.params);
    if (probeName == "distances") {
        const Camera& cam = request.scene.camera;
        if (x < 0 || y < 0 || x >= cam.width || y >= cam.height)
            throw InputError(InputLocation{"", 0, 0, "pixel"},
                             "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                                 std::to_string(cam.width) + " x " + std::to_string(cam.height) + " image");
        const PreparedScene scene = wvds::prepareScene(request.scene, settings, request.seed, request.projectDir);
        return distanceProbe(scene, request.scene, x, y);
    }
    if (probeName == "convergence") {
        const int maxSpp = request.spp > 0 ? request.spp : 64;
        RenderRequest converged = request;
        converged.params.set("estimator", std::string("mcwvds"));
        converged.spp = 8 * maxSpp;
        converged.seed = request.seed ^ 0x9e3779b97f4a7c15ull;
        converged.timeLimit = 0.0;
        const Image reference = render(converged, RenderCallbacks{}).image;
        ProbeResult r;
        r.title = "Convergence against MCWVDS at " + std::to_string(converged.spp) + " spp";
        r.xLabel = "samples per pixel";
        r.yLabel = "relMSE";
        for (const char* estimator : {"mcwvds", "reds", "rees", "rm", "mcds"}) {
            RenderRequest one = request;
            one.params.set("estimator", std::string(estimator));
            one.spp = maxSpp;
            one.timeLimit = 0.0;
            ProbeSeries s{estimator, {}, {}};
            RenderCallbacks callbacks;
            callbacks.intermediate = [&](const Image& image, int spp) {
                s.x.push_back(spp);
                s.y.push_back(computeMetrics(image, reference).relMSE);
            };
            const RenderResult last = render(one, callbacks);
            s.x.push_back(last.spp);
            s.y.push_back(computeMetrics(last.image, reference).relMSE);
            r.series.push_back(std::move(s));
        }
        return r;
    }
    return Technique::probe(request, probeName, x, y);
}

}  // namespace tyndall
