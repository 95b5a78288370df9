#include "volume_ris/gpu_renderer.h"

#include "tyndall/core/error.h"
#include "tyndall/gpu/shader_compiler.h"
#include "tyndall/gpu/slicer.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>

namespace tyndall::volume_ris {

namespace {

constexpr std::uint32_t kGroupSize = 64;
constexpr std::uint32_t kBands = 16;  // as in the shader
constexpr int kBindings = 9;

struct Push {
    std::uint32_t first;  // work items, see the shader
    std::uint32_t end;    // one past the last item of this dispatch
    std::uint32_t width;
    std::uint32_t index;
    std::uint32_t pixels;
    std::uint32_t bandGroups;  // groups of 64 pixels in each of the kBands bands that work items take in turn
};

std::string shaderPath() {
    return std::string(TYNDALL_SHADER_DIR) + "/volume_ris/volume_ris.comp.glsl";
}

}  // namespace

GpuRenderer::GpuRenderer() : context_(gpu::sharedContext()) {}

gpu::ComputeKernel& GpuRenderer::kernel(const PreparedScene& scene) {
    const shader::RisFrame& f = scene.frame;
    const bool surfaces = scene.surfaces.triangleCount > 0;
    const int vertexTotal = f.lightCount > 0 ? int(scene.vertices.size()) : 0;
    int maxVertices = 3;
    for (int i = 0; i < f.lightCount; ++i)
        maxVertices = std::max(maxVertices, scene.lights[std::size_t(i)].vertexCount);
    const std::string key = "m" + std::to_string(f.mediumKind) + "-p" + std::to_string(f.planeCount) + "-l" +
                            std::to_string(f.lightCount) + "-v" + std::to_string(vertexTotal) + "-mv" +
                            std::to_string(maxVertices) + "-ph" + std::to_string(f.phase.kind) + "-d" +
                            std::to_string(f.distanceSampling) + "-ls" + std::to_string(f.lightSampling) +
                            (surfaces ? "" : "-nosurfaces") + (scene.grey ? "-grey" : "");
    std::string defines = "#define TY_RIS_MEDIUM " + std::to_string(f.mediumKind) + "\n#define TY_RIS_PLANES " +
                          std::to_string(f.planeCount) + "\n#define TY_RIS_LIGHTS " + std::to_string(f.lightCount) +
                          "\n#define TY_PHASE_KIND " + std::to_string(f.phase.kind) + "\n#define TY_RIS_DISTANCE " +
                          std::to_string(f.distanceSampling) + "\n#define TY_RIS_VERTICES " +
                          std::to_string(maxVertices) + "\n#define TY_RIS_LIGHT_SAMPLING " +
                          std::to_string(f.lightSampling) + "\n";
    if (vertexTotal > 0) defines += "#define TY_RIS_VERTEX_TOTAL " + std::to_string(vertexTotal) + "\n";
    if (!surfaces) defines += "#define TY_RIS_NO_SURFACES\n";
    if (scene.grey) defines += "#define TY_RIS_GREY\n";
    if (context_->device().shaderFloat64) defines += "#define TY_BVH_WORDS\n";
    return kernels_.get(*context_, {shaderPath(), defines, kBindings, std::uint32_t(sizeof(Push)), "volume_ris_" + key},
                        compileSeconds_);
}

void GpuRenderer::begin(const PreparedScene& scene, int width, int height) {
    compileSeconds_ = 0.0;
    kernel_ = &kernel(scene);
    gpu::Context& ctx = *context_;
    auto upload = [&](const auto& values) { return gpu::uploadBuffer(ctx, values); };
    buffers_.clear();
    buffers_.push_back(upload(scene.surfaces.bvh.nodes));
    buffers_.push_back(upload(scene.surfaces.bvh.triangles));
    auto frame = std::make_unique<gpu::Buffer>(ctx, sizeof(shader::RisFrame));
    frame->upload(&scene.frame, sizeof(shader::RisFrame));
    buffers_.push_back(std::move(frame));
    buffers_.push_back(upload(scene.planes));
    buffers_.push_back(upload(scene.lights));
    buffers_.push_back(upload(scene.vertices));
    buffers_.push_back(upload(scene.surfaces.triangles));
    buffers_.push_back(upload(scene.surfaces.materials));
    pixels_ = std::uint32_t(width) * std::uint32_t(height);
    width_ = std::uint32_t(width);
    // Kept from render to render at the same size and zeroed in place (see wvds/gpu_renderer.cpp).
    const VkDeviceSize accumulatorBytes = VkDeviceSize(pixels_) * 4 * sizeof(glm::vec4);
    if (!accumulators_ || accumulators_->size() != accumulatorBytes)
        accumulators_ = std::make_unique<gpu::Buffer>(ctx, accumulatorBytes);
    accumulators_->fill(0u);
    gpuMs_ = 0.0;
}

void GpuRenderer::addSamples(std::uint32_t first, std::uint32_t end, const RenderCallbacks& callbacks) {
    TY_CHECK(kernel_ != nullptr && accumulators_, "GpuRenderer::begin before addSamples");
    gpu::ComputeKernel& k = *kernel_;
    std::vector<const gpu::Buffer*> bindings;
    for (const auto& b : buffers_)
        bindings.push_back(b.get());
    bindings.push_back(accumulators_.get());
    std::uint64_t& sliceSize = sliceSizes_.try_emplace(&k, 1024).first->second;
    const std::uint32_t bandGroups = ((pixels_ + kGroupSize - 1) / kGroupSize + kBands - 1) / kBands;
    try {
        for (std::uint32_t index = first; index < end; ++index) {
            // One dispatch covers each pixel at most once, so the read-modify-write of its accumulators never races.
            const gpu::SliceStats stats = gpu::runSliced(
                *context_, std::uint64_t(kBands) * bandGroups * kGroupSize,
                [&](VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t count) {
                    Push push{std::uint32_t(begin), std::uint32_t(begin + count), width_, index, pixels_, bandGroups};
                    k.record(cmd, bindings, &push, std::uint32_t((count + kGroupSize - 1) / kGroupSize));
                    gpu::computeToComputeBarrier(cmd);
                },
                callbacks.cancel, 10.0, sliceSize);
            sliceSize = stats.nextSlice;
            gpuMs_ += stats.totalMs;
            k.resetDescriptors();
        }
    } catch (...) {
        k.resetDescriptors();
        throw;
    }
}

const std::vector<glm::vec4>& GpuRenderer::readAccumulators() {
    accumulators_->download(readback_, std::size_t(pixels_) * 4);
    return readback_;
}

}  // namespace tyndall::volume_ris
