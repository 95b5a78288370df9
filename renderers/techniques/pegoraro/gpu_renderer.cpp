#include "pegoraro/gpu_renderer.h"

#include "tyndall/core/error.h"
#include "tyndall/core/resources.h"
#include "tyndall/gpu/shader_compiler.h"
#include "tyndall/gpu/slicer.h"

#include <chrono>
#include <fstream>
#include <sstream>

namespace tyndall::pegoraro {

namespace {

constexpr std::uint32_t kGroupSize = 64;

struct Push {
    std::uint32_t first;
    std::uint32_t count;
    std::uint32_t width;
    std::uint32_t listed;
};

std::string shaderPath() {
    return shaderDirectory().string() + "/pegoraro/pegoraro.comp.glsl";
}

// Array sizes come in a few steps, so that a scene's order picks one of a handful of variants.
int roundTerms(int terms) {
    for (int step : {1, 2, 3, 5, 9, 17, 25, 33})
        if (terms <= step) return step;
    return shader::kPegoraroMaxTerms;
}

}  // namespace

GpuRenderer::GpuRenderer() : context_(gpu::sharedContext()), primaryHits_(*context_) {}

gpu::ComputeKernel& GpuRenderer::kernel(const Variant& v, double& compileSeconds) {
    const int terms = roundTerms(v.maxTerms);
    const bool words = context_->device().shaderFloat64;
    const std::string key = std::to_string(terms) + (v.useDouble ? "d" : "f") + (words ? "w" : "s") +
                            (v.shadows ? "" : "-noshadows") + (v.surfaces ? "" : "-nosurfaces") +
                            (v.grey ? "-grey" : "") + (v.deferredFallback ? "-deferred" : "") +
                            (v.raster ? "-raster" : "");

    std::string defines = "#define TY_PEGORARO_MAX_TERMS " + std::to_string(terms) + "\n";
    if (v.useDouble) defines += "#define TY_ENABLE_DOUBLE\n";
    if (words) defines += "#define TY_BVH_WORDS\n";
    if (!v.shadows) defines += "#define TY_PEGORARO_NO_SHADOWS\n";
    if (!v.surfaces) defines += "#define TY_PEGORARO_NO_SURFACES\n";
    if (v.grey) defines += "#define TY_PEGORARO_GREY\n";
    if (v.deferredFallback) defines += "#define TY_PEGORARO_DEFERRED_FALLBACK\n";
    if (v.raster) defines += "#define TY_PRIMARY_HITS\n";
    return kernels_.get(*context_, {shaderPath(), defines, 12, std::uint32_t(sizeof(Push)), "pegoraro_" + key},
                        compileSeconds);
}

GpuOutput GpuRenderer::render(const PreparedScene& scene, bool useDouble, int width, int height,
                              const RenderCallbacks& callbacks, StageTimes& times) {
    if (useDouble && !context_->device().shaderFloat64)
        throw InputError(InputLocation{"", 0, 0, "precision"},
                         "the GPU '" + context_->device().name +
                             "' has no double precision (shaderFloat64); use precision = float or device = cpu");
    // Pass 1 runs the closed form without the quadrature's code; the samples where an evaluation needs the quadrature
    // (the error bound, or an order beyond the series) are rendered again, over a list, by the full shader. With
    // fallback = always every evaluation needs it, so the full shader runs at once.
    Variant variant;
    variant.maxTerms = scene.maxTerms;
    variant.useDouble = useDouble;
    variant.shadows = scene.frame.shadows != 0;
    variant.surfaces = scene.triangleCount > 0;
    variant.grey = shader::pegoraroGrey(scene.frame);  // the shared test (no TY_PEGORARO_GREY here: the frame's values)
    variant.deferredFallback = scene.frame.fallbackMode != shader::kPegoraroFallbackAlways;
    double compileSeconds = 0.0;
    gpu::Context& ctx = *context_;
    auto upload = [&](const auto& values) { return gpu::uploadBuffer(ctx, values); };
    auto nodes = upload(scene.bvh.nodes);
    auto triangles = upload(scene.bvh.triangles);
    times.mark("upload");
    // Every sample but those around a light's projection sits on the S x S grid of its pixel: its camera hit can be
    // rasterised.
    PrimaryHits primary;
    if (variant.surfaces) {
        primary = primaryHits_.render(*nodes, *triangles, scene.bvh.triangles.size(), scene.frame.camera,
                                      std::max(scene.frame.supersampling, 1));
        compileSeconds += primary.compileSeconds;
        times.mark("camera hits");
    }
    variant.raster = primary.records != nullptr;
    gpu::ComputeKernel& first = kernel(variant, compileSeconds);
    times.mark("compile");
    // The variant with the quadrature's code, for the listed passes (compiled on first use, its time counted).
    auto fullKernel = [&]() -> gpu::ComputeKernel& {
        Variant full = variant;
        full.deferredFallback = false;
        return kernel(full, compileSeconds);
    };

    auto frame = std::make_unique<gpu::Buffer>(ctx, sizeof(shader::PegoraroFrame));
    frame->upload(&scene.frame, sizeof(shader::PegoraroFrame));
    auto lights = upload(scene.lights);
    auto media = upload(scene.media);
    auto coefficients = upload(scene.coefficients);
    auto surfaceTriangles = upload(scene.triangles);
    auto materials = upload(scene.materials);
    const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
    const std::uint64_t perPixel =
        std::uint64_t(std::max(scene.frame.supersampling, 1)) * std::max(scene.frame.supersampling, 1);
    const std::uint64_t samples = pixels * perPixel;
    if (samples > 0xFFFFFFFFull)
        throw InputError(InputLocation{"", 0, 0, "supersampling"}, "too many samples for one GPU render");
    gpu::Buffer radiance(ctx, samples * sizeof(glm::vec4));
    gpu::Buffer overflows(ctx, samples * sizeof(std::uint32_t));
    std::unique_ptr<gpu::Buffer> list = upload(std::vector<std::uint32_t>{0u});
    times.mark("upload");
    auto bindings = [&](gpu::Buffer& out, gpu::Buffer& outOverflows) {
        return std::vector<const gpu::Buffer*>{nodes.get(),
                                               triangles.get(),
                                               frame.get(),
                                               lights.get(),
                                               media.get(),
                                               coefficients.get(),
                                               surfaceTriangles.get(),
                                               materials.get(),
                                               &out,
                                               &outOverflows,
                                               list.get(),
                                               primary.records ? primary.records : nodes.get()};
    };

    // `count` items of a pass; progress runs over [progressFrom, progressTo). The listed pass starts with a smaller
    // slice: each of its samples runs the quadrature somewhere (up to ~13 ms each on lavapipe).
    double longestMs = 0.0, totalMs = 0.0;
    // listed: 0 every sample, 1 the samples of the list, 2 the nodes of the list (pixels around a light's projection,
    // written to `out` in list order).
    auto pass = [&](gpu::ComputeKernel& k, std::uint64_t count, std::uint32_t listed, double progressFrom,
                    double progressTo, gpu::Buffer& out, gpu::Buffer& outOverflows) {
        const std::vector<const gpu::Buffer*> buffers = bindings(out, outOverflows);
        gpu::SliceStats stats;
        try {
            stats = gpu::runSliced(
                ctx, count,
                [&](VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t n) {
                    if (callbacks.progress)
                        callbacks.progress(progressFrom + (progressTo - progressFrom) * double(begin) / double(count));
                    Push push{std::uint32_t(begin), std::uint32_t(count), std::uint32_t(width), listed};
                    k.record(cmd, buffers, &push, std::uint32_t((n + kGroupSize - 1) / kGroupSize));
                    gpu::computeToComputeBarrier(cmd);
                },
                callbacks.cancel, 10.0, listed != 0 ? 16 : 256);
        } catch (...) {
            k.resetDescriptors();
            throw;
        }
        k.resetDescriptors();
        longestMs = std::max(longestMs, stats.longestMs);
        totalMs += stats.totalMs;
    };
    pass(first, samples, 0, 0.0, variant.deferredFallback ? 0.9 : 1.0, radiance, overflows);
    times.mark("closed form");

    std::vector<glm::vec4> perSample = radiance.download<glm::vec4>(samples);
    times.mark("readback");
    if (variant.deferredFallback) {
        std::vector<std::uint32_t> deferred;
        for (std::uint64_t i = 0; i < samples; ++i)
            if (perSample[i].w > 0.0f) deferred.push_back(std::uint32_t(i));
        if (!deferred.empty()) {
            gpu::ComputeKernel& second = fullKernel();
            list = upload(deferred);
            times.mark("compile");
            pass(second, deferred.size(), 1, 0.9, 0.95, radiance, overflows);
            times.mark("fallback samples");
            perSample = radiance.download<glm::vec4>(samples);
            times.mark("readback");
        }
    }

    // The mean of each pixel's samples, the sums of their fallbacks and overflows.
    const std::vector<std::uint32_t> overflowsPerSample = overflows.download<std::uint32_t>(samples);
    GpuOutput out;
    out.radiance.assign(pixels, glm::vec4(0.0f));
    out.overflows.assign(pixels, 0u);
    for (std::uint64_t p = 0; p < pixels; ++p) {
        glm::vec4 sum(0.0f);
        for (std::uint64_t k = 0; k < perPixel; ++k) {
            sum += perSample[p * perPixel + k];
            out.overflows[p] += overflowsPerSample[p * perPixel + k];
        }
        out.radiance[p] = glm::vec4(glm::vec3(sum) / float(perPixel), sum.w);
    }
    times.mark("readback");

    // The pixels around a light's projection: their nodes (pegoraroSingularNode) by the full shader, summed per pixel.
    std::vector<std::uint32_t> singular;
    {
        SceneScope scope(scene);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                shader::vec2 point;
                if (shader::pegoraroSingularPoint(scene.frame, x, y, point))
                    singular.push_back(std::uint32_t(y * width + x));
            }
    }
    times.mark("singular pixels");
    if (!singular.empty()) {
        gpu::ComputeKernel& k = fullKernel();
        const std::uint32_t perNode = std::uint32_t(shader::kPegoraroSingularNodes);
        std::vector<std::uint32_t> items;
        for (std::uint32_t p : singular)
            for (std::uint32_t node = 0; node < perNode; ++node)
                items.push_back(p * perNode + node);
        list = upload(items);
        gpu::Buffer nodeRadiance(ctx, items.size() * sizeof(glm::vec4));
        gpu::Buffer nodeOverflows(ctx, items.size() * sizeof(std::uint32_t));
        times.mark("compile");
        pass(k, items.size(), 2, 0.95, 1.0, nodeRadiance, nodeOverflows);
        times.mark("singular nodes");
        const std::vector<glm::vec4> values = nodeRadiance.download<glm::vec4>(items.size());
        const std::vector<std::uint32_t> nodeOverflowCounts = nodeOverflows.download<std::uint32_t>(items.size());
        for (std::size_t i = 0; i < singular.size(); ++i) {
            glm::vec4 sum(0.0f);
            std::uint32_t overflowSum = 0;
            for (std::uint32_t node = 0; node < perNode; ++node) {
                sum += values[i * perNode + node];
                overflowSum += nodeOverflowCounts[i * perNode + node];
            }
            out.radiance[singular[i]] = sum;
            out.overflows[singular[i]] = overflowSum;
        }
    }
    out.deviceName = ctx.device().name;
    out.longestSliceMs = longestMs;
    out.gpuMs = totalMs + primary.gpuMs;
    out.primaryHitsMs = primary.gpuMs;
    out.compileSeconds = compileSeconds;
    out.primaryVisibility = primary.visibility;
    return out;
}

}  // namespace tyndall::pegoraro
