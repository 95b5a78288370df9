#include "tyndall/gpu/shader_compiler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "gpu_test.h"
#include "shared/phase.h"
#include "test_paths.h"
#include "tyndall/gpu/hot_reload.h"
#include "tyndall/gpu/resources.h"

namespace fs = std::filesystem;

namespace tyndall::gpu::test {
namespace {

constexpr std::uint32_t kSpirvMagic = 0x07230203;
constexpr std::uint32_t kSpirv15 = 0x00010500;

// A fresh folder per test under TYNDALL_TEST_TMP.
fs::path scratchDir(const std::string& name) {
    fs::path dir = fs::path(tyndall::test::scratchDir()) / "shader_compiler" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

// Writes a file and stamps it `secondsAhead` seconds in the future, so that every edit of a test has a modification
// time distinct from the previous one whatever the file system's timestamp resolution.
void writeFile(const fs::path& path, const std::string& text, int secondsAhead = 0) {
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out << text;
    }
    fs::last_write_time(path, fs::file_time_type::clock::now() + std::chrono::seconds(secondsAhead));
}

bool contains(const std::vector<fs::path>& files, const fs::path& file) {
    return std::find(files.begin(), files.end(), fs::absolute(file).lexically_normal()) != files.end();
}

// A compute kernel out[i] = in[i] * factor + <expression from the header>, for the hot-reload tests.
std::string scaleShader(const std::string& factor, const std::string& extraInclude = "") {
    return "#version 460\n"
           "#extension GL_GOOGLE_include_directive : require\n" +
           extraInclude +
           "layout(local_size_x = 64) in;\n"
           "layout(std430, set = 0, binding = 0) readonly buffer Input { float inputs[]; };\n"
           "layout(std430, set = 0, binding = 1) writeonly buffer Output { float outputs[]; };\n"
           "layout(push_constant) uniform Push { uint count; } push;\n"
           "void main() {\n"
           "    uint i = gl_GlobalInvocationID.x;\n"
           "    if (i < push.count) outputs[i] = inputs[i] * " +
           factor + ";\n}\n";
}

TEST(ShaderCompiler, InfersTheStageFromTheFileName) {
    EXPECT_EQ(stageFromPath("a/blur.comp.glsl"), ShaderStage::Compute);
    EXPECT_EQ(stageFromPath("quad.vert.glsl"), ShaderStage::Vertex);
    EXPECT_EQ(stageFromPath("proxy.geom.glsl"), ShaderStage::Geometry);
    EXPECT_EQ(stageFromPath("quad.frag.glsl"), ShaderStage::Fragment);
    EXPECT_EQ(stageFromPath("proxy.mesh.glsl"), ShaderStage::Mesh);
    EXPECT_EQ(stageFromPath("cull.task.glsl"), ShaderStage::Task);
    EXPECT_EQ(stageFromPath("shared/phase.h"), std::nullopt);
    EXPECT_EQ(stageFromPath("blur.glsl"), std::nullopt);
    EXPECT_EQ(stageFromPath("blur.comp"), std::nullopt);

    CompileResult result = compileGlsl(scratchDir("stage") / "nostage.glsl");
    ASSERT_FALSE(result.ok);
    EXPECT_NE(result.error->message.find("stage"), std::string::npos) << result.error->toString();
}

TEST(ShaderCompiler, CompilesAComputeShaderThatIncludesSharedHeaders) {
    const fs::path shader = fs::path(tyndall::test::sourceDir()) / "shaders/test/phase_eval.comp.glsl";
    CompileResult result = compileGlsl(shader);
    ASSERT_TRUE(result.ok) << result.log;
    EXPECT_FALSE(result.error.has_value());
    ASSERT_GT(result.spirv.size(), 5u);
    EXPECT_EQ(result.spirv[0], kSpirvMagic);
    EXPECT_EQ(result.spirv[1], kSpirv15) << "Vulkan 1.2 targets SPIR-V 1.5";

    const fs::path shared = fs::path(tyndall::test::sourceDir()) / "shaders/shared";
    EXPECT_TRUE(contains(result.dependencies, shader));
    for (const char* header : {"phase.h", "compat.h", "constants.h", "sampling.h"}) {
        EXPECT_TRUE(contains(result.dependencies, shared / header)) << header << " is a dependency";
    }
    EXPECT_TRUE(std::is_sorted(result.dependencies.begin(), result.dependencies.end()));
}

TEST(ShaderCompiler, ASyntaxErrorReportsTheFileAndLine) {
    const std::string source =
        "#version 460\n"
        "layout(local_size_x = 1) in;\n"
        "void main() {\n"
        "    float x = 1.0f;\n"
        "    x = x + ;\n"  // line 5
        "}\n";
    CompileResult inMemory = compileGlslSource(source, "inline/broken.comp.glsl", ShaderStage::Compute);
    ASSERT_FALSE(inMemory.ok);
    EXPECT_TRUE(inMemory.spirv.empty());
    ASSERT_TRUE(inMemory.error.has_value()) << inMemory.log;
    EXPECT_EQ(inMemory.error->file, "inline/broken.comp.glsl");
    EXPECT_EQ(inMemory.error->line, 5);
    EXPECT_FALSE(inMemory.error->message.empty());

    const fs::path file = scratchDir("syntax") / "broken.comp.glsl";
    writeFile(file, source);
    CompileResult fromFile = compileGlsl(file);
    ASSERT_FALSE(fromFile.ok);
    EXPECT_EQ(fromFile.error->file, file.string());
    EXPECT_EQ(fromFile.error->line, 5);
    EXPECT_EQ(fromFile.error->toString().rfind(file.string() + ":5: ", 0), 0u) << fromFile.error->toString();

    try {
        compileGlslOrThrow(file);
        FAIL() << "compileGlslOrThrow must throw on a compile error";
    } catch (const ShaderError& e) {
        EXPECT_EQ(e.file(), file.string());
        EXPECT_EQ(e.line(), 5);
        EXPECT_NE(std::string(e.what()).find(":5:"), std::string::npos);
    }
}

TEST(ShaderCompiler, AnErrorInAnIncludedHeaderReportsTheHeader) {
    const fs::path dir = scratchDir("header_error");
    fs::create_directories(dir / "lib");
    // Reached through a relative include and then a nested relative include from the header's own folder.
    writeFile(dir / "lib/outer.h", "#include \"inner.h\"\n");
    writeFile(dir / "lib/inner.h",
              "float good(float x) { return x; }\n"
              "\n"
              "float bad(float x) { return undeclaredThing * x; }\n");  // line 3
    writeFile(dir / "main.comp.glsl",
              "#version 460\n"
              "#extension GL_GOOGLE_include_directive : require\n"
              "#include \"lib/outer.h\"\n"
              "layout(local_size_x = 1) in;\n"
              "void main() {}\n");
    CompileResult result = compileGlsl(dir / "main.comp.glsl");
    ASSERT_FALSE(result.ok);
    ASSERT_TRUE(result.error.has_value()) << result.log;
    EXPECT_EQ(fs::path(result.error->file), (dir / "lib/inner.h").lexically_normal()) << result.error->toString();
    EXPECT_EQ(result.error->line, 3);
    EXPECT_NE(result.error->message.find("undeclaredThing"), std::string::npos) << result.error->message;
    EXPECT_TRUE(contains(result.dependencies, dir / "lib/outer.h"));
    EXPECT_TRUE(contains(result.dependencies, dir / "lib/inner.h"));
}

TEST(ShaderCompiler, IncludeDirectoriesAreSearchedAfterTheIncludingFolder) {
    const fs::path dir = scratchDir("include_dirs");
    fs::create_directories(dir / "local/shared");
    fs::create_directories(dir / "extra");
    writeFile(dir / "extra/scale.h", "const float kScale = 2.0f;\n");
    // A local shared/constants.h shadows the one in the default include directory.
    writeFile(dir / "local/shared/constants.h", "const float kLocal = 3.0f;\n");
    writeFile(dir / "local/main.comp.glsl",
              "#version 460\n"
              "#extension GL_GOOGLE_include_directive : require\n"
              "#include \"scale.h\"\n"
              "#include \"shared/constants.h\"\n"
              "#include \"shared/compat.h\"\n"
              "layout(local_size_x = 1) in;\n"
              "layout(std430, binding = 0) buffer Out { float v; };\n"
              "void main() { v = kScale * kLocal; }\n");
    CompileResult result =
        compileGlsl(dir / "local/main.comp.glsl", {dir / "extra", fs::path(tyndall::test::sourceDir()) / "shaders"});
    ASSERT_TRUE(result.ok) << result.log;
    EXPECT_TRUE(contains(result.dependencies, dir / "extra/scale.h"));
    EXPECT_TRUE(contains(result.dependencies, dir / "local/shared/constants.h"));
    EXPECT_TRUE(contains(result.dependencies, fs::path(tyndall::test::sourceDir()) / "shaders/shared/compat.h"));
}

TEST(ShaderCompiler, AMissingIncludeIsAnErrorThatNamesIt) {
    const std::string source =
        "#version 460\n"
        "#extension GL_GOOGLE_include_directive : require\n"
        "#include \"shared/no_such_header.h\"\n"  // line 3
        "layout(local_size_x = 1) in;\n"
        "void main() {}\n";
    CompileResult result = compileGlslSource(source, "missing.comp.glsl", ShaderStage::Compute);
    ASSERT_FALSE(result.ok);
    ASSERT_TRUE(result.error.has_value()) << result.log;
    EXPECT_EQ(result.error->file, "missing.comp.glsl");
    EXPECT_EQ(result.error->line, 3);
    EXPECT_NE(result.error->message.find("shared/no_such_header.h"), std::string::npos) << result.error->message;
}

TEST(ShaderCompiler, AMissingFileIsAnError) {
    const fs::path file = scratchDir("missing_file") / "gone.comp.glsl";
    CompileResult result = compileGlsl(file);
    ASSERT_FALSE(result.ok);
    EXPECT_EQ(result.error->file, file.string());
    EXPECT_EQ(result.error->line, 0);
    EXPECT_THROW(compileGlslOrThrow(file), ShaderError);
}

TEST(ShaderCompiler, ParsesTheFirstErrorOfAGlslangLog) {
    const std::string log =
        "WARNING: a.comp.glsl:2: 'x' : something harmless\n"
        "ERROR: /tmp/dir/b.h:12: 'foo' : undeclared identifier\n"
        "ERROR: a.comp.glsl:20: '' : compilation terminated\n"
        "ERROR: 2 compilation errors.  No code generated.\n";
    std::optional<ShaderDiagnostic> error = parseFirstGlslangError(log);
    ASSERT_TRUE(error.has_value());
    EXPECT_EQ(error->file, "/tmp/dir/b.h");
    EXPECT_EQ(error->line, 12);
    EXPECT_EQ(error->message, "'foo' : undeclared identifier");

    error = parseFirstGlslangError("ERROR: Linking compute stage: Missing entry point: Each stage requires one\n");
    ASSERT_TRUE(error.has_value());
    EXPECT_EQ(error->line, 0);
    EXPECT_EQ(parseFirstGlslangError("WARNING: only a warning\n"), std::nullopt);
}

TEST(ShaderCompiler, CompilesFromSeveralThreadsAtOnce) {
    const fs::path shader = fs::path(tyndall::test::sourceDir()) / "shaders/test/phase_eval.comp.glsl";
    const std::vector<std::uint32_t> reference = compileGlsl(shader).spirv;
    ASSERT_FALSE(reference.empty());
    std::vector<std::vector<std::uint32_t>> results(4);
    std::vector<std::thread> threads;
    for (auto& out : results)
        threads.emplace_back([&out, &shader] { out = compileGlsl(shader).spirv; });
    for (auto& thread : threads)
        thread.join();
    for (const auto& spirv : results)
        EXPECT_EQ(spirv, reference);
}

TEST(HotReload, RecompilesWhenTheShaderChanges) {
    const fs::path file = scratchDir("edit") / "scale.comp.glsl";
    writeFile(file, scaleShader("2.0f"));
    HotShader shader(file);
    ASSERT_TRUE(shader.hasSpirv()) << shader.log();
    EXPECT_EQ(shader.generation(), 1u);
    EXPECT_FALSE(shader.error().has_value());
    const std::vector<std::uint32_t> first = shader.spirv();

    EXPECT_EQ(shader.poll(), HotShader::PollResult::Unchanged);
    EXPECT_EQ(shader.generation(), 1u);

    writeFile(file, scaleShader("3.0f"), 1);
    EXPECT_EQ(shader.poll(), HotShader::PollResult::Reloaded);
    EXPECT_EQ(shader.generation(), 2u);
    EXPECT_NE(shader.spirv(), first);
    EXPECT_EQ(shader.poll(), HotShader::PollResult::Unchanged) << "a reload is not repeated without a change";
}

TEST(HotReload, ACompileErrorKeepsTheLastGoodSpirvUntilFixed) {
    const fs::path file = scratchDir("break") / "scale.comp.glsl";
    writeFile(file, scaleShader("2.0f"));
    HotShader shader(file);
    ASSERT_TRUE(shader.hasSpirv()) << shader.log();
    const std::vector<std::uint32_t> good = shader.spirv();

    writeFile(file, scaleShader("2.0f +"), 1);  // the error is on line 9
    EXPECT_EQ(shader.poll(), HotShader::PollResult::Failed);
    ASSERT_TRUE(shader.error().has_value());
    EXPECT_EQ(shader.error()->file, file.string());
    EXPECT_EQ(shader.error()->line, 9) << shader.log();
    EXPECT_EQ(shader.spirv(), good) << "the last good SPIR-V keeps running";
    EXPECT_EQ(shader.generation(), 1u);
    EXPECT_EQ(shader.poll(), HotShader::PollResult::Unchanged) << "a failure is not retried until something changes";

    writeFile(file, scaleShader("4.0f"), 2);
    EXPECT_EQ(shader.poll(), HotShader::PollResult::Reloaded);
    EXPECT_FALSE(shader.error().has_value());
    EXPECT_EQ(shader.generation(), 2u);
    EXPECT_NE(shader.spirv(), good);
}

TEST(HotReload, AChangeInAnIncludedHeaderTriggersAReload) {
    const fs::path dir = scratchDir("header");
    writeFile(dir / "factor.h", "const float kFactor = 2.0f;\n");
    writeFile(dir / "scale.comp.glsl", scaleShader("kFactor", "#include \"factor.h\"\n"));
    HotShader shader(dir / "scale.comp.glsl");
    ASSERT_TRUE(shader.hasSpirv()) << shader.log();
    EXPECT_TRUE(contains(shader.dependencies(), dir / "factor.h"));
    const std::vector<std::uint32_t> first = shader.spirv();

    writeFile(dir / "factor.h", "const float kFactor = 5.0f;\n", 1);
    EXPECT_EQ(shader.poll(), HotShader::PollResult::Reloaded);
    EXPECT_EQ(shader.generation(), 2u);
    EXPECT_NE(shader.spirv(), first);

    // An error in the header is reported at the header's line, and fixing the header recovers.
    writeFile(dir / "factor.h", "\nconst float kFactor = ;\n", 2);
    EXPECT_EQ(shader.poll(), HotShader::PollResult::Failed);
    ASSERT_TRUE(shader.error().has_value());
    EXPECT_EQ(fs::path(shader.error()->file), (dir / "factor.h").lexically_normal());
    EXPECT_EQ(shader.error()->line, 2);
    writeFile(dir / "factor.h", "const float kFactor = 2.0f;\n", 3);
    EXPECT_EQ(shader.poll(), HotShader::PollResult::Reloaded);
    EXPECT_EQ(shader.spirv(), first) << "the same source gives the same SPIR-V";
}

TEST(HotReload, AShaderThatStartsBrokenLoadsOnceFixed) {
    const fs::path file = scratchDir("starts_broken") / "scale.comp.glsl";
    writeFile(file, scaleShader("oops"));
    HotShader shader(file);
    EXPECT_FALSE(shader.hasSpirv());
    EXPECT_EQ(shader.generation(), 0u);
    ASSERT_TRUE(shader.error().has_value());
    EXPECT_EQ(shader.error()->line, 9);
    writeFile(file, scaleShader("1.5f"), 1);
    EXPECT_EQ(shader.poll(), HotShader::PollResult::Reloaded);
    EXPECT_TRUE(shader.hasSpirv());
    EXPECT_EQ(shader.generation(), 1u);
}

// Runs `spirv` (out[i] = in[i] * factor) on the GPU and returns the outputs.
std::vector<float> runScale(Context& context, const std::vector<std::uint32_t>& spirv, const std::vector<float>& in) {
    const auto n = static_cast<std::uint32_t>(in.size());
    Buffer input(context, n * sizeof(float)), output(context, n * sizeof(float));
    input.upload(in);
    ComputeKernel kernel(context, spirv, 2, sizeof(std::uint32_t), "hot_scale");
    context.submitAndWait([&](VkCommandBuffer cmd) { kernel.record(cmd, {&input, &output}, &n, (n + 63) / 64); });
    kernel.resetDescriptors();
    return output.download<float>(n);
}

using HotReloadGpu = GpuTest;

TEST_F(HotReloadGpu, TheReloadedKernelRunsAndTheBrokenOneKeepsTheLastGood) {
    const fs::path file = scratchDir("gpu") / "scale.comp.glsl";
    writeFile(file, scaleShader("2.0f"));
    HotShader shader(file);
    ASSERT_TRUE(shader.hasSpirv()) << shader.log();
    const std::vector<float> in = {0.0f, 1.0f, 2.5f, -4.0f, 100.0f};

    std::vector<float> out = runScale(context(), shader.spirv(), in);
    for (size_t i = 0; i < in.size(); ++i)
        EXPECT_EQ(out[i], in[i] * 2.0f) << i;

    writeFile(file, scaleShader("3.0f"), 1);
    ASSERT_EQ(shader.poll(), HotShader::PollResult::Reloaded);
    out = runScale(context(), shader.spirv(), in);
    for (size_t i = 0; i < in.size(); ++i)
        EXPECT_EQ(out[i], in[i] * 3.0f) << i;

    writeFile(file, scaleShader("3.0f +"), 2);
    ASSERT_EQ(shader.poll(), HotShader::PollResult::Failed);
    out = runScale(context(), shader.spirv(), in);
    for (size_t i = 0; i < in.size(); ++i)
        EXPECT_EQ(out[i], in[i] * 3.0f) << "the last good kernel runs, " << i;
}

TEST_F(HotReloadGpu, TheSharedPhaseFunctionAgreesWithItsCppSide) {
    const std::vector<std::uint32_t> spirv =
        compileGlslOrThrow(fs::path(tyndall::test::sourceDir()) / "shaders/test/phase_eval.comp.glsl");
    std::vector<float> mu;
    for (int i = 0; i <= 200; ++i)
        mu.push_back(-1.0f + 0.01f * static_cast<float>(i));
    const auto n = static_cast<std::uint32_t>(mu.size());
    struct {
        std::uint32_t count;
        float g;
    } push{n, 0.7f};
    Buffer input(context(), n * sizeof(float)), output(context(), n * sizeof(float));
    input.upload(mu);
    ComputeKernel kernel(context(), spirv, 2, sizeof(push), "phase_eval");
    context().submitAndWait([&](VkCommandBuffer cmd) { kernel.record(cmd, {&input, &output}, &push, (n + 63) / 64); });
    kernel.resetDescriptors();
    const std::vector<float> gpu = output.download<float>(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        const float cpu = shader::henyeyGreenstein(mu[i], push.g);
        // A few ulps: the GPU may contract to fma and use a different sqrt rounding.
        EXPECT_NEAR(gpu[i], cpu, 1e-5f * cpu) << "mu = " << mu[i];
    }
}

}  // namespace
}  // namespace tyndall::gpu::test
