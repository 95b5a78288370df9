#include "tyndall/gpu/graphics.h"

#include <atomic>

namespace tyndall::gpu {

namespace {

std::uint32_t channelsOf(VkFormat format) {
    switch (format) {
        case VK_FORMAT_R32_SFLOAT:
        case VK_FORMAT_D32_SFLOAT:
            return 1;
        case VK_FORMAT_R32G32_SFLOAT:
            return 2;
        case VK_FORMAT_R32G32B32A32_SFLOAT:
            return 4;
        default:
            return 0;
    }
}

VkImageAspectFlags aspectOf(VkFormat format) {
    return format == VK_FORMAT_D32_SFLOAT ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

bool operator==(const Blend& a, const Blend& b) {
    return a.enable == b.enable && a.srcColor == b.srcColor && a.dstColor == b.dstColor && a.colorOp == b.colorOp &&
           a.srcAlpha == b.srcAlpha && a.dstAlpha == b.dstAlpha && a.alphaOp == b.alphaOp;
}

bool isSecondSource(VkBlendFactor f) {
    return f == VK_BLEND_FACTOR_SRC1_COLOR || f == VK_BLEND_FACTOR_ONE_MINUS_SRC1_COLOR ||
           f == VK_BLEND_FACTOR_SRC1_ALPHA || f == VK_BLEND_FACTOR_ONE_MINUS_SRC1_ALPHA;
}

// Any earlier writer or reader of a buffer (shaders, transfers) before a transfer writes it.
void beforeTransferWrite(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &barrier, 0,
                         nullptr, 0, nullptr);
}

void afterTransferWrite(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                            VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_ALL_GRAPHICS_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
                             VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                         0, 1, &barrier, 0, nullptr, 0, nullptr);
}

constexpr VkPipelineStageFlags kDepthStages =
    VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;

}  // namespace

RenderTarget::RenderTarget(Context& context, std::uint32_t width, std::uint32_t height, VkFormat format,
                           std::uint32_t layers)
    : context_(context), width_(width), height_(height), layers_(layers), channels_(channelsOf(format)),
      format_(format) {
    static std::atomic<std::uint64_t> serials{0};
    serial_ = ++serials;
    if (channels_ == 0)
        throw GpuError("a render target's texels must be 32-bit floats (R32, R32G32, R32G32B32A32 or D32)");
    if (width == 0 || height == 0 || layers == 0) throw GpuError("a render target must not be empty");
    VkFormatProperties properties{};
    vkGetPhysicalDeviceFormatProperties(context.physicalDevice(), format, &properties);
    const VkFormatFeatureFlags needed =
        (isDepth() ? VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT) |
        VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
    if ((properties.optimalTilingFeatures & needed) != needed)
        throw GpuError("the device '" + context.device().name + "' cannot render to format " +
                       std::to_string(int(format)));

    VkDevice device = context.vk();
    try {
        VkImageCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
        info.imageType = VK_IMAGE_TYPE_2D;
        info.format = format;
        info.extent = {width, height, 1};
        info.mipLevels = 1;
        info.arrayLayers = layers;
        info.samples = VK_SAMPLE_COUNT_1_BIT;
        info.tiling = VK_IMAGE_TILING_OPTIMAL;
        info.usage = (isDepth() ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) |
                     VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
        info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
        info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        check(vkCreateImage(device, &info, nullptr, &image_), "creating a render target");

        VkMemoryRequirements req{};
        vkGetImageMemoryRequirements(device, image_, &req);
        VkMemoryAllocateInfo alloc{};
        alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = context.findMemoryType(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        check(vkAllocateMemory(device, &alloc, nullptr, &memory_),
              ("allocating " + std::to_string(req.size) + " bytes for a render target").c_str());
        check(vkBindImageMemory(device, image_, memory_, 0), "binding render target memory");

        for (std::uint32_t layer = 0; layer < layers; ++layer) {
            VkImageViewCreateInfo viewInfo{};
            viewInfo.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
            viewInfo.image = image_;
            viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
            viewInfo.format = format;
            viewInfo.subresourceRange = {aspectOf(format), 0, 1, layer, 1};
            VkImageView view = VK_NULL_HANDLE;
            check(vkCreateImageView(device, &viewInfo, nullptr, &view), "creating a render target view");
            views_.push_back(view);
        }
    } catch (...) {
        release();
        throw;
    }
}

RenderTarget::~RenderTarget() { release(); }

void RenderTarget::release() {
    VkDevice device = context_.vk();
    for (VkImageView view : views_) vkDestroyImageView(device, view, nullptr);
    views_.clear();
    if (image_) vkDestroyImage(device, image_, nullptr);
    if (memory_) vkFreeMemory(device, memory_, nullptr);
    image_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
}

void RenderTarget::use(VkCommandBuffer cmd, VkImageLayout layout, VkPipelineStageFlags stages, VkAccessFlags access) {
    VkImageMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    barrier.srcAccessMask = lastAccess_;
    barrier.dstAccessMask = access;
    barrier.oldLayout = layout_;  // UNDEFINED the first time: the contents are not kept
    barrier.newLayout = layout;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image_;
    barrier.subresourceRange = {aspectOf(format_), 0, 1, 0, layers_};
    vkCmdPipelineBarrier(cmd, lastStages_, stages, 0, 0, nullptr, 0, nullptr, 1, &barrier);
    layout_ = layout;
    lastStages_ = stages;
    lastAccess_ = access;
}

void RenderTarget::recordClear(VkCommandBuffer cmd, const std::array<float, 4>& value) {
    use(cmd, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    const VkImageSubresourceRange range{aspectOf(format_), 0, 1, 0, layers_};
    if (isDepth()) {
        const VkClearDepthStencilValue depth{value[0], 0};
        vkCmdClearDepthStencilImage(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &depth, 1, &range);
    } else {
        VkClearColorValue colour{};
        for (int c = 0; c < 4; ++c) colour.float32[c] = value[c];
        vkCmdClearColorImage(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &colour, 1, &range);
    }
}

void RenderTarget::recordCopyLayers(VkCommandBuffer cmd, const Buffer& buffer, std::uint32_t first,
                                    std::uint32_t count, VkDeviceSize offset) {
    if (offset + count * layerBytes() > buffer.size())
        throw GpuError("copying " + std::to_string(count) + " layer(s) of a render target overruns a buffer of " +
                       std::to_string(buffer.size()) + " bytes");
    use(cmd, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    beforeTransferWrite(cmd);
    VkBufferImageCopy region{};
    region.bufferOffset = offset;  // row length and image height 0: tightly packed, layer after layer
    region.imageSubresource = {aspectOf(format_), 0, first, count};
    region.imageExtent = {width_, height_, 1};
    vkCmdCopyImageToBuffer(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer.handle(), 1, &region);
    afterTransferWrite(cmd);
}

void RenderTarget::recordCopy(VkCommandBuffer cmd, const Buffer& buffer, std::uint32_t layer, VkDeviceSize offset) {
    if (layer >= layers_) throw GpuError("layer " + std::to_string(layer) + " of a render target with " +
                                         std::to_string(layers_) + " layers");
    recordCopyLayers(cmd, buffer, layer, 1, offset);
}

void RenderTarget::recordCopyAll(VkCommandBuffer cmd, const Buffer& buffer, VkDeviceSize offset) {
    recordCopyLayers(cmd, buffer, 0, layers_, offset);
}

std::vector<float> RenderTarget::readback(std::uint32_t layer) {
    Buffer staging(context_, layerBytes());
    context_.submitAndWait([&](VkCommandBuffer cmd) { recordCopy(cmd, staging, layer); });
    return staging.download<float>(std::size_t(width_) * height_ * channels_);
}

// ---------------------------------------------------------------------------------------------------------------------

namespace {

// The pipeline's stages, after checking that the description is complete and that the device has them (before any
// Vulkan object names a stage the device lacks).
VkShaderStageFlags stagesOf(const Context& context, const GraphicsPipelineDesc& desc) {
    const DeviceInfo& device = context.device();
    const std::string& name = desc.name;
    if (desc.fragment.empty() || desc.vertex.empty() == desc.mesh.empty() ||
        (!desc.mesh.empty() && !desc.geometry.empty()))
        throw GpuError("graphics pipeline " + name +
                       " needs a fragment shader and either a vertex shader (with an optional geometry shader) or a "
                       "mesh shader");
    if (!desc.geometry.empty() && !device.geometryShader)
        throw GpuError("graphics pipeline " + name + " has a geometry shader; the device '" + device.name +
                       "' has none");
    if (!desc.mesh.empty() && (!device.meshShader || !context.cmdDrawMeshTasks()))
        throw GpuError("graphics pipeline " + name + " has a mesh shader; the device '" + device.name +
                       "' has no VK_EXT_mesh_shader");
    if (!desc.mesh.empty()) return VK_SHADER_STAGE_MESH_BIT_EXT | VK_SHADER_STAGE_FRAGMENT_BIT;
    return VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT |
           (desc.geometry.empty() ? 0 : VK_SHADER_STAGE_GEOMETRY_BIT);
}

VkRenderPass createRenderPass(VkDevice device, const GraphicsPipelineDesc& desc, VkAttachmentLoadOp load) {
    // Attachments stay in their attachment layouts across the pass: RenderTarget::use moves them there before it
    // and away from there after it, with the barriers that order the pass against other work.
    std::vector<VkAttachmentDescription> attachments;
    std::vector<VkAttachmentReference> colourRefs;
    for (const ColourAttachment& colour : desc.colour) {
        colourRefs.push_back({std::uint32_t(attachments.size()), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL});
        attachments.push_back({0, colour.format, VK_SAMPLE_COUNT_1_BIT, load, VK_ATTACHMENT_STORE_OP_STORE,
                               VK_ATTACHMENT_LOAD_OP_DONT_CARE, VK_ATTACHMENT_STORE_OP_DONT_CARE,
                               VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL});
    }
    const VkAttachmentReference depthRef{std::uint32_t(attachments.size()),
                                         VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    if (desc.depth) {
        attachments.push_back({0, desc.depth->format, VK_SAMPLE_COUNT_1_BIT, load, VK_ATTACHMENT_STORE_OP_STORE,
                               VK_ATTACHMENT_LOAD_OP_DONT_CARE, VK_ATTACHMENT_STORE_OP_DONT_CARE,
                               VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                               VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL});
    }
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = std::uint32_t(colourRefs.size());
    subpass.pColorAttachments = colourRefs.data();
    subpass.pDepthStencilAttachment = desc.depth ? &depthRef : nullptr;
    VkRenderPassCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
    info.attachmentCount = std::uint32_t(attachments.size());
    info.pAttachments = attachments.data();
    info.subpassCount = 1;
    info.pSubpasses = &subpass;
    VkRenderPass pass = VK_NULL_HANDLE;
    check(vkCreateRenderPass(device, &info, nullptr, &pass), "creating a render pass");
    return pass;
}

VkShaderModule createModule(VkDevice device, const std::vector<std::uint32_t>& spirv, const std::string& what) {
    VkShaderModuleCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    info.codeSize = spirv.size() * sizeof(std::uint32_t);
    info.pCode = spirv.data();
    VkShaderModule module = VK_NULL_HANDLE;
    check(vkCreateShaderModule(device, &info, nullptr, &module), ("creating shader module " + what).c_str());
    return module;
}

}  // namespace

bool Blend::dualSource() const {
    return isSecondSource(srcColor) || isSecondSource(dstColor) || isSecondSource(srcAlpha) ||
           isSecondSource(dstAlpha);
}

GraphicsPipeline::GraphicsPipeline(Context& context, const GraphicsPipelineDesc& desc)
    : context_(context), name_(desc.name), colourCount_(std::uint32_t(desc.colour.size())),
      depthFormat_(desc.depth ? std::optional<VkFormat>(desc.depth->format) : std::nullopt),
      pushBytes_(desc.pushConstantBytes), mesh_(!desc.mesh.empty()), stages_(stagesOf(context, desc)),
      sets_(context, desc.bindingCount, stages_) {
    const DeviceInfo& device = context.device();
    for (const ColourAttachment& colour : desc.colour) {
        colourFormats_.push_back(colour.format);
        if (colour.blend.enable && colour.blend.dualSource() && !device.dualSrcBlend)
            throw GpuError("graphics pipeline " + name_ + " blends with a second fragment output; the device '" +
                           device.name + "' has no dualSrcBlend");
        if (!(colour.blend == desc.colour[0].blend) && !device.independentBlend)
            throw GpuError("graphics pipeline " + name_ + " blends its attachments differently; the device '" +
                           device.name + "' has no independentBlend");
        VkFormatProperties properties{};
        vkGetPhysicalDeviceFormatProperties(context.physicalDevice(), colour.format, &properties);
        if (colour.blend.enable && !(properties.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT))
            throw GpuError("graphics pipeline " + name_ + ": the device '" + device.name + "' cannot blend format " +
                           std::to_string(int(colour.format)));
    }

    VkDevice vk = context.vk();
    std::vector<VkShaderModule> modules;
    try {
        const VkDescriptorSetLayout setLayout = sets_.layout();
        VkPushConstantRange range{stages_, 0, pushBytes_};
        VkPipelineLayoutCreateInfo layoutInfo{};
        layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
        layoutInfo.setLayoutCount = 1;
        layoutInfo.pSetLayouts = &setLayout;
        layoutInfo.pushConstantRangeCount = pushBytes_ > 0 ? 1 : 0;
        layoutInfo.pPushConstantRanges = &range;
        check(vkCreatePipelineLayout(vk, &layoutInfo, nullptr, &layout_), "creating a pipeline layout");
        clearPass_ = createRenderPass(vk, desc, VK_ATTACHMENT_LOAD_OP_CLEAR);
        loadPass_ = createRenderPass(vk, desc, VK_ATTACHMENT_LOAD_OP_LOAD);

        std::vector<VkPipelineShaderStageCreateInfo> stages;
        auto addStage = [&](const std::vector<std::uint32_t>& spirv, VkShaderStageFlagBits stage, const char* what) {
            if (spirv.empty()) return;
            modules.push_back(createModule(vk, spirv, name_ + " (" + what + ")"));
            VkPipelineShaderStageCreateInfo info{};
            info.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
            info.stage = stage;
            info.module = modules.back();
            info.pName = "main";
            stages.push_back(info);
        };
        addStage(desc.mesh, VK_SHADER_STAGE_MESH_BIT_EXT, "mesh");
        addStage(desc.vertex, VK_SHADER_STAGE_VERTEX_BIT, "vertex");
        addStage(desc.geometry, VK_SHADER_STAGE_GEOMETRY_BIT, "geometry");
        addStage(desc.fragment, VK_SHADER_STAGE_FRAGMENT_BIT, "fragment");

        VkPipelineVertexInputStateCreateInfo vertexInput{};  // none: shaders fetch from storage buffers
        vertexInput.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
        VkPipelineInputAssemblyStateCreateInfo assembly{};
        assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
        assembly.topology = desc.topology;
        VkPipelineViewportStateCreateInfo viewport{};  // dynamic
        viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
        viewport.viewportCount = 1;
        viewport.scissorCount = 1;
        VkPipelineRasterizationStateCreateInfo raster{};
        raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
        raster.polygonMode = VK_POLYGON_MODE_FILL;
        raster.cullMode = desc.cull;
        raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
        raster.lineWidth = 1.0f;
        VkPipelineMultisampleStateCreateInfo multisample{};
        multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
        multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
        VkPipelineDepthStencilStateCreateInfo depth{};
        depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
        if (desc.depth) {
            depth.depthTestEnable = desc.depth->test ? VK_TRUE : VK_FALSE;
            depth.depthWriteEnable = desc.depth->write ? VK_TRUE : VK_FALSE;
            depth.depthCompareOp = desc.depth->compare;
        }
        std::vector<VkPipelineColorBlendAttachmentState> blends;
        for (const ColourAttachment& colour : desc.colour) {
            const Blend& b = colour.blend;
            blends.push_back({b.enable ? VK_TRUE : VK_FALSE, b.srcColor, b.dstColor, b.colorOp, b.srcAlpha, b.dstAlpha,
                              b.alphaOp,
                              VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                                  VK_COLOR_COMPONENT_A_BIT});
        }
        VkPipelineColorBlendStateCreateInfo blend{};
        blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
        blend.attachmentCount = std::uint32_t(blends.size());
        blend.pAttachments = blends.data();
        const VkDynamicState dynamicStates[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
        VkPipelineDynamicStateCreateInfo dynamic{};
        dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
        dynamic.dynamicStateCount = 2;
        dynamic.pDynamicStates = dynamicStates;

        VkGraphicsPipelineCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
        info.stageCount = std::uint32_t(stages.size());
        info.pStages = stages.data();
        info.pVertexInputState = mesh_ ? nullptr : &vertexInput;  // a mesh pipeline has neither
        info.pInputAssemblyState = mesh_ ? nullptr : &assembly;
        info.pViewportState = &viewport;
        info.pRasterizationState = &raster;
        info.pMultisampleState = &multisample;
        info.pDepthStencilState = desc.depth ? &depth : nullptr;
        info.pColorBlendState = &blend;
        info.pDynamicState = &dynamic;
        info.layout = layout_;
        info.renderPass = clearPass_;  // also serves loadPass_, which is compatible
        check(vkCreateGraphicsPipelines(vk, context.pipelineCache(), 1, &info, nullptr, &pipeline_),
              ("creating graphics pipeline " + name_).c_str());
    } catch (...) {
        for (VkShaderModule module : modules) vkDestroyShaderModule(vk, module, nullptr);
        release();
        throw;
    }
    for (VkShaderModule module : modules) vkDestroyShaderModule(vk, module, nullptr);
}

GraphicsPipeline::~GraphicsPipeline() { release(); }

void GraphicsPipeline::release() {
    VkDevice vk = context_.vk();
    for (auto& [key, framebuffer] : framebuffers_) vkDestroyFramebuffer(vk, framebuffer, nullptr);
    framebuffers_.clear();
    if (pipeline_) vkDestroyPipeline(vk, pipeline_, nullptr);
    if (loadPass_) vkDestroyRenderPass(vk, loadPass_, nullptr);
    if (clearPass_) vkDestroyRenderPass(vk, clearPass_, nullptr);
    if (layout_) vkDestroyPipelineLayout(vk, layout_, nullptr);
    pipeline_ = VK_NULL_HANDLE;
    loadPass_ = clearPass_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
}

VkFramebuffer GraphicsPipeline::framebuffer(const PassDesc& pass) {
    std::vector<AttachmentRef> refs = pass.colour;
    if (pass.depth) refs.push_back(*pass.depth);
    std::vector<std::pair<std::uint64_t, std::uint32_t>> key;
    std::vector<VkImageView> views;
    for (const AttachmentRef& ref : refs) {
        key.emplace_back(ref.target->serial(), ref.layer);
        views.push_back(ref.target->view(ref.layer));
    }
    auto found = framebuffers_.find(key);
    if (found != framebuffers_.end()) return found->second;
    VkFramebufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
    info.renderPass = clearPass_;
    info.attachmentCount = std::uint32_t(views.size());
    info.pAttachments = views.data();
    info.width = refs[0].target->width();
    info.height = refs[0].target->height();
    info.layers = 1;
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    check(vkCreateFramebuffer(context_.vk(), &info, nullptr, &framebuffer), "creating a framebuffer");
    framebuffers_.emplace(std::move(key), framebuffer);
    return framebuffer;
}

void GraphicsPipeline::beginPass(VkCommandBuffer cmd, const PassDesc& pass) {
    const std::string what = "a pass of graphics pipeline " + name_;
    if (inPass_) throw GpuError(what + " begins inside another");
    if (pass.colour.size() != colourCount_ || pass.depth.has_value() != depthFormat_.has_value())
        throw GpuError(what + " takes " + std::to_string(colourCount_) + " colour target(s) and " +
                       (depthFormat_ ? "a" : "no") + " depth target");
    if (!pass.clearColours.empty() && pass.clearColours.size() != colourCount_)
        throw GpuError(what + " takes one clear colour per colour target, or none");
    std::vector<AttachmentRef> refs = pass.colour;
    if (pass.depth) refs.push_back(*pass.depth);
    if (refs.empty()) throw GpuError(what + " has no target");
    for (std::size_t i = 0; i < refs.size(); ++i) {
        const RenderTarget* target = refs[i].target;
        const VkFormat expected = i < colourCount_ ? colourFormats_[i] : *depthFormat_;
        if (!target || target->format() != expected || refs[i].layer >= target->layers() ||
            target->width() != refs[0].target->width() || target->height() != refs[0].target->height())
            throw GpuError(what + ": target " + std::to_string(i) +
                           " is missing, has another format or size, or has no such layer");
    }
    for (std::uint32_t i = 0; i < colourCount_; ++i)
        pass.colour[i].target->use(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                   VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                                   VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    if (pass.depth)
        pass.depth->target->use(cmd, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, kDepthStages,
                                VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                                    VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);

    std::vector<VkClearValue> clears(refs.size());
    for (std::uint32_t i = 0; i < colourCount_ && !pass.clearColours.empty(); ++i)
        for (int c = 0; c < 4; ++c) clears[i].color.float32[c] = pass.clearColours[i][c];
    if (pass.depth) clears.back().depthStencil = {pass.clearDepth, 0};
    const std::uint32_t width = refs[0].target->width(), height = refs[0].target->height();
    VkRenderPassBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
    begin.renderPass = pass.load == LoadOp::Clear ? clearPass_ : loadPass_;
    begin.framebuffer = framebuffer(pass);
    begin.renderArea = {{0, 0}, {width, height}};
    begin.clearValueCount = pass.load == LoadOp::Clear ? std::uint32_t(clears.size()) : 0;
    begin.pClearValues = clears.data();
    vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
    inPass_ = true;

    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
    const VkViewport viewport{0.0f, 0.0f, float(width), float(height), 0.0f, 1.0f};
    const VkRect2D scissor{{0, 0}, {width, height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void GraphicsPipeline::bindResources(VkCommandBuffer cmd, const std::vector<const Buffer*>& buffers,
                                     const void* push) {
    VkDescriptorSet set = sets_.allocate(buffers, "graphics pipeline " + name_);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &set, 0, nullptr);
    if (pushBytes_ > 0 && push) vkCmdPushConstants(cmd, layout_, stages_, 0, pushBytes_, push);
}

void GraphicsPipeline::draw(VkCommandBuffer cmd, const std::vector<const Buffer*>& buffers, const void* push,
                            std::uint32_t vertexCount, std::uint32_t instanceCount, std::uint32_t firstVertex,
                            std::uint32_t firstInstance) {
    if (!inPass_) throw GpuError("graphics pipeline " + name_ + " draws outside a pass");
    if (mesh_) throw GpuError("graphics pipeline " + name_ + " has a mesh shader: draw it with drawMeshTasks");
    bindResources(cmd, buffers, push);
    vkCmdDraw(cmd, vertexCount, instanceCount, firstVertex, firstInstance);
}

void GraphicsPipeline::drawMeshTasks(VkCommandBuffer cmd, const std::vector<const Buffer*>& buffers, const void* push,
                                     std::uint32_t groupCount) {
    if (!inPass_) throw GpuError("graphics pipeline " + name_ + " draws outside a pass");
    if (!mesh_) throw GpuError("graphics pipeline " + name_ + " has no mesh shader: draw it with draw");
    if (groupCount > context_.device().maxMeshWorkGroups)
        throw GpuError("graphics pipeline " + name_ + " draws " + std::to_string(groupCount) +
                       " mesh workgroups; the device takes " + std::to_string(context_.device().maxMeshWorkGroups) +
                       " per draw");
    bindResources(cmd, buffers, push);
    if (groupCount > 0) context_.cmdDrawMeshTasks()(cmd, groupCount, 1, 1);
}

void GraphicsPipeline::endPass(VkCommandBuffer cmd) {
    if (!inPass_) throw GpuError("graphics pipeline " + name_ + " ends a pass it did not begin");
    vkCmdEndRenderPass(cmd);
    inPass_ = false;
}

void GraphicsPipeline::resetDescriptors() {
    sets_.reset();
    // Framebuffers of targets that no longer exist are never used again, but they are only freed here, where no
    // command buffer uses them any more: beyond a handful, drop them all and let the live ones be made again.
    constexpr std::size_t kKeptFramebuffers = 32;
    if (framebuffers_.size() > kKeptFramebuffers) {
        for (auto& [key, framebuffer] : framebuffers_) vkDestroyFramebuffer(context_.vk(), framebuffer, nullptr);
        framebuffers_.clear();
    }
}

void computeToGraphicsBarrier(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask =
        VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_ALL_GRAPHICS_BIT, 0, 1, &barrier, 0,
                         nullptr, 0, nullptr);
}

void graphicsToComputeBarrier(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                            VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_GRAPHICS_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                             VK_PIPELINE_STAGE_HOST_BIT,
                         0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace tyndall::gpu
