// A fixture for tests of techniques on the GPU: they render on gpu::sharedContext(), and any validation error it
// reports during a test fails that test. Skips the test when the machine has no Vulkan device.
#ifndef TYNDALL_TEST_TECHNIQUE_GPU_TEST_H
#define TYNDALL_TEST_TECHNIQUE_GPU_TEST_H

#include "tyndall/gpu/context.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace tyndall::test {

class TechniqueGpuTest : public ::testing::Test {
protected:
    void SetUp() override {
        try {
            before_ = gpu::sharedContext()->validationErrors().size();
        } catch (const gpu::GpuError& e) {
            GTEST_SKIP() << "no Vulkan device: " << e.what();
        }
    }
    void TearDown() override {
        const std::vector<std::string> errors = gpu::sharedContext()->validationErrors();
        for (std::size_t i = before_; i < errors.size(); ++i)
            ADD_FAILURE() << "Vulkan validation error: " << errors[i];
    }

private:
    std::size_t before_ = 0;
};

}  // namespace tyndall::test

#endif  // TYNDALL_TEST_TECHNIQUE_GPU_TEST_H
