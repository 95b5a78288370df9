// A fixture for GPU tests: one Context with the validation layers on, and a check after every test that the layers
// reported no error.
#pragma once

#include "test_paths.h"
#include "tyndall/gpu/context.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace tyndall::gpu::test {

inline Context& sharedContext() {
    static std::unique_ptr<Context> context = [] {
        ContextOptions options;
        options.validation = 1;
        return std::make_unique<Context>(options);
    }();
    return *context;
}

class GpuTest : public ::testing::Test {
protected:
    void SetUp() override { errorsBefore_ = sharedContext().validationErrors().size(); }
    void TearDown() override {
        std::vector<std::string> errors = sharedContext().validationErrors();
        for (size_t i = errorsBefore_; i < errors.size(); ++i) ADD_FAILURE() << "Vulkan validation error: " << errors[i];
    }
    Context& context() { return sharedContext(); }

private:
    size_t errorsBefore_ = 0;
};

inline std::vector<std::uint32_t> loadSpirv(const std::string& name) {
    std::ifstream in(tyndall::test::spirvDir() + "/" + name + ".spv", std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    std::vector<std::uint32_t> words(bytes.size() / 4);
    std::memcpy(words.data(), bytes.data(), words.size() * 4);
    return words;
}

}  // namespace tyndall::gpu::test
