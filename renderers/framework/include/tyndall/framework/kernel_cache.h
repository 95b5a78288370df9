// Compile-time variants of a technique's shaders (model: Falcor's program defines). On lavapipe every branch compiled
// into a shader costs its full price on every pixel, so what a scene does not have (surfaces, GGX, a medium kind) is
// compiled out with #defines; each technique keeps one kernel per set of defines, compiled on first use.
#pragma once

#include "tyndall/gpu/context.h"
#include "tyndall/gpu/resources.h"
#include "tyndall/gpu/shader_compiler.h"

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace tyndall {

// The SPIR-V of the GLSL file `path` with `defines` (lines of "#define NAME VALUE") inserted after its #version line
// (followed by "#line 2", so that errors keep the file's line numbers). Throws gpu::GpuError when the file cannot be
// read and gpu::ShaderError when it does not compile.
std::vector<std::uint32_t> compileShaderVariant(const std::string& path, gpu::ShaderStage stage,
                                                const std::string& defines);

// Compute kernels by file and defines.
class KernelCache {
public:
    struct Kernel {
        std::string path;         // the GLSL file
        std::string defines;      // its variant
        std::uint32_t bindings;   // storage buffers in set 0
        std::uint32_t pushBytes;  // push constants
        std::string label;        // the kernel's name in timings and validation messages
    };
    // The kernel, compiled on first use (its compile time added to `compileSeconds`) and kept for later calls.
    gpu::ComputeKernel& get(gpu::Context& context, const Kernel& kernel, double& compileSeconds);
    std::size_t size() const { return kernels_.size(); }
    // Where the kernel's next gpu::runSliced starts: the slice size that its last run ended on (`initial` before any
    // run), kept by the caller from SliceStats::nextSlice. A kernel run frame after frame then goes in a few slices
    // of the target's length instead of growing each time from a cautious guess: on lavapipe every submission costs
    // a wait and starts with idle cores.
    std::uint64_t& sliceSize(const gpu::ComputeKernel& kernel, std::uint64_t initial) {
        return sliceSizes_.try_emplace(&kernel, initial).first->second;
    }

private:
    std::map<std::string, std::unique_ptr<gpu::ComputeKernel>> kernels_;
    std::map<const gpu::ComputeKernel*, std::uint64_t> sliceSizes_;
};

}  // namespace tyndall
