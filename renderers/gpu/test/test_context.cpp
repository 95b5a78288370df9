#include "gpu_test.h"

#include "test_paths.h"
#include "tyndall/gpu/resources.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numeric>

namespace tyndall::gpu::test {
namespace {

TEST_F(GpuTest, ContextRunsHeadlessOnADeviceWithAComputeQueue) {
    const DeviceInfo& d = context().device();
    EXPECT_FALSE(d.name.empty());
    EXPECT_GT(d.queueCount, 0u);
    EXPECT_GE(d.apiVersion, uint32_t(VK_API_VERSION_1_1));
    EXPECT_TRUE(context().validationEnabled()) << "the tests run with the Khronos validation layers";
}

TEST(GpuContext, PicksTheBestDeviceAndHonoursOverrides) {
    std::vector<DeviceInfo> devices = Context::enumerateDevices();
    ASSERT_FALSE(devices.empty());
    Context byIndex(ContextOptions{"0", 0});
    EXPECT_EQ(byIndex.device().name, devices[0].name);
    Context byName(ContextOptions{devices[0].name.substr(0, 4), 0});
    EXPECT_EQ(byName.device().name, devices[0].name);
    try {
        Context missing(ContextOptions{"no-such-gpu", 0});
        FAIL() << "a device that does not exist must be refused";
    } catch (const GpuError& e) {
        EXPECT_NE(std::string(e.what()).find(devices[0].name), std::string::npos) << "the error lists the devices";
    }
    EXPECT_THROW(Context(ContextOptions{"99", 0}), GpuError);
}

TEST_F(GpuTest, BufferUploadAndReadbackRoundTrip) {
    std::vector<std::uint32_t> values(1 << 18);
    std::iota(values.begin(), values.end(), 7u);
    Buffer buffer(context(), values.size() * 4);
    buffer.upload(values);
    EXPECT_EQ(buffer.download<std::uint32_t>(values.size()), values);
    EXPECT_THROW(buffer.upload(values.data(), values.size() * 4, 4), GpuError) << "an overrun is an error, not a crash";
}

TEST_F(GpuTest, BufferFillsInPlaceAndReadsBackIntoAVectorItReuses) {
    std::vector<std::uint32_t> values(1 << 16);
    std::iota(values.begin(), values.end(), 3u);
    Buffer buffer(context(), values.size() * 4);
    buffer.upload(values);
    buffer.fill(0x3f800000u);  // 1.0f
    std::vector<float> out(values.size() + 10, -1.0f);
    const float* storage = out.data();
    buffer.download(out, values.size());
    ASSERT_EQ(out.size(), values.size());
    EXPECT_EQ(out.data(), storage) << "the vector's storage is reused";
    EXPECT_TRUE(std::all_of(out.begin(), out.end(), [](float v) { return v == 1.0f; }));
    buffer.fill(0u);
    buffer.download(out, 100);
    EXPECT_EQ(out.size(), 100u);
    EXPECT_TRUE(std::all_of(out.begin(), out.end(), [](float v) { return v == 0.0f; }));
}

TEST_F(GpuTest, ComputeKernelWithDescriptorsAndPushConstants) {
    constexpr uint32_t n = 1000;
    std::vector<float> in(n);
    for (uint32_t i = 0; i < n; ++i) in[i] = float(i) * 0.5f;
    Buffer input(context(), n * 4), output(context(), n * 4);
    input.upload(in);
    ComputeKernel kernel(context(), loadSpirv("add_one"), 2, 12, "add_one");
    struct {
        uint32_t count, offset;
        float value;
    } push{n, 0, 1.0f};
    double ms = context().submitTimed([&](VkCommandBuffer cmd) {
        kernel.record(cmd, {&input, &output}, &push, (n + 63) / 64);
    });
    kernel.resetDescriptors();
    std::vector<float> out = output.download<float>(n);
    for (uint32_t i = 0; i < n; ++i) ASSERT_EQ(out[i], in[i] + 1.0f) << i;
    if (context().device().timestampPeriod > 0.0f) {
        EXPECT_GE(ms, 0.0) << "timestamps report the GPU time";
    }
    EXPECT_THROW(context().submitAndWait([&](VkCommandBuffer cmd) { kernel.record(cmd, {&input}, &push, 1); }),
                 GpuError) << "a wrong number of buffers is refused before Vulkan sees it";
}

TEST_F(GpuTest, AnImpossibleAllocationIsAnErrorNotACrash) {
    try {
        Buffer huge(context(), VkDeviceSize(1) << 50);  // 1 PiB
        FAIL() << "a 1 PiB buffer cannot exist";
    } catch (const GpuError& e) {
        EXPECT_FALSE(std::string(e.what()).empty());
    }
}

// A buffer of size 0 is invalid (VUID-VkBufferCreateInfo-size-00912) yet harmless to the driver.
void createBufferOfSizeZero(Context& context) {
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = 0;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBuffer buffer = VK_NULL_HANDLE;
    if (vkCreateBuffer(context.vk(), &info, nullptr, &buffer) == VK_SUCCESS) vkDestroyBuffer(context.vk(), buffer, nullptr);
}

TEST(GpuValidation, LayersReportMisuse) {
    // A buffer of size 0 is invalid (VUID-VkBufferCreateInfo-size-00912) yet harmless to the driver: the layers must
    // report it, or the clean runs of the other tests prove nothing.
    ExpectedValidationErrors expected;
    ContextOptions options;
    options.validation = 1;
    Context context(options);
    ASSERT_TRUE(context.validationEnabled());
    createBufferOfSizeZero(context);
    EXPECT_FALSE(context.validationErrors().empty());
}

TEST(GpuValidation, SynchronisationValidationReportsAHazard) {
    // Two transfers write one buffer in one command buffer without a barrier between them: a write-after-write hazard
    // that lavapipe executes in order and a GPU may not. Synchronisation validation must report it (SYNC-HAZARD-*), or
    // the clean runs of the GPU tests prove nothing about their barriers.
    ExpectedValidationErrors expected;
    ContextOptions options;
    options.validation = 1;
    Context context(options);
    ASSERT_TRUE(context.syncValidationEnabled());
    Buffer buffer(context, 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    context.submitAndWait([&](VkCommandBuffer cmd) {
        vkCmdFillBuffer(cmd, buffer.handle(), 0, 256, 1u);
        vkCmdFillBuffer(cmd, buffer.handle(), 0, 256, 2u);
    });
    const std::vector<std::string> errors = context.validationErrors();
    ASSERT_FALSE(errors.empty());
    EXPECT_NE(errors[0].find("SYNC-HAZARD-WRITE-AFTER-WRITE"), std::string::npos) << errors[0];
}

TEST(GpuValidation, AnErrorFailsTheTestThatCausedIt) {
    // In a child process (this executable, this test alone, TYNDALL_PROVOKE_VALIDATION_ERROR set): a validation error
    // on a context no fixture checks. The listener (renderers/testing/validation_listener.cpp) must fail the child and
    // name this test.
    if (std::getenv("TYNDALL_PROVOKE_VALIDATION_ERROR")) {
        Context context(ContextOptions{.validation = 1});
        createBufferOfSizeZero(context);
        return;
    }
    const std::string command = "TYNDALL_PROVOKE_VALIDATION_ERROR=1 " + tyndall::test::selfCommand() +
                                " --gtest_filter=GpuValidation.AnErrorFailsTheTestThatCausedIt 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buffer[4096];
    while (std::size_t n = std::fread(buffer, 1, sizeof(buffer), pipe))
        output.append(buffer, n);
    const int status = ::pclose(pipe);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0) << output;
    EXPECT_NE(output.find("Vulkan validation error during GpuValidation.AnErrorFailsTheTestThatCausedIt"),
              std::string::npos)
        << output;
}

}  // namespace
}  // namespace tyndall::gpu::test
