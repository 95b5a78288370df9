#include "tyndall/gpu/resources.h"

#include <algorithm>

namespace tyndall::gpu {

namespace {

struct RawBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
};

RawBuffer createRaw(Context& context, VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags required,
                    VkMemoryPropertyFlags preferred) {
    RawBuffer raw;
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = std::max<VkDeviceSize>(size, 4);
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check(vkCreateBuffer(context.vk(), &info, nullptr, &raw.buffer), "creating a buffer");
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(context.vk(), raw.buffer, &req);
    VkMemoryAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    alloc.allocationSize = req.size;
    try {
        alloc.memoryTypeIndex = context.findMemoryType(req.memoryTypeBits, required, preferred);
        check(vkAllocateMemory(context.vk(), &alloc, nullptr, &raw.memory),
              ("allocating " + std::to_string(req.size) + " bytes of GPU memory").c_str());
        check(vkBindBufferMemory(context.vk(), raw.buffer, raw.memory, 0), "binding buffer memory");
        if (required & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
            check(vkMapMemory(context.vk(), raw.memory, 0, VK_WHOLE_SIZE, 0, &raw.mapped), "mapping a buffer");
    } catch (...) {
        if (raw.memory) vkFreeMemory(context.vk(), raw.memory, nullptr);
        vkDestroyBuffer(context.vk(), raw.buffer, nullptr);
        throw;
    }
    return raw;
}

void destroyRaw(Context& context, RawBuffer& raw) {
    if (raw.buffer) vkDestroyBuffer(context.vk(), raw.buffer, nullptr);
    if (raw.memory) vkFreeMemory(context.vk(), raw.memory, nullptr);  // unmaps implicitly
    raw = RawBuffer{};
}

constexpr VkMemoryPropertyFlags kHostVisible =
    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;

}  // namespace

Buffer::Buffer(Context& context, VkDeviceSize size, VkBufferUsageFlags usage) : context_(context), size_(size) {
    usage |= VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    // Host-visible and device-local together is what lavapipe and integrated GPUs offer: no staging needed.
    RawBuffer raw;
    try {
        raw = createRaw(context, size, usage, kHostVisible | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    } catch (const GpuError& e) {
        if (e.outOfMemory()) throw;
        raw = createRaw(context, size, usage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    }
    buffer_ = raw.buffer;
    memory_ = raw.memory;
    mapped_ = raw.mapped;
}

Buffer::~Buffer() {
    RawBuffer raw{buffer_, memory_, mapped_};
    destroyRaw(context_, raw);
}

void Buffer::upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset) {
    if (bytes == 0) return;
    if (offset + bytes > size_) throw GpuError("upload of " + std::to_string(bytes) + " bytes overruns a buffer of " +
                                               std::to_string(size_));
    if (mapped_) std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
    else copyThroughStaging(data, nullptr, bytes, offset);
}

void Buffer::download(void* data, VkDeviceSize bytes, VkDeviceSize offset) const {
    if (bytes == 0) return;
    if (offset + bytes > size_) throw GpuError("readback of " + std::to_string(bytes) + " bytes overruns a buffer of " +
                                               std::to_string(size_));
    if (mapped_) std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
    else copyThroughStaging(nullptr, data, bytes, offset);
}

void Buffer::fill(std::uint32_t value) {
    if (mapped_) {
        std::uint32_t* words = static_cast<std::uint32_t*>(mapped_);
        std::fill(words, words + size_ / 4, value);
        return;
    }
    context_.submitAndWait([&](VkCommandBuffer cmd) { vkCmdFillBuffer(cmd, buffer_, 0, VK_WHOLE_SIZE, value); });
}

void Buffer::copyThroughStaging(const void* in, void* out, VkDeviceSize bytes, VkDeviceSize offset) const {
    RawBuffer staging = createRaw(context_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                  kHostVisible, 0);
    try {
        if (in) std::memcpy(staging.mapped, in, bytes);
        context_.submitAndWait([&](VkCommandBuffer cmd) {
            VkBufferCopy region{};
            region.size = bytes;
            if (in) {
                region.dstOffset = offset;
                vkCmdCopyBuffer(cmd, staging.buffer, buffer_, 1, &region);
            } else {
                region.srcOffset = offset;
                vkCmdCopyBuffer(cmd, buffer_, staging.buffer, 1, &region);
            }
        });
        if (out) std::memcpy(out, staging.mapped, bytes);
    } catch (...) {
        destroyRaw(context_, staging);
        throw;
    }
    destroyRaw(context_, staging);
}

// ---------------------------------------------------------------------------------------------------------------------

StorageDescriptorSets::StorageDescriptorSets(Context& context, std::uint32_t bindingCount, VkShaderStageFlags stages)
    : context_(context), bindingCount_(bindingCount) {
    std::vector<VkDescriptorSetLayoutBinding> bindings(bindingCount);
    for (std::uint32_t i = 0; i < bindingCount; ++i) {
        bindings[i].binding = i;
        bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = stages;
    }
    VkDescriptorSetLayoutCreateInfo setInfo{};
    setInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    setInfo.bindingCount = bindingCount;
    setInfo.pBindings = bindings.data();
    check(vkCreateDescriptorSetLayout(context.vk(), &setInfo, nullptr, &layout_), "creating a descriptor set layout");
}

StorageDescriptorSets::~StorageDescriptorSets() {
    for (VkDescriptorPool pool : pools_) vkDestroyDescriptorPool(context_.vk(), pool, nullptr);
    vkDestroyDescriptorSetLayout(context_.vk(), layout_, nullptr);
}

constexpr std::uint32_t kSetsPerPool = 64;

void StorageDescriptorSets::growPool() {
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, std::max(1u, bindingCount_) * kSetsPerPool};
    VkDescriptorPoolCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    info.maxSets = kSetsPerPool;
    info.poolSizeCount = 1;
    info.pPoolSizes = &size;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    check(vkCreateDescriptorPool(context_.vk(), &info, nullptr, &pool), "creating a descriptor pool");
    pools_.push_back(pool);
    setsInCurrentPool_ = 0;
}

VkDescriptorSet StorageDescriptorSets::allocate(const std::vector<const Buffer*>& buffers, const std::string& owner) {
    if (buffers.size() != bindingCount_)
        throw GpuError(owner + " takes " + std::to_string(bindingCount_) + " buffers, got " +
                       std::to_string(buffers.size()));
    if (pools_.empty() || setsInCurrentPool_ == kSetsPerPool) growPool();
    VkDescriptorSetAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    alloc.descriptorPool = pools_.back();
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &layout_;
    VkDescriptorSet set = VK_NULL_HANDLE;
    check(vkAllocateDescriptorSets(context_.vk(), &alloc, &set), "allocating a descriptor set");
    ++setsInCurrentPool_;

    std::vector<VkDescriptorBufferInfo> infos(buffers.size());
    std::vector<VkWriteDescriptorSet> writes(buffers.size());
    for (size_t i = 0; i < buffers.size(); ++i) {
        infos[i] = VkDescriptorBufferInfo{buffers[i]->handle(), 0, VK_WHOLE_SIZE};
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstSet = set;
        writes[i].dstBinding = uint32_t(i);
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(context_.vk(), uint32_t(writes.size()), writes.data(), 0, nullptr);
    return set;
}

void StorageDescriptorSets::reset() {
    for (VkDescriptorPool pool : pools_) vkResetDescriptorPool(context_.vk(), pool, 0);
    // Keep one pool; the others were only needed for the busiest frame.
    while (pools_.size() > 1) {
        vkDestroyDescriptorPool(context_.vk(), pools_.back(), nullptr);
        pools_.pop_back();
    }
    setsInCurrentPool_ = 0;
}

// ---------------------------------------------------------------------------------------------------------------------

ComputeKernel::ComputeKernel(Context& context, const std::vector<std::uint32_t>& spirv, std::uint32_t bindingCount,
                             std::uint32_t pushConstantBytes, const std::string& name)
    : context_(context), name_(name), pushBytes_(pushConstantBytes),
      sets_(context, bindingCount, VK_SHADER_STAGE_COMPUTE_BIT) {
    VkDevice device = context.vk();
    try {
        VkShaderModuleCreateInfo moduleInfo{};
        moduleInfo.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
        moduleInfo.codeSize = spirv.size() * sizeof(std::uint32_t);
        moduleInfo.pCode = spirv.data();
        check(vkCreateShaderModule(device, &moduleInfo, nullptr, &module_), ("creating shader module " + name).c_str());

        const VkDescriptorSetLayout setLayout = sets_.layout();
        VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes};
        VkPipelineLayoutCreateInfo layoutInfo{};
        layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
        layoutInfo.setLayoutCount = 1;
        layoutInfo.pSetLayouts = &setLayout;
        layoutInfo.pushConstantRangeCount = pushConstantBytes > 0 ? 1 : 0;
        layoutInfo.pPushConstantRanges = &range;
        check(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout_), "creating a pipeline layout");

        VkComputePipelineCreateInfo pipelineInfo{};
        pipelineInfo.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
        pipelineInfo.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        pipelineInfo.stage.module = module_;
        pipelineInfo.stage.pName = "main";
        pipelineInfo.layout = layout_;
        check(vkCreateComputePipelines(device, context.pipelineCache(), 1, &pipelineInfo, nullptr, &pipeline_),
              ("creating compute pipeline " + name).c_str());
    } catch (...) {
        release();  // the destructor does not run for a constructor that throws
        throw;
    }
}

ComputeKernel::~ComputeKernel() { release(); }

void ComputeKernel::release() {
    VkDevice device = context_.vk();
    if (pipeline_) vkDestroyPipeline(device, pipeline_, nullptr);
    if (layout_) vkDestroyPipelineLayout(device, layout_, nullptr);
    if (module_) vkDestroyShaderModule(device, module_, nullptr);
    pipeline_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
    module_ = VK_NULL_HANDLE;
}

void ComputeKernel::record(VkCommandBuffer cmd, const std::vector<const Buffer*>& buffers, const void* push,
                           std::uint32_t groupsX, std::uint32_t groupsY, std::uint32_t groupsZ) {
    VkDescriptorSet set = sets_.allocate(buffers, "kernel " + name_);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set, 0, nullptr);
    if (pushBytes_ > 0 && push) vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes_, push);
    vkCmdDispatch(cmd, groupsX, groupsY, groupsZ);
}

void ComputeKernel::resetDescriptors() { sets_.reset(); }

void computeToComputeBarrier(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr,
                         0, nullptr);
}

}  // namespace tyndall::gpu
