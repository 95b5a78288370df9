#include "isv/gpu_renderer.h"
#include "tyndall/gpu/context.h"
namespace tyndall::isv {
struct GpuRenderer::Impl {};
GpuRenderer::GpuRenderer() = default;
GpuRenderer::~GpuRenderer() = default;
GpuOutput GpuRenderer::render(const PreparedScene&, const RenderCallbacks&) { throw std::runtime_error("gpu: todo"); }
}
