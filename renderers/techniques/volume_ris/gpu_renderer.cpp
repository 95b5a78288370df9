#include "volume_ris/gpu_renderer.h"

#include "tyndall/core/error.h"
#include "tyndall/core/resources.h"
#include "tyndall/gpu/shader_compiler.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>

namespace tyndall::volume_ris {

namespace {

constexpr int kBindings = 9;

// The shader's push constants are a slice of GpuAccumulation's, field for field.
using Push = GpuAccumulation::Slice;
static_assert(sizeof(Push) == 6 * sizeof(std::uint32_t));

std::string shaderPath() {
    return shaderDirectory().string() + "/volume_ris/volume_ris.comp.glsl";
}

}  // namespace

GpuRenderer::GpuRenderer() : context_(gpu::sharedContext()), accumulation_(*context_) {}

gpu::ComputeKernel& GpuRenderer::kernel(const PreparedScene& scene) {
    const shader::RisFrame& f = scene.frame;
    const bool surfaces = scene.surfaces.triangleCount > 0;
    const int vertexTotal = f.lightCount > 0 ? int(scene.vertices.size()) : 0;
    int maxVertices = 3;
    for (int i = 0; i < f.lightCount; ++i)
        maxVertices = std::max(maxVertices, scene.lights[std::size_t(i)].vertexCount);
    const std::string key = "m" + std::to_string(f.mediumKind) + "-p" + std::to_string(f.planeCount) + "-l" +
                            std::to_string(f.lightCount) + "-v" + std::to_string(vertexTotal) + "-mv" +
                            std::to_string(maxVertices) + "-ph" + std::to_string(f.phase.kind) + "-d" +
                            std::to_string(f.distanceSampling) + "-ls" + std::to_string(f.lightSampling) +
                            (surfaces ? "" : "-nosurfaces") + (scene.grey ? "-grey" : "");
    std::string defines = "#define TY_RIS_MEDIUM " + std::to_string(f.mediumKind) + "\n#define TY_RIS_PLANES " +
                          std::to_string(f.planeCount) + "\n#define TY_RIS_LIGHTS " + std::to_string(f.lightCount) +
                          "\n#define TY_PHASE_KIND " + std::to_string(f.phase.kind) + "\n#define TY_RIS_DISTANCE " +
                          std::to_string(f.distanceSampling) + "\n#define TY_RIS_VERTICES " +
                          std::to_string(maxVertices) + "\n#define TY_RIS_LIGHT_SAMPLING " +
                          std::to_string(f.lightSampling) + "\n";
    if (vertexTotal > 0) defines += "#define TY_RIS_VERTEX_TOTAL " + std::to_string(vertexTotal) + "\n";
    if (!surfaces) defines += "#define TY_RIS_NO_SURFACES\n";
    defines += scene.surfaces.shaderDefines();
    if (scene.grey) defines += "#define TY_RIS_GREY\n";
    if (context_->device().shaderFloat64) defines += "#define TY_BVH_WORDS\n";
    return kernels_.get(*context_, {shaderPath(), defines, kBindings, std::uint32_t(sizeof(Push)), "volume_ris_" + key},
                        compileSeconds_);
}

void GpuRenderer::begin(const PreparedScene& scene, int width, int height) {
    compileSeconds_ = 0.0;
    kernel_ = &kernel(scene);
    gpu::Context& ctx = *context_;
    auto upload = [&](const auto& values) { return gpu::uploadBuffer(ctx, values); };
    buffers_.clear();
    buffers_.push_back(upload(scene.surfaces.bvh.nodes));
    buffers_.push_back(upload(scene.surfaces.bvh.triangles));
    auto frame = std::make_unique<gpu::Buffer>(ctx, sizeof(shader::RisFrame));
    frame->upload(&scene.frame, sizeof(shader::RisFrame));
    buffers_.push_back(std::move(frame));
    buffers_.push_back(upload(scene.planes));
    buffers_.push_back(upload(scene.lights));
    buffers_.push_back(upload(scene.vertices));
    buffers_.push_back(upload(scene.surfaces.triangles));
    buffers_.push_back(upload(scene.surfaces.materials));
    // Per pixel and half, two vec4s (medium with the sample count in w, surface).
    accumulation_.begin(width, height, 4);
}

void GpuRenderer::addSamples(std::uint32_t first, std::uint32_t end, const RenderCallbacks& callbacks) {
    TY_CHECK(kernel_ != nullptr, "GpuRenderer::begin before addSamples");
    std::vector<const gpu::Buffer*> inputs;
    for (const auto& b : buffers_)
        inputs.push_back(b.get());
    accumulation_.addSamples(*kernel_, inputs, first, end, callbacks, [](const Push& slice) { return slice; });
}

const std::vector<glm::vec4>& GpuRenderer::readAccumulators() {
    return accumulation_.read();
}

}  // namespace tyndall::volume_ris
