// Linked into every GPU test executable (renderers/CMakeLists.txt, tyndall_gpu_validation_listener): a test during
// which any Vulkan context of the process reported a validation error (synchronisation hazards included) fails, whether
// or not its fixture checks its own context. gtest lets no listener fail a test that has ended, so the listener notes
// the errors of each test and an environment fails the run at its end, naming the test and the messages; ctest runs
// each test in a process of its own (gtest_discover_tests), so the failure is that test's.
#include "tyndall/gpu/context.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

namespace {

struct Finding {
    std::string test;
    std::string message;
};
std::vector<Finding> gFindings;

class ValidationListener final : public ::testing::EmptyTestEventListener {
    void OnTestStart(const ::testing::TestInfo&) override { before_ = tyndall::gpu::processValidationErrors().size(); }
    void OnTestEnd(const ::testing::TestInfo& info) override {
        const std::vector<std::string> errors = tyndall::gpu::processValidationErrors();
        for (std::size_t i = before_; i < errors.size(); ++i) {
            const std::string test = std::string(info.test_suite_name()) + "." + info.name();
            std::fprintf(stderr, "Vulkan validation error during %s: %s\n", test.c_str(), errors[i].c_str());
            gFindings.push_back({test, errors[i]});
        }
    }
    std::size_t before_ = 0;
};

class ValidationEnvironment final : public ::testing::Environment {
    void TearDown() override {
        for (const Finding& f : gFindings)
            ADD_FAILURE() << "Vulkan validation error during " << f.test << ": " << f.message;
    }
};

const bool gRegistered = [] {
    ::testing::UnitTest::GetInstance()->listeners().Append(new ValidationListener);
    ::testing::AddGlobalTestEnvironment(new ValidationEnvironment);
    return true;
}();

}  // namespace
