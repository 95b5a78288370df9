#include "pegoraro/pegoraro.h"

#include "pegoraro/gpu_renderer.h"
#include "pegoraro/prepared.h"

#include "tyndall/core/error.h"
#include "tyndall/core/text.h"
#include "tyndall/framework/renderer_pool.h"
#include "tyndall/framework/row_loop.h"
#include "tyndall/framework/stage_times.h"

#include <atomic>
#include <chrono>
#include <cmath>

namespace tyndall {

using pegoraro::Precision;
using pegoraro::PreparedScene;
using pegoraro::Settings;

PegoraroTechnique::PegoraroTechnique() = default;
PegoraroTechnique::~PegoraroTechnique() = default;

std::vector<ParamInfo> PegoraroTechnique::parameters() const {
    std::vector<ParamInfo> p;
    p.push_back(deviceParameter(
        "Where the closed form runs: the GPU (Vulkan compute) or the CPU; auto takes the GPU unless the only "
        "Vulkan device is a software one (lavapipe), where the CPU path is faster"));
    p.push_back({"precision",
                 ParamType::Enum,
                 "Arithmetic of the closed form: float is fast and good to ~1e-5 up to order 4; double to ~1e-10 up to "
                 "order 12; auto picks float on the GPU up to order 4 and double otherwise",
                 "",
                 0,
                 0,
                 std::string("auto"),
                 {"auto", "float", "double"}});
    p.push_back({"supersampling", ParamType::Int,
                 "S x S rays per pixel on a regular grid (a box filter like the reference's)", "", 1, 16,
                 std::int64_t(2)});
    p.push_back({"shadows", ParamType::Bool,
                 "Exact volumetric shadows (lit intervals of each ray) and shadow rays at surfaces; off: the paper's "
                 "unshadowed air-light",
                 "", 0, 1, true});
    p.push_back(
        {"hgTerms", ParamType::Int,
         "Terms of the Henyey-Greenstein expansion (order + 1); its truncation error is reported. The closed "
         "form is good to 1e-8 in double up to ~12 terms; at 16 terms to ~2e-5 for g = 0.7 and ~1e-3 for "
         "g = 0.9 (fewer with a spot, whose terms add); from ~20 terms it fails: fallback = auto then computes by "
         "quadrature, and fallback = never is refused where its error bound exceeds 1e-2. Float: up to ~5 terms",
         "", 1, pegoraro::kMaxHgTerms, std::int64_t(8)});
    p.push_back({"hgTolerance", ParamType::Float,
                 "If > 0, choose the Henyey-Greenstein terms instead of hgTerms: the fewest whose L1 truncation error "
                 "(the fraction of scattered power misplaced) is at most this; an error if 32 terms do not reach it",
                 "", 0.0, 0.5, 0.0});
    p.push_back({"hgExpansion",
                 ParamType::Enum,
                 "Henyey-Greenstein as truncated Legendre series (Eq. 11-13) or Taylor series (Eq. 14-16)",
                 "",
                 0,
                 0,
                 std::string("legendre"),
                 {"legendre", "taylor"}});
    p.push_back({"hgTaylorCentre", ParamType::Float, "The cosine mu_0 the Taylor expansion is centred on (Eq. 15)", "",
                 -0.9, 0.9, 0.0});
    p.push_back({"fallback",
                 ParamType::Enum,
                 "auto: adaptive quadrature where the closed form's error bound exceeds fallbackTolerance; never; "
                 "always (quadrature everywhere, for comparison)",
                 "",
                 0,
                 0,
                 std::string("auto"),
                 {"auto", "never", "always"}});
    p.push_back({"fallbackTolerance",
                 ParamType::Float,
                 "Relative error bound above which a pixel falls back",
                 "",
                 1e-10,
                 1.0,
                 1e-4,
                 {},
                 true});
    p.push_back({"quadratureTolerance",
                 ParamType::Float,
                 "Relative tolerance of the fallback quadrature",
                 "",
                 1e-10,
                 1e-2,
                 1e-6,
                 {},
                 true});
    return p;
}

Support PegoraroTechnique::supports(const HomogeneousMedium& medium) const {
    if (medium.shape != MediumShape::Infinite)
        return Support::no("the medium '" + medium.name +
                           "' is bounded; the closed form integrates along whole rays in an infinite medium");
    return Support::yes();
}

Support PegoraroTechnique::supports(const ParticleMedium& medium) const {
    return Support::no("the particle medium '" + medium.name +
                       "' is heterogeneous; the closed form needs a homogeneous one");
}

Support PegoraroTechnique::supports(const PointLight& light) const {
    if (light.distribution.polynomial().size() > std::size_t(kMaxLightTerms))
        return Support::no("the light '" + light.name + "' has more than " + std::to_string(kMaxLightTerms) +
                           " polynomial terms (spot exponent above " + std::to_string(kMaxLightTerms - 1) + ")");
    return Support::yes();
}

Support PegoraroTechnique::supports(const DirectionalLight& light) const {
    return Support::no("the directional light '" + light.name +
                       "' is not punctual; the closed form takes point lights");
}

Support PegoraroTechnique::supports(const AreaLight& light) const {
    return Support::no("the area light '" + light.name + "' is not punctual; the closed form takes point lights");
}

namespace {

struct CpuResult {
    std::vector<glm::vec4> radiance;  // rgb, fallbacks
    std::vector<std::uint32_t> overflows;
};

// The shared per-pixel renderer on the CPU, rows in parallel.
CpuResult renderCpu(const PreparedScene& scene, bool useDouble, int width, int height, int threads,
                    const RenderCallbacks& callbacks) {
    CpuResult out;
    out.radiance.resize(std::size_t(width) * height);
    out.overflows.resize(std::size_t(width) * height);
    RowLoop(height, threads, callbacks)
        .run<pegoraro::SceneScope>(
            [&](int y) {
                for (int x = 0; x < width; ++x) {
                    const std::size_t i = std::size_t(y) * width + x;
                    int overflows = 0;
                    out.radiance[i] = useDouble ? shader::pegoraroPixel_double(scene.frame, x, y, overflows)
                                                : shader::pegoraroPixel_float(scene.frame, x, y, overflows);
                    out.overflows[i] = std::uint32_t(overflows);
                }
            },
            scene);
    return out;
}

}  // namespace

void PegoraroTechnique::check(const RenderRequest& request) const {
    requireSupported(request.scene);
    (void)pegoraro::prepareScene(request.scene, pegoraro::settingsFrom(request.params), request.projectDir);
}

RenderResult PegoraroTechnique::render(const RenderRequest& request, const RenderCallbacks& callbacks) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    StageTimes times;
    requireSupported(request.scene);

    const Settings settings = pegoraro::settingsFrom(request.params);
    const PreparedScene scene = pegoraro::prepareScene(request.scene, settings, request.projectDir);
    times.mark("prepare");
    const int width = request.scene.camera.width, height = request.scene.camera.height;

    std::vector<glm::vec4> radiance;
    std::vector<std::uint32_t> overflows;
    std::string deviceName = "cpu";
    double longestSliceMs = 0.0, gpuMs = 0.0, compileSeconds = 0.0, primaryHitsMs = 0.0;
    std::string primaryVisibility;
    bool useDouble = settings.precision == Precision::Double;
    const bool onGpu = runsOnGpu(settings.device, AutoDevice::HardwareGpu);
    if (onGpu) {
        RendererPool<pegoraro::GpuRenderer>::Lease renderer = RendererPool<pegoraro::GpuRenderer>::lease();
        if (settings.precision == Precision::Auto)
            useDouble = scene.maxTerms - 1 > pegoraro::kAutoFloatMaxOrder && renderer->context().device().shaderFloat64;
        pegoraro::checkClosedFormRange(scene, settings, useDouble);
        pegoraro::GpuOutput g = renderer->render(scene, useDouble, width, height, callbacks, times);
        radiance = std::move(g.radiance);
        overflows = std::move(g.overflows);
        deviceName = g.deviceName;
        longestSliceMs = g.longestSliceMs;
        gpuMs = g.gpuMs;
        primaryHitsMs = g.primaryHitsMs;
        compileSeconds = g.compileSeconds;
        primaryVisibility = g.primaryVisibility;
    } else {
        if (settings.precision == Precision::Auto) useDouble = true;
        pegoraro::checkClosedFormRange(scene, settings, useDouble);
        CpuResult c = renderCpu(scene, useDouble, width, height, request.threads, callbacks);
        radiance = std::move(c.radiance);
        overflows = std::move(c.overflows);
        times.mark("passes");
    }

    RenderResult result;
    result.image = Image(width, height, {"R", "G", "B", "fallbacks"});
    std::size_t fallbackPixels = 0, overflowPixels = 0, nonFinite = 0;
    double fallbackEvaluations = 0.0;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const std::size_t i = std::size_t(y) * width + x;
            glm::vec4 v = radiance[i];
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
                ++nonFinite;
                v = glm::vec4(0.0f, 0.0f, 0.0f, v.w);
            }
            for (int c = 0; c < 3; ++c)
                result.image.at(x, y, c) = v[c];
            result.image.at(x, y, 3) = v.w;
            if (v.w > 0.0f) ++fallbackPixels;
            fallbackEvaluations += v.w;
            if (overflows[i] > 0) ++overflowPixels;
        }
    }
    if (callbacks.progress) callbacks.progress(1.0);

    result.spp = 1;
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    times.mark("resolve");
    stampMetadata(result, request);
    auto& meta = result.image.metadata;
    times.writeTo(meta);
    meta["device"] = deviceName;
    meta["pegoraro:precision"] = useDouble ? "double" : "float";
    meta["pegoraro:fallbackPixels"] = std::to_string(fallbackPixels);
    meta["pegoraro:fallbackEvaluations"] = formatShort(fallbackEvaluations);
    meta["pegoraro:shadowOverflowPixels"] = std::to_string(overflowPixels);
    meta["pegoraro:maxTerms"] = std::to_string(scene.maxTerms);
    meta["nonFiniteSamples"] = std::to_string(nonFinite);
    if (onGpu) {
        meta["gpu:longestSliceMs"] = formatShort(longestSliceMs);
        meta["gpu:totalMs"] = formatShort(gpuMs);
        // Each pass's share (tyndall_gpu_frames_bench reports them): camera hits, then the closed form.
        meta["gpu:primaryHitsMs"] = formatShort(primaryHitsMs);
        meta["gpu:closedFormMs"] = formatShort(gpuMs - primaryHitsMs);
        meta["gpu:compileSeconds"] = formatShort(compileSeconds);
        if (!primaryVisibility.empty()) meta["primaryVisibility"] = primaryVisibility;
    }
    for (std::size_t m = 0; m < scene.phases.size(); ++m) {
        const pegoraro::PhasePolynomial& p = scene.phases[m];
        if (p.exact) continue;
        const std::string key = "pegoraro:phaseTruncation[" + request.scene.media[m].name + "]";
        meta[key] = "terms " + std::to_string(p.c.size()) + ", L1 " + formatShort(p.l1Error) + ", max relative " +
                    formatShort(p.maxRelError) + ", minimum " + formatShort(p.minimum);
    }
    return result;
}

}  // namespace tyndall
