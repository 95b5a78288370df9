// Visibility on the GPU: the BVH backend (shared traversal of shaders/shared/bvh.h over storage buffers) and the
// ray-query backend (acceleration structures and shaders/features/ray_query_visibility.comp.glsl). See visibility.h.
#include "tyndall/gpu/visibility.h"

#include "tyndall/core/resources.h"
#include "tyndall/core/scene.h"
#include "tyndall/gpu/bvh.h"
#include "tyndall/gpu/resources.h"
#include "tyndall/gpu/shader_compiler.h"

#include <algorithm>
#include <cstring>
#include <string>

namespace tyndall::gpu {
namespace {

constexpr std::uint32_t kGroupSize = 64;
// Rays per dispatch: well below the guaranteed maxComputeWorkGroupCount[0] of 65535 groups. Ray and flag offsets of a
// chunk (32 and 4 bytes per ray) are multiples of 256, the largest minStorageBufferOffsetAlignment Vulkan allows.
constexpr std::uint32_t kChunkRays = 16384 * kGroupSize;

std::uint32_t groupsFor(std::uint32_t rays) {
    return (rays + kGroupSize - 1) / kGroupSize;
}

// One ray per invocation: bvhOccluded over the interval (0, tMax). Rays are (origin, tMax), (dir, 0). The BVH arrays
// are bound by one of the two accessor blocks below, which the kernel source is assembled from.
constexpr const char* kBvhKernelHead = R"(#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/bvh.h"
layout(local_size_x = 64) in;
)";

// The arrays as 64-bit words, the cheaper loads on lavapipe (see the top of shared/bvh.h); needs shaderFloat64.
constexpr const char* kBvhAccessWords = R"(
layout(std430, set = 0, binding = 0) readonly buffer BvhNodes { dvec4 bvhNodes[]; };
layout(std430, set = 0, binding = 1) readonly buffer BvhTriangles { dvec2 bvhTriangles[]; };
uvec4 bvhWords(dvec2 w) { return uvec4(unpackDouble2x32(w.x), unpackDouble2x32(w.y)); }
BvhNode bvhNode(int i) { dvec4 w = bvhNodes[i]; return bvhNodeFromWords(bvhWords(w.xy), bvhWords(w.zw)); }
BvhTriangle bvhTriangle(int i) {
    return bvhTriangleFromWords(bvhWords(bvhTriangles[3 * i]), bvhWords(bvhTriangles[3 * i + 1]),
                                bvhWords(bvhTriangles[3 * i + 2]));
}
)";

// The arrays as structs, for devices without shaderFloat64.
constexpr const char* kBvhAccessStructs = R"(
layout(std430, set = 0, binding = 0) readonly buffer BvhNodes { BvhNode bvhNodes[]; };
layout(std430, set = 0, binding = 1) readonly buffer BvhTriangles { BvhTriangle bvhTriangles[]; };
BvhNode bvhNode(int i) { return bvhNodes[i]; }
BvhTriangle bvhTriangle(int i) { return bvhTriangles[i]; }
)";

constexpr const char* kBvhKernelMain = R"(
layout(std430, set = 0, binding = 2) readonly buffer Rays { vec4 rays[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Occluded { uint occluded[]; };  // 1 occluded, 0 visible
layout(push_constant) uniform Push {
    uint first;  // first ray of this dispatch
    uint count;  // number of rays in all
} push;
void main() {
    uint i = push.first + gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    vec4 originTMax = rays[2 * i];
    vec4 direction = rays[2 * i + 1];
    occluded[i] = bvhOccluded(originTMax.xyz, direction.xyz, 0.0f, originTMax.w) ? 1u : 0u;
}
)";

struct BvhPush {
    std::uint32_t first;
    std::uint32_t count;
};

// The push constants of ray_query_visibility.comp.glsl.
struct RayQueryPush {
    std::uint32_t count;
    std::uint32_t cullMask;
};

// A buffer with a device address, for acceleration structures and their build inputs (the shared Buffer has none).
// Host-visible buffers stay mapped.
struct AddressedBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    VkDeviceAddress address = 0;
};

AddressedBuffer createAddressed(Context& context, VkDeviceSize size, VkBufferUsageFlags usage, bool hostVisible) {
    AddressedBuffer out;
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = std::max<VkDeviceSize>(size, 16);
    info.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check(vkCreateBuffer(context.vk(), &info, nullptr, &out.buffer), "creating an acceleration structure buffer");
    try {
        VkMemoryRequirements req{};
        vkGetBufferMemoryRequirements(context.vk(), out.buffer, &req);
        VkMemoryAllocateFlagsInfo flags{};
        flags.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO;
        flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        VkMemoryAllocateInfo alloc{};
        alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        alloc.pNext = &flags;
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex =
            hostVisible ? context.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                                         VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)
                        : context.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        check(vkAllocateMemory(context.vk(), &alloc, nullptr, &out.memory),
              ("allocating " + std::to_string(req.size) + " bytes of GPU memory").c_str());
        check(vkBindBufferMemory(context.vk(), out.buffer, out.memory, 0), "binding buffer memory");
        if (hostVisible) check(vkMapMemory(context.vk(), out.memory, 0, VK_WHOLE_SIZE, 0, &out.mapped), "mapping");
        VkBufferDeviceAddressInfo addressInfo{};
        addressInfo.sType = VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO;
        addressInfo.buffer = out.buffer;
        out.address = vkGetBufferDeviceAddress(context.vk(), &addressInfo);
    } catch (...) {
        if (out.memory) vkFreeMemory(context.vk(), out.memory, nullptr);
        vkDestroyBuffer(context.vk(), out.buffer, nullptr);
        throw;
    }
    return out;
}

void destroyAddressed(Context& context, AddressedBuffer& buffer) {
    if (buffer.buffer) vkDestroyBuffer(context.vk(), buffer.buffer, nullptr);
    if (buffer.memory) vkFreeMemory(context.vk(), buffer.memory, nullptr);  // unmaps implicitly
    buffer = AddressedBuffer{};
}

template <typename T>
T loadDeviceFunction(Context& context, const char* name) {
    PFN_vkVoidFunction function = vkGetDeviceProcAddr(context.vk(), name);
    if (!function) throw GpuError(std::string("the Vulkan device has no ") + name, VK_ERROR_EXTENSION_NOT_PRESENT);
    return reinterpret_cast<T>(function);
}

// Makes acceleration structure builds visible to later builds and to compute shaders.
void accelerationStructureBarrier(VkCommandBuffer cmd, VkPipelineStageFlags dstStage, VkAccessFlags dstAccess) {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
    barrier.dstAccessMask = dstAccess;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, dstStage, 0, 1, &barrier, 0,
                         nullptr, 0, nullptr);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------------

struct Visibility::RayQuery {
    explicit RayQuery(Context& context) : context(context) {}
    ~RayQuery();
    RayQuery(const RayQuery&) = delete;
    RayQuery& operator=(const RayQuery&) = delete;

    void loadFunctions();
    // Creates the structure's buffer and handle for the sizes of `build`, and records its build with fresh scratch.
    void record(VkCommandBuffer cmd, VkAccelerationStructureBuildGeometryInfoKHR& build, std::uint32_t primitives,
                AddressedBuffer& storage, VkAccelerationStructureKHR& structure, AddressedBuffer& scratch);
    void build(const std::vector<TriangleMesh>& meshes);
    void createPipeline();

    Context& context;
    PFN_vkCreateAccelerationStructureKHR createAccelerationStructure = nullptr;
    PFN_vkDestroyAccelerationStructureKHR destroyAccelerationStructure = nullptr;
    PFN_vkGetAccelerationStructureBuildSizesKHR getBuildSizes = nullptr;
    PFN_vkCmdBuildAccelerationStructuresKHR cmdBuild = nullptr;
    PFN_vkGetAccelerationStructureDeviceAddressKHR getDeviceAddress = nullptr;

    AddressedBuffer bottomStorage, topStorage;
    VkAccelerationStructureKHR bottom = VK_NULL_HANDLE;
    VkAccelerationStructureKHR top = VK_NULL_HANDLE;

    VkShaderModule module = VK_NULL_HANDLE;
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
};

Visibility::RayQuery::~RayQuery() {
    VkDevice device = context.vk();
    if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
    if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
    if (setLayout) vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
    if (module) vkDestroyShaderModule(device, module, nullptr);
    if (top) destroyAccelerationStructure(device, top, nullptr);
    if (bottom) destroyAccelerationStructure(device, bottom, nullptr);
    destroyAddressed(context, topStorage);
    destroyAddressed(context, bottomStorage);
}

void Visibility::RayQuery::loadFunctions() {
    createAccelerationStructure =
        loadDeviceFunction<PFN_vkCreateAccelerationStructureKHR>(context, "vkCreateAccelerationStructureKHR");
    destroyAccelerationStructure =
        loadDeviceFunction<PFN_vkDestroyAccelerationStructureKHR>(context, "vkDestroyAccelerationStructureKHR");
    getBuildSizes = loadDeviceFunction<PFN_vkGetAccelerationStructureBuildSizesKHR>(
        context, "vkGetAccelerationStructureBuildSizesKHR");
    cmdBuild =
        loadDeviceFunction<PFN_vkCmdBuildAccelerationStructuresKHR>(context, "vkCmdBuildAccelerationStructuresKHR");
    getDeviceAddress = loadDeviceFunction<PFN_vkGetAccelerationStructureDeviceAddressKHR>(
        context, "vkGetAccelerationStructureDeviceAddressKHR");
}

void Visibility::RayQuery::record(VkCommandBuffer cmd, VkAccelerationStructureBuildGeometryInfoKHR& build,
                                  std::uint32_t primitives, AddressedBuffer& storage,
                                  VkAccelerationStructureKHR& structure, AddressedBuffer& scratch) {
    VkAccelerationStructureBuildSizesInfoKHR sizes{};
    sizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
    getBuildSizes(context.vk(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &build, &primitives, &sizes);

    storage = createAddressed(context, sizes.accelerationStructureSize,
                              VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, false);
    VkAccelerationStructureCreateInfoKHR createInfo{};
    createInfo.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR;
    createInfo.buffer = storage.buffer;
    createInfo.size = sizes.accelerationStructureSize;
    createInfo.type = build.type;
    check(createAccelerationStructure(context.vk(), &createInfo, nullptr, &structure),
          "creating an acceleration structure");

    // Scratch addresses must be multiples of minAccelerationStructureScratchOffsetAlignment: over-allocate and align.
    VkPhysicalDeviceAccelerationStructurePropertiesKHR properties{};
    properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
    VkPhysicalDeviceProperties2 properties2{};
    properties2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    properties2.pNext = &properties;
    vkGetPhysicalDeviceProperties2(context.physicalDevice(), &properties2);
    VkDeviceSize alignment = std::max<VkDeviceSize>(properties.minAccelerationStructureScratchOffsetAlignment, 1);
    scratch = createAddressed(context, sizes.buildScratchSize + alignment, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);

    build.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    build.dstAccelerationStructure = structure;
    build.scratchData.deviceAddress = (scratch.address + alignment - 1) / alignment * alignment;
    VkAccelerationStructureBuildRangeInfoKHR range{};
    range.primitiveCount = primitives;
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
    cmdBuild(cmd, 1, &build, &ranges);
}

void Visibility::RayQuery::build(const std::vector<TriangleMesh>& meshes) {
    loadFunctions();
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    for (const TriangleMesh& mesh : meshes) {
        glm::uvec3 offset(std::uint32_t(positions.size()));
        positions.insert(positions.end(), mesh.positions.begin(), mesh.positions.end());
        for (const glm::uvec3& tri : mesh.triangles)
            triangles.push_back(tri + offset);
    }

    const VkBufferUsageFlags inputUsage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
    AddressedBuffer vertices, indices, instances, bottomScratch, topScratch;
    auto release = [&] {
        for (AddressedBuffer* b : {&vertices, &indices, &instances, &bottomScratch, &topScratch})
            destroyAddressed(context, *b);
    };
    try {
        VkDeviceAddress bottomAddress = 0;
        VkAccelerationStructureGeometryKHR triangleGeometry{};
        VkAccelerationStructureBuildGeometryInfoKHR bottomBuild{};
        if (!triangles.empty()) {
            vertices = createAddressed(context, positions.size() * sizeof(glm::vec3), inputUsage, true);
            std::memcpy(vertices.mapped, positions.data(), positions.size() * sizeof(glm::vec3));
            indices = createAddressed(context, triangles.size() * sizeof(glm::uvec3), inputUsage, true);
            std::memcpy(indices.mapped, triangles.data(), triangles.size() * sizeof(glm::uvec3));

            triangleGeometry.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
            triangleGeometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
            triangleGeometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
            VkAccelerationStructureGeometryTrianglesDataKHR& data = triangleGeometry.geometry.triangles;
            data.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
            data.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
            data.vertexData.deviceAddress = vertices.address;
            data.vertexStride = sizeof(glm::vec3);
            data.maxVertex = std::uint32_t(positions.size() - 1);
            data.indexType = VK_INDEX_TYPE_UINT32;
            data.indexData.deviceAddress = indices.address;

            bottomBuild.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
            bottomBuild.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
            bottomBuild.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
            bottomBuild.geometryCount = 1;
            bottomBuild.pGeometries = &triangleGeometry;
            context.submitAndWait([&](VkCommandBuffer cmd) {
                record(cmd, bottomBuild, std::uint32_t(triangles.size()), bottomStorage, bottom, bottomScratch);
                // The top-level build of the next submission reads it.
                accelerationStructureBarrier(cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                                             VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR);
            });
            VkAccelerationStructureDeviceAddressInfoKHR addressInfo{};
            addressInfo.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR;
            addressInfo.accelerationStructure = bottom;
            bottomAddress = getDeviceAddress(context.vk(), &addressInfo);
        }

        // One instance with the identity transform, or none for an empty scene.
        VkAccelerationStructureInstanceKHR instance{};
        instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
        instance.mask = 0xFF;
        instance.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
        instance.accelerationStructureReference = bottomAddress;
        instances = createAddressed(context, sizeof(instance), inputUsage, true);
        std::memcpy(instances.mapped, &instance, sizeof(instance));
        const std::uint32_t instanceCount = triangles.empty() ? 0u : 1u;

        VkAccelerationStructureGeometryKHR instanceGeometry{};
        instanceGeometry.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
        instanceGeometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
        instanceGeometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
        instanceGeometry.geometry.instances.sType =
            VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
        instanceGeometry.geometry.instances.arrayOfPointers = VK_FALSE;
        instanceGeometry.geometry.instances.data.deviceAddress = instances.address;

        VkAccelerationStructureBuildGeometryInfoKHR topBuild{};
        topBuild.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
        topBuild.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
        topBuild.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
        topBuild.geometryCount = 1;
        topBuild.pGeometries = &instanceGeometry;
        context.submitAndWait([&](VkCommandBuffer cmd) {
            record(cmd, topBuild, instanceCount, topStorage, top, topScratch);
            accelerationStructureBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                         VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR);
        });
    } catch (...) {
        release();
        throw;
    }
    release();  // the build inputs and scratch are not needed once the builds completed
}

void Visibility::RayQuery::createPipeline() {
    VkDevice device = context.vk();
    std::vector<std::uint32_t> spirv =
        compileGlslOrThrow((shaderDirectory() / "features/ray_query_visibility.comp.glsl").string());
    VkShaderModuleCreateInfo moduleInfo{};
    moduleInfo.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    moduleInfo.codeSize = spirv.size() * sizeof(std::uint32_t);
    moduleInfo.pCode = spirv.data();
    check(vkCreateShaderModule(device, &moduleInfo, nullptr, &module), "creating the ray-query visibility module");

    VkDescriptorSetLayoutBinding bindings[3]{};
    for (std::uint32_t i = 0; i < 3; ++i) {
        bindings[i].binding = i;
        bindings[i].descriptorType =
            i == 0 ? VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo setInfo{};
    setInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    setInfo.bindingCount = 3;
    setInfo.pBindings = bindings;
    check(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &setLayout), "creating a descriptor set layout");

    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(RayQueryPush)};
    VkPipelineLayoutCreateInfo layoutInfo{};
    layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &setLayout;
    layoutInfo.pushConstantRangeCount = 1;
    layoutInfo.pPushConstantRanges = &range;
    check(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout), "creating a pipeline layout");

    VkComputePipelineCreateInfo pipelineInfo{};
    pipelineInfo.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    pipelineInfo.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipelineInfo.stage.module = module;
    pipelineInfo.stage.pName = "main";
    pipelineInfo.layout = layout;
    check(vkCreateComputePipelines(device, context.pipelineCache(), 1, &pipelineInfo, nullptr, &pipeline),
          "creating the ray-query visibility pipeline");
}

// ---------------------------------------------------------------------------------------------------------------------

Visibility::Visibility(Context& context, const std::vector<TriangleMesh>& meshes) : context_(context) {
    for (const TriangleMesh& mesh : meshes)
        triangleCount_ += mesh.triangles.size();
    if (context.rayQueryEnabled()) {
        backend_ = Backend::RayQuery;
        rayQuery_ = std::make_unique<RayQuery>(context);
        rayQuery_->build(meshes);
        rayQuery_->createPipeline();
    } else {
        backend_ = Backend::Bvh;
        createBvhBackend(meshes);
    }
}

Visibility::~Visibility() = default;

const char* Visibility::backendName() const {
    return backend_ == Backend::RayQuery ? "ray query" : "bvh";
}

VkAccelerationStructureKHR Visibility::topLevel() const {
    return rayQuery_ ? rayQuery_->top : VK_NULL_HANDLE;
}

void Visibility::createBvhBackend(const std::vector<TriangleMesh>& meshes) {
    Bvh bvh = buildBvh(meshes);
    nodes_ = std::make_unique<Buffer>(context_, bvh.nodes.size() * sizeof(shader::BvhNode));
    nodes_->upload(bvh.nodes);
    // A zero-sized buffer is invalid: an empty scene keeps one unused triangle (its lone root holds none).
    triangles_ = std::make_unique<Buffer>(context_,
                                          std::max<std::size_t>(bvh.triangles.size(), 1) * sizeof(shader::BvhTriangle));
    triangles_->upload(bvh.triangles);

    const std::string source = std::string(kBvhKernelHead) +
                               (context_.device().shaderFloat64 ? kBvhAccessWords : kBvhAccessStructs) + kBvhKernelMain;
    CompileResult compiled = compileGlslSource(source, "visibility_bvh.comp.glsl", ShaderStage::Compute);
    if (!compiled.ok) throw ShaderError(*compiled.error);
    bvhKernel_ =
        std::make_unique<ComputeKernel>(context_, compiled.spirv, 4, std::uint32_t(sizeof(BvhPush)), "visibility_bvh");
}

std::vector<std::uint32_t> Visibility::occluded(const std::vector<glm::vec4>& rays) {
    if (rays.size() % 2 != 0) throw GpuError("visibility rays come in pairs of vec4 (origin, tMax), (direction, 0)");
    if (rays.empty()) return {};
    if (rays.size() / 2 > 0xFFFFFFFFu) throw GpuError("too many visibility rays in one call");
    return backend_ == Backend::RayQuery ? occludedRayQuery(rays) : occludedBvh(rays);
}

std::vector<std::uint32_t> Visibility::occludedBvh(const std::vector<glm::vec4>& rays) {
    const std::uint32_t count = std::uint32_t(rays.size() / 2);
    Buffer rayBuffer(context_, rays.size() * sizeof(glm::vec4));
    Buffer flags(context_, count * sizeof(std::uint32_t));
    rayBuffer.upload(rays);
    try {
        context_.submitAndWait([&](VkCommandBuffer cmd) {
            for (std::uint32_t first = 0; first < count; first += kChunkRays) {
                BvhPush push{first, count};
                bvhKernel_->record(cmd, {nodes_.get(), triangles_.get(), &rayBuffer, &flags}, &push,
                                   groupsFor(std::min(kChunkRays, count - first)));
            }
            computeToComputeBarrier(cmd);
        });
    } catch (...) {
        bvhKernel_->resetDescriptors();
        throw;
    }
    bvhKernel_->resetDescriptors();
    return flags.download<std::uint32_t>(count);
}

std::vector<std::uint32_t> Visibility::occludedRayQuery(const std::vector<glm::vec4>& rays) {
    const std::uint32_t count = std::uint32_t(rays.size() / 2);
    // ray_query_visibility.comp.glsl takes (origin, tMin), (direction, tMax).
    std::vector<glm::vec4> converted(rays.size());
    for (std::size_t i = 0; i < count; ++i) {
        converted[2 * i] = glm::vec4(glm::vec3(rays[2 * i]), 0.0f);
        converted[2 * i + 1] = glm::vec4(glm::vec3(rays[2 * i + 1]), rays[2 * i].w);
    }
    Buffer rayBuffer(context_, converted.size() * sizeof(glm::vec4));
    Buffer flags(context_, count * sizeof(std::uint32_t));
    rayBuffer.upload(converted);

    // One descriptor set per chunk, with the chunk's ranges of the ray and flag buffers.
    const std::uint32_t chunks = (count + kChunkRays - 1) / kChunkRays;
    VkDevice device = context_.vk();
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, chunks},
                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 * chunks}};
    VkDescriptorPoolCreateInfo poolInfo{};
    poolInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    poolInfo.maxSets = chunks;
    poolInfo.poolSizeCount = 2;
    poolInfo.pPoolSizes = sizes;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    check(vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool), "creating a descriptor pool");
    try {
        std::vector<VkDescriptorSetLayout> layouts(chunks, rayQuery_->setLayout);
        std::vector<VkDescriptorSet> sets(chunks);
        VkDescriptorSetAllocateInfo alloc{};
        alloc.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
        alloc.descriptorPool = pool;
        alloc.descriptorSetCount = chunks;
        alloc.pSetLayouts = layouts.data();
        check(vkAllocateDescriptorSets(device, &alloc, sets.data()), "allocating descriptor sets");
        for (std::uint32_t c = 0; c < chunks; ++c) {
            const VkDeviceSize first = VkDeviceSize(c) * kChunkRays;
            const VkDeviceSize n = std::min<VkDeviceSize>(kChunkRays, count - first);
            VkWriteDescriptorSetAccelerationStructureKHR structure{};
            structure.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR;
            structure.accelerationStructureCount = 1;
            structure.pAccelerationStructures = &rayQuery_->top;
            VkDescriptorBufferInfo rayInfo{rayBuffer.handle(), first * 2 * sizeof(glm::vec4),
                                           n * 2 * sizeof(glm::vec4)};
            VkDescriptorBufferInfo flagInfo{flags.handle(), first * sizeof(std::uint32_t), n * sizeof(std::uint32_t)};
            VkWriteDescriptorSet writes[3]{};
            for (std::uint32_t i = 0; i < 3; ++i) {
                writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
                writes[i].dstSet = sets[c];
                writes[i].dstBinding = i;
                writes[i].descriptorCount = 1;
                writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            }
            writes[0].pNext = &structure;
            writes[0].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
            writes[1].pBufferInfo = &rayInfo;
            writes[2].pBufferInfo = &flagInfo;
            vkUpdateDescriptorSets(device, 3, writes, 0, nullptr);
        }
        context_.submitAndWait([&](VkCommandBuffer cmd) {
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, rayQuery_->pipeline);
            for (std::uint32_t c = 0; c < chunks; ++c) {
                const std::uint32_t n = std::min(kChunkRays, count - c * kChunkRays);
                RayQueryPush push{n, 0xFFu};
                vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, rayQuery_->layout, 0, 1, &sets[c], 0,
                                        nullptr);
                vkCmdPushConstants(cmd, rayQuery_->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
                vkCmdDispatch(cmd, groupsFor(n), 1, 1);
            }
            computeToComputeBarrier(cmd);
        });
    } catch (...) {
        vkDestroyDescriptorPool(device, pool, nullptr);
        throw;
    }
    vkDestroyDescriptorPool(device, pool, nullptr);
    return flags.download<std::uint32_t>(count);
}

}  // namespace tyndall::gpu
