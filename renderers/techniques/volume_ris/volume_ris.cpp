#include "volume_ris/volume_ris.h"

#include "volume_ris/gpu_renderer.h"
#include "volume_ris/prepared.h"

#include "tyndall/core/error.h"
#include "tyndall/core/text.h"
#include "tyndall/framework/progressive.h"
#include "tyndall/framework/renderer_pool.h"
#include "tyndall/framework/row_loop.h"
#include "tyndall/framework/stage_times.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace tyndall {

using volume_ris::PreparedScene;
using volume_ris::Settings;

VolumeRisTechnique::VolumeRisTechnique() = default;
VolumeRisTechnique::~VolumeRisTechnique() = default;

std::vector<ParamInfo> VolumeRisTechnique::parameters() const {
    std::vector<ParamInfo> p;
    p.push_back({"candidates", ParamType::Int,
                 "Candidates M per camera ray (and per surface hit) resampled into the one that gets a shadow ray",
                 "", 1, shader::kRisMaxCandidates, std::int64_t(32), {}, true});
    p.push_back({"samplesPerPixel", ParamType::Int,
                 "Camera rays per pixel, jittered in the pixel (a box filter like the reference's), when the render "
                 "does not ask for a number",
                 "spp", 1, 65536, std::int64_t(16), {}, true});
    p.push_back({"distanceSampling",
                 ParamType::Enum,
                 "Source pdf of a candidate's distance along the camera ray: proportional to the transmittance over "
                 "the medium segment, or equiangular about the chosen light's centre",
                 "",
                 0,
                 0,
                 std::string("transmittance"),
                 {"transmittance", "equiangular"}});
    p.push_back({"lightSampling",
                 ParamType::Enum,
                 "Source pdf of a candidate's light point (after a light is chosen by power): uniform in the solid "
                 "angle the polygon subtends at the shading point, or uniform on its area",
                 "",
                 0,
                 0,
                 std::string("solidAngle"),
                 {"solidAngle", "area"}});
    p.push_back({"shadows", ParamType::Bool,
                 "Visibility of the chosen candidate by a shadow ray through the BVH; off: the unshadowed image", "", 0,
                 1, true});
    p.push_back(
        deviceParameter("Where the estimator runs: the GPU (Vulkan compute) or the CPU; auto takes any Vulkan device, "
                        "lavapipe included (3-7 x faster than the CPU path for this technique), else the CPU"));
    return p;
}

Support VolumeRisTechnique::supports(const HomogeneousMedium& medium) const {
    if (medium.shape == MediumShape::ConvexPolyhedron && int(medium.planes.size()) > shader::kRisMaxPlanes)
        return Support::no("the medium '" + medium.name + "' has more than " + std::to_string(shader::kRisMaxPlanes) +
                           " faces");
    return Support::yes();
}

Support VolumeRisTechnique::supports(const ParticleMedium& medium) const {
    return Support::no("the particle medium '" + medium.name +
                       "' is heterogeneous; Volume-RIS here renders one homogeneous medium");
}

Support VolumeRisTechnique::supports(const PointLight& light) const {
    return Support::no("the point light '" + light.name +
                       "' is not an area light; Volume-RIS samples points on polygonal area lights");
}

Support VolumeRisTechnique::supports(const DirectionalLight& light) const {
    return Support::no("the directional light '" + light.name +
                       "' is not an area light; Volume-RIS samples points on polygonal area lights");
}

Support VolumeRisTechnique::supports(const AreaLight& light) const {
    if (int(light.vertices.size()) > shader::kRisMaxVertices)
        return Support::no("the area light '" + light.name + "' has more than " +
                           std::to_string(shader::kRisMaxVertices) + " vertices");
    return Support::yes();
}

namespace {

// Accumulators: per pixel and half (even, odd camera samples), two vec4s: the sum of the medium's samples with w
// counting them, and the sum of the surface's.
void addSamplesCpu(const PreparedScene& scene, int width, int height, std::vector<glm::vec4>& acc,
                   std::uint32_t first, std::uint32_t end, int threads, const RenderCallbacks& callbacks,
                   std::atomic<long>& nonFinite) {
    RowLoop(height, threads, callbacks.cancel)
        .run<volume_ris::SceneScope>(
            [&](int y) {
                for (int x = 0; x < width; ++x) {
                    const std::size_t pixel = std::size_t(y) * width + x;
                    for (std::uint32_t s = first; s < end; ++s) {
                        const shader::RisTerms t = shader::risSample(scene.frame, x, y, s);
                        glm::vec4* a = &acc[(pixel * 2 + (s & 1u)) * 2];
                        a[0].w += 1.0f;
                        const glm::vec3 v = t.medium + t.surface;
                        if (!std::isfinite(v.x + v.y + v.z)) {
                            nonFinite.fetch_add(1, std::memory_order_relaxed);
                            continue;
                        }
                        a[0] += glm::vec4(t.medium, 0.0f);
                        a[1] += glm::vec4(t.surface, 0.0f);
                    }
                }
            },
            scene);
}

// R, G, B and the variance of each pixel's mean from its two halves, (A - B)^2 / 4, as the reference writes it; then
// the medium's and the surface's parts of R, G, B (their sum), for a denoiser that filters them apart.
Image resolve(const std::vector<glm::vec4>& acc, int width, int height, long& nonFinitePixels) {
    Image image(width, height,
                estimateChannels({"medium.R", "medium.G", "medium.B", "surface.R", "surface.G", "surface.B"}));
    long bad = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t pixel = std::size_t(y) * width + x;
            const glm::vec4* h0 = &acc[pixel * 4];
            const glm::vec4* h1 = &acc[pixel * 4 + 2];
            const float n0 = h0[0].w, n1 = h1[0].w, n = n0 + n1;
            const glm::vec3 sum0 = glm::vec3(h0[0]) + glm::vec3(h0[1]), sum1 = glm::vec3(h1[0]) + glm::vec3(h1[1]);
            glm::vec3 medium = n > 0.0f ? (glm::vec3(h0[0]) + glm::vec3(h1[0])) / n : glm::vec3(0.0f);
            glm::vec3 surface = n > 0.0f ? (glm::vec3(h0[1]) + glm::vec3(h1[1])) / n : glm::vec3(0.0f);
            const glm::vec3 variance = n0 > 0.0f && n1 > 0.0f ? varianceOfMean(sum0 / n0, sum1 / n1) : glm::vec3(0.0f);
            if (!writeEstimate(image, x, y, medium + surface, variance)) {
                ++bad;
                medium = surface = glm::vec3(0.0f);
            }
            for (int c = 0; c < 3; ++c) {
                image.at(x, y, 6 + c) = medium[c];
                image.at(x, y, 9 + c) = surface[c];
            }
        }
    nonFinitePixels = bad;
    return image;
}

}  // namespace

void VolumeRisTechnique::check(const RenderRequest& request) const {
    requireSupported(request.scene);
    (void)volume_ris::prepareScene(request.scene, volume_ris::settingsFrom(request.params), request.seed,
                                   request.projectDir);
}

RenderResult VolumeRisTechnique::render(const RenderRequest& request, const RenderCallbacks& callbacks) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    StageTimes times;
    requireSupported(request.scene);
    const Settings settings = volume_ris::settingsFrom(request.params);
    const PreparedScene scene = volume_ris::prepareScene(request.scene, settings, request.seed, request.projectDir);
    times.mark("prepare");
    const int spp = request.spp > 0 ? request.spp : settings.samplesPerPixel;
    const int width = request.scene.camera.width, height = request.scene.camera.height;

    // Unlike WVDS and Pegoraro, whose CPU paths beat lavapipe, this technique runs faster on lavapipe than on the CPU
    // path (docs/volume-ris.md, Measured): auto takes any Vulkan device.
    const bool onGpu = runsOnGpu(settings.device, AutoDevice::AnyGpu);
    std::vector<glm::vec4> acc;  // the CPU path's accumulators
    RendererPool<volume_ris::GpuRenderer>::Lease renderer;  // the process's renderers (framework/renderer_pool.h)
    if (onGpu) renderer = RendererPool<volume_ris::GpuRenderer>::lease();
    if (onGpu) {
        renderer->begin(scene, width, height);
    } else {
        acc.assign(std::size_t(width) * height * 4, glm::vec4(0.0f));
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
            addSamplesCpu(scene, width, height, acc, first, end, request.threads, pass, nonFiniteSamples);
        times.mark("samples");
    };
    ProgressiveResult progressive = renderProgressively(request, spp, callbacks, start, addSamples, [&] {
        const std::vector<glm::vec4>& values = onGpu ? renderer->readAccumulators() : acc;
        times.mark("readback");
        Image image = resolve(values, width, height, nonFinitePixels);
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
    meta["device"] = onGpu ? gpu::sharedContext()->device().name : "cpu";
    meta["nonFiniteSamples"] = std::to_string(nonFiniteSamples.load() + nonFinitePixels);
    if (onGpu) {
        meta["gpu:totalMs"] = formatShort(renderer->gpuMs());
        meta["gpu:compileSeconds"] = formatShort(renderer->compileSeconds());
    }
    return result;
}

}  // namespace tyndall
