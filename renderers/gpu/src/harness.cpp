#include "tyndall/gpu/harness.h"

#include "tyndall/gpu/resources.h"
#include "tyndall/gpu/shader_compiler.h"

#include <cmath>

namespace tyndall::gpu {

namespace {

std::string kernelSource(const std::string& prelude, const std::string& body, bool isDouble) {
    const std::string type = isDouble ? "dvec4" : "vec4";
    return "#version 460\n"
           "#extension GL_GOOGLE_include_directive : require\n" +
           prelude +
           "\n"
           "layout(local_size_x = 64) in;\n"
           "layout(std430, set = 0, binding = 0) readonly buffer Inputs { " + type + " inputs[]; };\n"
           "layout(std430, set = 0, binding = 1) writeonly buffer Outputs { " + type + " outputs[]; };\n"
           "layout(push_constant) uniform Push { uint count; } push;\n" +
           type + " evaluate(" + type + " x) {\n" + body + "\n}\n"
           "void main() {\n"
           "    uint i = gl_GlobalInvocationID.x;\n"
           "    if (i < push.count) outputs[i] = evaluate(inputs[i]);\n"
           "}\n";
}

template <typename T>
std::vector<T> run(Context& context, const std::string& source, const std::vector<T>& inputs, double* gpuMilliseconds) {
    CompileResult compiled = compileGlslSource(source, "harness.comp.glsl", ShaderStage::Compute);
    if (!compiled.ok) throw ShaderError(*compiled.error);
    const uint32_t n = uint32_t(inputs.size());
    Buffer in(context, std::max<size_t>(1, n) * sizeof(T)), out(context, std::max<size_t>(1, n) * sizeof(T));
    in.upload(inputs);
    ComputeKernel kernel(context, compiled.spirv, 2, sizeof(uint32_t), "harness");
    const auto record = [&](VkCommandBuffer cmd) { kernel.record(cmd, {&in, &out}, &n, (n + 63) / 64); };
    if (gpuMilliseconds)
        *gpuMilliseconds = context.submitTimed(record);
    else
        context.submitAndWait(record);
    return out.download<T>(n);
}

template <typename V, typename F>
HarnessReport compare(const std::vector<V>& inputs, const std::vector<V>& gpu, const F& cpu, double floor) {
    HarnessReport report;
    for (size_t i = 0; i < inputs.size(); ++i) {
        V expected = cpu(inputs[i]);
        for (int c = 0; c < 4; ++c) {
            double e = double(expected[c]), g = double(gpu[i][c]);
            if (!std::isfinite(e) || !std::isfinite(g)) {
                bool same = (std::isnan(e) && std::isnan(g)) || e == g;
                if (!same) report.nonFiniteMismatches += 1;
                continue;
            }
            double abs = std::abs(g - e);
            double rel = abs / std::max(std::abs(e), floor);
            report.maxAbsDiff = std::max(report.maxAbsDiff, abs);
            if (rel > report.maxRelDiff) {
                report.maxRelDiff = rel;
                report.worstIndex = i;
                report.worstComponent = c;
            }
        }
    }
    return report;
}

}  // namespace

std::vector<glm::vec4> evaluateOnGpu(Context& context, const std::string& prelude, const std::string& body,
                                     const std::vector<glm::vec4>& inputs, double* gpuMilliseconds) {
    return run(context, kernelSource(prelude, body, false), inputs, gpuMilliseconds);
}

std::vector<glm::dvec4> evaluateOnGpuDouble(Context& context, const std::string& prelude, const std::string& body,
                                            const std::vector<glm::dvec4>& inputs) {
    if (!context.device().shaderFloat64) throw GpuError("the device '" + context.device().name + "' has no float64");
    return run(context, kernelSource(prelude, body, true), inputs, nullptr);
}

HarnessReport compareWithCpu(const std::vector<glm::vec4>& inputs, const std::vector<glm::vec4>& gpu,
                             const std::function<glm::vec4(const glm::vec4&)>& cpu, double relativeFloor) {
    return compare(inputs, gpu, cpu, relativeFloor);
}

HarnessReport compareWithCpu(const std::vector<glm::dvec4>& inputs, const std::vector<glm::dvec4>& gpu,
                             const std::function<glm::dvec4(const glm::dvec4&)>& cpu, double relativeFloor) {
    return compare(inputs, gpu, cpu, relativeFloor);
}

}  // namespace tyndall::gpu
