#include "tyndall/framework/primary_hits.h"

#include "tyndall/framework/kernel_cache.h"

#include "shared/constants.h"
#include "tyndall/core/resources.h"
#include "tyndall/gpu/graphics.h"
#include "tyndall/gpu/shader_compiler.h"

#include <chrono>
#include <cstdlib>

namespace tyndall {

namespace {

struct Push {
    shader::CameraParams camera;
    std::int32_t samplesPerSide;
};

// Triangle ids travel as floats in the records: exact up to 2^24.
constexpr std::uint64_t kMaxTriangles = std::uint64_t(1) << 24;

std::string shaderPath(const char* name) {
    return (shaderDirectory() / "primary" / name).string();
}

}  // namespace

std::string rasterPrimaryUnsupported(const gpu::DeviceInfo& device, std::uint64_t samplesWide,
                                     std::uint64_t samplesHigh, std::uint64_t triangles) {
    if (!device.graphics) return "the device's queue has no graphics";
    const std::uint64_t side = std::min<std::uint64_t>(
        device.maxImageDimension2D, std::min(device.maxFramebufferWidth, device.maxFramebufferHeight));
    if (samplesWide > device.maxFramebufferWidth || samplesHigh > device.maxFramebufferHeight ||
        samplesWide > device.maxImageDimension2D || samplesHigh > device.maxImageDimension2D)
        return "a grid of " + std::to_string(samplesWide) + " x " + std::to_string(samplesHigh) +
               " samples exceeds the device's largest render target (" + std::to_string(side) + " per side)";
    const std::uint64_t bytes = samplesWide * samplesHigh * 16;
    if (bytes > device.maxStorageBufferRange)
        return "a grid of " + std::to_string(samplesWide) + " x " + std::to_string(samplesHigh) + " samples needs " +
               std::to_string(bytes) + " bytes, beyond the device's storage-buffer range of " +
               std::to_string(device.maxStorageBufferRange);
    if (triangles > kMaxTriangles)
        return std::to_string(triangles) + " triangles: the records hold ids up to " + std::to_string(kMaxTriangles);
    return "";
}

RasterPrimaryHits::RasterPrimaryHits(gpu::Context& context) : context_(context) {}
RasterPrimaryHits::~RasterPrimaryHits() = default;

PrimaryHits RasterPrimaryHits::render(const gpu::Buffer& bvhNodes, const gpu::Buffer& bvhTriangles,
                                      std::uint64_t triangles, const shader::CameraParams& camera, int samplesPerSide) {
    PrimaryHits out;
    const std::uint64_t wide = std::uint64_t(camera.width) * std::uint64_t(samplesPerSide);
    const std::uint64_t high = std::uint64_t(camera.height) * std::uint64_t(samplesPerSide);
    if (const char* off = std::getenv("TYNDALL_RASTER_PRIMARY"); off && std::string(off) == "0") {
        out.visibility = "traced: TYNDALL_RASTER_PRIMARY=0";
        return out;
    }
    if (std::string why = rasterPrimaryUnsupported(context_.device(), wide, high, triangles); !why.empty()) {
        out.visibility = "traced: " + why;
        return out;
    }
    try {
        if (!pipeline_) {
            const auto start = std::chrono::steady_clock::now();
            gpu::GraphicsPipelineDesc desc;
            desc.name = "primary_hits";
            desc.vertex = compileShaderVariant(shaderPath("primary.vert.glsl"), gpu::ShaderStage::Vertex, "");
            desc.fragment = compileShaderVariant(shaderPath("primary.frag.glsl"), gpu::ShaderStage::Fragment, "");
            desc.colour = {gpu::ColourAttachment{VK_FORMAT_R32G32B32A32_SFLOAT, gpu::Blend::none()}};
            desc.depth = gpu::DepthAttachment{VK_FORMAT_D32_SFLOAT, true, true, VK_COMPARE_OP_GREATER};
            desc.bindingCount = 2;
            desc.pushConstantBytes = sizeof(Push);
            pipeline_ = std::make_unique<gpu::GraphicsPipeline>(context_, desc);
            out.compileSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
        gpu::RenderTarget& records = gpu::keptRenderTarget(context_, recordTarget_, std::uint32_t(wide),
                                                           std::uint32_t(high), VK_FORMAT_R32G32B32A32_SFLOAT);
        gpu::RenderTarget& depth = gpu::keptRenderTarget(context_, depthTarget_, std::uint32_t(wide),
                                                         std::uint32_t(high), VK_FORMAT_D32_SFLOAT);
        gpu::Buffer& recordBuffer = gpu::keptBuffer(context_, records_, records.layerBytes());
        const Push push{camera, samplesPerSide};
        const std::vector<const gpu::Buffer*> buffers{&bvhNodes, &bvhTriangles};
        gpu::PassDesc pass;
        pass.colour = {gpu::AttachmentRef{&records, 0}};
        pass.depth = gpu::AttachmentRef{&depth, 0};
        pass.clearColours = {std::array<float, 4>{shader::kInfinity, 0.0f, 0.0f, 0.0f}};
        pass.clearDepth = 0.0f;
        out.gpuMs = context_.submitTimed([&](VkCommandBuffer cmd) {
            pipeline_->beginPass(cmd, pass);
            if (triangles > 0) pipeline_->draw(cmd, buffers, &push, std::uint32_t(3 * triangles));
            pipeline_->endPass(cmd);
            records.recordCopy(cmd, recordBuffer, 0);
        });
        pipeline_->resetDescriptors();
        out.records = &recordBuffer;
        out.visibility = "raster";
    } catch (const gpu::GpuError& e) {
        if (pipeline_) pipeline_->resetDescriptors();
        out.records = nullptr;
        out.visibility = std::string("traced: ") + e.what();
    }
    return out;
}

}  // namespace tyndall
