// The GPU check's report (packaging/gpu-check.sh, docs/gpu.md): from what `tyndall info --json` said of the device,
// the Google Test JSON of every GPU test executable and the frame-time benchmark's JSON, one JSON document and its
// Markdown rendering. Pure functions, so that the verdicts are unit-tested on canned outputs.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace tyndall::gpucheck {

// One run of a child process.
struct ProcessRun {
    std::string command;  // as the report shows it
    int exitCode = -1;    // -1: it did not start
    int signal = 0;       // the signal that ended it (a crash, or SIGKILL on a timeout)
    bool timedOut = false;
    double seconds = 0.0;
    std::string log;  // where its output went
};

// A test executable of the bundle and the tests of it that need a GPU.
struct TestSuite {
    std::string executable;
    std::string filter;  // --gtest_filter
};

struct TestRun {
    TestSuite suite;
    ProcessRun run;
    nlohmann::json gtest;  // its --gtest_output JSON; null when it wrote none
    std::string logText;   // its output, for the skip reasons
};

// The tests that skip where the device lacks a feature, and that feature's name in `tyndall info --json`. On a device
// that has the feature, such a test skipping is a failure: the path it checks has not run.
struct FeatureTest {
    std::string test;  // Suite.Name
    std::string feature;
};
const std::vector<FeatureTest>& featureTests();

// Every GPU test executable of the bundle with its GPU tests (what tyndall-gpu-check runs without --only).
const std::vector<TestSuite>& gpuTestSuites();

// The skip message of each skipped test in a Google Test log ("file:line: Skipped" then the message, then
// "[  SKIPPED ] Suite.Name").
nlohmann::json skipReasons(const std::string& log);

// `info`: `tyndall info --json`'s document (null when it printed none); `infoRun` its process. `environment`: what the
// script found (driver files, library path, host). The report's "verdict" is "pass" when a Vulkan device was found,
// every test executable ran to its end and every test passed or skipped for a feature the device lacks; "no device"
// when there was none; "fail" otherwise. Missed frame-time targets are reported, not failures.
nlohmann::json buildReport(const nlohmann::json& info, const ProcessRun& infoRun, const std::vector<TestRun>& tests,
                           const nlohmann::json& frames, const ProcessRun& framesRun,
                           const nlohmann::json& environment);

std::string markdownReport(const nlohmann::json& report);

}  // namespace tyndall::gpucheck
