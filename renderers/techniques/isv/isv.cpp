#include "isv/isv.h"

#include "isv/gpu_renderer.h"
#include "isv/prepared.h"

#include "tyndall/core/error.h"
#include "tyndall/core/text.h"
#include "tyndall/framework/renderer_pool.h"
#include "tyndall/framework/stage_times.h"
#include "tyndall/gpu/context.h"

#include <chrono>
#include <cmath>
#include <cstdio>

namespace tyndall {

IsvTechnique::IsvTechnique() = default;
IsvTechnique::~IsvTechnique() = default;

std::vector<ParamInfo> IsvTechnique::parameters() const {
    std::vector<ParamInfo> p;
    p.push_back(deviceParameter(
        "Where it runs: Vulkan graphics pipelines or the CPU model of the same passes; auto takes the GPU"));
    p.push_back({"proxies",
                 ParamType::Enum,
                 "What builds the interval-shading proxies on the GPU (Sec. 2.3): mesh (a mesh shader, as Tricard and "
                 "the thesis; needs VK_EXT_mesh_shader), geometry (a geometry shader, runs everywhere); auto: mesh "
                 "where the device has it. Both draw the same triangles",
                 "",
                 0,
                 0,
                 std::string("auto"),
                 {"auto", "geometry", "mesh"}});
    p.push_back({"integration",
                 ParamType::Enum,
                 "C_scat over a fragment's interval (thesis Sec. 3.7-3.11): analytic (constant extinction, closed "
                 "form), taylor (four Taylor terms about the midpoint), simpson (Simpson's rule with `steps` steps), "
                 "wasted-pixels (red: fragments below the threshold, green: shaded)",
                 "",
                 0,
                 0,
                 std::string("simpson"),
                 isv::integrationNames()});
    p.push_back({"steps", ParamType::Int, "Simpson's rule steps per fragment (Sec. 3.10)", "", 1, 10, std::int64_t(1)});
    p.push_back({"fading", ParamType::Bool,
                 "Extinction fading: the Gaussian falloff of Eq. 9 (off: constant extinction in each tetrahedron, "
                 "edges visible)",
                 "", 0, 1, true});
    p.push_back({"threshold", ParamType::Float,
                 "Early out (Sec. 3.11): fragments whose optical thickness is below it are skipped", "", 0.0, 1.0,
                 1e-3, {}, true});
    p.push_back({"multiScatter", ParamType::Float,
                 "m of Eq. 11: the crude multiple-scattering term (0: single scattering, as the reference)", "", 0.0,
                 1.0, 0.0});
    p.push_back({"selfShadowing", ParamType::Bool, "The volumetric shadow map (Sec. 3.4): the medium shadows itself",
                 "", 0, 1, true});
    p.push_back({"vsmResolution", ParamType::Int, "Volumetric shadow map texels per side", "", 8, 1024,
                 std::int64_t(128), {}, true});
    p.push_back({"vsmSlices", ParamType::Int, "Volumetric shadow map depth slices", "", 2, 64, std::int64_t(16)});
    p.push_back({"opaqueShadows", ParamType::Bool,
                 "The opaque shadow map: surfaces shadow the medium and each other (Sec. 3.6)", "", 0, 1, true});
    p.push_back({"shadowMapResolution", ParamType::Int, "Opaque shadow map texels per side", "", 16, 4096,
                 std::int64_t(1024), {}, true});
    p.push_back({"pcfRadius", ParamType::Int,
                 "Soft shadows: percentage-closer filtering over (2r + 1)^2 shadow-map texels (0: off)", "", 0, 8,
                 std::int64_t(0)});
    p.push_back({"supersampling", ParamType::Int, "S x S fragments per pixel, box filtered", "", 1, 8,
                 std::int64_t(1)});
    p.push_back({"nearPlane", ParamType::Float,
                 "Tetrahedra reaching closer to the camera than this are culled (thesis Sec. 2.3.4)", "m", 1e-4, 10.0,
                 0.05, {}, true});
    return p;
}

std::string IsvTechnique::reduceForPreview(ParamSet& params, int factor) const {
    if (factor <= 1) return {};
    // The maps' texels in proportion to the image's pixels, down to a floor that still shows the shadows' shapes; the
    // volumetric map's slices (each a draw of every particle: the vertex work) by the factor, down to 4. On lavapipe
    // at 32 x 32 (smoke, 5000 particles): 199 -> 89 ms of GPU time.
    bool reduced = shrinkForPreview(params, "shadowMapResolution", factor, 64);
    reduced |= shrinkForPreview(params, "vsmResolution", factor, 16);
    reduced |= shrinkForPreview(params, "vsmSlices", factor, 4);
    reduced |= shrinkForPreview(params, "supersampling", 8, 1);
    return reduced ? "coarser shadow maps" : "";
}

Support IsvTechnique::supports(const HomogeneousMedium& medium) const {
    return Support::no("the medium '" + medium.name +
                       "' is homogeneous; ISV renders particle media (LTSD, WVDS and Pegoraro render homogeneous ones)");
}

Support IsvTechnique::supports(const ParticleMedium&) const {
    return Support::yes();  // a chromatic extinction too: coloured shadows (beyond the thesis, whose are grey)
}

Support IsvTechnique::supports(const PointLight&) const {
    return Support::yes();  // with a perspective volumetric shadow map (beyond the thesis, its future work)
}

Support IsvTechnique::supports(const DirectionalLight& light) const {
    if (!light.gobo.empty())
        return Support::no("the directional light '" + light.name +
                           "' has a gobo; ISV's shadow maps cover the whole beam (remove the gobo or render it with "
                           "WVDS)");
    return Support::yes();
}

Support IsvTechnique::supports(const AreaLight& light) const {
    return Support::no("the area light '" + light.name +
                       "' is not a directional light or a point light; ISV's shadow maps are seen from one point or "
                       "direction (LTSD and Volume-RIS render area lights)");
}

Support IsvTechnique::supports(const Material&) const {
    return Support::yes();
}

void IsvTechnique::check(const RenderRequest& request) const {
    requireSupported(request.scene);
    (void)isv::prepareScene(request.scene, isv::settingsFrom(request.params), request.projectDir);
}

namespace {

// The CPU model's passes for the frame's light: (rgb, transmittance) per pixel of the rendering resolution.
std::vector<glm::vec4> renderCpu(const isv::PreparedScene& scene, int threads, const RenderCallbacks& callbacks) {
    const std::atomic<bool>* cancel = callbacks.cancel;
    std::vector<float> shadow, slabs, vsm;
    if (scene.shadowMap) shadow = isv::shadowMapCpu(scene, threads, cancel);
    if (callbacks.progress) callbacks.progress(0.1);
    if (scene.vsm) {
        slabs = isv::vsmSlabsCpu(scene, threads, cancel);
        vsm = isv::slicesFromSlabs(slabs, scene.frame.vsm);
    }
    if (callbacks.progress) callbacks.progress(0.3);
    const std::vector<glm::vec4> background = isv::surfacesCpu(scene, vsm, shadow, threads, cancel);
    if (callbacks.progress) callbacks.progress(0.5);
    return isv::compositeCpu(scene, background, vsm, shadow, isv::backToFront(scene), threads, cancel);
}

}  // namespace

RenderResult IsvTechnique::render(const RenderRequest& request, const RenderCallbacks& callbacks) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    StageTimes times;
    requireSupported(request.scene);
    const isv::Settings settings = isv::settingsFrom(request.params);
    isv::PreparedScene scene = isv::prepareScene(request.scene, settings, request.projectDir);
    times.mark("prepare");
    const int width = request.scene.camera.width, height = request.scene.camera.height;
    const int ss = scene.supersampling;
    const int lights = isv::lightCount(request.scene);
    const int passes = std::max(lights, 1);

    bool onGpu = runsOnGpu(settings.device, AutoDevice::Gpu);
    std::string fallback;
    if (onGpu) {
        // What the device cannot hold or do for any light (its buffer and image limits, dual-source blending for
        // coloured shadows): an error under device = gpu, the CPU model under auto.
        for (int pass = 0; pass < passes && onGpu; ++pass) {
            isv::lightScene(scene, request.scene, settings, lights == 0 ? -1 : pass);
            if (const std::optional<InputError> problem =
                    isv::deviceLimitProblem(scene, gpu::sharedContext()->device())) {
                if (settings.device == Device::Gpu) throw *problem;
                onGpu = false;
                fallback = problem->where().field + ": " + problem->message() + " (rendered on the CPU)";
            }
        }
    }

    // One pass per light, summed: every term of ISV's radiance (the particles' in-scattering, Eq. 7, and the surfaces'
    // reflection) is linear in the light, and the compositing's transmittance does not depend on it.
    std::vector<glm::vec4> pixels;
    std::string deviceName = "cpu";
    std::string proxies = "none (the CPU model intersects each pixel's ray with the tetrahedra)";
    isv::GpuTimings timings;
    for (int pass = 0; pass < passes; ++pass) {
        isv::lightScene(scene, request.scene, settings, lights == 0 ? -1 : pass);
        RenderCallbacks passCallbacks = callbacks;
        if (callbacks.progress)
            passCallbacks.progress = [&callbacks, pass, passes](double x) {
                callbacks.progress((double(pass) + x) / double(passes));
            };
        std::vector<glm::vec4> lit;
        if (onGpu) {
            RendererPool<isv::GpuRenderer>::Lease renderer = RendererPool<isv::GpuRenderer>::lease();
            isv::GpuOutput g = renderer->render(scene, passCallbacks, settings.proxies);
            lit = std::move(g.pixels);
            deviceName = g.deviceName;
            timings.totalMs += g.timings.totalMs;
            timings.shadowMapMs += g.timings.shadowMapMs;
            timings.vsmMs += g.timings.vsmMs;
            timings.surfacesMs += g.timings.surfacesMs;
            timings.sortMs += g.timings.sortMs;
            timings.particlesMs += g.timings.particlesMs;
            timings.longestSliceMs = std::max(timings.longestSliceMs, g.timings.longestSliceMs);
            timings.compileSeconds += g.timings.compileSeconds;
            proxies = g.meshProxies ? "mesh" : "geometry";
        } else {
            lit = renderCpu(scene, request.threads, passCallbacks);
        }
        if (pass == 0) {
            pixels = std::move(lit);
        } else {
            for (std::size_t i = 0; i < pixels.size(); ++i)
                pixels[i] += glm::vec4(glm::vec3(lit[i]), 0.0f);
        }
    }
    times.mark("passes");

    RenderResult result;
    result.image = Image(width, height, {"R", "G", "B", "transmittance"});
    std::size_t nonFinite = 0;
    const float norm = 1.0f / float(ss * ss);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            glm::vec4 sum(0.0f);
            for (int sy = 0; sy < ss; ++sy)
                for (int sx = 0; sx < ss; ++sx)
                    sum += pixels[std::size_t(y * ss + sy) * scene.width + std::size_t(x * ss + sx)];
            sum *= norm;
            for (int c = 0; c < 4; ++c) {
                const bool finite = std::isfinite(sum[c]);
                if (!finite) ++nonFinite;
                result.image.at(x, y, c) = finite ? sum[c] : 0.0f;
            }
        }
    if (callbacks.progress) callbacks.progress(1.0);
    times.mark("resolve");
    result.spp = 1;
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    stampMetadata(result, request);
    auto& meta = result.image.metadata;
    times.writeTo(meta);
    meta["device"] = deviceName;
    meta["nonFiniteSamples"] = std::to_string(nonFinite);
    meta["isv:particles"] = std::to_string(scene.particles.size());
    meta["isv:lights"] = std::to_string(lights);
    if (!fallback.empty()) meta["isv:fallback"] = fallback;
    meta["isv:proxies"] = proxies;
    if (onGpu) {
        meta["gpu:totalMs"] = formatShort(timings.totalMs);
        meta["gpu:longestSliceMs"] = formatShort(timings.longestSliceMs);
        meta["gpu:compileSeconds"] = formatShort(timings.compileSeconds);
        meta["gpu:shadowMapMs"] = formatShort(timings.shadowMapMs);
        meta["gpu:vsmMs"] = formatShort(timings.vsmMs);
        meta["gpu:surfacesMs"] = formatShort(timings.surfacesMs);
        meta["gpu:sortMs"] = formatShort(timings.sortMs);
        meta["gpu:particlesMs"] = formatShort(timings.particlesMs);
    }
    return result;
}

}  // namespace tyndall
