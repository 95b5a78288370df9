// The renderer library's own Vulkan instance and device (GPU framework issue). It runs headless, picks the best
// device (discrete > integrated > virtual > CPU, overridable by name or index), and is what every GPU technique renders
// with. The studio's window keeps its own device and only displays finished images.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace tyndall::gpu {

// A failure of the GPU: no device, device lost, out of memory, a failed Vulkan call. Typed, so that callers can report
// it instead of crashing.
class GpuError : public std::runtime_error {
public:
    GpuError(const std::string& what, VkResult result = VK_ERROR_UNKNOWN) : std::runtime_error(what), result_(result) {}
    VkResult result() const { return result_; }
    bool deviceLost() const { return result_ == VK_ERROR_DEVICE_LOST; }
    bool outOfMemory() const {
        return result_ == VK_ERROR_OUT_OF_DEVICE_MEMORY || result_ == VK_ERROR_OUT_OF_HOST_MEMORY;
    }

private:
    VkResult result_;
};

// Throws GpuError naming the call when result is not VK_SUCCESS.
void check(VkResult result, const char* what);

struct DeviceInfo {
    int index = 0;
    std::string name;
    std::string
        driver;  // the driver's name and version ("NVIDIA 550.54.15", "llvmpipe Mesa 22.3.6"); Vulkan 1.2 devices
    VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
    std::uint32_t apiVersion = 0;
    std::uint32_t queueFamily = 0;  // a family with compute (and graphics when available)
    std::uint32_t queueCount = 0;
    float timestampPeriod = 0.0f;  // ns per timestamp tick; 0 when the queue has no timestamps
    bool timelineSemaphores = false;
    bool shaderFloat64 = false;
    bool rayQuery = false;            // VK_KHR_ray_query + acceleration structures
    bool meshShader = false;          // VK_EXT_mesh_shader and its meshShader feature (Vulkan 1.2 devices); enabled
    std::uint32_t maxMeshWorkGroups = 0;  // the most workgroups of one vkCmdDrawMeshTasksEXT(x, 1, 1)
    // Limits a technique checks before it allocates (VkPhysicalDeviceLimits).
    std::uint64_t maxStorageBufferRange = 0;  // bytes of one storage-buffer binding
    std::uint32_t maxImageDimension2D = 0;    // texels per side of a render target
    std::uint32_t maxFramebufferWidth = 0, maxFramebufferHeight = 0;
    std::uint32_t maxImageArrayLayers = 0;
    bool descriptorIndexing = false;  // runtime descriptor arrays, partially bound
    // Graphics pipelines (gpu/graphics.h); each is enabled on the device when it has it.
    bool graphics = false;                  // the queue family also does graphics
    bool geometryShader = false;
    bool fragmentStoresAndAtomics = false;  // storage buffer writes from fragment shaders
    bool independentBlend = false;          // a blend state per colour attachment
    bool dualSrcBlend = false;              // blend factors from a second fragment output (SRC1_*)
    std::string typeName() const;
};

struct ContextOptions {
    std::string device;  // "" for the best device; a decimal index; or a case-insensitive substring of its name
    // Khronos validation layers. Default: on in debug builds and whenever TYNDALL_VULKAN_VALIDATION=1.
    int validation = -1;   // -1 default, 0 off, 1 on
    bool rayQuery = true;  // enable VK_KHR_ray_query when the device has it (false forces the BVH path)
};

class Context {
public:
    explicit Context(const ContextOptions& options = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    // Every physical device, in the order Vulkan reports them (for `tyndall info` and --device). Throws GpuError when
    // there is no Vulkan at all.
    static std::vector<DeviceInfo> enumerateDevices();

    const DeviceInfo& device() const { return info_; }
    VkInstance instance() const { return instance_; }
    VkPhysicalDevice physicalDevice() const { return physical_; }
    VkDevice vk() const { return device_; }
    VkQueue queue() const { return queue_; }
    bool validationEnabled() const { return validation_; }
    // Validation with synchronisation validation (the default with validation; TYNDALL_VULKAN_SYNC_VALIDATION=0 turns
    // it off).
    bool syncValidationEnabled() const { return syncValidation_; }
    // True when the device was created with VK_KHR_ray_query, acceleration structures and buffer device addresses.
    bool rayQueryEnabled() const { return rayQueryEnabled_; }
    // vkCmdDrawMeshTasksEXT when the device was created with mesh shaders (DeviceInfo::meshShader), else null.
    PFN_vkCmdDrawMeshTasksEXT cmdDrawMeshTasks() const { return cmdDrawMeshTasks_; }

    // Messages of error severity from the validation layers since the context was created, each "<message id>: <text>"
    // (tests fail on any).
    std::vector<std::string> validationErrors() const;

    // Records commands into a one-time command buffer, submits them and waits. Throws GpuError on device loss or
    // any failure. Thread-safe: submissions to the single queue are serialised.
    void submitAndWait(const std::function<void(VkCommandBuffer)>& record);

    // Like submitAndWait, and returns the GPU time of the recorded commands in milliseconds (timestamp queries), or a
    // negative value when the queue has no timestamps.
    double submitTimed(const std::function<void(VkCommandBuffer)>& record);

    // Memory type with all `required` flags among `typeBits`, preferring `preferred`; throws GpuError when none.
    std::uint32_t findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                 VkMemoryPropertyFlags preferred = 0) const;

    VkPipelineCache pipelineCache() const { return pipelineCache_; }

private:
    void createInstance();
    void pickDevice(const std::string& request);
    void createDevice(bool rayQuery);
    void release();  // destroys the Vulkan objects created so far

    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkCommandPool commandPool_ = VK_NULL_HANDLE;
    VkQueryPool timestampPool_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkPipelineCache pipelineCache_ = VK_NULL_HANDLE;
    DeviceInfo info_;
    bool validation_ = false;
    bool syncValidation_ = false;
    int suppressedMessages_ = 0;  // validation messages of a known, documented cause (context.cpp, kSuppressions)
    bool rayQueryEnabled_ = false;
    PFN_vkCmdDrawMeshTasksEXT cmdDrawMeshTasks_ = nullptr;
    std::mutex submitMutex_;
    mutable std::mutex messageMutex_;
    std::vector<std::string> validationErrors_;

    static VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                              VkDebugUtilsMessageTypeFlagsEXT types,
                                                              const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                              void* user);
};

// The process's context for the techniques, created with default options on first use (thread-safe) and kept until
// exit: every technique renders on it, so that pipelines and device memory are not duplicated per technique. Throws
// GpuError when there is no Vulkan device.
std::shared_ptr<Context> sharedContext();

// Every validation error of every context of this process, in order: what the GPU tests' listener
// (renderers/testing/validation_listener.cpp) fails a test on, whichever context the test used.
std::vector<std::string> processValidationErrors();

// While one exists, validation errors are expected (a test of the validation itself): contexts still collect them
// (Context::validationErrors), the process's list does not.
class ExpectedValidationErrors {
public:
    ExpectedValidationErrors();
    ~ExpectedValidationErrors();
    ExpectedValidationErrors(const ExpectedValidationErrors&) = delete;
    ExpectedValidationErrors& operator=(const ExpectedValidationErrors&) = delete;
};

// True when Vulkan has a device that is not a CPU implementation (lavapipe is one): what `device = auto` of the
// techniques asks, since their CPU paths are faster than lavapipe. False without Vulkan. Computed once.
bool hardwareDeviceAvailable();

}  // namespace tyndall::gpu
