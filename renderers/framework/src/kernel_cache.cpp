#include "tyndall/framework/kernel_cache.h"

#include <chrono>
#include <fstream>
#include <sstream>

namespace tyndall {

std::vector<std::uint32_t> compileShaderVariant(const std::string& path, gpu::ShaderStage stage,
                                                const std::string& defines) {
    std::ifstream file(path);
    if (!file) throw gpu::GpuError("cannot read the shader " + path);
    std::stringstream text;
    text << file.rdbuf();
    std::string source = text.str();
    if (!defines.empty()) source.insert(source.find('\n') + 1, defines + "#line 2\n");
    gpu::CompileResult compiled = gpu::compileGlslSource(source, path, stage);
    if (!compiled.ok) throw gpu::ShaderError(*compiled.error);
    return compiled.spirv;
}

gpu::ComputeKernel& KernelCache::get(gpu::Context& context, const Kernel& kernel, double& compileSeconds) {
    const std::string key = kernel.path + "\n" + std::to_string(kernel.bindings) + "\n" +
                            std::to_string(kernel.pushBytes) + "\n" + kernel.defines;
    auto it = kernels_.find(key);
    if (it != kernels_.end()) return *it->second;
    const auto start = std::chrono::steady_clock::now();
    auto compiled = std::make_unique<gpu::ComputeKernel>(
        context, compileShaderVariant(kernel.path, gpu::ShaderStage::Compute, kernel.defines), kernel.bindings,
        kernel.pushBytes, kernel.label);
    compileSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return *kernels_.emplace(key, std::move(compiled)).first->second;
}

}  // namespace tyndall
