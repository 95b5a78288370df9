#include "ltsd/ltsd.h"

#include "ltsd/gpu_renderer.h"
#include "ltsd/prepared.h"

#include "tyndall/core/error.h"
#include "tyndall/core/text.h"
#include "tyndall/framework/renderer_pool.h"
#include "tyndall/framework/row_loop.h"
#include "tyndall/framework/stage_times.h"
#include "tyndall/gpu/context.h"
#include "tyndall/image/denoise.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace tyndall {

LtsdTechnique::LtsdTechnique() = default;
LtsdTechnique::~LtsdTechnique() = default;

std::vector<ParamInfo> LtsdTechnique::parameters() const {
    std::vector<ParamInfo> p;
    p.push_back(deviceParameter(
        "Where it runs: the GPU (Vulkan compute) or the CPU; auto takes the GPU, lavapipe included (1.3-3.4x "
        "faster there than the CPU path), and the CPU without Vulkan"));
    p.push_back({"nodes",
                 ParamType::Int,
                 "N of Eq. 15: quadrature nodes of the air-light per light (and per side of a two-sided light's "
                 "plane); the paper's quality/speed slider",
                 "",
                 1,
                 1024,
                 std::int64_t(8),
                 {},
                 true});
    p.push_back({"placement",
                 ParamType::Enum,
                 "Where the nodes go on each light's lit part of the ray: midpoint (N equal partitions, the paper), "
                 "transmittance (equal parts of the camera transmittance), equiangular (equal angles seen from the "
                 "light's centroid, dense near the light)",
                 "",
                 0,
                 0,
                 std::string("equiangular"),
                 ltsd::placementNames()});
    p.push_back({"transmittance",
                 ParamType::Enum,
                 "The aggregated transmittance towards a light: polygon (its mean over the light's solid angle, 9 "
                 "nodes per triangle; a few per cent) or min-distance (the paper's Eq. 10, e^(-sigma_t d) with d the "
                 "nearest distance to the light: +20 % of the image's energy at sigma_t ~ 1 /m)",
                 "",
                 0,
                 0,
                 std::string("polygon"),
                 ltsd::transmittanceNames()});
    p.push_back({"supersampling", ParamType::Int,
                 "S x S rays per pixel on a regular grid (a box filter like the reference's)", "", 1, 16,
                 std::int64_t(1)});
    p.push_back({"shadows",
                 ParamType::Enum,
                 "Shadows by the ratio estimators of Sec. 6 (Eq. 22-23): off (the unshadowed, noise-free image), ratio "
                 "(the raw Monte Carlo ratio per pixel), ratio-denoised (numerator and denominator denoised apart, "
                 "then divided)",
                 "",
                 0,
                 0,
                 std::string("ratio-denoised"),
                 ltsd::shadowNames()});
    p.push_back({"ratioSamples", ParamType::Int,
                 "Camera samples per pixel of the ratio estimators (one shadow ray per light and term each); a render "
                 "request's spp overrides it",
                 "spp", 1, 65536, std::int64_t(16), {}, true});
    p.push_back({"sMethod", ParamType::Enum,
                 "S, the phase function's integral over each light's polygon: accurate (the boundary form, 3 Gauss "
                 "nodes per edge, ~1e-5 relative for every g, no table) or paper (Eq. 21's fitted LTSDs: 5-12 % over "
                 "random polygons, tens of per cent on a small light near the phase function's peak)",
                 "", 0, 0, std::string("accurate"), ltsd::sMethodNames()});
    return p;
}

std::string LtsdTechnique::reduceForPreview(ParamSet& params, int factor) const {
    if (factor <= 1) return {};
    // A pixel's cost is about its nodes (Eq. 15's sum) plus its ratio samples' shadow rays: at 1/16 of the image
    // N = 500 would still take ~200 ms on two cores. Each by the factor, down to the defaults' order (8 nodes, 2
    // samples), and one ray per pixel.
    std::vector<std::string> what;
    if (shrinkForPreview(params, "nodes", factor, 8)) what.push_back("nodes");
    if (params.getEnum("shadows") != "off" && shrinkForPreview(params, "ratioSamples", factor, 2))
        what.push_back("samples");
    if (shrinkForPreview(params, "supersampling", factor, 1) && what.empty()) what.push_back("samples");
    if (what.empty()) return {};
    return "fewer " + (what.size() == 2 ? what[0] + " and " + what[1] : what[0]);
}

std::string LtsdTechnique::labelFor(const ParamSet& params) const {
    // Without shadows it is the paper's noise-free unshadowed image; with them, the ratio estimators of Sec. 6.
    // The paper's S is named, so that it and the accurate one can be told apart side by side.
    const std::string& shadows = params.getEnum("shadows");
    const std::string s = params.getEnum("sMethod") == "paper" ? ", paper's S" : "";
    return shadows == "off" ? "LTSD (unshadowed" + s + ")" : "LTSD (" + shadows + " shadows" + s + ")";
}

Support LtsdTechnique::supports(const HomogeneousMedium& medium) const {
    const std::string refusal = ltsdPhaseRefusal(toString(medium.phase.kind));
    if (!refusal.empty())
        return Support::no(std::string("the medium '") + medium.name + "' has a " + toString(medium.phase.kind) +
                           " phase function: " + refusal);
    if (medium.shape == MediumShape::ConvexPolyhedron && int(medium.planes.size()) > shader::kLtsdMaxPlanes)
        return Support::no("the medium '" + medium.name + "' has more than " + std::to_string(shader::kLtsdMaxPlanes) +
                           " faces");
    return Support::yes();
}

Support LtsdTechnique::supports(const ParticleMedium& medium) const {
    return Support::no("the particle medium '" + medium.name + "' is heterogeneous; LTSD needs a homogeneous one");
}

Support LtsdTechnique::supports(const PointLight& light) const {
    return Support::no("the point light '" + light.name +
                       "' subtends no solid angle; LTSD integrates over area lights' polygons (Pegoraro renders point "
                       "lights)");
}

Support LtsdTechnique::supports(const DirectionalLight& light) const {
    return Support::no("the directional light '" + light.name +
                       "' is not an area light; LTSD integrates over area lights' polygons");
}

Support LtsdTechnique::supports(const AreaLight& light) const {
    if (int(light.vertices.size()) > shader::kLtsdLightMaxVertices)
        return Support::no("the area light '" + light.name + "' has more than " +
                           std::to_string(shader::kLtsdLightMaxVertices) + " vertices");
    return Support::yes();
}

Support LtsdTechnique::supports(const Material&) const {
    return Support::yes();  // diffuse, and GGX isotropic or anisotropic through the LTC GGX tables
}

void LtsdTechnique::check(const RenderRequest& request) const {
    requireSupported(request.scene);
    (void)ltsd::prepareScene(request.scene, ltsd::settingsFrom(request.params), request.projectDir);
}

namespace {

// The analytic pass on the CPU: per pixel A-bar and T L_c-bar.
std::vector<glm::vec4> renderCpu(const ltsd::PreparedScene& scene, int width, int height, int threads,
                                 const RenderCallbacks& callbacks) {
    std::vector<glm::vec4> out(std::size_t(width) * height * 2);
    RowLoop(height, threads, callbacks, 0.0, 0.5)
        .run<ltsd::SceneScope>(
            [&](int y) {
                for (int x = 0; x < width; ++x) {
                    glm::vec3 air, surface;
                    shader::ltsdPixelTerms(scene.frame, x, y, air, surface);
                    const std::size_t i = std::size_t(y) * width + x;
                    out[2 * i] = glm::vec4(air, 0.0f);
                    out[2 * i + 1] = glm::vec4(surface, 0.0f);
                }
            },
            scene);
    return out;
}

// The ratio estimators' pass on the CPU: per pixel the sums of the four LtsdRatioTerms over `samples` camera samples.
std::vector<glm::vec4> renderRatioCpu(const ltsd::PreparedScene& scene, int width, int height, int samples,
                                      std::uint32_t seed, int threads, const RenderCallbacks& callbacks) {
    std::vector<glm::vec4> out(std::size_t(width) * height * 4);
    RowLoop(height, threads, callbacks, 0.5, 1.0)
        .run<ltsd::SceneScope>(
            [&](int y) {
                for (int x = 0; x < width; ++x) {
                    glm::vec3 sums[4] = {};
                    for (int k = 0; k < samples; ++k) {
                        const shader::LtsdRatioTerms r =
                            shader::ltsdRatioSample(scene.frame, x, y, std::uint32_t(k), seed);
                        sums[0] += r.airNumerator;
                        sums[1] += r.airDenominator;
                        sums[2] += r.surfaceNumerator;
                        sums[3] += r.surfaceDenominator;
                    }
                    const std::size_t i = std::size_t(y) * width + x;
                    for (int t = 0; t < 4; ++t)
                        out[4 * i + t] = glm::vec4(sums[t], 0.0f);
                }
            },
            scene);
    return out;
}

// A channel set of one term of the ratio sums (t = 0..3) as an image.
Image ratioTerm(const std::vector<glm::vec4>& sums, int width, int height, int term) {
    Image image(width, height, {"R", "G", "B"});
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c)
                image.at(x, y, c) = sums[4 * (std::size_t(y) * width + x) + term][c];
    return image;
}

}  // namespace

RenderResult LtsdTechnique::render(const RenderRequest& request, const RenderCallbacks& callbacks) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    StageTimes times;
    requireSupported(request.scene);
    const ltsd::Settings settings = ltsd::settingsFrom(request.params);
    const ltsd::PreparedScene scene = ltsd::prepareScene(request.scene, settings, request.projectDir);
    times.mark("prepare");
    const int width = request.scene.camera.width, height = request.scene.camera.height;

    const bool onGpu = runsOnGpu(settings.device, AutoDevice::AnyGpu);
    const bool shadows = settings.shadows != ltsd::kShadowsOff && scene.surfaces.triangleCount > 0;
    const int ratioSamples =
        request.spp > 0 && request.spp < RenderRequest::kUnboundedSpp ? request.spp : settings.ratioSamples;
    const std::uint32_t seed = std::uint32_t(request.seed ^ (request.seed >> 32));
    // The passes' values: the CPU path's own, or the GPU renderer's (kept there from render to render).
    std::vector<glm::vec4> cpuTerms, cpuSums;
    const std::vector<glm::vec4>* terms = &cpuTerms;
    const std::vector<glm::vec4>* sums = &cpuSums;
    // The process's renderers (framework/renderer_pool.h), leased until the values are resolved.
    RendererPool<ltsd::GpuRenderer>::Lease renderer;
    std::string deviceName = "cpu";
    double longestSliceMs = 0.0, gpuMs = 0.0, compileSeconds = 0.0;
    double primaryHitsMs = 0.0, ratioMs = 0.0;  // of gpuMs: the camera hits, the ratio estimators' pass
    std::string primaryVisibility;
    if (onGpu) {
        renderer = RendererPool<ltsd::GpuRenderer>::lease();
        ltsd::GpuOutput g = renderer->render(scene, width, height, callbacks, times);
        terms = g.values;
        deviceName = g.deviceName;
        longestSliceMs = g.longestSliceMs;
        gpuMs = g.gpuMs;
        primaryHitsMs = g.primaryHitsMs;
        compileSeconds = g.compileSeconds;
        primaryVisibility = g.primaryVisibility;
        if (shadows) {
            ltsd::GpuOutput r = renderer->renderRatio(scene, width, height, ratioSamples, seed, callbacks, times);
            sums = r.values;
            longestSliceMs = std::max(longestSliceMs, r.longestSliceMs);
            gpuMs += r.gpuMs;
            ratioMs = r.gpuMs;
            compileSeconds += r.compileSeconds;
        }
    } else {
        cpuTerms = renderCpu(scene, width, height, request.threads, callbacks);
        times.mark("analytic pass");
        if (shadows) cpuSums = renderRatioCpu(scene, width, height, ratioSamples, seed, request.threads, callbacks);
        times.mark("ratio pass");
    }

    // Eq. 23: L = A-bar <R_A> + T L_c-bar <R_C>, each ratio from its numerator and denominator, denoised apart or raw.
    // Where a denominator is zero (no unshadowed sample reached the light) the ratio is 1: nothing says it is shadowed,
    // and the analytic term is then small itself.
    Image ratioAir, ratioSurface;
    if (shadows) {
        DenoiseGuides guides;
        const SurfaceGuides surface = centreRayGuides(scene.surfaces, scene.frame.camera, width, height);
        Image unshadowed(width, height, {"R", "G", "B"});
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const std::size_t i = std::size_t(y) * width + x;
                for (int c = 0; c < 3; ++c)
                    unshadowed.at(x, y, c) = (*terms)[2 * i][c] + (*terms)[2 * i + 1][c];
            }
        guides.depth = &surface.depth;
        guides.normal = &surface.normal;
        guides.guide = &unshadowed;
        DenoiseSettings denoiseSettings;
        denoiseSettings.ratioFallback = 1.0f;
        const bool denoised = settings.shadows == ltsd::kShadowsRatioDenoised;
        ratioAir = denoiseRatio(ratioTerm(*sums, width, height, 0), ratioTerm(*sums, width, height, 1), nullptr, guides,
                                denoiseSettings, denoised);
        ratioSurface = denoiseRatio(ratioTerm(*sums, width, height, 2), ratioTerm(*sums, width, height, 3), nullptr,
                                    guides, denoiseSettings, denoised);
    }

    RenderResult result;
    result.image = Image(width, height, {"R", "G", "B", "unshadowed.R", "unshadowed.G", "unshadowed.B"});
    std::size_t nonFinite = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t i = std::size_t(y) * width + x;
            for (int c = 0; c < 3; ++c) {
                const float air = (*terms)[2 * i][c], surface = (*terms)[2 * i + 1][c];
                float value = air + surface;
                if (shadows) value = air * ratioAir.at(x, y, c) + surface * ratioSurface.at(x, y, c);
                const bool finite = std::isfinite(value) && std::isfinite(air + surface);
                if (!finite) ++nonFinite;
                result.image.at(x, y, c) = finite ? value : 0.0f;
                result.image.at(x, y, 3 + c) = finite ? air + surface : 0.0f;
            }
        }
    if (callbacks.progress) callbacks.progress(1.0);
    times.mark("resolve");
    result.spp = shadows ? ratioSamples : 1;
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    stampMetadata(result, request);
    auto& meta = result.image.metadata;
    meta["device"] = deviceName;
    meta["nonFiniteSamples"] = std::to_string(nonFinite);
    if (scene.frame.hasMedium != 0) {
        meta["ltsd:sMethod"] = ltsd::sMethodNames()[std::size_t(settings.sMethod)];
        meta["ltsd:table"] = scene.tablePath.empty() ? "none" : scene.tablePath;
        meta["ltsd:g"] = formatShort(scene.g);
    }
    if (!scene.ltcTablePath.empty()) meta["ltsd:ltcTable"] = scene.ltcTablePath;
    if (!scene.ltcAnisotropicTablePath.empty()) meta["ltsd:ltcAnisotropicTable"] = scene.ltcAnisotropicTablePath;
    meta["ltsd:shadows"] = shadows ? ltsd::shadowNames()[std::size_t(settings.shadows)] : "off";
    times.writeTo(meta);
    if (onGpu) {
        meta["gpu:longestSliceMs"] = formatShort(longestSliceMs);
        meta["gpu:totalMs"] = formatShort(gpuMs);
        // Each pass's share (tyndall_gpu_frames_bench reports them): camera hits, the analytic air-light, the ratios.
        meta["gpu:primaryHitsMs"] = formatShort(primaryHitsMs);
        meta["gpu:airLightMs"] = formatShort(gpuMs - primaryHitsMs - ratioMs);
        if (shadows) meta["gpu:ratioMs"] = formatShort(ratioMs);
        meta["gpu:compileSeconds"] = formatShort(compileSeconds);
        if (!primaryVisibility.empty()) meta["primaryVisibility"] = primaryVisibility;
    }
    return result;
}

}  // namespace tyndall
