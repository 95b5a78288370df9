// Buffers with upload and readback, and compute kernels with classic descriptor sets and push constants.
#pragma once

#include "tyndall/gpu/context.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <cstring>
#include <vector>

namespace tyndall::gpu {

// A storage buffer. Host-visible memory when the device offers it with device-local (integrated GPUs, lavapipe), so
// that upload and readback are plain copies; otherwise device-local memory with a staging copy.
class Buffer {
public:
    Buffer(Context& context, VkDeviceSize size, VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    ~Buffer();
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;

    VkBuffer handle() const { return buffer_; }
    VkDeviceSize size() const { return size_; }

    void upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
    void download(void* data, VkDeviceSize bytes, VkDeviceSize offset = 0) const;
    // Sets every 32-bit word of the buffer to `value`, in place (no host array, no staging copy).
    void fill(std::uint32_t value);

    template <typename T>
    void upload(const std::vector<T>& values) { upload(values.data(), values.size() * sizeof(T)); }
    template <typename T>
    std::vector<T> download(std::size_t count) const {
        std::vector<T> out(count);
        download(out.data(), count * sizeof(T));
        return out;
    }
    // Into `out`, whose storage is reused when it is large enough: a progressive render reads the same buffer after
    // every pass, and fresh pages for each read cost more than the copy (page faults: ~8 ms per 8 MB on this VM).
    template <typename T>
    void download(std::vector<T>& out, std::size_t count) const {
        out.resize(count);
        download(out.data(), count * sizeof(T));
    }

private:
    void copyThroughStaging(const void* in, void* out, VkDeviceSize bytes, VkDeviceSize offset) const;

    Context& context_;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkDeviceSize size_ = 0;
    void* mapped_ = nullptr;  // non-null for host-visible memory
};

// A storage buffer holding `values` (at least one element's room, so that an empty array still binds).
template <typename T>
std::unique_ptr<Buffer> uploadBuffer(Context& context, const std::vector<T>& values) {
    auto buffer = std::make_unique<Buffer>(context, VkDeviceSize(std::max<std::size_t>(values.size(), 1) * sizeof(T)));
    if (!values.empty()) buffer->upload(values);
    return buffer;
}

// The buffer in `slot`, made anew only when it is missing or smaller than `bytes`: a renderer keeps its output buffers
// from render to render (an edit renders the view again at the same size, or smaller for a reduced first image), since
// a fresh buffer of a few MB costs more in page faults on first touch than the pass that writes it (~8 ms per 8 MB on
// this VM). It may be larger than asked, and holds what the last render left: the caller writes the part it reads.
inline Buffer& keptBuffer(Context& context, std::unique_ptr<Buffer>& slot, VkDeviceSize bytes) {
    if (!slot || slot->size() < bytes) {
        slot.reset();  // the old one's memory goes back before the new one's is taken
        slot = std::make_unique<Buffer>(context, bytes);
    }
    return *slot;
}

// Set 0 of a pipeline: `bindingCount` storage buffers (binding i = buffers[i]) visible to `stages`, and descriptor sets
// for it from pools that grow when the busiest frame needs more (ComputeKernel and GraphicsPipeline).
class StorageDescriptorSets {
public:
    StorageDescriptorSets(Context& context, std::uint32_t bindingCount, VkShaderStageFlags stages);
    ~StorageDescriptorSets();
    StorageDescriptorSets(const StorageDescriptorSets&) = delete;
    StorageDescriptorSets& operator=(const StorageDescriptorSets&) = delete;

    VkDescriptorSetLayout layout() const { return layout_; }
    // A set holding `buffers`; throws GpuError naming `owner` when their number is not bindingCount.
    VkDescriptorSet allocate(const std::vector<const Buffer*>& buffers, const std::string& owner);
    // Frees every set; only once the command buffers that used them have completed.
    void reset();

private:
    void growPool();

    Context& context_;
    std::uint32_t bindingCount_;
    VkDescriptorSetLayout layout_ = VK_NULL_HANDLE;
    std::vector<VkDescriptorPool> pools_;
    std::uint32_t setsInCurrentPool_ = 0;
};

// A compute pipeline whose set 0 holds `bindingCount` storage buffers (binding i = buffers[i]) and whose push constant
// block has `pushConstantBytes` bytes.
class ComputeKernel {
public:
    ComputeKernel(Context& context, const std::vector<std::uint32_t>& spirv, std::uint32_t bindingCount,
                  std::uint32_t pushConstantBytes, const std::string& name);
    ~ComputeKernel();
    ComputeKernel(const ComputeKernel&) = delete;
    ComputeKernel& operator=(const ComputeKernel&) = delete;

    // Records a dispatch. Descriptor sets come from the kernel's pool; call resetDescriptors() once the command
    // buffers that used them have completed.
    void record(VkCommandBuffer cmd, const std::vector<const Buffer*>& buffers, const void* push,
                std::uint32_t groupsX, std::uint32_t groupsY = 1, std::uint32_t groupsZ = 1);
    void resetDescriptors();
    const std::string& name() const { return name_; }

private:
    void release();  // destroys the Vulkan objects created so far

    Context& context_;
    std::string name_;
    std::uint32_t pushBytes_;
    StorageDescriptorSets sets_;
    VkShaderModule module_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
};

// A barrier that makes compute-shader writes visible to later compute reads and host reads.
void computeToComputeBarrier(VkCommandBuffer cmd);

}  // namespace tyndall::gpu
