// Graphics pipelines for techniques that rasterise (ISV's tetrahedral particles are drawn as blended proxies):
// offscreen render targets, pipelines built from SPIR-V, and passes and draws recorded into the caller's command
// buffer. As with ComputeKernel, shader data lives in storage buffers: there are no vertex inputs (vertex shaders
// fetch by gl_VertexIndex / gl_InstanceIndex) and no samplers (a target's texels are copied into a Buffer).
//
// Conventions are Vulkan's: NDC y = -1 is image row 0 (the first row of readback() and of a copy), x = -1 is column
// 0; depth is in [0, 1]. Nothing is culled unless the description asks; front faces are counter-clockwise.
//
// A target tracks its image layout, and the stages that used it last, in recording order: record the commands that
// use a target in the order they are submitted (one queue, as everywhere in tyndall_gpu), and every call below puts
// the barrier it needs in front of itself. Hot reload: a pipeline is immutable; build a new GraphicsPipeline from the
// stages' new SPIR-V (HotShader per stage file, *.vert.glsl / *.geom.glsl / *.frag.glsl) when a generation changes.
#pragma once

#include "tyndall/gpu/resources.h"

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tyndall::gpu {

// An offscreen 2D image of `layers` array layers whose texels are 32-bit floats: VK_FORMAT_R32_SFLOAT,
// R32G32_SFLOAT, R32G32B32A32_SFLOAT (colour) or D32_SFLOAT (depth). A view per layer serves as an attachment.
class RenderTarget {
public:
    RenderTarget(Context& context, std::uint32_t width, std::uint32_t height, VkFormat format,
                 std::uint32_t layers = 1);
    ~RenderTarget();
    RenderTarget(const RenderTarget&) = delete;
    RenderTarget& operator=(const RenderTarget&) = delete;

    std::uint32_t width() const { return width_; }
    std::uint32_t height() const { return height_; }
    std::uint32_t layers() const { return layers_; }
    VkFormat format() const { return format_; }
    bool isDepth() const { return format_ == VK_FORMAT_D32_SFLOAT; }
    std::uint32_t channels() const { return channels_; }  // floats per texel
    VkDeviceSize layerBytes() const { return VkDeviceSize(width_) * height_ * channels_ * 4; }
    VkImage image() const { return image_; }
    VkImageView view(std::uint32_t layer) const { return views_.at(layer); }
    std::uint64_t serial() const { return serial_; }  // unique in the process (framebuffer caches key on it)

    // Records a clear of every layer: a colour target takes value's first channels(), a depth target value[0].
    void recordClear(VkCommandBuffer cmd, const std::array<float, 4>& value);
    // Records a copy of one layer into `buffer` at `offset`, tightly packed: rows of width() texels of channels()
    // floats, row 0 first. The copy is then visible to shaders (compute and graphics), transfers and the host.
    void recordCopy(VkCommandBuffer cmd, const Buffer& buffer, std::uint32_t layer, VkDeviceSize offset = 0);
    // Every layer, layer k at offset + k * layerBytes().
    void recordCopyAll(VkCommandBuffer cmd, const Buffer& buffer, VkDeviceSize offset = 0);
    // Submits a copy of one layer, waits and returns its texels as recordCopy lays them out, which is tyndall::Image's
    // layout (row-major from row 0, channels interleaved): it copies straight into Image::data().
    std::vector<float> readback(std::uint32_t layer = 0);

    // Records the barrier that makes the image ready for `access` by `stages` in `layout`, after its last use.
    // The calls above and GraphicsPipeline::beginPass use it; other code rarely needs to.
    void use(VkCommandBuffer cmd, VkImageLayout layout, VkPipelineStageFlags stages, VkAccessFlags access);

private:
    void recordCopyLayers(VkCommandBuffer cmd, const Buffer& buffer, std::uint32_t first, std::uint32_t count,
                          VkDeviceSize offset);
    void release();

    Context& context_;
    std::uint32_t width_, height_, layers_, channels_ = 0;
    VkFormat format_;
    std::uint64_t serial_;
    VkImage image_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    std::vector<VkImageView> views_;
    VkImageLayout layout_ = VK_IMAGE_LAYOUT_UNDEFINED;
    VkPipelineStageFlags lastStages_ = VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT;
    VkAccessFlags lastAccess_ = 0;
};

// The render target in `slot`, made anew only when it is missing or differs in size, format or layers (keptBuffer's
// reason: a renderer's targets stay from one render to the next).
inline RenderTarget& keptRenderTarget(Context& context, std::unique_ptr<RenderTarget>& slot, std::uint32_t width,
                                      std::uint32_t height, VkFormat format, std::uint32_t layers = 1) {
    if (!slot || slot->width() != width || slot->height() != height || slot->format() != format ||
        slot->layers() != layers) {
        slot.reset();
        slot = std::make_unique<RenderTarget>(context, width, height, format, layers);
    }
    return *slot;
}

// The blend state of one colour attachment: result = src * srcFactor (op) dst * dstFactor, for colour and alpha.
struct Blend {
    bool enable = false;
    VkBlendFactor srcColor = VK_BLEND_FACTOR_ONE, dstColor = VK_BLEND_FACTOR_ZERO;
    VkBlendOp colorOp = VK_BLEND_OP_ADD;
    VkBlendFactor srcAlpha = VK_BLEND_FACTOR_ONE, dstAlpha = VK_BLEND_FACTOR_ZERO;
    VkBlendOp alphaOp = VK_BLEND_OP_ADD;

    static Blend none() { return {}; }  // the fragment's value replaces the texel
    static Blend additive() {           // dst + src, colour and alpha
        return {true, VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE, VK_BLEND_OP_ADD,
                VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE, VK_BLEND_OP_ADD};
    }
    // ISV's premultiplied "under": rgb = src.rgb + dst.rgb * src.a, a = dst.a * src.a (src.a is the fragment's
    // transmittance). Draws 1, 2, 3 over a clear value give C3 + a3 (C2 + a2 (C1 + a1 clear)).
    static Blend premultipliedUnder() {
        return {true, VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_SRC_ALPHA, VK_BLEND_OP_ADD,
                VK_BLEND_FACTOR_ZERO, VK_BLEND_FACTOR_SRC_ALPHA, VK_BLEND_OP_ADD};
    }
    // The same with a transmittance per channel, from the fragment's second output (dual-source blending, output
    // `layout(location = 0, index = 1)`, needs DeviceInfo::dualSrcBlend): rgb = src.rgb + dst.rgb * src1.rgb,
    // a = dst.a * src1.a.
    static Blend premultipliedUnderPerChannel() {
        return {true, VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_SRC1_COLOR, VK_BLEND_OP_ADD,
                VK_BLEND_FACTOR_ZERO, VK_BLEND_FACTOR_SRC1_ALPHA, VK_BLEND_OP_ADD};
    }
    bool dualSource() const;  // a factor reads the second output
};

struct ColourAttachment {
    VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT;
    Blend blend;
};

struct DepthAttachment {
    VkFormat format = VK_FORMAT_D32_SFLOAT;
    bool test = true;
    bool write = true;
    VkCompareOp compare = VK_COMPARE_OP_LESS;
};

struct GraphicsPipelineDesc {
    std::string name;                                       // for errors
    std::vector<std::uint32_t> vertex, geometry, fragment;  // SPIR-V; geometry empty for none
    // SPIR-V of a mesh stage (VK_EXT_mesh_shader, DeviceInfo::meshShader) instead of the vertex and geometry stages:
    // draw with drawMeshTasks. topology is then unused.
    std::vector<std::uint32_t> mesh;
    VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkCullModeFlags cull = VK_CULL_MODE_NONE;
    std::vector<ColourAttachment> colour;  // location i = colour[i]
    std::optional<DepthAttachment> depth;
    std::uint32_t bindingCount = 0;       // storage buffers in set 0, binding i = buffers[i], every stage
    std::uint32_t pushConstantBytes = 0;  // one block for every stage
};

// A layer of a target to render into.
struct AttachmentRef {
    RenderTarget* target = nullptr;
    std::uint32_t layer = 0;
};

enum class LoadOp {
    Clear,  // the pass starts from its clear values
    Load,   // the pass starts from the targets' contents (a slice of a long draw, a later pass)
};

struct PassDesc {
    std::vector<AttachmentRef> colour;  // one per ColourAttachment of the pipeline, in its order
    std::optional<AttachmentRef> depth;  // exactly when the pipeline has a depth attachment
    LoadOp load = LoadOp::Clear;
    std::vector<std::array<float, 4>> clearColours;  // one per colour attachment, or none for zeros
    float clearDepth = 1.0f;
};

// A graphics pipeline with a classic render pass (no dynamic rendering: the device may be Vulkan 1.2), viewport and
// scissor covering the targets, and framebuffers cached per set of attachments.
class GraphicsPipeline {
public:
    GraphicsPipeline(Context& context, const GraphicsPipelineDesc& desc);
    ~GraphicsPipeline();
    GraphicsPipeline(const GraphicsPipeline&) = delete;
    GraphicsPipeline& operator=(const GraphicsPipeline&) = delete;

    // Records the start of a pass into the targets (same size, formats as described) and binds the pipeline.
    void beginPass(VkCommandBuffer cmd, const PassDesc& pass);
    // Records a draw of vertices [firstVertex, firstVertex + vertexCount) for each instance; inside a pass. Descriptor
    // sets come from the pipeline's pool: call resetDescriptors() once the command buffers that used them completed.
    void draw(VkCommandBuffer cmd, const std::vector<const Buffer*>& buffers, const void* push,
              std::uint32_t vertexCount, std::uint32_t instanceCount = 1, std::uint32_t firstVertex = 0,
              std::uint32_t firstInstance = 0);
    // Records groupCount mesh-shader workgroups (a mesh pipeline's draw), at most DeviceInfo::maxMeshWorkGroups; inside
    // a pass, descriptors as draw().
    void drawMeshTasks(VkCommandBuffer cmd, const std::vector<const Buffer*>& buffers, const void* push,
                       std::uint32_t groupCount);
    void endPass(VkCommandBuffer cmd);
    bool usesMeshShader() const { return mesh_; }
    // Also forgets the cached framebuffers when there are many (targets come and go), under the same condition.
    void resetDescriptors();
    const std::string& name() const { return name_; }

private:
    VkFramebuffer framebuffer(const PassDesc& pass);
    // A descriptor set of `buffers` and the push constants, for the next draw.
    void bindResources(VkCommandBuffer cmd, const std::vector<const Buffer*>& buffers, const void* push);
    void release();

    Context& context_;
    std::string name_;
    std::uint32_t colourCount_;
    std::vector<VkFormat> colourFormats_;
    std::optional<VkFormat> depthFormat_;
    std::uint32_t pushBytes_;
    bool mesh_;
    VkShaderStageFlags stages_;
    StorageDescriptorSets sets_;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkRenderPass clearPass_ = VK_NULL_HANDLE, loadPass_ = VK_NULL_HANDLE;  // compatible: differ in load ops only
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    std::map<std::vector<std::pair<std::uint64_t, std::uint32_t>>, VkFramebuffer> framebuffers_;  // (serial, layer)s
    bool inPass_ = false;
};

// Storage-buffer writes of compute shaders made visible to the graphics stages (and indirect draws' reads).
void computeToGraphicsBarrier(VkCommandBuffer cmd);
// Storage-buffer writes of graphics stages (fragment stores) made visible to compute shaders, transfers and the host.
void graphicsToComputeBarrier(VkCommandBuffer cmd);

}  // namespace tyndall::gpu
