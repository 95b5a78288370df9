// GPU framework benchmarks (lavapipe here):
//   build/renderers/bench/tyndall_gpu_bench
// - the overhead of an empty full-screen compute pass (one invocation per pixel writing one value) at 512x512 and
//   1920x1080: wall time of submit + wait, and GPU time from timestamps;
// - shadow rays per second through the shared BVH traversal on the GPU against Embree's rtcOccluded1 on the CPU, on the
//   same rays (target >= 10 % of Embree's rate, stretch 25 %);
// - e^z E_n(z) of shared/expint.h (Pegoraro's closed form) per invocation, in float and double: order n alone
//   (orders:0), orders 1..n through expintEnScaledAll's array (orders:1) or streamed from the recurrence pivot without
//   an array (orders:2); GPU time per invocation (the CPU side is in expint_bench.cpp).
#include "tyndall/core/geometry.h"
#include "tyndall/core/resources.h"
#include "tyndall/gpu/bvh.h"
#include "tyndall/gpu/harness.h"
#include "tyndall/gpu/resources.h"
#include "tyndall/gpu/shader_compiler.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"

#include <benchmark/benchmark.h>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace tyndall::gpu;

Context& context() {
    static Context c(ContextOptions{"", 0});
    return c;
}

void BM_EmptyComputePass(benchmark::State& state) {
    const uint32_t width = uint32_t(state.range(0)), height = uint32_t(state.range(1));
    static const std::string source =
        "#version 460\n"
        "layout(local_size_x = 8, local_size_y = 8) in;\n"
        "layout(std430, set = 0, binding = 0) writeonly buffer Image { float pixels[]; };\n"
        "layout(push_constant) uniform Push { uint width; uint height; } push;\n"
        "void main() {\n"
        "    uvec2 p = gl_GlobalInvocationID.xy;\n"
        "    if (p.x < push.width && p.y < push.height) pixels[p.y * push.width + p.x] = 0.0f;\n"
        "}\n";
    CompileResult compiled = compileGlslSource(source, "empty.comp.glsl", ShaderStage::Compute);
    if (!compiled.ok) {
        state.SkipWithError(compiled.log.c_str());
        return;
    }
    Buffer image(context(), VkDeviceSize(width) * height * 4);
    ComputeKernel kernel(context(), compiled.spirv, 1, 8, "empty");
    uint32_t push[2] = {width, height};
    double gpuMs = 0.0;
    for (auto _ : state) {
        gpuMs += context().submitTimed(
            [&](VkCommandBuffer cmd) { kernel.record(cmd, {&image}, push, (width + 7) / 8, (height + 7) / 8); });
        kernel.resetDescriptors();
    }
    state.counters["gpu_ms"] = gpuMs / double(state.iterations());
}
BENCHMARK(BM_EmptyComputePass)->Args({512, 512})->Args({1920, 1080})->Unit(benchmark::kMillisecond);

// Shadow rays between random points in the default project's room (the same rays for both sides).
struct ShadowRays {
    tyndall::gpu::Bvh bvh;
    std::vector<tyndall::TriangleMesh> meshes;
    std::vector<glm::vec4> rays;  // (origin, tMax), (dir, 0)
    static constexpr uint32_t kCount = 1u << 18;
};

const ShadowRays& shadowRays() {
    static ShadowRays r = [] {
        ShadowRays out;
        const std::string dir = (tyndall::resourceRoot() / "projects").string();
        tyndall::Project project = tyndall::loadProject(tyndall::techniqueCatalogue(), dir + "/default.json");
        for (const tyndall::Mesh& mesh : project.scene.meshes) out.meshes.push_back(tyndall::buildMesh(mesh, dir));
        out.bvh = tyndall::gpu::buildBvh(out.meshes);
        std::mt19937 rng(5);
        std::uniform_real_distribution<float> x(-1.9f, 1.9f), y(0.05f, 2.9f);
        for (uint32_t i = 0; i < ShadowRays::kCount; ++i) {
            glm::vec3 a(x(rng), y(rng), x(rng)), b(x(rng), y(rng), x(rng));
            float len = glm::length(b - a);
            out.rays.push_back(glm::vec4(a, len));
            out.rays.push_back(glm::vec4((b - a) / len, 0.0f));
        }
        return out;
    }();
    return r;
}

void BM_GpuBvhShadowRays(benchmark::State& state) {
    const ShadowRays& r = shadowRays();
    static const std::string source =
        "#version 460\n"
        "#extension GL_GOOGLE_include_directive : require\n"
        "#include \"shared/bvh.h\"\n"
        "layout(local_size_x = 64) in;\n"
        "layout(std430, set = 0, binding = 0) readonly buffer BvhNodes { dvec4 bvhNodes[]; };\n"
        "layout(std430, set = 0, binding = 1) readonly buffer BvhTriangles { dvec2 bvhTriangles[]; };\n"
        "layout(std430, set = 0, binding = 2) readonly buffer Rays { vec4 rays[]; };\n"
        "layout(std430, set = 0, binding = 3) writeonly buffer Occluded { uint occluded[]; };\n"
        "layout(push_constant) uniform Push { uint count; } push;\n"
        // 64-bit words, the cheaper loads on lavapipe (see the top of shared/bvh.h).
        "uvec4 bvhWords(dvec2 w) { return uvec4(unpackDouble2x32(w.x), unpackDouble2x32(w.y)); }\n"
        "BvhNode bvhNode(int i) { dvec4 w = bvhNodes[i]; return bvhNodeFromWords(bvhWords(w.xy), bvhWords(w.zw)); }\n"
        "BvhTriangle bvhTriangle(int i) {\n"
        "    return bvhTriangleFromWords(bvhWords(bvhTriangles[3 * i]), bvhWords(bvhTriangles[3 * i + 1]),\n"
        "                                bvhWords(bvhTriangles[3 * i + 2]));\n"
        "}\n"
        "void main() {\n"
        "    uint i = gl_GlobalInvocationID.x;\n"
        "    if (i >= push.count) return;\n"
        "    vec4 o = rays[2 * i], d = rays[2 * i + 1];\n"
        "    occluded[i] = bvhOccluded(o.xyz, d.xyz, 0.0f, o.w * 0.99999f) ? 1u : 0u;\n"
        "}\n";
    if (!context().device().shaderFloat64) {
        state.SkipWithError("the device has no float64");
        return;
    }
    CompileResult compiled = compileGlslSource(source, "shadow.comp.glsl", ShaderStage::Compute);
    if (!compiled.ok) {
        state.SkipWithError(compiled.log.c_str());
        return;
    }
    Buffer nodes(context(), r.bvh.nodes.size() * sizeof(tyndall::shader::BvhNode));
    Buffer triangles(context(), r.bvh.triangles.size() * sizeof(tyndall::shader::BvhTriangle));
    Buffer rays(context(), r.rays.size() * sizeof(glm::vec4)), flags(context(), ShadowRays::kCount * 4);
    nodes.upload(r.bvh.nodes);
    triangles.upload(r.bvh.triangles);
    rays.upload(r.rays);
    ComputeKernel kernel(context(), compiled.spirv, 4, 4, "shadow");
    const uint32_t n = ShadowRays::kCount;
    for (auto _ : state) {
        context().submitAndWait(
            [&](VkCommandBuffer cmd) { kernel.record(cmd, {&nodes, &triangles, &rays, &flags}, &n, n / 64); });
        kernel.resetDescriptors();
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * n);
}
BENCHMARK(BM_GpuBvhShadowRays)->Unit(benchmark::kMillisecond)->UseRealTime();

// Embree's rtcOccluded1 on the same rays: on one core (range 0 = 1) and on every core of the machine (0), which is
// what the GPU BVH's target compares against (lavapipe uses every core too).
void BM_EmbreeShadowRays(benchmark::State& state) {
    const ShadowRays& r = shadowRays();
    RTCDevice device = rtcNewDevice(nullptr);
    RTCScene scene = rtcNewScene(device);
    for (unsigned m = 0; m < r.meshes.size(); ++m) {
        const tyndall::TriangleMesh& mesh = r.meshes[m];
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        std::memcpy(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, mesh.positions.size()),
                    mesh.positions.data(), mesh.positions.size() * 12);
        std::memcpy(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, mesh.triangles.size()),
                    mesh.triangles.data(), mesh.triangles.size() * 12);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene);
    auto trace = [&](uint32_t begin, uint32_t end) {
        size_t blocked = 0;
        for (uint32_t i = begin; i < end; ++i) {
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            RTCRay ray{};
            glm::vec4 o = r.rays[2 * i], d = r.rays[2 * i + 1];
            ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
            ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
            ray.tnear = 0.0f;
            ray.tfar = o.w * 0.99999f;
            ray.mask = 0xffffffffu;
            rtcOccluded1(scene, &context, &ray);
            blocked += ray.tfar < 0.0f;
        }
        return blocked;
    };
    const int threads = int(state.range(0));
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    std::atomic<size_t> blocked{0};
    for (auto _ : state) {
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<uint32_t>(0, ShadowRays::kCount, 4096),
                              [&](const tbb::blocked_range<uint32_t>& range) {
                                  blocked += trace(range.begin(), range.end());
                              });
        });
    }
    benchmark::DoNotOptimize(blocked.load());
    state.SetItemsProcessed(int64_t(state.iterations()) * ShadowRays::kCount);
    state.SetLabel(threads == 1 ? "one core" : "every core");
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
}
BENCHMARK(BM_EmbreeShadowRays)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

// Compiles a kernel; when it does not compile, or needs float64 the device lacks, skips the benchmark and returns no
// code.
std::vector<uint32_t> compileOrSkip(benchmark::State& state, const std::string& source, const char* name,
                                    bool needsFloat64) {
    if (needsFloat64 && !context().device().shaderFloat64) {
        state.SkipWithError("the device has no float64");
        return {};
    }
    CompileResult compiled = compileGlslSource(source, name, ShaderStage::Compute);
    if (!compiled.ok) state.SkipWithError(compiled.log.c_str());
    return compiled.ok ? compiled.spirv : std::vector<uint32_t>();
}

// The body of the kernel below: order n alone (mode 0), orders 1..n through expintEnScaledAll's array (mode 1) or
// streamed from the recurrence pivot without an array (mode 2).
const char* expintBody(int mode) {
    if (mode == 1)
        return "    ORDERS orders;\n"
               "    expintEnScaledAll(push.n, t, orders);\n"
               "    REAL2 sum = REAL2(0);\n"
               "    for (int j = 0; j < push.n; ++j) sum += orders.value[j];\n"
               "    values[i] = vec2(sum);\n";
    if (mode == 2)
        return "    int m = expintRecurrencePivot(push.n, t);\n"
               "    REAL2 pivot = expintEnScaled(m, t);\n"
               "    REAL2 sum = pivot, g = pivot;\n"
               "    for (int j = m - 1; j >= 1; --j) { g = expintEnScaledDown(j, t, g); sum += g; }\n"
               "    g = pivot;\n"
               "    for (int j = m; j < push.n; ++j) { g = expintEnScaledUp(j, t, g); sum += g; }\n"
               "    values[i] = vec2(sum);\n";
    return "    values[i] = vec2(expintEnScaled(push.n, t));\n";
}

// Arguments t = H (v - i), H log-uniform in [1e-4, 50], v log-uniform in [1e-4, 1e4], as in expint_bench.cpp.
void BM_GpuExpintEnScaled(benchmark::State& state) {
    const bool isDouble = state.range(0) != 0;
    const int order = int(state.range(1));
    const int mode = int(state.range(2));  // see expintBody
    const uint32_t count = 1u << 18;
    std::string source = std::string("#version 460\n#extension GL_GOOGLE_include_directive : require\n") +
                         (isDouble ? "#define TY_ENABLE_DOUBLE\n#define REAL2 dvec2\n#define ORDERS ExpintOrdersD\n"
                                   : "#define REAL2 vec2\n#define ORDERS ExpintOrders\n") +
                         "#include \"shared/expint.h\"\n"
                         "layout(local_size_x = 64) in;\n"
                         "layout(std430, set = 0, binding = 0) readonly buffer Args { vec2 ts[]; };\n"
                         "layout(std430, set = 0, binding = 1) writeonly buffer Values { vec2 values[]; };\n"
                         "layout(push_constant) uniform Push { uint count; int n; } push;\n"
                         "void main() {\n"
                         "    uint i = gl_GlobalInvocationID.x;\n"
                         "    if (i >= push.count) return;\n"
                         "    REAL2 t = REAL2(ts[i]);\n" +
                         expintBody(mode) + "}\n";
    std::vector<uint32_t> spirv = compileOrSkip(state, source, "expint.comp.glsl", isDouble);
    if (spirv.empty()) return;
    std::vector<glm::vec2> ts(count);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> logH(std::log(1e-4f), std::log(50.0f)), logV(std::log(1e-4f), std::log(1e4f));
    for (glm::vec2& t : ts) {
        float h = std::exp(logH(rng)), v = std::exp(logV(rng));
        t = glm::vec2(h * v, -h);
    }
    Buffer args(context(), count * sizeof(glm::vec2)), values(context(), count * sizeof(glm::vec2));
    args.upload(ts);
    ComputeKernel kernel(context(), spirv, 2, 8, "expint");
    const uint32_t push[2] = {count, uint32_t(order)};
    double gpuMs = 0.0;
    for (auto _ : state) {
        gpuMs += context().submitTimed([&](VkCommandBuffer cmd) {
            kernel.record(cmd, {&args, &values}, push, count / 64);
        });
        kernel.resetDescriptors();
    }
    state.counters["gpu_ns/invocation"] = gpuMs * 1e6 / double(state.iterations()) / double(count);
}
BENCHMARK(BM_GpuExpintEnScaled)
    ->ArgNames({"double", "n", "orders"})
    ->Args({0, 1, 0})
    ->Args({0, 9, 0})
    ->Args({0, 33, 0})
    ->Args({0, 9, 1})
    ->Args({0, 33, 1})
    ->Args({0, 9, 2})
    ->Args({0, 33, 2})
    ->Args({1, 1, 0})
    ->Args({1, 9, 0})
    ->Args({1, 9, 1})
    ->Args({1, 9, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
