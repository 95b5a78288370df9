#include "ltsd/ltsd.h"

#include "ltsd/gpu_renderer.h"
#include "ltsd/prepared.h"

#include "tyndall/error.h"
#include "tyndall/gpu/context.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace tyndall {

LtsdTechnique::LtsdTechnique() = default;
LtsdTechnique::~LtsdTechnique() = default;

std::vector<ParamInfo> LtsdTechnique::parameters() const {
    std::vector<ParamInfo> p;
    p.push_back({"device",
                 ParamType::Enum,
                 "Where it runs: the GPU (Vulkan compute) or the CPU; auto takes the GPU unless the only Vulkan device "
                 "is a software one (lavapipe), where the CPU path is faster",
                 "",
                 0,
                 0,
                 std::string("auto"),
                 {"auto", "gpu", "cpu"}});
    p.push_back({"nodes", ParamType::Int,
                 "N of Eq. 15: quadrature nodes of the air-light per light (and per side of a two-sided light's "
                 "plane); the paper's quality/speed slider",
                 "", 1, 1024, std::int64_t(8), {}, true});
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
    return p;
}

Support LtsdTechnique::supports(const HomogeneousMedium& medium) const {
    if (medium.phase.kind != PhaseKind::HenyeyGreenstein && medium.phase.kind != PhaseKind::Isotropic)
        return Support::no(std::string("the medium '") + medium.name + "' has a " + toString(medium.phase.kind) +
                           " phase function; LTSD tables are fitted for Henyey-Greenstein (and isotropic) only");
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

Support LtsdTechnique::supports(const Material& material) const {
    if (material.kind != Material::Kind::Diffuse)
        return Support::no("the GGX material '" + material.name +
                           "' needs LTC GGX tables, which are not fitted yet; LTSD shades diffuse surfaces");
    return Support::yes();
}

void LtsdTechnique::check(const RenderRequest& request) const {
    requireSupported(request.scene);
    (void)ltsd::prepareScene(request.scene, ltsd::settingsFrom(request.params), request.projectDir);
}

namespace {

std::vector<glm::vec4> renderCpu(const ltsd::PreparedScene& scene, int width, int height, int threads,
                                 const RenderCallbacks& callbacks) {
    std::vector<glm::vec4> out(std::size_t(width) * height);
    std::atomic<int> rowsDone{0};
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, height, 1), [&](const tbb::blocked_range<int>& rows) {
            ltsd::SceneScope scope(scene);
            for (int y = rows.begin(); y < rows.end(); ++y) {
                if (callbacks.cancel && callbacks.cancel->load(std::memory_order_relaxed)) return;
                for (int x = 0; x < width; ++x)
                    out[std::size_t(y) * width + x] = glm::vec4(shader::ltsdPixel(scene.frame, x, y), 1.0f);
                const int done = rowsDone.fetch_add(1) + 1;
                if (callbacks.progress && (done % 16 == 0)) callbacks.progress(double(done) / height);
            }
        });
    });
    if (callbacks.cancel && callbacks.cancel->load()) throw Cancelled();
    return out;
}

std::string formatDouble(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.6g", x);
    return buffer;
}

}  // namespace

RenderResult LtsdTechnique::render(const RenderRequest& request, const RenderCallbacks& callbacks) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    requireSupported(request.scene);
    const ltsd::Settings settings = ltsd::settingsFrom(request.params);
    const ltsd::PreparedScene scene = ltsd::prepareScene(request.scene, settings, request.projectDir);
    const int width = request.scene.camera.width, height = request.scene.camera.height;

    bool onGpu = settings.device == ltsd::Device::Gpu;
    if (settings.device == ltsd::Device::Auto) onGpu = gpu::hardwareDeviceAvailable();
    std::vector<glm::vec4> radiance;
    std::string deviceName = "cpu";
    ltsd::GpuOutput g;
    if (onGpu) {
        if (!gpu_) gpu_ = std::make_unique<ltsd::GpuRenderer>();
        g = gpu_->render(scene, width, height, callbacks);
        radiance = std::move(g.radiance);
        deviceName = g.deviceName;
    } else {
        radiance = renderCpu(scene, width, height, request.threads, callbacks);
    }

    RenderResult result;
    result.image = Image(width, height, {"R", "G", "B"});
    std::size_t nonFinite = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const glm::vec4 v = radiance[std::size_t(y) * width + x];
            const bool finite = std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
            if (!finite) ++nonFinite;
            for (int c = 0; c < 3; ++c)
                result.image.at(x, y, c) = finite ? v[c] : 0.0f;
        }
    if (callbacks.progress) callbacks.progress(1.0);
    result.spp = 1;
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    stampMetadata(result, request);
    auto& meta = result.image.metadata;
    meta["device"] = deviceName;
    meta["nonFiniteSamples"] = std::to_string(nonFinite);
    if (scene.frame.hasMedium != 0) {
        meta["ltsd:table"] = scene.tablePath;
        meta["ltsd:g"] = formatDouble(scene.g);
    }
    if (onGpu) {
        meta["gpu:longestSliceMs"] = formatDouble(g.longestSliceMs);
        meta["gpu:totalMs"] = formatDouble(g.gpuMs);
        meta["gpu:compileSeconds"] = formatDouble(g.compileSeconds);
    }
    return result;
}

}  // namespace tyndall
