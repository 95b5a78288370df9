#include "pegoraro/gpu_renderer.h"

#include "tyndall/error.h"
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
};

std::string shaderPath() {
    return std::string(TYNDALL_SHADER_DIR) + "/pegoraro/pegoraro.comp.glsl";
}

// Array sizes come in a few steps, so that a scene's order picks one of a handful of variants.
int roundTerms(int terms) {
    for (int step : {1, 2, 3, 5, 9, 17, 25, 33})
        if (terms <= step) return step;
    return shader::kPegoraroMaxTerms;
}

}  // namespace

GpuRenderer::GpuRenderer() : context_(gpu::sharedContext()) {}

gpu::ComputeKernel& GpuRenderer::kernel(int maxTerms, bool useDouble, bool shadows) {
    const int terms = roundTerms(maxTerms);
    const bool words = context_->device().shaderFloat64;
    const std::string key =
        std::to_string(terms) + (useDouble ? "d" : "f") + (words ? "w" : "s") + (shadows ? "" : "-noshadows");
    auto it = kernels_.find(key);
    if (it != kernels_.end()) return *it->second;

    std::ifstream file(shaderPath());
    if (!file) throw gpu::GpuError("cannot read the shader " + shaderPath());
    std::stringstream text;
    text << file.rdbuf();
    std::string source = text.str();
    // Defines go right after the #version line.
    std::string defines = "#define TY_PEGORARO_MAX_TERMS " + std::to_string(terms) + "\n";
    if (useDouble) defines += "#define TY_ENABLE_DOUBLE\n";
    if (words) defines += "#define TY_BVH_WORDS\n";
    if (!shadows) defines += "#define TY_PEGORARO_NO_SHADOWS\n";
    const std::size_t lineEnd = source.find('\n');
    source.insert(lineEnd + 1, defines + "#line 2\n");
    gpu::CompileResult compiled = gpu::compileGlslSource(source, shaderPath(), gpu::ShaderStage::Compute);
    if (!compiled.ok) throw gpu::ShaderError(*compiled.error);
    auto k = std::make_unique<gpu::ComputeKernel>(*context_, compiled.spirv, 10, std::uint32_t(sizeof(Push)),
                                                  "pegoraro_" + key);
    return *kernels_.emplace(key, std::move(k)).first->second;
}

GpuOutput GpuRenderer::render(const PreparedScene& scene, bool useDouble, int width, int height,
                              const RenderCallbacks& callbacks) {
    if (useDouble && !context_->device().shaderFloat64)
        throw InputError(InputLocation{"", 0, 0, "precision"},
                         "the GPU '" + context_->device().name +
                             "' has no double precision (shaderFloat64); use precision = float or device = cpu");
    const auto compileStart = std::chrono::steady_clock::now();
    gpu::ComputeKernel& k = kernel(scene.maxTerms, useDouble, scene.frame.shadows != 0);
    const double compileSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - compileStart).count();
    gpu::Context& ctx = *context_;

    auto upload = [&](const auto& values) { return gpu::uploadBuffer(ctx, values); };
    auto nodes = upload(scene.bvh.nodes);
    auto triangles = upload(scene.bvh.triangles);
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
    const std::vector<const gpu::Buffer*> buffers = {
        nodes.get(),        triangles.get(),        frame.get(),     lights.get(), media.get(),
        coefficients.get(), surfaceTriangles.get(), materials.get(), &radiance,    &overflows};

    gpu::SliceStats stats;
    try {
        stats = gpu::runSliced(
            ctx, samples,
            [&](VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t count) {
                if (callbacks.progress) callbacks.progress(double(begin) / double(samples));
                Push push{std::uint32_t(begin), std::uint32_t(samples), std::uint32_t(width)};
                k.record(cmd, buffers, &push, std::uint32_t((count + kGroupSize - 1) / kGroupSize));
                gpu::computeToComputeBarrier(cmd);
            },
            callbacks.cancel, 10.0, 256);
    } catch (...) {
        k.resetDescriptors();
        throw;
    }
    k.resetDescriptors();

    // The mean of each pixel's samples, the sums of their fallbacks and overflows.
    const std::vector<glm::vec4> perSample = radiance.download<glm::vec4>(samples);
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
    out.deviceName = ctx.device().name;
    out.longestSliceMs = stats.longestMs;
    out.gpuMs = stats.totalMs;
    out.compileSeconds = compileSeconds;
    return out;
}

}  // namespace tyndall::pegoraro
