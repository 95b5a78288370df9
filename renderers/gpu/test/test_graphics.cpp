#include "gpu_test.h"

#include "test_paths.h"
#include "tyndall/gpu/graphics.h"
#include "tyndall/gpu/hot_reload.h"
#include "tyndall/gpu/slicer.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

namespace tyndall::gpu::test {
namespace {

using Rgba = std::array<float, 4>;
constexpr std::uint32_t kSize = 16;  // targets are kSize x kSize: pixel centres at NDC odd multiples of 1/16

// A triangle for triangles.vert.glsl: three vec4.
struct Triangle {
    float ax, ay, bx, by, cx, cy, depth, unused;
    Rgba colour;
};
static_assert(sizeof(Triangle) == 48, "three vec4 per triangle");

Triangle fullScreen(const Rgba& colour, float depth = 0.5f) {
    return {-1.0f, -1.0f, 3.0f, -1.0f, -1.0f, 3.0f, depth, 0.0f, colour};
}

// A pixel centre's NDC coordinate.
float ndc(std::uint32_t pixel) { return (2.0f * float(pixel) + 1.0f) / float(kSize) - 1.0f; }

class GraphicsTest : public GpuTest {
protected:
    GraphicsPipelineDesc trianglesDesc(const std::string& fragment, std::vector<ColourAttachment> colour) {
        GraphicsPipelineDesc desc;
        desc.name = "test " + fragment;
        desc.vertex = loadSpirv("triangles.vert");
        desc.fragment = loadSpirv(fragment + ".frag");
        desc.colour = std::move(colour);
        desc.bindingCount = 1;
        return desc;
    }

    // One pass into `target` (layer 0): draws the triangles one per draw call, after a clear to `clear`.
    void drawEach(GraphicsPipeline& pipeline, RenderTarget& target, const Rgba& clear,
                  const std::vector<Triangle>& triangles) {
        auto buffer = uploadBuffer(context(), triangles);
        context().submitAndWait([&](VkCommandBuffer cmd) {
            PassDesc pass;
            pass.colour = {{&target, 0}};
            pass.clearColours = {clear};
            pipeline.beginPass(cmd, pass);
            for (std::uint32_t i = 0; i < triangles.size(); ++i)
                pipeline.draw(cmd, {buffer.get()}, nullptr, 3, 1, 3 * i);
            pipeline.endPass(cmd);
        });
        pipeline.resetDescriptors();
    }
};

// Every texel of an RGBA readback: `inside(x, y)` decides between two colours.
void expectTexels(const std::vector<float>& texels, const std::function<bool(std::uint32_t, std::uint32_t)>& inside,
                  const Rgba& in, const Rgba& out) {
    ASSERT_EQ(texels.size(), std::size_t(kSize) * kSize * 4);
    for (std::uint32_t y = 0; y < kSize; ++y)
        for (std::uint32_t x = 0; x < kSize; ++x)
            for (int c = 0; c < 4; ++c) {
                const float expected = inside(x, y) ? in[c] : out[c];
                ASSERT_EQ(texels[(y * kSize + x) * 4 + c], expected) << "pixel " << x << ", " << y << " channel " << c;
            }
}

TEST_F(GraphicsTest, TriangleCoversItsPixelsAndNdcYMinusOneIsRowZero) {
    RenderTarget target(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
    GraphicsPipeline pipeline(context(), trianglesDesc("flat_colour", {{VK_FORMAT_R32G32B32A32_SFLOAT}}));
    const Rgba colour{0.25f, 2.0f, -3.0f, 1.0f}, clear{7.0f, 8.0f, 9.0f, 10.0f};
    // Corners (-1, -1), (1, -1), (-1, 0): a wedge along NDC y = -1, no pixel centre on its slanted edge.
    drawEach(pipeline, target, clear, {{-1.0f, -1.0f, 1.0f, -1.0f, -1.0f, 0.0f, 0.5f, 0.0f, colour}});
    const std::vector<float> texels = target.readback();
    expectTexels(texels, [](std::uint32_t x, std::uint32_t y) { return ndc(y) < -1.0f + 0.5f * (1.0f - ndc(x)); },
                 colour, clear);
    EXPECT_EQ(texels[0], colour[0]) << "row 0 is NDC y = -1";
    EXPECT_EQ(texels[(kSize - 1) * kSize * 4], clear[0]) << "the last row is NDC y = +1";
}

TEST_F(GraphicsTest, PremultipliedUnderBlendingComposesDrawsInOrder) {
    RenderTarget target(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
    GraphicsPipeline pipeline(
        context(), trianglesDesc("flat_colour", {{VK_FORMAT_R32G32B32A32_SFLOAT, Blend::premultipliedUnder()}}));
    // Dyadic values: every product and sum below is exact in float, so the blend unit must match bit for bit.
    const Rgba clear{0.5f, 0.25f, 1.0f, 1.0f};
    const Rgba c1{0.25f, 0.5f, 0.125f, 0.5f}, c2{0.125f, 0.25f, 0.5f, 0.75f}, c3{1.0f, 0.5f, 0.25f, 0.25f};
    drawEach(pipeline, target, clear, {fullScreen(c1), fullScreen(c2), fullScreen(c3)});
    Rgba expected{};
    for (int c = 0; c < 3; ++c) expected[c] = c3[c] + c3[3] * (c2[c] + c2[3] * (c1[c] + c1[3] * clear[c]));
    expected[3] = c3[3] * c2[3] * c1[3] * clear[3];
    expectTexels(target.readback(), [](std::uint32_t, std::uint32_t) { return true; }, expected, expected);
}

// ISV's coloured shadows: each channel is attenuated by its own factor, the fragment's second output.
TEST_F(GraphicsTest, DualSourceBlendingAttenuatesEachChannelByTheSecondOutput) {
    if (!context().device().dualSrcBlend) GTEST_SKIP() << "the device has no dualSrcBlend";
    RenderTarget target(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
    GraphicsPipeline pipeline(context(), trianglesDesc("dual_source", {{VK_FORMAT_R32G32B32A32_SFLOAT,
                                                                         Blend::premultipliedUnderPerChannel()}}));
    // Dyadic values again; the second output is (a, a / 2, depth, a) per draw.
    const Rgba clear{0.5f, 0.25f, 1.0f, 1.0f};
    const Rgba c1{0.25f, 0.5f, 0.125f, 0.5f}, c2{0.125f, 0.25f, 0.5f, 0.75f};
    const float d1 = 0.25f, d2 = 0.125f;
    drawEach(pipeline, target, clear, {fullScreen(c1, d1), fullScreen(c2, d2)});
    auto factor = [](const Rgba& c, float depth, int channel) {
        return channel == 0 ? c[3] : channel == 1 ? 0.5f * c[3] : channel == 2 ? depth : c[3];
    };
    Rgba expected{};
    for (int c = 0; c < 3; ++c)
        expected[c] = c2[c] + factor(c2, d2, c) * (c1[c] + factor(c1, d1, c) * clear[c]);
    expected[3] = c2[3] * c1[3] * clear[3];
    expectTexels(target.readback(), [](std::uint32_t, std::uint32_t) { return true; }, expected, expected);
}

// A mesh pipeline draws what the vertex pipeline draws where the device has VK_EXT_mesh_shader, and is refused with
// that reason where it has not (lavapipe).
TEST_F(GraphicsTest, MeshShaderPipelineDrawsOrIsRefusedWithTheReason) {
    GraphicsPipelineDesc desc;
    desc.name = "test triangle.mesh";
    desc.mesh = loadSpirv("triangle.mesh");
    desc.fragment = loadSpirv("flat_colour.frag");
    desc.colour = {{VK_FORMAT_R32G32B32A32_SFLOAT}};
    desc.bindingCount = 1;
    if (!context().device().meshShader) {
        try {
            GraphicsPipeline pipeline(context(), desc);
            ADD_FAILURE() << "a mesh pipeline needs mesh shaders";
        } catch (const GpuError& e) {
            EXPECT_NE(std::string(e.what()).find("VK_EXT_mesh_shader"), std::string::npos) << e.what();
        }
        return;
    }
    RenderTarget target(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
    GraphicsPipeline pipeline(context(), desc);
    ASSERT_TRUE(pipeline.usesMeshShader());
    const Rgba colour{0.25f, 2.0f, -3.0f, 1.0f}, clear{7.0f, 8.0f, 9.0f, 10.0f};
    auto buffer = uploadBuffer(context(), std::vector<Triangle>{
                                              {-1.0f, -1.0f, 1.0f, -1.0f, -1.0f, 0.0f, 0.5f, 0.0f, colour}});
    context().submitAndWait([&](VkCommandBuffer cmd) {
        PassDesc pass;
        pass.colour = {{&target, 0}};
        pass.clearColours = {clear};
        pipeline.beginPass(cmd, pass);
        pipeline.drawMeshTasks(cmd, {buffer.get()}, nullptr, 1);
        pipeline.endPass(cmd);
    });
    expectTexels(target.readback(), [](std::uint32_t x, std::uint32_t y) { return ndc(y) < -1.0f + 0.5f * (1.0f - ndc(x)); },
                 colour, clear);
}

TEST_F(GraphicsTest, AdditiveBlendingIntoASingleChannelTarget) {
    RenderTarget target(context(), kSize, kSize, VK_FORMAT_R32_SFLOAT);
    GraphicsPipeline pipeline(context(), trianglesDesc("flat_colour", {{VK_FORMAT_R32_SFLOAT, Blend::additive()}}));
    drawEach(pipeline, target, {2.0f, 0.0f, 0.0f, 0.0f},
             {fullScreen({0.25f, 9.0f, 9.0f, 9.0f}), fullScreen({0.5f, 9.0f, 9.0f, 9.0f}),
              fullScreen({1.0f, 9.0f, 9.0f, 9.0f})});
    const std::vector<float> texels = target.readback();
    ASSERT_EQ(texels.size(), std::size_t(kSize) * kSize);
    for (float value : texels) ASSERT_EQ(value, 3.75f);
}

TEST_F(GraphicsTest, FragmentDepthDecidesWhichDrawWinsWhateverTheOrder) {
    GraphicsPipelineDesc desc = trianglesDesc("frag_depth", {{VK_FORMAT_R32G32B32A32_SFLOAT}});
    desc.depth = DepthAttachment{};  // D32, test and write, LESS
    GraphicsPipeline pipeline(context(), desc);
    const Rgba nearColour{1.0f, 0.0f, 0.0f, 1.0f}, farColour{0.0f, 1.0f, 0.0f, 1.0f};
    const std::vector<Triangle> nearFirst = {fullScreen(nearColour, 0.25f), fullScreen(farColour, 0.75f)};
    const std::vector<Triangle> farFirst = {nearFirst[1], nearFirst[0]};
    for (const std::vector<Triangle>* order : {&nearFirst, &farFirst}) {
        RenderTarget colour(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
        RenderTarget depth(context(), kSize, kSize, VK_FORMAT_D32_SFLOAT);
        auto buffer = uploadBuffer(context(), *order);
        context().submitAndWait([&](VkCommandBuffer cmd) {
            PassDesc pass;
            pass.colour = {{&colour, 0}};
            pass.depth = AttachmentRef{&depth, 0};
            pipeline.beginPass(cmd, pass);
            pipeline.draw(cmd, {buffer.get()}, nullptr, 6);
            pipeline.endPass(cmd);
        });
        pipeline.resetDescriptors();
        expectTexels(colour.readback(), [](std::uint32_t, std::uint32_t) { return true; }, nearColour, nearColour);
        for (float value : depth.readback()) ASSERT_EQ(value, 0.25f);
    }
}

TEST_F(GraphicsTest, GeometryShaderTurnsPointsIntoSquares) {
    if (!context().device().geometryShader) GTEST_SKIP() << "the device has no geometry shaders";
    RenderTarget target(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
    GraphicsPipelineDesc desc;
    desc.name = "test squares";
    desc.vertex = loadSpirv("points.vert");
    desc.geometry = loadSpirv("squares.geom");
    desc.fragment = loadSpirv("flat_colour.frag");
    desc.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
    desc.colour = {{VK_FORMAT_R32G32B32A32_SFLOAT}};
    desc.bindingCount = 1;
    desc.pushConstantBytes = 16;
    GraphicsPipeline pipeline(context(), desc);
    // (centre, half size) in multiples of 1/8, so that no edge passes through a pixel centre.
    const std::vector<Rgba> points = {{-0.5f, -0.5f, 0.25f, 0.0f}, {0.5f, 0.25f, 0.125f, 0.0f},
                                      {0.25f, -0.75f, 0.125f, 0.0f}};
    auto buffer = uploadBuffer(context(), points);
    const Rgba colour{0.5f, 0.75f, 1.0f, 1.0f}, clear{0.0f, 0.0f, 0.0f, 0.0f};
    context().submitAndWait([&](VkCommandBuffer cmd) {
        PassDesc pass;
        pass.colour = {{&target, 0}};
        pipeline.beginPass(cmd, pass);
        pipeline.draw(cmd, {buffer.get()}, &colour, std::uint32_t(points.size()));
        pipeline.endPass(cmd);
    });
    pipeline.resetDescriptors();
    expectTexels(target.readback(),
                 [&](std::uint32_t x, std::uint32_t y) {
                     for (const Rgba& p : points)
                         if (std::abs(ndc(x) - p[0]) < p[2] && std::abs(ndc(y) - p[1]) < p[2]) return true;
                     return false;
                 },
                 colour, clear);
}

TEST_F(GraphicsTest, DrawingIntoOneLayerLeavesTheOthersAndCopiesLayerAfterLayer) {
    constexpr std::uint32_t kLayers = 4, kDrawn = 2;
    RenderTarget target(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT, kLayers);
    GraphicsPipeline pipeline(context(), trianglesDesc("flat_colour", {{VK_FORMAT_R32G32B32A32_SFLOAT}}));
    auto clearOf = [](std::uint32_t layer) { return Rgba{float(layer), float(layer) + 0.5f, -float(layer), 1.0f}; };
    const Rgba colour{9.0f, 8.0f, 7.0f, 6.0f};
    const std::vector<Triangle> wedge = {{-1.0f, -1.0f, 1.0f, -1.0f, -1.0f, 0.0f, 0.5f, 0.0f, colour}};
    auto inWedge = [](std::uint32_t x, std::uint32_t y) { return ndc(y) < -1.0f + 0.5f * (1.0f - ndc(x)); };
    auto triangles = uploadBuffer(context(), wedge);
    Buffer copy(context(), kLayers * target.layerBytes());
    context().submitAndWait([&](VkCommandBuffer cmd) {
        for (std::uint32_t layer = 0; layer < kLayers; ++layer) {  // a clear pass per layer, each its own value
            PassDesc pass;
            pass.colour = {{&target, layer}};
            pass.clearColours = {clearOf(layer)};
            pipeline.beginPass(cmd, pass);
            pipeline.endPass(cmd);
        }
        PassDesc pass;
        pass.colour = {{&target, kDrawn}};
        pass.load = LoadOp::Load;
        pipeline.beginPass(cmd, pass);
        pipeline.draw(cmd, {triangles.get()}, nullptr, 3);
        pipeline.endPass(cmd);
        target.recordCopyAll(cmd, copy);
    });
    pipeline.resetDescriptors();
    const std::vector<float> all = copy.download<float>(kLayers * kSize * kSize * 4);
    for (std::uint32_t layer = 0; layer < kLayers; ++layer) {
        SCOPED_TRACE("layer " + std::to_string(layer));
        const std::vector<float> texels(all.begin() + layer * kSize * kSize * 4,
                                        all.begin() + (layer + 1) * kSize * kSize * 4);
        if (layer == kDrawn) expectTexels(texels, inWedge, colour, clearOf(layer));
        else expectTexels(texels, [](std::uint32_t, std::uint32_t) { return false; }, colour, clearOf(layer));
        EXPECT_EQ(texels, target.readback(layer)) << "the copy of all layers and readback agree";
    }
}

TEST_F(GraphicsTest, DrawsReadWhatAComputeKernelWroteBeforeTheBarrier) {
    // add_one.comp writes the triangle (every float + 0.5, all exact) that the draw in the same command buffer reads.
    const Rgba colour{0.25f, 0.5f, 0.75f, 1.0f};
    const Triangle triangle = fullScreen(colour);
    std::vector<float> input(sizeof(Triangle) / 4);
    std::memcpy(input.data(), &triangle, sizeof(Triangle));
    for (float& value : input) value -= 0.5f;
    auto inputBuffer = uploadBuffer(context(), input);
    Buffer triangles(context(), sizeof(Triangle));
    struct {
        std::uint32_t count, offset;
        float value;
    } push{std::uint32_t(input.size()), 0, 0.5f};
    ComputeKernel kernel(context(), loadSpirv("add_one"), 2, 12, "add_one");
    GraphicsPipeline pipeline(context(), trianglesDesc("flat_colour", {{VK_FORMAT_R32G32B32A32_SFLOAT}}));
    RenderTarget target(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
    context().submitAndWait([&](VkCommandBuffer cmd) {
        kernel.record(cmd, {inputBuffer.get(), &triangles}, &push, 1);
        computeToGraphicsBarrier(cmd);
        PassDesc pass;
        pass.colour = {{&target, 0}};
        pipeline.beginPass(cmd, pass);
        pipeline.draw(cmd, {&triangles}, nullptr, 3);
        pipeline.endPass(cmd);
    });
    kernel.resetDescriptors();
    pipeline.resetDescriptors();
    expectTexels(target.readback(), [](std::uint32_t, std::uint32_t) { return true; }, colour, colour);
}

TEST_F(GraphicsTest, SlicedDrawEqualsOneDrawBitForBit) {
    // Overlapping triangles blended "under": the result depends on their order and on every rounding, so equality
    // says that slices drew the same primitives in the same order.
    constexpr std::uint32_t kTriangles = 4000;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> position(-1.2f, 1.2f), value(0.0f, 1.0f), alpha(0.5f, 1.0f);
    std::vector<Triangle> triangles(kTriangles);
    for (Triangle& t : triangles)
        t = {position(rng), position(rng), position(rng), position(rng), position(rng), position(rng), 0.5f, 0.0f,
             {value(rng), value(rng), value(rng), alpha(rng)}};
    auto buffer = uploadBuffer(context(), triangles);
    GraphicsPipeline pipeline(
        context(), trianglesDesc("flat_colour", {{VK_FORMAT_R32G32B32A32_SFLOAT, Blend::premultipliedUnder()}}));
    const Rgba clear{0.1f, 0.2f, 0.3f, 1.0f};

    RenderTarget whole(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
    context().submitAndWait([&](VkCommandBuffer cmd) {
        PassDesc pass;
        pass.colour = {{&whole, 0}};
        pass.clearColours = {clear};
        pipeline.beginPass(cmd, pass);
        pipeline.draw(cmd, {buffer.get()}, nullptr, 3 * kTriangles);
        pipeline.endPass(cmd);
    });

    RenderTarget sliced(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
    context().submitAndWait([&](VkCommandBuffer cmd) { sliced.recordClear(cmd, clear); });
    // Work items are triangles; each slice is a pass that loads what the previous slices drew.
    const SliceStats stats = runSliced(context(), kTriangles, [&](VkCommandBuffer cmd, uint64_t begin, uint64_t count) {
        PassDesc pass;
        pass.colour = {{&sliced, 0}};
        pass.load = LoadOp::Load;
        pipeline.beginPass(cmd, pass);
        pipeline.draw(cmd, {buffer.get()}, nullptr, std::uint32_t(3 * count), 1, std::uint32_t(3 * begin));
        pipeline.endPass(cmd);
    });
    pipeline.resetDescriptors();
    EXPECT_GT(stats.slices, 1);
    const std::vector<float> a = whole.readback(), b = sliced.readback();
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);
    EXPECT_NE(a[0], clear[0]) << "the triangles cover the target";
}

TEST_F(GraphicsTest, PipelineRebuildsFromAReloadedStage) {
    const std::filesystem::path dir = std::filesystem::path(tyndall::test::scratchDir()) / "graphics_hot_reload";
    std::filesystem::create_directories(dir);
    const std::filesystem::path shader = dir / "constant.frag.glsl";
    auto write = [&](const char* value) {
        std::ofstream(shader) << "#version 460\nlayout(location = 0) out vec4 result;\nvoid main() { result = vec4("
                              << value << "); }\n";
    };
    write("0.25");
    HotShader fragment(shader);
    ASSERT_TRUE(fragment.hasSpirv()) << fragment.log();
    RenderTarget target(context(), kSize, kSize, VK_FORMAT_R32G32B32A32_SFLOAT);
    auto render = [&] {
        GraphicsPipelineDesc desc = trianglesDesc("flat_colour", {{VK_FORMAT_R32G32B32A32_SFLOAT}});
        desc.fragment = fragment.spirv();
        GraphicsPipeline pipeline(context(), desc);
        drawEach(pipeline, target, {0.0f, 0.0f, 0.0f, 0.0f}, {fullScreen({0.0f, 0.0f, 0.0f, 0.0f})});
        return target.readback()[0];
    };
    EXPECT_EQ(render(), 0.25f);
    write("0.75");
    // Make sure the change is seen even where file times are coarse.
    std::filesystem::last_write_time(shader, std::filesystem::last_write_time(shader) + std::chrono::seconds(2));
    ASSERT_EQ(fragment.poll(), HotShader::PollResult::Reloaded) << fragment.log();
    EXPECT_EQ(render(), 0.75f);
}

}  // namespace
}  // namespace tyndall::gpu::test
