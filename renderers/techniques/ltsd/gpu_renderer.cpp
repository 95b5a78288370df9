#include "ltsd/gpu_renderer.h"

#include "tyndall/core/error.h"
#include "tyndall/core/resources.h"
#include "tyndall/gpu/shader_compiler.h"
#include "tyndall/gpu/slicer.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>

namespace tyndall::ltsd {

namespace {

constexpr std::uint32_t kGroupSize = 64;

struct Push {
    std::uint32_t first;    // first pixel of this dispatch
    std::uint32_t count;    // pixels in the image
    std::uint32_t width;
    std::uint32_t samples;  // the ratio pass: camera samples per pixel
    std::uint32_t seed;
};

std::string shaderPath() {
    return shaderDirectory().string() + "/ltsd/ltsd.comp.glsl";
}

}  // namespace

GpuRenderer::GpuRenderer() : context_(gpu::sharedContext()), primaryHits_(*context_) {}

gpu::ComputeKernel& GpuRenderer::kernel(const PreparedScene& scene, bool ratio, bool raster, double& compileSeconds) {
    const shader::LtsdFrame& f = scene.frame;
    const bool words = context_->device().shaderFloat64;
    const bool medium = f.hasMedium != 0;
    const bool surfaces = scene.surfaces.triangleCount > 0;
    const bool ggx = surfaces && scene.surfaces.anyGgx;
    const bool anisotropic = ggx && scene.anyAnisotropic;
    // The lights' most vertices bound the kernel's polygon loops (kLtsdLoopVertices, shared/ltsd.h).
    int vertices = 3;
    for (const shader::LtsdLight& light : scene.lights)
        vertices = std::max(vertices, light.vertexCount);
    const std::string key =
        std::to_string(f.lightCount) + "l" + std::to_string(vertices) + "v-" + std::to_string(f.planeCount) + "p-" +
        std::to_string(f.placement) + "-" + std::to_string(f.transmittance) + "-s" + std::to_string(f.sMethod) +
        std::to_string(f.sLobe) + (medium ? "" : "-nomedium") + (surfaces ? "" : "-nosurfaces") +
        (scene.anyTwoSided ? "-twosided" : "") + (ggx ? "-ggx" : "") + (anisotropic ? "-aniso" : "") +
        (words ? "-w" : "") + (ratio ? "-ratio" : "") + (raster ? "-raster" : "");
    std::string defines = "#define TY_LTSD_LIGHTS " + std::to_string(f.lightCount) + "\n#define TY_LTSD_PLANES " +
                          std::to_string(f.planeCount) + "\n#define TY_LTSD_PLACEMENT " + std::to_string(f.placement) +
                          "\n#define TY_LTSD_TRANSMITTANCE " + std::to_string(f.transmittance) +
                          "\n#define TY_LTSD_S_METHOD " + std::to_string(f.sMethod) + "\n#define TY_LTSD_S_LOBE " +
                          std::to_string(f.sLobe) + "\n#define TY_LTSD_VERTICES " + std::to_string(vertices) + "\n";
    if (!medium) defines += "#define TY_LTSD_NO_MEDIUM\n";
    if (!surfaces) defines += "#define TY_LTSD_NO_SURFACES\n";
    if (!scene.anyTwoSided) defines += "#define TY_LTSD_ONE_SIDED\n";
    if (!ggx) defines += "#define TY_LTSD_NO_GGX\n";
    if (!anisotropic) defines += "#define TY_LTSD_NO_ANISOTROPIC\n";
    if (words) defines += "#define TY_BVH_WORDS\n";
    defines += scene.surfaces.shaderDefines();
    if (ratio) defines += "#define TY_LTSD_RATIO\n";
    if (raster) defines += "#define TY_PRIMARY_HITS\n";
    return kernels_.get(*context_, {shaderPath(), defines, 10, std::uint32_t(sizeof(Push)), "ltsd_" + key},
                        compileSeconds);
}

GpuOutput GpuRenderer::render(const PreparedScene& scene, int width, int height, const RenderCallbacks& callbacks,
                              StageTimes& times) {
    return run(scene, false, width, height, 0, 0u, callbacks, times);
}

GpuOutput GpuRenderer::renderRatio(const PreparedScene& scene, int width, int height, int samples, std::uint32_t seed,
                                   const RenderCallbacks& callbacks, StageTimes& times) {
    return run(scene, true, width, height, samples, seed, callbacks, times);
}

GpuOutput GpuRenderer::run(const PreparedScene& scene, bool ratio, int width, int height, int samples,
                           std::uint32_t seed, const RenderCallbacks& callbacks, StageTimes& times) {
    GpuOutput out;
    const std::string pass = ratio ? "ratio " : "";
    gpu::Context& ctx = *context_;
    auto upload = [&](const auto& values) { return gpu::uploadBuffer(ctx, values); };
    auto nodes = upload(scene.surfaces.bvh.nodes);
    auto triangles = upload(scene.surfaces.bvh.triangles);
    times.mark(pass + "upload");
    // The analytic pass's rays sit on the S x S grid of each pixel: their closest hits can be rasterised. The ratio
    // pass's rays are jittered: traced.
    PrimaryHits primary;
    if (!ratio && scene.surfaces.triangleCount > 0) {
        primary = primaryHits_.render(*nodes, *triangles, scene.surfaces.bvh.triangles.size(), scene.frame.camera,
                                      std::max(scene.frame.supersampling, 1));
        out.primaryVisibility = primary.visibility;
        out.compileSeconds += primary.compileSeconds;
        times.mark("camera hits");
    }
    const bool raster = primary.records != nullptr;
    gpu::ComputeKernel& k = kernel(scene, ratio, raster, out.compileSeconds);
    times.mark("compile");
    auto frame = std::make_unique<gpu::Buffer>(ctx, sizeof(shader::LtsdFrame));
    frame->upload(&scene.frame, sizeof(shader::LtsdFrame));
    auto lights = upload(scene.lights);
    auto planes = upload(scene.planes);
    auto surfaceTriangles = upload(scene.surfaces.triangles);
    auto materials = upload(scene.surfaces.materials);
    auto ltcEntries = upload(scene.ltcEntries);
    const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
    const std::uint64_t perPixel = ratio ? 4 : 2;
    gpu::Buffer& radiance = gpu::keptBuffer(ctx, outputs_[ratio], pixels * perPixel * sizeof(glm::vec4));
    times.mark(pass + "upload");
    const std::vector<const gpu::Buffer*> bindings{nodes.get(),      triangles.get(),
                                                   frame.get(),      lights.get(),
                                                   planes.get(),     surfaceTriangles.get(),
                                                   materials.get(),  &radiance,
                                                   ltcEntries.get(), raster ? primary.records : nodes.get()};
    gpu::SliceStats stats;
    std::uint64_t& sliceSize = kernels_.sliceSize(k, ratio ? 64 : 1024);
    try {
        stats = gpu::runSliced(
            ctx, pixels,
            [&](VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t n) {
                if (callbacks.progress) callbacks.progress(double(begin) / double(pixels));
                Push push{std::uint32_t(begin), std::uint32_t(pixels), std::uint32_t(width), std::uint32_t(samples),
                          seed};
                k.record(cmd, bindings, &push, std::uint32_t((n + kGroupSize - 1) / kGroupSize));
                gpu::computeToComputeBarrier(cmd);
            },
            callbacks.cancel, 10.0, sliceSize);
        sliceSize = stats.nextSlice;
    } catch (...) {
        k.resetDescriptors();
        throw;
    }
    k.resetDescriptors();
    times.mark(pass + "kernel");
    radiance.download(values_[ratio], pixels * perPixel);
    out.values = &values_[ratio];
    times.mark(pass + "readback");
    out.deviceName = ctx.device().name;
    out.longestSliceMs = stats.longestMs;
    out.gpuMs = stats.totalMs + primary.gpuMs;
    out.primaryHitsMs = primary.gpuMs;
    return out;
}

}  // namespace tyndall::ltsd
