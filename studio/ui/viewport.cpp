#include "viewport.h"

#include "trace.h"

#include "tyndall/core/resources.h"
#include "tyndall/gpu/shader_compiler.h"

#include <QKeyEvent>
#include <QMouseEvent>
#include <QWheelEvent>
#include <QVulkanDeviceFunctions>
#include <QVulkanFunctions>

#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace tyndall::studio {

namespace {

struct Push {
    std::uint32_t width, height;
};

std::vector<std::uint32_t> compileStage(const std::string& name, gpu::ShaderStage stage) {
    const std::string path = (shaderDirectory() / "studio" / name).string();
    std::ifstream file(path);
    if (!file) throw std::runtime_error("cannot read the shader " + path);
    std::stringstream text;
    text << file.rdbuf();
    gpu::CompileResult compiled = gpu::compileGlslSource(text.str(), path, stage);
    if (!compiled.ok) throw std::runtime_error(compiled.log);
    return compiled.spirv;
}

bool isSrgb(VkFormat format) {
    return format == VK_FORMAT_B8G8R8A8_SRGB || format == VK_FORMAT_R8G8B8A8_SRGB || format == VK_FORMAT_A8B8G8R8_SRGB_PACK32;
}

// Draws the viewport's frame: a storage buffer per frame in flight, read by a full-screen triangle, in a render pass of
// its own. QVulkanWindow's default pass clears a colour and a depth-stencil attachment that this draw never needs: every
// pixel is written once. On a software device each of those clears, and each sRGB decode and encode, costs a pass over
// the window on the cores the renders share, with the GUI thread waiting for it in the present.
class ViewportRenderer final : public QVulkanWindowRenderer {
public:
    explicit ViewportRenderer(Viewport* window) : window_(window) {}

    void initResources() override {
        device_ = window_->device();
        df_ = window_->vulkanInstance()->deviceFunctions(device_);
        try {
            createRenderPass();
            createPipeline();
        } catch (const std::exception& e) {
            window_->setFailure(QString::fromStdString(e.what()));
        }
    }

    void initSwapChainResources() override {
        const QSize size = window_->swapChainImageSize();
        bytes_ = VkDeviceSize(std::max(1, size.width() * size.height())) * 4;
        const int frames = window_->concurrentFrameCount();
        buffers_.assign(std::size_t(frames), VK_NULL_HANDLE);
        memories_.assign(std::size_t(frames), VK_NULL_HANDLE);
        mapped_.assign(std::size_t(frames), nullptr);
        framebuffers_.assign(std::size_t(window_->swapChainImageCount()), VK_NULL_HANDLE);
        for (int i = 0; i < window_->swapChainImageCount() && renderPass_; ++i) {
            VkImageView view = window_->swapChainImageView(i);
            VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
            info.renderPass = renderPass_;
            info.attachmentCount = 1;
            info.pAttachments = &view;
            info.width = std::uint32_t(size.width());
            info.height = std::uint32_t(size.height());
            info.layers = 1;
            check(df_->vkCreateFramebuffer(device_, &info, nullptr, &framebuffers_[std::size_t(i)]), "vkCreateFramebuffer");
        }
        for (int i = 0; i < frames && pipeline_; ++i) {
            VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
            info.size = bytes_;
            info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
            check(df_->vkCreateBuffer(device_, &info, nullptr, &buffers_[std::size_t(i)]), "vkCreateBuffer");
            VkMemoryRequirements req;
            df_->vkGetBufferMemoryRequirements(device_, buffers_[std::size_t(i)], &req);
            VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
            alloc.allocationSize = req.size;
            alloc.memoryTypeIndex = window_->hostVisibleMemoryIndex();
            check(df_->vkAllocateMemory(device_, &alloc, nullptr, &memories_[std::size_t(i)]), "vkAllocateMemory");
            df_->vkBindBufferMemory(device_, buffers_[std::size_t(i)], memories_[std::size_t(i)], 0);
            df_->vkMapMemory(device_, memories_[std::size_t(i)], 0, bytes_, 0, &mapped_[std::size_t(i)]);
            VkDescriptorBufferInfo bufferInfo{buffers_[std::size_t(i)], 0, bytes_};
            VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
            write.dstSet = sets_[std::size_t(i)];
            write.descriptorCount = 1;
            write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            write.pBufferInfo = &bufferInfo;
            df_->vkUpdateDescriptorSets(device_, 1, &write, 0, nullptr);
        }
    }

    void releaseSwapChainResources() override {
        for (std::size_t i = 0; i < buffers_.size(); ++i) {
            if (memories_[i]) {
                df_->vkUnmapMemory(device_, memories_[i]);
                df_->vkFreeMemory(device_, memories_[i], nullptr);
            }
            if (buffers_[i]) df_->vkDestroyBuffer(device_, buffers_[i], nullptr);
        }
        for (VkFramebuffer framebuffer : framebuffers_)
            if (framebuffer) df_->vkDestroyFramebuffer(device_, framebuffer, nullptr);
        buffers_.clear();
        memories_.clear();
        mapped_.clear();
        framebuffers_.clear();
    }

    void releaseResources() override {
        if (pipeline_) df_->vkDestroyPipeline(device_, pipeline_, nullptr);
        if (layout_) df_->vkDestroyPipelineLayout(device_, layout_, nullptr);
        if (pool_) df_->vkDestroyDescriptorPool(device_, pool_, nullptr);
        if (setLayout_) df_->vkDestroyDescriptorSetLayout(device_, setLayout_, nullptr);
        if (renderPass_) df_->vkDestroyRenderPass(device_, renderPass_, nullptr);
        renderPass_ = VK_NULL_HANDLE;
        pipeline_ = VK_NULL_HANDLE;
        layout_ = VK_NULL_HANDLE;
        pool_ = VK_NULL_HANDLE;
        setLayout_ = VK_NULL_HANDLE;
    }

    void startNextFrame() override {
        const QSize size = window_->swapChainImageSize();
        const int f = window_->currentFrame();
        const std::size_t image = std::size_t(window_->currentSwapChainImageIndex());
        VkCommandBuffer cmd = window_->currentCommandBuffer();
        if (pipeline_ && std::size_t(f) < mapped_.size() && image < framebuffers_.size()) {
            upload(static_cast<std::uint8_t*>(mapped_[std::size_t(f)]), size);
            VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
            begin.renderPass = renderPass_;
            begin.framebuffer = framebuffers_[image];
            begin.renderArea.extent = {std::uint32_t(size.width()), std::uint32_t(size.height())};
            df_->vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
            df_->vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
            VkViewport viewport{0.0f, 0.0f, float(size.width()), float(size.height()), 0.0f, 1.0f};
            VkRect2D scissor{{0, 0}, {std::uint32_t(size.width()), std::uint32_t(size.height())}};
            df_->vkCmdSetViewport(cmd, 0, 1, &viewport);
            df_->vkCmdSetScissor(cmd, 0, 1, &scissor);
            df_->vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &sets_[std::size_t(f)], 0,
                                         nullptr);
            const Push push{std::uint32_t(size.width()), std::uint32_t(size.height())};
            df_->vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(Push), &push);
            df_->vkCmdDraw(cmd, 3, 1, 0, 0);
            df_->vkCmdEndRenderPass(cmd);
        } else {
            // Without a pipeline (its failure is shown in the window's place), the default pass clears the image.
            VkClearValue clear[3]{};
            clear[0].color = {{0.11f, 0.11f, 0.12f, 1.0f}};
            clear[1].depthStencil = {1.0f, 0};
            clear[2].color = clear[0].color;
            VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
            begin.renderPass = window_->defaultRenderPass();
            begin.framebuffer = window_->currentFramebuffer();
            begin.renderArea.extent = {std::uint32_t(size.width()), std::uint32_t(size.height())};
            begin.clearValueCount = window_->sampleCountFlagBits() > VK_SAMPLE_COUNT_1_BIT ? 3 : 2;
            begin.pClearValues = clear;
            df_->vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
            df_->vkCmdEndRenderPass(cmd);
        }
        window_->countPresented();
        window_->frameReady();
        trace("frame %d submitted", window_->framesPresented());
    }

private:
    void check(VkResult r, const char* what) {
        if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: " + std::to_string(int(r)));
    }

    // The frame into the mapped buffer, row by row; what it does not cover is black.
    void upload(std::uint8_t* out, QSize size) {
        QImage frame = window_->frame();
        if (frame.format() != QImage::Format_RGBA8888) frame = frame.convertToFormat(QImage::Format_RGBA8888);
        const std::size_t rowBytes = std::size_t(size.width()) * 4;
        const int w = std::min(frame.width(), size.width()), h = std::min(frame.height(), size.height());
        for (int y = 0; y < h; ++y) {
            std::uint8_t* row = out + std::size_t(y) * rowBytes;
            std::memcpy(row, frame.constScanLine(y), std::size_t(w) * 4);
            std::memset(row + std::size_t(w) * 4, 0, rowBytes - std::size_t(w) * 4);
        }
        std::memset(out + std::size_t(h) * rowBytes, 0, std::size_t(size.height() - h) * rowBytes);
    }

    VkShaderModule module(const std::vector<std::uint32_t>& spirv) {
        VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
        info.codeSize = spirv.size() * 4;
        info.pCode = spirv.data();
        VkShaderModule m;
        check(df_->vkCreateShaderModule(device_, &info, nullptr, &m), "vkCreateShaderModule");
        return m;
    }

    // One colour attachment over the swapchain image, not cleared (the draw writes every pixel), ready to present.
    void createRenderPass() {
        VkAttachmentDescription colour{};
        colour.format = window_->colorFormat();
        colour.samples = VK_SAMPLE_COUNT_1_BIT;
        colour.loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        colour.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        colour.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        colour.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        colour.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        colour.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
        VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
        VkSubpassDescription subpass{};
        subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
        subpass.colorAttachmentCount = 1;
        subpass.pColorAttachments = &ref;
        // The image is written once the acquire semaphore, which QVulkanWindow waits for at this stage, is signalled.
        VkSubpassDependency acquired{};
        acquired.srcSubpass = VK_SUBPASS_EXTERNAL;
        acquired.dstSubpass = 0;
        acquired.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
        acquired.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
        acquired.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
        VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
        info.attachmentCount = 1;
        info.pAttachments = &colour;
        info.subpassCount = 1;
        info.pSubpasses = &subpass;
        info.dependencyCount = 1;
        info.pDependencies = &acquired;
        check(df_->vkCreateRenderPass(device_, &info, nullptr, &renderPass_), "vkCreateRenderPass");
    }

    void createPipeline() {
        const std::vector<std::uint32_t> vert = compileStage("display.vert.glsl", gpu::ShaderStage::Vertex);
        const std::vector<std::uint32_t> frag = compileStage("display.frag.glsl", gpu::ShaderStage::Fragment);

        VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT,
                                             nullptr};
        VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        setInfo.bindingCount = 1;
        setInfo.pBindings = &binding;
        check(df_->vkCreateDescriptorSetLayout(device_, &setInfo, nullptr, &setLayout_), "vkCreateDescriptorSetLayout");
        const int frames = window_->concurrentFrameCount();
        VkDescriptorPoolSize poolSize{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, std::uint32_t(frames)};
        VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        poolInfo.maxSets = std::uint32_t(frames);
        poolInfo.poolSizeCount = 1;
        poolInfo.pPoolSizes = &poolSize;
        check(df_->vkCreateDescriptorPool(device_, &poolInfo, nullptr, &pool_), "vkCreateDescriptorPool");
        std::vector<VkDescriptorSetLayout> layouts(std::size_t(frames), setLayout_);
        sets_.assign(std::size_t(frames), VK_NULL_HANDLE);
        VkDescriptorSetAllocateInfo allocInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        allocInfo.descriptorPool = pool_;
        allocInfo.descriptorSetCount = std::uint32_t(frames);
        allocInfo.pSetLayouts = layouts.data();
        check(df_->vkAllocateDescriptorSets(device_, &allocInfo, sets_.data()), "vkAllocateDescriptorSets");

        VkPushConstantRange range{VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(Push)};
        VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        layoutInfo.setLayoutCount = 1;
        layoutInfo.pSetLayouts = &setLayout_;
        layoutInfo.pushConstantRangeCount = 1;
        layoutInfo.pPushConstantRanges = &range;
        check(df_->vkCreatePipelineLayout(device_, &layoutInfo, nullptr, &layout_), "vkCreatePipelineLayout");

        VkShaderModule vs = module(vert), fs = module(frag);
        VkPipelineShaderStageCreateInfo stages[2]{{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                                  {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
        stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
        stages[0].module = vs;
        stages[0].pName = "main";
        stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
        stages[1].module = fs;
        stages[1].pName = "main";
        // Whether the target encodes sRGB itself, as a constant: the shader's decode is compiled in only when it does.
        const VkBool32 srgbTarget = isSrgb(window_->colorFormat()) ? VK_TRUE : VK_FALSE;
        const VkSpecializationMapEntry entry{0, 0, sizeof(VkBool32)};
        const VkSpecializationInfo specialization{1, &entry, sizeof(VkBool32), &srgbTarget};
        stages[1].pSpecializationInfo = &specialization;
        VkPipelineVertexInputStateCreateInfo vertexInput{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
        VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
        assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
        VkPipelineViewportStateCreateInfo viewportState{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
        viewportState.viewportCount = 1;
        viewportState.scissorCount = 1;
        VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
        raster.polygonMode = VK_POLYGON_MODE_FILL;
        raster.cullMode = VK_CULL_MODE_NONE;
        raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
        raster.lineWidth = 1.0f;
        VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
        multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
        VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
        VkPipelineColorBlendAttachmentState blendAttachment{};
        blendAttachment.colorWriteMask = 0xF;
        VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
        blend.attachmentCount = 1;
        blend.pAttachments = &blendAttachment;
        const VkDynamicState dynamicStates[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
        VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
        dynamic.dynamicStateCount = 2;
        dynamic.pDynamicStates = dynamicStates;
        VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
        info.stageCount = 2;
        info.pStages = stages;
        info.pVertexInputState = &vertexInput;
        info.pInputAssemblyState = &assembly;
        info.pViewportState = &viewportState;
        info.pRasterizationState = &raster;
        info.pMultisampleState = &multisample;
        info.pDepthStencilState = &depth;
        info.pColorBlendState = &blend;
        info.pDynamicState = &dynamic;
        info.layout = layout_;
        info.renderPass = renderPass_;
        const VkResult r = df_->vkCreateGraphicsPipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_);
        df_->vkDestroyShaderModule(device_, vs, nullptr);
        df_->vkDestroyShaderModule(device_, fs, nullptr);
        check(r, "vkCreateGraphicsPipelines");
    }

    Viewport* window_;
    VkDevice device_ = VK_NULL_HANDLE;
    QVulkanDeviceFunctions* df_ = nullptr;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkRenderPass renderPass_ = VK_NULL_HANDLE;
    std::vector<VkFramebuffer> framebuffers_;  // one per swapchain image
    std::vector<VkDescriptorSet> sets_;
    std::vector<VkBuffer> buffers_;
    std::vector<VkDeviceMemory> memories_;
    std::vector<void*> mapped_;
    VkDeviceSize bytes_ = 0;
};

}  // namespace

Viewport::Viewport() {
    // The composed frame holds display-encoded (sRGB) bytes: a UNORM target shows them as they are. An sRGB target
    // (Mesa lists it first) would make the shader decode every pixel and the rasterizer encode it again.
    setPreferredColorFormats({VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_A8B8G8R8_UNORM_PACK32});
    frameTimer_.setSingleShot(true);
    connect(&frameTimer_, &QTimer::timeout, this, [this] { requestUpdate(); });
    // QVulkanWindow always asks for FIFO presentation, which blocks the GUI thread until the next vertical blank: up
    // to 16 ms per frame, for nothing, since the viewport draws only when its frame changed. Mesa's drivers (lavapipe
    // here) take the mode from this variable when the swapchain is made. Immediate never blocks; mailbox would not tear
    // either, but Mesa gives it 5 images and QVulkanWindow takes at most 3 (it fails to start). A software swapchain
    // copies each whole image to the window, so tearing is not seen. The user's own setting wins; other drivers
    // ignore it.
    if (!qEnvironmentVariableIsSet("MESA_VK_WSI_PRESENT_MODE")) qputenv("MESA_VK_WSI_PRESENT_MODE", "immediate");
}

QVulkanWindowRenderer* Viewport::createRenderer() {
    return new ViewportRenderer(this);
}

void Viewport::setFrame(const QImage& frame) {
    frame_ = frame;
    // A software swapchain blocks the GUI thread for each frame (5-20 ms here); kMinFrameIntervalMs from the end of
    // one frame to the start of the next let the event loop run between two of them. The newest frame is always the one drawn.
    const qint64 since = sinceLastFrame_.isValid() ? sinceLastFrame_.elapsed() : kMinFrameIntervalMs;
    if (since >= kMinFrameIntervalMs) {
        requestUpdate();
    } else if (!frameTimer_.isActive()) {
        frameTimer_.start(int(kMinFrameIntervalMs - since));
    }
}

void Viewport::countPresented() { ++presented_; }

bool Viewport::event(QEvent* event) {
    const bool result = QVulkanWindow::event(event);
    // From the end of the frame's presentation (which is where it blocks), so that the next frame waits after it.
    if (event->type() == QEvent::UpdateRequest) sinceLastFrame_.start();
    return result;
}

QSize Viewport::pixelSize() const {
    return size() * devicePixelRatio();
}

void Viewport::resizeEvent(QResizeEvent* event) {
    QVulkanWindow::resizeEvent(event);
    emit resized(pixelSize());
}

void Viewport::keyPressEvent(QKeyEvent* event) {
    emit keyPressed(event->key(), event->modifiers());
}

void Viewport::keyReleaseEvent(QKeyEvent* event) {
    emit keyReleased(event->key(), event->modifiers());
}

void Viewport::mousePressEvent(QMouseEvent* event) {
    emit mousePressed(event->position() * devicePixelRatio(), event->buttons());
}

void Viewport::mouseMoveEvent(QMouseEvent* event) {
    emit mouseMoved(event->position() * devicePixelRatio(), event->buttons());
}

void Viewport::mouseDoubleClickEvent(QMouseEvent* event) {
    emit mouseDoubleClicked(event->position() * devicePixelRatio());
}

void Viewport::wheelEvent(QWheelEvent* event) {
    emit wheelTurned(event->angleDelta().y() / 120.0);
}

}  // namespace tyndall::studio
