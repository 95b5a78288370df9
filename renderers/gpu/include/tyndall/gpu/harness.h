// The GPU-vs-CPU harness (GPU framework issue, item 6): runs a shared function over many inputs in a compute shader
// and on the CPU, and reports the largest difference. Every technique's tests use it to show that the GPU runs the
// same math as the CPU paths.
#pragma once

#include "tyndall/gpu/context.h"

#include <glm/glm.hpp>

#include <functional>
#include <string>
#include <vector>

namespace tyndall::gpu {

struct HarnessReport {
    double maxAbsDiff = 0.0;
    double maxRelDiff = 0.0;  // |gpu - cpu| / max(|cpu|, relativeFloor)
    size_t worstIndex = 0;    // input whose component differs most (relative)
    int worstComponent = 0;
    size_t nonFiniteMismatches = 0;  // inputs where exactly one side is NaN or infinite
};

// `prelude` is GLSL placed after the #version line: #includes of shared headers and helper functions. `body` is the
// body of `vec4 evaluate(vec4 x)`. Every input is evaluated in one invocation. Throws ShaderError for GLSL that does
// not compile (with file and line) and GpuError for GPU failures. With `gpuMilliseconds`, the dispatch's GPU time
// (timestamps; negative where the queue has none) is stored there, for benchmarks of shared functions.
std::vector<glm::vec4> evaluateOnGpu(Context& context, const std::string& prelude, const std::string& body,
                                     const std::vector<glm::vec4>& inputs, double* gpuMilliseconds = nullptr);

// The same in double precision (dvec4), for devices with shaderFloat64; throws GpuError when the device lacks it.
std::vector<glm::dvec4> evaluateOnGpuDouble(Context& context, const std::string& prelude, const std::string& body,
                                            const std::vector<glm::dvec4>& inputs);

// Compares GPU results with `cpu` applied to the same inputs.
HarnessReport compareWithCpu(const std::vector<glm::vec4>& inputs, const std::vector<glm::vec4>& gpu,
                             const std::function<glm::vec4(const glm::vec4&)>& cpu, double relativeFloor = 1e-6);
HarnessReport compareWithCpu(const std::vector<glm::dvec4>& inputs, const std::vector<glm::dvec4>& gpu,
                             const std::function<glm::dvec4(const glm::dvec4&)>& cpu, double relativeFloor = 1e-300);

}  // namespace tyndall::gpu
