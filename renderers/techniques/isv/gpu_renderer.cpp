#include "isv/gpu_renderer.h"

#include "tyndall/core/error.h"
#include "tyndall/core/resources.h"
#include "tyndall/framework/kernel_cache.h"
#include "tyndall/gpu/graphics.h"
#include "tyndall/gpu/resources.h"
#include "tyndall/gpu/shader_compiler.h"
#include "tyndall/gpu/slicer.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

namespace tyndall::isv {

namespace {

constexpr std::uint32_t kGroupSize = 64;

// shaders/isv/isv_view.glsl's IsvView, std430.
struct ViewBlock {
    shader::CameraParams camera;
    float nearPlane;
    std::int32_t width;
    std::int32_t height;
    std::int32_t particleCount;
};
static_assert(sizeof(ViewBlock) == 80);

struct RangePush {
    std::uint32_t first, end;
};
struct SurfacePush {
    std::uint32_t first, end;
    float rayOffset;
};
struct ProxyPush {
    std::int32_t slab;     // -1 for the camera pass
    std::int32_t ordered;  // 1: particles in the sorted order
    std::uint32_t first;   // mesh shader: the draw's first particle (the vertex stage has gl_VertexIndex)
    std::uint32_t count;   // mesh shader: the draw's particles
};
constexpr std::uint32_t kMeshParticlesPerGroup = 32;  // features/isv_proxy.mesh.glsl's workgroup
struct SortPush {
    std::uint32_t count, k, j;
};
struct SumPush {
    std::uint32_t texels, slices, channels;
};

std::string shaderPath(const std::string& name) {
    return (shaderDirectory() / "isv" / name).string();
}

// Compiles shaders/isv/<name> with `defines` inserted after its #version line.
std::vector<std::uint32_t> compileStage(const std::string& name, gpu::ShaderStage stage, const std::string& defines) {
    return compileShaderVariant(shaderPath(name), stage, defines);
}

std::uint32_t groups(std::uint64_t n) {
    return std::uint32_t((n + kGroupSize - 1) / kGroupSize);
}

std::string megabytes(std::uint64_t bytes) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.1f MB", double(bytes) / 1048576.0);
    return text;
}

}  // namespace

std::optional<InputError> deviceLimitProblem(const PreparedScene& scene, const gpu::DeviceInfo& device) {
    auto problem = [&](const std::string& field, const std::string& what) {
        return InputError(InputLocation{"", 0, 0, field},
                          what + " on the device '" + device.name + "'; or render this view with device = cpu");
    };
    if (scene.chromatic && !device.dualSrcBlend)
        return problem("device", "coloured shadows (a chromatic extinction) composite each channel by its own "
                                 "transmittance, which needs dualSrcBlend, missing");
    const std::uint64_t range = device.maxStorageBufferRange;
    const std::uint64_t count = scene.particles.size();
    const std::uint64_t sortCount = std::bit_ceil(std::max<std::uint64_t>(count, 1));
    const std::uint64_t particleBytes = std::max(count * sizeof(shader::IsvParticle), sortCount * sizeof(glm::uvec2));
    if (particleBytes > range)
        return problem("particleMedia",
                       "the view's " + std::to_string(count) + " particles need " + megabytes(particleBytes) +
                           " in one storage buffer, more than the " + megabytes(range) + " allowed (about " +
                           std::to_string(range / sizeof(shader::IsvParticle)) + " particles): use fewer particles");
    const std::uint64_t channels = scene.chromatic ? 4 : 1;
    if (scene.vsm) {
        const shader::IsvLightSpace& g = scene.frame.vsm;
        const std::uint64_t bytes = std::uint64_t(g.size) * g.size * channels * std::uint64_t(g.slices) * 4;
        if (bytes > range)
            return problem("vsmResolution",
                           "the volumetric shadow map of " + std::to_string(g.size) + "^2 texels x " +
                               std::to_string(g.slices) + " slices" + (scene.chromatic ? " x RGBA" : "") + " needs " +
                               megabytes(bytes) + ", more than the " + megabytes(range) +
                               " one storage buffer allows: lower vsmResolution or vsmSlices");
        if (std::uint32_t(g.slices - 1) > device.maxImageArrayLayers)
            return problem("vsmSlices", std::to_string(g.slices - 1) + " slabs exceed the " +
                                            std::to_string(device.maxImageArrayLayers) + " layers of a render target");
    }
    if (scene.shadowMap) {
        const std::uint64_t size = std::uint64_t(scene.frame.shadowMap.size);
        if (size * size * 4 > range)
            return problem("shadowMapResolution", "the opaque shadow map of " + std::to_string(size) + "^2 texels needs " +
                                                      megabytes(size * size * 4) + ", more than the " +
                                                      megabytes(range) + " one storage buffer allows");
    }
    const std::uint32_t side = std::min({device.maxImageDimension2D, device.maxFramebufferWidth,
                                         device.maxFramebufferHeight});
    const std::uint64_t pixelBytes = std::uint64_t(scene.width) * std::uint64_t(scene.height) * 16;
    if (std::uint32_t(scene.width) > side || std::uint32_t(scene.height) > side || pixelBytes > range)
        return problem("supersampling",
                       "the rendering resolution " + std::to_string(scene.width) + " x " +
                           std::to_string(scene.height) + " (the image's times supersampling) exceeds the device's " +
                           std::to_string(side) + " texels per side or " + megabytes(range) +
                           " per storage buffer: lower supersampling or the image size");
    const std::uint64_t bvhBytes = std::max({scene.surfaces.bvh.nodes.size() * sizeof(scene.surfaces.bvh.nodes[0]),
                                             scene.surfaces.bvh.triangles.size() *
                                                 sizeof(scene.surfaces.bvh.triangles[0]),
                                             scene.surfaces.triangles.size() * sizeof(shader::SurfaceTriangle)});
    if (bvhBytes > range)
        return problem("meshes", "the surfaces' triangles need " + megabytes(bvhBytes) + " in one storage buffer, " +
                                     "more than the " + megabytes(range) + " allowed: use fewer triangles");
    return std::nullopt;
}

struct GpuRenderer::Impl {
    std::shared_ptr<gpu::Context> context = gpu::sharedContext();
    KernelCache kernels;
    std::map<std::string, std::unique_ptr<gpu::GraphicsPipeline>> pipelines;
    double compileSeconds = 0.0;

    bool words() const { return context->device().shaderFloat64; }

    gpu::ComputeKernel& kernel(const std::string& file, std::uint32_t bindings, std::uint32_t pushBytes, bool bvh,
                               const std::string& variant = "") {
        const std::string defines = (bvh && words() ? "#define TY_BVH_WORDS\n" : "") + variant;
        return kernels.get(*context, {shaderPath(file), defines, bindings, pushBytes, "isv_" + file}, compileSeconds);
    }

    // The proxies' pipeline: the camera's (premultiplied-under blending into RGBA, per channel by dual-source blending
    // for chromatic media) or the volumetric shadow map's (additive into R32, or RGBA for chromatic media). The phase
    // function is a compile-time variant when the particles share one kind.
    gpu::GraphicsPipeline& proxies(bool lightView, bool chromatic, bool mesh, const std::string& defines) {
        const std::string key = std::string(lightView ? "vsm\n" : "camera\n") + (chromatic ? "rgb\n" : "") +
                                (mesh ? "mesh\n" : "") + defines;
        auto it = pipelines.find(key);
        if (it != pipelines.end()) return *it->second;
        const auto start = std::chrono::steady_clock::now();
        gpu::GraphicsPipelineDesc desc;
        desc.name = lightView ? "isv_vsm" : "isv_particles";
        const std::string view = lightView ? "#define TY_ISV_LIGHT_VIEW\n" : "";
        if (mesh) {
            desc.mesh = compileStage("../features/isv_proxy.mesh.glsl", gpu::ShaderStage::Mesh, view);
        } else {
            desc.vertex = compileStage("proxy.vert.glsl", gpu::ShaderStage::Vertex, "");
            desc.geometry = compileStage("proxy.geom.glsl", gpu::ShaderStage::Geometry, view);
        }
        desc.fragment = compileStage(lightView ? "vsm.frag.glsl" : "particle.frag.glsl", gpu::ShaderStage::Fragment,
                                     defines);
        desc.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
        const VkFormat vsmFormat = chromatic ? VK_FORMAT_R32G32B32A32_SFLOAT : VK_FORMAT_R32_SFLOAT;
        const gpu::Blend under =
            chromatic ? gpu::Blend::premultipliedUnderPerChannel() : gpu::Blend::premultipliedUnder();
        desc.colour = {lightView ? gpu::ColourAttachment{vsmFormat, gpu::Blend::additive()}
                                 : gpu::ColourAttachment{VK_FORMAT_R32G32B32A32_SFLOAT, under}};
        desc.bindingCount = lightView ? 4 : 7;
        desc.pushConstantBytes = sizeof(ProxyPush);
        auto p = std::make_unique<gpu::GraphicsPipeline>(*context, desc);
        compileSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return *pipelines.emplace(key, std::move(p)).first->second;
    }

    gpu::GraphicsPipeline& background() {
        auto it = pipelines.find("background");
        if (it != pipelines.end()) return *it->second;
        gpu::GraphicsPipelineDesc desc;
        desc.name = "isv_background";
        desc.vertex = compileStage("fullscreen.vert.glsl", gpu::ShaderStage::Vertex, "");
        desc.fragment = compileStage("background.frag.glsl", gpu::ShaderStage::Fragment, "");
        desc.colour = {gpu::ColourAttachment{VK_FORMAT_R32G32B32A32_SFLOAT, gpu::Blend::none()}};
        desc.bindingCount = 1;
        desc.pushConstantBytes = sizeof(std::int32_t);
        return *pipelines.emplace("background", std::make_unique<gpu::GraphicsPipeline>(*context, desc))
                    .first->second;
    }
};

GpuRenderer::GpuRenderer() : impl_(std::make_unique<Impl>()) {}
GpuRenderer::~GpuRenderer() = default;

GpuOutput GpuRenderer::render(const PreparedScene& scene, const RenderCallbacks& callbacks, Proxies proxies) {
    Impl& im = *impl_;
    gpu::Context& ctx = *im.context;
    GpuOutput out;
    const bool mesh = proxies == Proxies::Mesh || (proxies == Proxies::Auto && ctx.device().meshShader);
    if (mesh && !ctx.device().meshShader)
        throw InputError(InputLocation{"", 0, 0, "proxies"},
                         "the device '" + ctx.device().name +
                             "' has no mesh shaders (VK_EXT_mesh_shader); set proxies to geometry or auto");
    out.meshProxies = mesh;
    // The technique checks this first to fall back to the CPU under device = auto; here it guards direct callers.
    if (const std::optional<InputError> problem = deviceLimitProblem(scene, ctx.device())) throw *problem;
    // A draw of `count` particles from `first`: points for the vertex and geometry stages, or workgroups of the mesh
    // shader.
    auto drawProxies = [&](gpu::GraphicsPipeline& pipeline, VkCommandBuffer cmd,
                           const std::vector<const gpu::Buffer*>& b, ProxyPush push, std::uint32_t count,
                           std::uint32_t first) {
        if (mesh) {
            // In draws of at most the device's workgroups per draw, in order.
            const std::uint32_t most = std::uint32_t(std::clamp<std::uint64_t>(
                std::uint64_t(ctx.device().maxMeshWorkGroups) * kMeshParticlesPerGroup, kMeshParticlesPerGroup,
                std::uint64_t(1) << 30));
            for (std::uint32_t done = 0; done < count; done += most) {
                push.first = first + done;
                push.count = std::min(most, count - done);
                pipeline.drawMeshTasks(cmd, b, &push,
                                       (push.count + kMeshParticlesPerGroup - 1) / kMeshParticlesPerGroup);
            }
        } else {
            pipeline.draw(cmd, b, &push, count, 1, first);
        }
    };
    const double compiledBefore = im.compileSeconds;
    const auto progress = [&](double f) {
        if (callbacks.progress) callbacks.progress(f);
    };

    // The frame's settings as compile-time variants (lavapipe pays for every branch compiled in), and the phase
    // function's kind when every medium has the same one (the common case).
    const shader::IsvFrame& f = scene.frame;
    int phaseKind = f.mediumCount > 0 ? f.media[0].phase.kind : shader::kPhaseIsotropic;
    for (int m = 1; m < f.mediumCount; ++m)
        if (f.media[m].phase.kind != phaseKind) phaseKind = -1;
    auto define = [](const char* name, int value) {
        return std::string("#define ") + name + " " + std::to_string(value) + "\n";
    };
    const bool chromatic = scene.chromatic;
    const std::string maps = define("TY_ISV_VSM", f.hasVsm) + define("TY_ISV_SHADOW_MAP", f.hasShadowMap) +
                             define("TY_ISV_PCF", f.pcfRadius) + define("TY_ISV_CHROMATIC", chromatic ? 1 : 0);
    const std::string light = define("TY_ISV_LIGHT_TYPE", f.lightType);
    std::string shading = maps + light + define("TY_ISV_INTEGRATION", f.integration) +
                          define("TY_ISV_STEPS", f.steps) + define("TY_ISV_FADING", f.fading);
    if (phaseKind >= 0) shading += define("TY_PHASE_KIND", phaseKind);

    const std::uint32_t particleCount = std::uint32_t(scene.particles.size());
    auto upload = [&](const auto& values) { return gpu::uploadBuffer(ctx, values); };
    auto particles = upload(scene.particles);
    gpu::Buffer frame(ctx, sizeof(shader::IsvFrame));
    frame.upload(&scene.frame, sizeof(shader::IsvFrame));
    ViewBlock viewBlock{scene.camera, scene.nearPlane, scene.width, scene.height, std::int32_t(particleCount)};
    gpu::Buffer view(ctx, sizeof(ViewBlock));
    view.upload(&viewBlock, sizeof(ViewBlock));
    auto nodes = upload(scene.surfaces.bvh.nodes);
    auto triangles = upload(scene.surfaces.bvh.triangles);
    auto surfaceTriangles = upload(scene.surfaces.triangles);
    auto materials = upload(scene.surfaces.materials);
    const std::uint32_t sortCount = std::max<std::uint32_t>(1u, std::bit_ceil(std::max(particleCount, 1u)));
    // The sort's dispatch, in rows of at most 32768 groups (a dimension is guaranteed 65535); sort.comp.glsl flattens it.
    const std::uint32_t sortGroupsTotal = groups(sortCount);
    const glm::uvec2 sortGroups(std::min(sortGroupsTotal, 32768u), (sortGroupsTotal + 32767u) / 32768u);
    gpu::Buffer order(ctx, VkDeviceSize(sortCount) * sizeof(glm::uvec2));

    auto sliced = [&](std::uint64_t total, const gpu::SliceRecorder& record, std::uint64_t first, double& ms) {
        const gpu::SliceStats s = gpu::runSliced(ctx, total, record, callbacks.cancel, 10.0, first);
        ms += s.totalMs;
        out.timings.longestSliceMs = std::max(out.timings.longestSliceMs, s.longestMs);
    };

    // 1. The opaque shadow map.
    const shader::IsvLightSpace& sm = scene.frame.shadowMap;
    const std::uint64_t shadowTexels = scene.shadowMap ? std::uint64_t(sm.size) * sm.size : 1;
    gpu::Buffer shadow(ctx, shadowTexels * sizeof(float));
    if (scene.shadowMap) {
        gpu::ComputeKernel& k = im.kernel("shadow_map.comp.glsl", 4, sizeof(RangePush), true);
        const std::vector<const gpu::Buffer*> b{nodes.get(), triangles.get(), &frame, &shadow};
        sliced(
            shadowTexels,
            [&](VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t n) {
                RangePush push{std::uint32_t(begin), std::uint32_t(begin + n)};
                k.record(cmd, b, &push, groups(n));
            },
            4096, out.timings.shadowMapMs);
        k.resetDescriptors();
    } else {
        shadow.fill(0u);
    }
    progress(0.1);

    // 2. The volumetric shadow map: every particle drawn into each slab it meets, then the slabs summed into slices.
    const shader::IsvLightSpace& vg = scene.frame.vsm;
    const std::uint64_t vsmTexels = scene.vsm ? std::uint64_t(vg.size) * vg.size : 1;
    const std::uint64_t vsmChannels = chromatic ? 4 : 1;  // RGB optical depth in RGBA texels, or one
    gpu::Buffer vsm(ctx, vsmTexels * vsmChannels * (scene.vsm ? vg.slices : 1) * sizeof(float));
    if (scene.vsm) {
        const std::uint32_t slabs = std::uint32_t(vg.slices - 1);
        gpu::RenderTarget target(ctx, std::uint32_t(vg.size), std::uint32_t(vg.size),
                                 chromatic ? VK_FORMAT_R32G32B32A32_SFLOAT : VK_FORMAT_R32_SFLOAT, slabs);
        gpu::GraphicsPipeline& pipeline = im.proxies(
            true, chromatic, mesh, define("TY_ISV_FADING", f.fading) + define("TY_ISV_CHROMATIC", chromatic ? 1 : 0));
        const std::vector<const gpu::Buffer*> b{particles.get(), &order, &frame, &view};
        sliced(
            std::uint64_t(slabs) * particleCount,
            [&](VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t n) {
                for (std::uint64_t i = begin; i < begin + n;) {
                    const std::uint32_t slab = std::uint32_t(i / particleCount);
                    const std::uint32_t first = std::uint32_t(i % particleCount);
                    const std::uint32_t count = std::uint32_t(std::min<std::uint64_t>(particleCount - first,
                                                                                      begin + n - i));
                    gpu::PassDesc pass;
                    pass.colour = {gpu::AttachmentRef{&target, slab}};
                    pass.load = first == 0 ? gpu::LoadOp::Clear : gpu::LoadOp::Load;
                    pipeline.beginPass(cmd, pass);
                    drawProxies(pipeline, cmd, b, ProxyPush{std::int32_t(slab), 0, 0, 0}, count, first);
                    pipeline.endPass(cmd);
                    i += count;
                }
            },
            64, out.timings.vsmMs);
        pipeline.resetDescriptors();
        gpu::Buffer slabBuffer(ctx, vsmTexels * vsmChannels * slabs * sizeof(float));
        gpu::ComputeKernel& sum = im.kernel("vsm_sum.comp.glsl", 2, sizeof(SumPush), false);
        out.timings.vsmMs += ctx.submitTimed([&](VkCommandBuffer cmd) {
            target.recordCopyAll(cmd, slabBuffer);
            const SumPush push{std::uint32_t(vsmTexels), std::uint32_t(vg.slices), std::uint32_t(vsmChannels)};
            sum.record(cmd, {&slabBuffer, &vsm}, &push, groups(vsmTexels));
            gpu::computeToGraphicsBarrier(cmd);
        });
        sum.resetDescriptors();
    } else {
        vsm.fill(0u);
    }
    progress(0.3);

    // 3. The surfaces seen from the camera: the colour the particles are blended over and where they are clipped.
    const std::uint64_t pixels = std::uint64_t(scene.width) * scene.height;
    gpu::Buffer surfaces(ctx, pixels * sizeof(glm::vec4));
    {
        gpu::ComputeKernel& k = im.kernel("surfaces.comp.glsl", 9, sizeof(SurfacePush), true, maps + light);
        const std::vector<const gpu::Buffer*> b{nodes.get(), triangles.get(), surfaceTriangles.get(), materials.get(),
                                               &frame,      &view,           &vsm,                   &shadow,
                                               &surfaces};
        sliced(
            pixels,
            [&](VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t n) {
                SurfacePush push{std::uint32_t(begin), std::uint32_t(begin + n), scene.surfaces.rayOffset};
                k.record(cmd, b, &push, groups(n));
                gpu::computeToGraphicsBarrier(cmd);
            },
            4096, out.timings.surfacesMs);
        k.resetDescriptors();
    }
    progress(0.5);

    // 4. Back to front: keys, then the bitonic network.
    {
        gpu::ComputeKernel& k = im.kernel("sort.comp.glsl", 3, sizeof(SortPush), false);
        const std::vector<const gpu::Buffer*> b{particles.get(), &order, &view};
        out.timings.sortMs += ctx.submitTimed([&](VkCommandBuffer cmd) {
            SortPush push{sortCount, 0u, 0u};
            k.record(cmd, b, &push, sortGroups.x, sortGroups.y);
            gpu::computeToComputeBarrier(cmd);
            for (std::uint32_t size = 2; size <= sortCount; size <<= 1)
                for (std::uint32_t j = size >> 1; j > 0; j >>= 1) {
                    push = SortPush{sortCount, size, j};
                    k.record(cmd, b, &push, sortGroups.x, sortGroups.y);
                    gpu::computeToComputeBarrier(cmd);
                }
            gpu::computeToGraphicsBarrier(cmd);
        });
        k.resetDescriptors();
    }
    progress(0.6);

    // 5. The particles over the surfaces, back to front, in slices of about 10 ms.
    gpu::RenderTarget target(ctx, std::uint32_t(scene.width), std::uint32_t(scene.height),
                             VK_FORMAT_R32G32B32A32_SFLOAT);
    {
        gpu::GraphicsPipeline& bg = im.background();
        out.timings.particlesMs += ctx.submitTimed([&](VkCommandBuffer cmd) {
            gpu::PassDesc pass;
            pass.colour = {gpu::AttachmentRef{&target, 0}};
            pass.load = gpu::LoadOp::Clear;
            bg.beginPass(cmd, pass);
            const std::int32_t width = scene.width;
            bg.draw(cmd, {&surfaces}, &width, 3);
            bg.endPass(cmd);
        });
        bg.resetDescriptors();
    }
    if (particleCount > 0) {
        gpu::GraphicsPipeline& pipeline = im.proxies(false, chromatic, mesh, shading);
        const std::vector<const gpu::Buffer*> b{particles.get(), &order, &frame, &view, &vsm, &shadow, &surfaces};
        sliced(
            particleCount,
            [&](VkCommandBuffer cmd, std::uint64_t begin, std::uint64_t n) {
                progress(0.6 + 0.4 * double(begin) / double(particleCount));
                gpu::PassDesc pass;
                pass.colour = {gpu::AttachmentRef{&target, 0}};
                pass.load = gpu::LoadOp::Load;
                pipeline.beginPass(cmd, pass);
                drawProxies(pipeline, cmd, b, ProxyPush{-1, 1, 0, 0}, std::uint32_t(n), std::uint32_t(begin));
                pipeline.endPass(cmd);
            },
            16, out.timings.particlesMs);
        pipeline.resetDescriptors();
    }

    const std::vector<float> values = target.readback(0);
    out.pixels.resize(pixels);
    for (std::uint64_t i = 0; i < pixels; ++i)
        out.pixels[i] = glm::vec4(values[4 * i], values[4 * i + 1], values[4 * i + 2], values[4 * i + 3]);
    out.deviceName = ctx.device().name;
    out.timings.totalMs = out.timings.shadowMapMs + out.timings.vsmMs + out.timings.surfacesMs + out.timings.sortMs +
                          out.timings.particlesMs;
    out.timings.compileSeconds = im.compileSeconds - compiledBefore;
    return out;
}

}  // namespace tyndall::isv
