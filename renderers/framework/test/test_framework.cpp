// The framework's shared pieces on their own: what every technique relies on without restating it.
#include "shared/accumulation.h"
#include "shared/camera.h"
#include "tyndall/core/error.h"
#include "tyndall/framework/gpu_accumulation.h"
#include "tyndall/framework/kernel_cache.h"
#include "tyndall/framework/progressive.h"
#include "tyndall/framework/renderer_pool.h"
#include "tyndall/framework/row_loop.h"
#include "tyndall/framework/shader_params.h"
#include "tyndall/framework/stage_times.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <random>
#include <thread>
#include <utility>
#include <vector>

namespace tyndall {
namespace {

// ---------------------------------------------------------------------------------------------------------------------
// The camera: cameraPixel inverts cameraRay (the studio draws its markers with it)

TEST(Camera, APointOnThePixelsRayProjectsBackToThePixel) {
    Camera camera;
    camera.position = Vec3(0.2, 1.5, 4.6);
    camera.target = Vec3(0.0, 0.9, 0.0);
    camera.fovY = 40.0;
    camera.width = 320;
    camera.height = 240;
    const shader::CameraParams cam = toCameraParams(camera);
    for (const glm::vec2 pixel : {glm::vec2(0.5f, 0.5f), glm::vec2(160.0f, 120.0f), glm::vec2(319.5f, 17.25f)}) {
        glm::vec3 o, d;
        shader::cameraRay(cam, pixel.x, pixel.y, o, d);
        for (const float t : {0.5f, 3.0f, 40.0f}) {
            float depth = 0.0f;
            const glm::vec2 back = shader::cameraPixel(cam, o + t * d, depth);
            EXPECT_NEAR(back.x, pixel.x, 1e-3f);
            EXPECT_NEAR(back.y, pixel.y, 1e-3f);
            EXPECT_NEAR(depth, t * glm::dot(d, cam.forward), 1e-4f * t);
        }
    }
    float depth = 1.0f;
    shader::cameraPixel(cam, cam.position - cam.forward, depth);
    EXPECT_LT(depth, 0.0f) << "behind the camera";
}

// ---------------------------------------------------------------------------------------------------------------------
// The row loop

TEST(RowLoop, RunsEveryRowOnceAndReportsProgressUpToItsSpan) {
    std::vector<std::atomic<int>> visits(137);
    std::mutex mutex;
    std::vector<double> fractions;
    RenderCallbacks callbacks;
    callbacks.progress = [&](double f) {
        const std::lock_guard lock(mutex);
        fractions.push_back(f);
    };
    RowLoop(137, 2, callbacks, 0.25, 0.75).run([&](int y) { visits[std::size_t(y)].fetch_add(1); });
    for (const auto& v : visits)
        EXPECT_EQ(v.load(), 1);
    ASSERT_FALSE(fractions.empty());
    for (double f : fractions) {
        EXPECT_GE(f, 0.25);
        EXPECT_LE(f, 0.75 + 1e-12);
    }
}

TEST(RowLoop, ThrowsCancelledOnceTheFlagIsSetAndStartsNoFurtherRow) {
    std::atomic<bool> cancel{false};
    std::atomic<int> rows{0};
    EXPECT_THROW(RowLoop(10000, 2, &cancel).run([&](int) {
        if (rows.fetch_add(1) == 10) cancel = true;
    }),
                 Cancelled);
    EXPECT_LT(rows.load(), 10000);
}

// ---------------------------------------------------------------------------------------------------------------------
// The progressive schedule

TEST(Progressive, PassesOf1_1_2_4UntilTheSppWithAnImageAfterEachButTheLast) {
    RenderRequest request;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> passes;
    std::vector<int> intermediates;
    RenderCallbacks callbacks;
    callbacks.intermediate = [&](const Image& image, int spp) {
        EXPECT_EQ(image.width(), 1);
        intermediates.push_back(spp);
    };
    std::uint32_t added = 0;
    const ProgressiveResult result = renderProgressively(
        request, 10, callbacks, std::chrono::steady_clock::now(),
        [&](std::uint32_t first, std::uint32_t end, const RenderCallbacks&) {
            EXPECT_EQ(first, added);  // contiguous, no sample twice
            passes.emplace_back(first, end);
            added = end;
        },
        [&] {
            Image image(1, 1, estimateChannels());
            image.at(0, 0, 0) = float(added);
            return image;
        });
    const std::vector<std::pair<std::uint32_t, std::uint32_t>> expected = {{0, 1}, {1, 2}, {2, 4}, {4, 8}, {8, 10}};
    EXPECT_EQ(passes, expected);
    EXPECT_EQ(intermediates, (std::vector<int>{1, 2, 4, 8}));
    EXPECT_EQ(result.spp, 10);
    EXPECT_EQ(result.image.at(0, 0, 0), 10.0f);  // the last pass's image, resolved after it
}

TEST(Progressive, StopsAtTheTimeLimitWithTheSamplesItHas) {
    RenderRequest request;
    request.timeLimit = 0.15;
    int added = 0;
    const ProgressiveResult result = renderProgressively(
        request, RenderRequest::kUnboundedSpp, {}, std::chrono::steady_clock::now(),
        [&](std::uint32_t first, std::uint32_t end, const RenderCallbacks&) {
            std::this_thread::sleep_for(std::chrono::milliseconds(20) * (end - first));
            added = int(end);
        },
        [] { return Image(1, 1, estimateChannels()); });
    EXPECT_EQ(result.spp, added);
    EXPECT_GE(result.spp, 1);
    EXPECT_LT(result.spp, 64);  // ~7 samples fit in 0.15 s; an unbounded render without the limit never ends
}

TEST(Progressive, CancellationFromAPassPropagates) {
    std::atomic<bool> cancel{false};
    RenderCallbacks callbacks;
    callbacks.cancel = &cancel;
    int resolved = 0;
    EXPECT_THROW(renderProgressively(
                     RenderRequest{}, 100, callbacks, std::chrono::steady_clock::now(),
                     [&](std::uint32_t first, std::uint32_t, const RenderCallbacks& pass) {
                         if (first >= 4) cancel = true;
                         if (pass.cancel && pass.cancel->load()) throw Cancelled();
                     },
                     [&] {
                         ++resolved;
                         return Image(1, 1, estimateChannels());
                     }),
                 Cancelled);
    EXPECT_EQ(resolved, 3);  // after the passes ending at 1, 2 and 4
}

// ---------------------------------------------------------------------------------------------------------------------
// The variance of a pixel's mean from its two halves

// Halves of n samples of a known variance: the mean of (meanA - meanB)^2 / 4 over many pixels is sigma^2 / n, the
// variance of the mean of all n (Eq. in docs/reference.md, "variance channels").
TEST(VarianceOfMean, EstimatesTheVarianceOfThePixelMean) {
    std::mt19937 rng(7);
    std::normal_distribution<double> sample(3.0, 2.0);  // sigma^2 = 4
    const int n = 16, pixels = 20000;
    double sum = 0.0;
    for (int p = 0; p < pixels; ++p) {
        glm::dvec3 a(0.0), b(0.0);
        for (int i = 0; i < n / 2; ++i) {
            a += glm::dvec3(sample(rng));
            b += glm::dvec3(sample(rng));
        }
        sum += varianceOfMean(a / double(n / 2), b / double(n / 2)).x;
    }
    // The estimate is a scaled chi-square with 1 degree of freedom: its mean over 20000 pixels has a relative
    // standard deviation of sqrt(2 / 20000) = 1 %; 4 % is four of them.
    EXPECT_NEAR(sum / pixels, 4.0 / n, 0.04 * 4.0 / n);
}

TEST(WriteEstimate, WritesValueAndVarianceAndZeroesANonFinitePixel) {
    Image image(2, 1, estimateChannels({"medium.R"}));
    ASSERT_EQ(image.channelCount(), 7);
    EXPECT_TRUE(writeEstimate(image, 0, 0, glm::vec3(1, 2, 3), glm::vec3(0.5f, 0.25f, 0.125f)));
    EXPECT_EQ(image.at(0, 0, 1), 2.0f);
    EXPECT_EQ(image.at(0, 0, 5), 0.125f);
    EXPECT_FALSE(writeEstimate(image, 1, 0, glm::vec3(1, std::numeric_limits<float>::infinity(), 3), glm::vec3(1)));
    for (int c = 0; c < 6; ++c)
        EXPECT_EQ(image.at(1, 0, c), 0.0f);
}

// ---------------------------------------------------------------------------------------------------------------------
// The accumulating dispatch

// Every pixel is exactly one work item's, whatever the image's size: a dispatch never adds to a pixel twice (a race)
// or leaves one out.
TEST(AccumulationMapping, EveryPixelIsExactlyOneItems) {
    for (const auto& [w, h] : {std::pair{1, 1}, {7, 5}, {64, 1}, {100, 37}, {1024, 17}, {513, 511}}) {
        const std::uint32_t pixels = std::uint32_t(w * h);
        const std::uint32_t bandGroups = shader::accumulationBandGroups(pixels);
        std::vector<int> hits(pixels, 0);
        const std::uint32_t items = shader::kAccumulationBands * bandGroups * shader::kAccumulationGroup;
        for (std::uint32_t item = 0; item < items; ++item) {
            const std::uint32_t pixel = shader::accumulationPixel(item, bandGroups);
            if (pixel < pixels) ++hits[pixel];
        }
        for (std::uint32_t p = 0; p < pixels; ++p)
            ASSERT_EQ(hits[p], 1) << w << " x " << h << ", pixel " << p;
    }
}

class GpuAccumulationTest : public ::testing::Test {
protected:
    static gpu::Context& context() {
        static gpu::Context context([] {
            gpu::ContextOptions options;
            options.validation = 1;
            return options;
        }());
        return context;
    }
    gpu::ComputeKernel& kernel() {
        double seconds = 0.0;
        return kernels_.get(context(),
                            {std::string(TYNDALL_FRAMEWORK_TEST_DIR) + "/accumulate.comp.glsl", "", 2,
                             std::uint32_t(sizeof(GpuAccumulation::Slice)), "accumulate"},
                            seconds);
    }
    void TearDown() override {
        for (const std::string& e : context().validationErrors())
            ADD_FAILURE() << "Vulkan validation error: " << e;
    }
    KernelCache kernels_;
};

// Samples added in two calls (the progressive passes) reach every pixel once each, into the half of their index; a
// new render at the same size starts from zero.
TEST_F(GpuAccumulationTest, AddsEverySampleToEveryPixelOnceInItsHalf) {
    gpu::Buffer scale(context(), sizeof(float));
    const float one = 1.0f;
    scale.upload(&one, sizeof(float));
    GpuAccumulation accumulation(context());
    const int width = 97, height = 45;
    for (int render = 0; render < 2; ++render) {
        accumulation.begin(width, height, 2);
        gpu::ComputeKernel& k = kernel();
        auto push = [](const GpuAccumulation::Slice& s) { return s; };
        accumulation.addSamples(k, {&scale}, 0, 3, {}, push);
        accumulation.addSamples(k, {&scale}, 3, 7, {}, push);
        const std::vector<glm::vec4>& acc = accumulation.read();
        ASSERT_EQ(acc.size(), std::size_t(width * height * 2));
        for (int pixel = 0; pixel < width * height; ++pixel) {
            const glm::vec4 even = acc[std::size_t(pixel) * 2], odd = acc[std::size_t(pixel) * 2 + 1];
            ASSERT_EQ(even, glm::vec4(4.0f * float(pixel), 0 + 2 + 4 + 6, 4, 0)) << "pixel " << pixel;
            ASSERT_EQ(odd, glm::vec4(3.0f * float(pixel), 1 + 3 + 5, 3, 0)) << "pixel " << pixel;
        }
        EXPECT_GT(accumulation.gpuMs(), 0.0);
    }
}

TEST_F(GpuAccumulationTest, ThrowsCancelledBetweenSlices) {
    gpu::Buffer scale(context(), sizeof(float));
    GpuAccumulation accumulation(context());
    accumulation.begin(64, 64, 2);
    const std::atomic<bool> cancel{true};
    RenderCallbacks callbacks;
    callbacks.cancel = &cancel;
    EXPECT_THROW(accumulation.addSamples(kernel(), {&scale}, 0, 4, callbacks, [](const auto& s) { return s; }),
                 Cancelled);
}

TEST(StageTimes, EachMarkTakesTheTimeSinceThePreviousAndRepeatedStagesAddUp) {
    StageTimes times;
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    times.mark("prepare");
    times.mark("kernel");
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    times.mark("kernel");
    EXPECT_GE(times.ms("prepare"), 39.0);
    EXPECT_GE(times.ms("kernel"), 4.0);
    EXPECT_LT(times.ms("kernel"), times.ms("prepare"));
    EXPECT_EQ(times.ms("readback"), 0.0);
    ASSERT_EQ(times.stages().size(), 2u);
    EXPECT_EQ(times.stages()[0].first, "prepare");
    EXPECT_DOUBLE_EQ(times.totalMs(), times.ms("prepare") + times.ms("kernel"));
    std::map<std::string, std::string> metadata;
    times.writeTo(metadata);
    ASSERT_EQ(metadata.size(), 2u);
    EXPECT_NEAR(std::stod(metadata.at("time:prepare")), times.ms("prepare"), 0.01 * times.ms("prepare"));
    EXPECT_TRUE(metadata.count("time:kernel"));
}

// A stand-in for a technique's GPU renderer: counts how many were made.
struct CountedRenderer {
    CountedRenderer() { ++made; }
    static inline int made = 0;
};

TEST(RendererPool, ALeaseGivenBackServesTheNextAndConcurrentLeasesGetTheirOwn) {
    CountedRenderer* first = nullptr;
    {
        RendererPool<CountedRenderer>::Lease a = RendererPool<CountedRenderer>::lease();
        first = &*a;
        EXPECT_EQ(RendererPool<CountedRenderer>::idle(), 0u);
    }
    EXPECT_EQ(RendererPool<CountedRenderer>::idle(), 1u);
    {
        RendererPool<CountedRenderer>::Lease again = RendererPool<CountedRenderer>::lease();
        EXPECT_EQ(&*again, first);  // kept, not made anew
        RendererPool<CountedRenderer>::Lease other = RendererPool<CountedRenderer>::lease();
        EXPECT_NE(&*other, first);  // in use: a second one
        EXPECT_EQ(CountedRenderer::made, 2);
        RendererPool<CountedRenderer>::Lease moved = std::move(other);
        EXPECT_FALSE(other);
        EXPECT_TRUE(moved);
    }
    EXPECT_EQ(RendererPool<CountedRenderer>::idle(), 2u);
    EXPECT_EQ(CountedRenderer::made, 2);
}

TEST_F(GpuAccumulationTest, AKeptBufferIsReusedUntilALargerOneIsAskedFor) {
    std::unique_ptr<gpu::Buffer> slot;
    gpu::Buffer& a = gpu::keptBuffer(context(), slot, 4096);
    EXPECT_EQ(a.size(), 4096u);
    const std::uint32_t word = 0xC0FFEEu;
    a.upload(&word, sizeof word);
    EXPECT_EQ(&gpu::keptBuffer(context(), slot, 4096), &a);
    gpu::Buffer& smaller = gpu::keptBuffer(context(), slot, 1024);  // a reduced image: the same buffer
    EXPECT_EQ(&smaller, &a);
    std::uint32_t back = 0;
    smaller.download(&back, sizeof back);
    EXPECT_EQ(back, word);  // what the last render left
    gpu::Buffer& larger = gpu::keptBuffer(context(), slot, 8192);
    EXPECT_GE(larger.size(), 8192u);
    EXPECT_EQ(slot.get(), &larger);
}

}  // namespace
}  // namespace tyndall
