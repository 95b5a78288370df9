#include "tyndall/gpu/context.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cstdlib>
#include <cstring>

namespace tyndall::gpu {

void check(VkResult result, const char* what) {
    if (result == VK_SUCCESS) return;
    std::string reason;
    switch (result) {
        case VK_ERROR_DEVICE_LOST:
            reason = "the device was lost";
            break;
        case VK_ERROR_OUT_OF_DEVICE_MEMORY:
            reason = "out of device memory";
            break;
        case VK_ERROR_OUT_OF_HOST_MEMORY:
            reason = "out of host memory";
            break;
        case VK_ERROR_INITIALIZATION_FAILED:
            reason = "initialisation failed";
            break;
        case VK_ERROR_INCOMPATIBLE_DRIVER:
            reason = "no compatible Vulkan driver";
            break;
        case VK_ERROR_LAYER_NOT_PRESENT:
            reason = "a requested layer is not installed";
            break;
        case VK_ERROR_EXTENSION_NOT_PRESENT:
            reason = "a requested extension is not available";
            break;
        case VK_ERROR_FEATURE_NOT_PRESENT:
            reason = "a requested feature is not available";
            break;
        case VK_TIMEOUT:
            reason = "timed out";
            break;
        default:
            reason = "VkResult " + std::to_string(int(result));
            break;
    }
    throw GpuError(std::string(what) + ": " + reason, result);
}

std::string DeviceInfo::typeName() const {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return "discrete GPU";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return "integrated GPU";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return "virtual GPU";
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return "CPU";
        default:
            return "other";
    }
}

namespace {

int typeRank(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return 4;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return 3;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return 1;
        default:
            return 0;
    }
}

bool hasExtension(const std::vector<VkExtensionProperties>& extensions, const char* name) {
    return std::any_of(extensions.begin(), extensions.end(),
                       [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::vector<VkExtensionProperties> deviceExtensions(VkPhysicalDevice device) {
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> out(count);
    vkEnumerateDeviceExtensionProperties(device, nullptr, &count, out.data());
    return out;
}

// Fills one extension structure of the device's properties (its sType set by the caller).
template <class Properties>
void queryProperties(VkPhysicalDevice device, Properties& properties) {
    VkPhysicalDeviceProperties2 props2{};
    props2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    props2.pNext = &properties;
    vkGetPhysicalDeviceProperties2(device, &props2);
}

DeviceInfo describe(VkPhysicalDevice device, int index) {
    DeviceInfo info;
    info.index = index;
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(device, &props);
    info.name = props.deviceName;
    info.type = props.deviceType;
    info.apiVersion = props.apiVersion;
    info.maxStorageBufferRange = props.limits.maxStorageBufferRange;
    info.maxImageDimension2D = props.limits.maxImageDimension2D;
    info.maxFramebufferWidth = props.limits.maxFramebufferWidth;
    info.maxFramebufferHeight = props.limits.maxFramebufferHeight;
    info.maxImageArrayLayers = props.limits.maxImageArrayLayers;
    if (props.apiVersion >= VK_API_VERSION_1_2) {
        VkPhysicalDeviceVulkan12Properties v12props{};
        v12props.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES;
        queryProperties(device, v12props);
        info.driver = std::string(v12props.driverName) + " " + v12props.driverInfo;
    }

    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, families.data());
    int best = -1;
    for (uint32_t i = 0; i < familyCount; ++i) {
        if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
        // Prefer a family that also does graphics (the studio's display path); any compute family will do.
        if (best < 0 ||
            ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && !(families[best].queueFlags & VK_QUEUE_GRAPHICS_BIT)))
            best = int(i);
    }
    if (best >= 0) {
        info.queueFamily = uint32_t(best);
        info.queueCount = families[best].queueCount;
        info.graphics = (families[best].queueFlags & VK_QUEUE_GRAPHICS_BIT) != 0;
        if (families[best].timestampValidBits > 0) info.timestampPeriod = props.limits.timestampPeriod;
    }

    std::vector<VkExtensionProperties> extensions = deviceExtensions(device);
    VkPhysicalDeviceVulkan12Features v12{};
    v12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    VkPhysicalDeviceMeshShaderFeaturesEXT mesh{};
    mesh.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    const bool meshExtension = hasExtension(extensions, VK_EXT_MESH_SHADER_EXTENSION_NAME);
    if (props.apiVersion >= VK_API_VERSION_1_2) {
        features.pNext = &v12;
        if (meshExtension) v12.pNext = &mesh;
    }
    vkGetPhysicalDeviceFeatures2(device, &features);
    info.shaderFloat64 = features.features.shaderFloat64 == VK_TRUE;
    info.geometryShader = features.features.geometryShader == VK_TRUE;
    info.fragmentStoresAndAtomics = features.features.fragmentStoresAndAtomics == VK_TRUE;
    info.independentBlend = features.features.independentBlend == VK_TRUE;
    info.dualSrcBlend = features.features.dualSrcBlend == VK_TRUE;
    info.timelineSemaphores = v12.timelineSemaphore == VK_TRUE;
    info.descriptorIndexing = v12.runtimeDescriptorArray == VK_TRUE && v12.descriptorBindingPartiallyBound == VK_TRUE;
    info.rayQuery = hasExtension(extensions, VK_KHR_RAY_QUERY_EXTENSION_NAME) &&
                    hasExtension(extensions, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
    info.meshShader = meshExtension && mesh.meshShader == VK_TRUE;
    if (info.meshShader) {
        VkPhysicalDeviceMeshShaderPropertiesEXT meshProps{};
        meshProps.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_PROPERTIES_EXT;
        queryProperties(device, meshProps);
        info.maxMeshWorkGroups = std::min(meshProps.maxMeshWorkGroupCount[0], meshProps.maxMeshWorkGroupTotalCount);
    }
    return info;
}

bool validationRequested(int option) {
    if (option >= 0) return option == 1;
    if (const char* env = std::getenv("TYNDALL_VULKAN_VALIDATION")) return std::strcmp(env, "0") != 0;
#ifndef NDEBUG
    return true;
#else
    return false;
#endif
}

bool layerAvailable(const char* name) {
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    return std::any_of(layers.begin(), layers.end(),
                       [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

std::string lower(std::string s) {
    for (char& c : s)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

// Validation messages that are not Tyndall's mistakes, by message id and the devices they concern, each with the
// reason. Every other message of error severity fails the test that caused it.
struct Suppression {
    const char* messageId;
    const char* device;  // a substring of the device's name; "" for every device
    const char* reason;
};
constexpr std::array<Suppression, 0> kSuppressions{};  // none so far

std::mutex gProcessErrorsMutex;
std::vector<std::string> gProcessErrors;
std::atomic<int> gExpectedErrorScopes{0};

void recordProcessValidationError(const std::string& message) {
    if (gExpectedErrorScopes.load() > 0) return;
    std::lock_guard lock(gProcessErrorsMutex);
    gProcessErrors.push_back(message);
}

bool suppressedValidationMessage(const char* id, const std::string& device) {
    for (const Suppression& s : kSuppressions)
        if (std::strcmp(s.messageId, id) == 0 && device.find(s.device) != std::string::npos) return true;
    return false;
}

}  // namespace

VKAPI_ATTR VkBool32 VKAPI_CALL Context::onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                            VkDebugUtilsMessageTypeFlagsEXT,
                                                            const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                            void* user) {
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        auto* self = static_cast<Context*>(user);
        const char* id = data && data->pMessageIdName ? data->pMessageIdName : "";
        std::lock_guard lock(self->messageMutex_);
        if (suppressedValidationMessage(id, self->info_.name)) {
            ++self->suppressedMessages_;
            return VK_FALSE;
        }
        self->validationErrors_.push_back(std::string(id) + ": " +
                                          (data && data->pMessage ? data->pMessage : "validation error"));
        recordProcessValidationError(self->validationErrors_.back());
    }
    return VK_FALSE;
}

std::vector<DeviceInfo> Context::enumerateDevices() {
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.apiVersion = VK_API_VERSION_1_2;
    VkInstanceCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ci.pApplicationInfo = &app;
    VkInstance instance = VK_NULL_HANDLE;
    check(vkCreateInstance(&ci, nullptr, &instance), "creating a Vulkan instance");
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance, &count, devices.data());
    std::vector<DeviceInfo> out;
    for (uint32_t i = 0; i < count; ++i)
        out.push_back(describe(devices[i], int(i)));
    vkDestroyInstance(instance, nullptr);
    return out;
}

Context::Context(const ContextOptions& options) {
    validation_ = validationRequested(options.validation) && layerAvailable(kValidationLayer);
    try {
        createInstance();
        pickDevice(options.device);
        createDevice(options.rayQuery && info_.rayQuery);
    } catch (...) {
        release();  // the destructor does not run for a constructor that throws
        throw;
    }
}

void Context::createInstance() {
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "Tyndall";
    app.pEngineName = "Tyndall";
    app.apiVersion = VK_API_VERSION_1_2;
    std::vector<const char*> layers, extensions;
    if (validation_) {
        layers.push_back(kValidationLayer);
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);  // the layer provides it
    }
    // With validation, synchronisation validation too (hazards that a software device forgives show up on a GPU):
    // off with TYNDALL_VULKAN_SYNC_VALIDATION=0; the best-practices checks on with TYNDALL_VULKAN_BEST_PRACTICES=1
    // (advice, not errors: docs/testing.md).
    const char* sync = std::getenv("TYNDALL_VULKAN_SYNC_VALIDATION");
    syncValidation_ = validation_ && (!sync || std::strcmp(sync, "0") != 0);
    std::vector<VkValidationFeatureEnableEXT> enabled;
    if (syncValidation_) enabled.push_back(VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT);
    const char* practices = std::getenv("TYNDALL_VULKAN_BEST_PRACTICES");
    if (practices && std::strcmp(practices, "0") != 0)
        enabled.push_back(VK_VALIDATION_FEATURE_ENABLE_BEST_PRACTICES_EXT);
    VkDebugUtilsMessengerCreateInfoEXT messengerInfo{};
    messengerInfo.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    messengerInfo.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messengerInfo.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messengerInfo.pfnUserCallback = &Context::onValidationMessage;
    messengerInfo.pUserData = this;

    VkInstanceCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = uint32_t(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    ci.enabledExtensionCount = uint32_t(extensions.size());
    ci.ppEnabledExtensionNames = extensions.data();
    VkValidationFeaturesEXT features{};
    features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    features.enabledValidationFeatureCount = uint32_t(enabled.size());
    features.pEnabledValidationFeatures = enabled.data();
    features.pNext = &messengerInfo;  // also catches messages from instance creation itself
    if (validation_) ci.pNext = &features;
    check(vkCreateInstance(&ci, nullptr, &instance_), "creating a Vulkan instance");
    if (validation_) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
        if (create) check(create(instance_, &messengerInfo, nullptr, &messenger_), "creating the validation messenger");
    }
}

void Context::pickDevice(const std::string& request) {
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    if (count == 0) throw GpuError("no Vulkan device found (install mesa-vulkan-drivers for lavapipe)");
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance_, &count, devices.data());
    std::vector<DeviceInfo> infos;
    for (uint32_t i = 0; i < count; ++i)
        infos.push_back(describe(devices[i], int(i)));

    int chosen = -1;
    if (!request.empty()) {
        char* end = nullptr;
        long index = std::strtol(request.c_str(), &end, 10);
        if (end && *end == '\0') {
            if (index < 0 || index >= long(count))
                throw GpuError("no Vulkan device with index " + request + "; there are " + std::to_string(count));
            chosen = int(index);
        } else {
            for (const DeviceInfo& d : infos)
                if (lower(d.name).find(lower(request)) != std::string::npos) {
                    chosen = d.index;
                    break;
                }
            if (chosen < 0) {
                std::string names;
                for (const DeviceInfo& d : infos)
                    names += " '" + d.name + "'";
                throw GpuError("no Vulkan device named like '" + request + "'; devices:" + names);
            }
        }
    } else {
        for (const DeviceInfo& d : infos) {
            if (d.queueCount == 0 || d.apiVersion < VK_API_VERSION_1_1) continue;
            if (chosen < 0 || typeRank(d.type) > typeRank(infos[chosen].type)) chosen = d.index;
        }
        if (chosen < 0) throw GpuError("no Vulkan 1.1 device with a compute queue");
    }
    physical_ = devices[chosen];
    info_ = infos[chosen];
    if (info_.queueCount == 0) throw GpuError("the Vulkan device '" + info_.name + "' has no compute queue");
}

void Context::createDevice(bool rayQuery) {
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{};
    queueInfo.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queueInfo.queueFamilyIndex = info_.queueFamily;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;

    VkPhysicalDeviceVulkan12Features v12{};
    v12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    v12.timelineSemaphore = info_.timelineSemaphores ? VK_TRUE : VK_FALSE;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.features.shaderFloat64 = info_.shaderFloat64 ? VK_TRUE : VK_FALSE;
    features.features.geometryShader = info_.geometryShader ? VK_TRUE : VK_FALSE;
    features.features.fragmentStoresAndAtomics = info_.fragmentStoresAndAtomics ? VK_TRUE : VK_FALSE;
    features.features.independentBlend = info_.independentBlend ? VK_TRUE : VK_FALSE;
    features.features.dualSrcBlend = info_.dualSrcBlend ? VK_TRUE : VK_FALSE;
    if (info_.apiVersion >= VK_API_VERSION_1_2) features.pNext = &v12;

    // Ray queries need acceleration structures, which need buffer device addresses.
    std::vector<const char*> extensions;
    VkPhysicalDeviceAccelerationStructureFeaturesKHR accelerationFeatures{};
    accelerationFeatures.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
    VkPhysicalDeviceRayQueryFeaturesKHR rayQueryFeatures{};
    rayQueryFeatures.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR;
    if (rayQuery && info_.apiVersion >= VK_API_VERSION_1_2) {
        extensions = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_QUERY_EXTENSION_NAME,
                      VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
        accelerationFeatures.accelerationStructure = VK_TRUE;
        rayQueryFeatures.rayQuery = VK_TRUE;
        v12.bufferDeviceAddress = VK_TRUE;
        v12.pNext = &accelerationFeatures;
        accelerationFeatures.pNext = &rayQueryFeatures;
        rayQueryEnabled_ = true;
    }

    // Mesh shaders (ISV's proxies where the device has them); SPIR-V 1.4, which the extension needs, is core in 1.2.
    VkPhysicalDeviceMeshShaderFeaturesEXT meshFeatures{};
    meshFeatures.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT;
    if (info_.meshShader) {
        extensions.push_back(VK_EXT_MESH_SHADER_EXTENSION_NAME);
        meshFeatures.meshShader = VK_TRUE;
        meshFeatures.pNext = v12.pNext;
        v12.pNext = &meshFeatures;
    }

    VkDeviceCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    ci.pNext = &features;
    ci.queueCreateInfoCount = 1;
    ci.pQueueCreateInfos = &queueInfo;
    ci.enabledExtensionCount = uint32_t(extensions.size());
    ci.ppEnabledExtensionNames = extensions.data();
    check(vkCreateDevice(physical_, &ci, nullptr, &device_), "creating the Vulkan device");
    vkGetDeviceQueue(device_, info_.queueFamily, 0, &queue_);
    if (info_.meshShader) {
        cmdDrawMeshTasks_ =
            reinterpret_cast<PFN_vkCmdDrawMeshTasksEXT>(vkGetDeviceProcAddr(device_, "vkCmdDrawMeshTasksEXT"));
        if (!cmdDrawMeshTasks_) info_.meshShader = false;
    }

    VkCommandPoolCreateInfo poolInfo{};
    poolInfo.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = info_.queueFamily;
    check(vkCreateCommandPool(device_, &poolInfo, nullptr, &commandPool_), "creating a command pool");

    VkFenceCreateInfo fenceInfo{};
    fenceInfo.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    check(vkCreateFence(device_, &fenceInfo, nullptr, &fence_), "creating a fence");

    if (info_.timestampPeriod > 0.0f) {
        VkQueryPoolCreateInfo queryInfo{};
        queryInfo.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
        queryInfo.queryType = VK_QUERY_TYPE_TIMESTAMP;
        queryInfo.queryCount = 2;
        check(vkCreateQueryPool(device_, &queryInfo, nullptr, &timestampPool_), "creating a timestamp query pool");
    }

    VkPipelineCacheCreateInfo cacheInfo{};
    cacheInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
    check(vkCreatePipelineCache(device_, &cacheInfo, nullptr, &pipelineCache_), "creating a pipeline cache");
}

Context::~Context() {
    release();
}

void Context::release() {
    if (device_) {
        vkDeviceWaitIdle(device_);
        if (pipelineCache_) vkDestroyPipelineCache(device_, pipelineCache_, nullptr);
        if (timestampPool_) vkDestroyQueryPool(device_, timestampPool_, nullptr);
        if (fence_) vkDestroyFence(device_, fence_, nullptr);
        if (commandPool_) vkDestroyCommandPool(device_, commandPool_, nullptr);
        vkDestroyDevice(device_, nullptr);
        device_ = VK_NULL_HANDLE;
    }
    if (messenger_) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(instance_, messenger_, nullptr);
        messenger_ = VK_NULL_HANDLE;
    }
    if (instance_) {
        vkDestroyInstance(instance_, nullptr);
        instance_ = VK_NULL_HANDLE;
    }
}

std::vector<std::string> Context::validationErrors() const {
    std::lock_guard lock(messageMutex_);
    return validationErrors_;
}

void Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record) {
    std::lock_guard lock(submitMutex_);
    VkCommandBufferAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    alloc.commandPool = commandPool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    check(vkAllocateCommandBuffers(device_, &alloc, &cmd), "allocating a command buffer");
    struct Free {
        VkDevice device;
        VkCommandPool pool;
        VkCommandBuffer cmd;
        ~Free() { vkFreeCommandBuffers(device, pool, 1, &cmd); }
    } freeOnExit{device_, commandPool_, cmd};

    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(cmd, &begin), "beginning a command buffer");
    record(cmd);
    check(vkEndCommandBuffer(cmd), "ending a command buffer");

    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    check(vkResetFences(device_, 1, &fence_), "resetting a fence");
    check(vkQueueSubmit(queue_, 1, &submit, fence_), "submitting work to the GPU");
    check(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "waiting for the GPU");
}

double Context::submitTimed(const std::function<void(VkCommandBuffer)>& record) {
    if (!timestampPool_) {
        submitAndWait(record);
        return -1.0;
    }
    submitAndWait([&](VkCommandBuffer cmd) {
        vkCmdResetQueryPool(cmd, timestampPool_, 0, 2);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestampPool_, 0);
        record(cmd);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestampPool_, 1);
    });
    uint64_t ticks[2] = {0, 0};
    check(vkGetQueryPoolResults(device_, timestampPool_, 0, 2, sizeof ticks, ticks, sizeof(uint64_t),
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "reading GPU timestamps");
    return double(ticks[1] - ticks[0]) * double(info_.timestampPeriod) * 1e-6;
}

std::uint32_t Context::findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                      VkMemoryPropertyFlags preferred) const {
    VkPhysicalDeviceMemoryProperties memory{};
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory);
    int fallback = -1;
    for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
        if (!(typeBits & (1u << i))) continue;
        VkMemoryPropertyFlags flags = memory.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        if ((flags & preferred) == preferred) return i;
        if (fallback < 0) fallback = int(i);
    }
    if (fallback < 0) throw GpuError("no Vulkan memory type with the required properties");
    return uint32_t(fallback);
}

std::vector<std::string> processValidationErrors() {
    std::lock_guard lock(gProcessErrorsMutex);
    return gProcessErrors;
}

ExpectedValidationErrors::ExpectedValidationErrors() {
    ++gExpectedErrorScopes;
}
ExpectedValidationErrors::~ExpectedValidationErrors() {
    --gExpectedErrorScopes;
}

std::shared_ptr<Context> sharedContext() {
    static std::mutex mutex;
    static std::shared_ptr<Context> context;
    std::lock_guard lock(mutex);
    if (!context) context = std::make_shared<Context>();
    return context;
}

bool hardwareDeviceAvailable() {
    static const bool has = [] {
        try {
            for (const DeviceInfo& d : Context::enumerateDevices())
                if (d.type != VK_PHYSICAL_DEVICE_TYPE_CPU) return true;
        } catch (const std::exception&) {
        }
        return false;
    }();
    return has;
}

}  // namespace tyndall::gpu
