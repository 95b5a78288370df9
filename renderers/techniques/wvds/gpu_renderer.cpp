#include "wvds/gpu_renderer.h"

#include "tyndall/core/error.h"
#include "tyndall/gpu/shader_compiler.h"
#include "tyndall/gpu/slicer.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>

namespace tyndall::wvds {

namespace {

constexpr std::uint32_t kGroupSize = 64;

struct Push {
    std::uint32_t first;  // work items, see the shader
    std::uint32_t end;    // one past the last item of this dispatch (its groups may reach beyond: they must not add)
    std::uint32_t width;
    std::uint32_t index;
    std::uint32_t stride;
    std::uint32_t ratioLights;
    std::uint32_t pixels;
    std::uint32_t bandGroups;  // groups of 64 pixels in each of the kBands bands that work items take in turn
};

constexpr std::uint32_t kBands = 16;  // as in the shader

std::string shaderPath() {
    return std::string(TYNDALL_SHADER_DIR) + "/wvds/wvds.comp.glsl";
}

}  // namespace

GpuRenderer::GpuRenderer() : context_(gpu::sharedContext()) {}

gpu::ComputeKernel& GpuRenderer::kernel(int estimator, int planeCount, int planeTotal, bool box, int phaseKind,
                                        int lightCount, bool surfaces, bool grey, bool gobos) {
    const int maxPlanes = planeCount <= 6 ? 6 : planeCount <= 8 ? 8 : shader::kWvdsMaxPlanes;
    const std::string key = std::to_string(estimator) + "-" + (box ? std::string("box") : std::to_string(planeCount)) +
                            "-" + std::to_string(planeTotal) + "-" + std::to_string(phaseKind) + "-" +
                            std::to_string(lightCount) + (surfaces ? "" : "-nosurfaces") + (grey ? "-grey" : "") +
                            (gobos ? "" : "-nogobos");
    std::string defines = "#define TY_WVDS_ESTIMATOR " + std::to_string(estimator) + "\n#define TY_WVDS_MAX_PLANES " +
                          std::to_string(maxPlanes) + "\n#define TY_PHASE_KIND " + std::to_string(phaseKind) +
                          "\n#define TY_WVDS_LIGHTS " + std::to_string(lightCount) + "\n#define TY_WVDS_PLANES " +
                          std::to_string(planeCount) + "\n";
    if (planeTotal > 0) defines += "#define TY_WVDS_PLANE_TOTAL " + std::to_string(planeTotal) + "\n";
    if (box) defines += "#define TY_WVDS_BOX\n";
    if (!surfaces) defines += "#define TY_WVDS_NO_SURFACES\n";
    if (grey) defines += "#define TY_WVDS_GREY\n";
    if (!gobos) defines += "#define TY_WVDS_NO_GOBOS\n";
    if (context_->device().shaderFloat64) defines += "#define TY_BVH_WORDS\n#define TY_ACCUMULATOR_WORDS\n";
    return kernels_.get(*context_, {shaderPath(), defines, 8, std::uint32_t(sizeof(Push)), "wvds_" + key},
                        compileSeconds_);
}

void GpuRenderer::begin(const PreparedScene& scene, int width, int height, int stride, int ratioLights) {
    compileSeconds_ = 0.0;
    kernel_ = &kernel(scene.frame.estimator, scene.frame.planeCount, int(scene.planes.size()), scene.box,
                      scene.frame.phase.kind, scene.frame.lightCount, scene.surfaces.triangleCount > 0,
                      shader::wvdsGrey(scene.frame),
                      std::any_of(scene.lights.begin(), scene.lights.end(),
                                  [](const shader::WvdsLight& l) { return l.goboCount > 0; }));
    gpu::Context& ctx = *context_;
    auto upload = [&](const auto& values) { return gpu::uploadBuffer(ctx, values); };
    buffers_.clear();
    buffers_.push_back(upload(scene.surfaces.bvh.nodes));
    buffers_.push_back(upload(scene.surfaces.bvh.triangles));
    auto frame = std::make_unique<gpu::Buffer>(ctx, sizeof(shader::WvdsFrame));
    frame->upload(&scene.frame, sizeof(shader::WvdsFrame));
    buffers_.push_back(std::move(frame));
    buffers_.push_back(upload(scene.planes));
    buffers_.push_back(upload(scene.lights));
    buffers_.push_back(upload(scene.surfaces.triangles));
    buffers_.push_back(upload(scene.surfaces.materials));
    pixels_ = std::uint32_t(width) * std::uint32_t(height);
    width_ = std::uint32_t(width);
    stride_ = std::uint32_t(stride);
    ratioLights_ = std::uint32_t(ratioLights);
    // The accumulators stay from render to render at the same size (an edit re-renders the view at its size), zeroed
    // in place: a fresh 8-32 MB buffer and a host array of zeros for it cost page faults, ~8 ms per 8 MB here.
    const VkDeviceSize accumulatorBytes = VkDeviceSize(pixels_) * 2 * stride_ * sizeof(glm::vec4);
    if (!accumulators_ || accumulators_->size() != accumulatorBytes)
        accumulators_ = std::make_unique<gpu::Buffer>(ctx, accumulatorBytes);
    accumulators_->fill(0u);
    longestSliceMs_ = gpuMs_ = 0.0;
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
                    Push push{std::uint32_t(begin),
                              std::uint32_t(begin + count),
                              width_,
                              index,
                              stride_,
                              ratioLights_,
                              pixels_,
                              bandGroups};
                    k.record(cmd, bindings, &push, std::uint32_t((count + kGroupSize - 1) / kGroupSize));
                    gpu::computeToComputeBarrier(cmd);
                },
                callbacks.cancel, 10.0, sliceSize);
            sliceSize = stats.nextSlice;
            longestSliceMs_ = std::max(longestSliceMs_, stats.longestMs);
            gpuMs_ += stats.totalMs;
            k.resetDescriptors();
        }
    } catch (...) {
        k.resetDescriptors();
        throw;
    }
}

const std::vector<glm::vec4>& GpuRenderer::readAccumulators() {
    accumulators_->download(readback_, std::size_t(pixels_) * 2 * stride_);
    return readback_;
}

}  // namespace tyndall::wvds
