#include "wvds/gpu_renderer.h"

#include "tyndall/core/error.h"
#include "tyndall/core/resources.h"
#include "tyndall/gpu/shader_compiler.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>

namespace tyndall::wvds {

namespace {

// As the shader's push constants: a slice of GpuAccumulation's with the accumulators' layout in the middle.
struct Push {
    std::uint32_t first, end, width, index;
    std::uint32_t stride;
    std::uint32_t ratioLights;
    std::uint32_t pixels, bandGroups;
};

std::string shaderPath() {
    return shaderDirectory().string() + "/wvds/wvds.comp.glsl";
}

}  // namespace

GpuRenderer::GpuRenderer() : context_(gpu::sharedContext()), accumulation_(*context_) {}

gpu::ComputeKernel& GpuRenderer::kernel(int estimator, int planeCount, int planeTotal, bool box, int phaseKind,
                                        int lightCount, const GpuSurfaces& surfaces, bool grey, bool gobos) {
    const bool hasSurfaces = surfaces.triangleCount > 0;
    const int maxPlanes = planeCount <= 6 ? 6 : planeCount <= 8 ? 8 : shader::kWvdsMaxPlanes;
    const std::string key = std::to_string(estimator) + "-" + (box ? std::string("box") : std::to_string(planeCount)) +
                            "-" + std::to_string(planeTotal) + "-" + std::to_string(phaseKind) + "-" +
                            std::to_string(lightCount) + (hasSurfaces ? "" : "-nosurfaces") + (grey ? "-grey" : "") +
                            (gobos ? "" : "-nogobos");
    std::string defines = "#define TY_WVDS_ESTIMATOR " + std::to_string(estimator) + "\n#define TY_WVDS_MAX_PLANES " +
                          std::to_string(maxPlanes) + "\n#define TY_PHASE_KIND " + std::to_string(phaseKind) +
                          "\n#define TY_WVDS_LIGHTS " + std::to_string(lightCount) + "\n#define TY_WVDS_PLANES " +
                          std::to_string(planeCount) + "\n";
    if (planeTotal > 0) defines += "#define TY_WVDS_PLANE_TOTAL " + std::to_string(planeTotal) + "\n";
    if (box) defines += "#define TY_WVDS_BOX\n";
    if (!hasSurfaces) defines += "#define TY_WVDS_NO_SURFACES\n";
    defines += surfaces.shaderDefines();
    if (grey) defines += "#define TY_WVDS_GREY\n";
    if (!gobos) defines += "#define TY_WVDS_NO_GOBOS\n";
    if (context_->device().shaderFloat64) defines += "#define TY_BVH_WORDS\n#define TY_ACCUMULATOR_WORDS\n";
    return kernels_.get(*context_, {shaderPath(), defines, 8, std::uint32_t(sizeof(Push)), "wvds_" + key},
                        compileSeconds_);
}

void GpuRenderer::begin(const PreparedScene& scene, int width, int height, int stride, int ratioLights) {
    compileSeconds_ = 0.0;
    kernel_ = &kernel(scene.frame.estimator, scene.frame.planeCount, int(scene.planes.size()), scene.box,
                      scene.frame.phase.kind, scene.frame.lightCount, scene.surfaces, shader::wvdsGrey(scene.frame),
                      std::any_of(scene.lights.begin(), scene.lights.end(),
                                  [](const shader::WvdsLight& l) { return l.goboCount > 0; }));
    gpu::Context& ctx = *context_;
    auto upload = [&](const auto& values) { return gpu::uploadBuffer(ctx, values); };
    buffers_.clear();
    buffers_.push_back(upload(scene.surfaces.bvh.nodes));
    buffers_.push_back(upload(scene.surfaces.bvh.triangles));
    auto frame = std::make_unique<gpu::Buffer>(ctx, sizeof(shader::WvdsFrame));
    frame->upload(&scene.frame, sizeof(shader::WvdsFrame));
    buffers_.push_back(std::move(frame));
    buffers_.push_back(upload(scene.planes));
    buffers_.push_back(upload(scene.lights));
    buffers_.push_back(upload(scene.surfaces.triangles));
    buffers_.push_back(upload(scene.surfaces.materials));
    stride_ = std::uint32_t(stride);
    ratioLights_ = std::uint32_t(ratioLights);
    accumulation_.begin(width, height, 2 * std::size_t(stride));  // two halves
}

void GpuRenderer::addSamples(std::uint32_t first, std::uint32_t end, const RenderCallbacks& callbacks) {
    TY_CHECK(kernel_ != nullptr, "GpuRenderer::begin before addSamples");
    std::vector<const gpu::Buffer*> inputs;
    for (const auto& b : buffers_)
        inputs.push_back(b.get());
    accumulation_.addSamples(*kernel_, inputs, first, end, callbacks, [&](const GpuAccumulation::Slice& s) {
        return Push{s.first, s.end, s.width, s.index, stride_, ratioLights_, s.pixels, s.bandGroups};
    });
}

const std::vector<glm::vec4>& GpuRenderer::readAccumulators() {
    return accumulation_.read();
}

}  // namespace tyndall::wvds
