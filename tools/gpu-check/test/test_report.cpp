// The GPU check's verdicts on canned outputs of `tyndall info --json`, Google Test and Google Benchmark.
#include "report.h"

#include <gtest/gtest.h>

namespace tyndall::gpucheck {
namespace {

using nlohmann::json;

json infoWith(bool meshShader) {
    return {{"tyndall", "0.1.0"},
            {"devices",
             {{{"name", "CPU"}, {"threads", 16}},
              {{"name", "NVIDIA H100"},
               {"vulkan", "1.3"},
               {"type", "discrete GPU"},
               {"driver", "NVIDIA 550.54"},
               {"float64", true},
               {"rayQuery", true},
               {"meshShader", meshShader},
               {"geometryShader", true},
               {"timestamps", true}}}}};
}

ProcessRun exited(int code, const std::string& command = "x") {
    ProcessRun run;
    run.command = command;
    run.exitCode = code;
    run.seconds = 1.5;
    run.log = "/out/logs/x.log";
    return run;
}

json gtestJson(const std::vector<std::tuple<std::string, std::string, std::string>>& tests) {
    // (suite, name, "ok" | "skip" | failure message)
    json suites = json::array();
    for (const auto& [suite, name, outcome] : tests) {
        json t = {{"name", name}, {"status", "RUN"}, {"result", outcome == "skip" ? "SKIPPED" : "COMPLETED"}};
        if (outcome != "ok" && outcome != "skip") t["failures"] = {{{"failure", outcome}, {"type", ""}}};
        suites.push_back({{"name", suite}, {"testsuite", {t}}});
    }
    return {{"testsuites", suites}};
}

TestRun testRun(const std::string& executable, const json& gtest, int exitCode, const std::string& log = "") {
    TestRun t;
    t.suite = {executable, "*"};
    t.run = exited(exitCode);
    t.gtest = gtest;
    t.logText = log;
    return t;
}

// The LTSD case at 1920 x 1080 and, with `isvError`, an ISV case that could not run on the GPU.
json framesJson(double ltsdMs, double target, bool isvError = false) {
    json frames = {{"benchmarks",
                    {{{"name", "BM_Frame/ltsd/1920x1080/manual_time"},
                      {"iterations", 40},
                      {"real_time", ltsdMs},
                      {"time_unit", "ms"},
                      {"label", "NVIDIA H100"},
                      {"wallMs", 9.0},
                      {"targetMs", target},
                      {"primaryHitsMs", ltsdMs / 4},
                      {"airLightMs", 3 * ltsdMs / 4}}}}};
    if (isvError) {
        frames["benchmarks"].push_back({{"name", "BM_Frame/isv/512x512/manual_time"},
                                        {"error_occurred", true},
                                        {"error_message", "the view did not run on the GPU (device cpu)"}});
    }
    return frames;
}

const std::string kMeshSkipLog =
    "[ RUN      ] IsvGpu.MeshAndGeometryProducersAgree\n"
    "/src/test_isv.cpp:1021: Skipped\n"
    "the device has no mesh shaders\n"
    "[  SKIPPED ] IsvGpu.MeshAndGeometryProducersAgree (85 ms)\n";

TEST(GpuCheckReport, SkipReasonsComeFromTheLog) {
    const json reasons = skipReasons(kMeshSkipLog + "[  SKIPPED ] 1 test, listed below:\n");
    ASSERT_TRUE(reasons.contains("IsvGpu.MeshAndGeometryProducersAgree"));
    EXPECT_EQ(reasons["IsvGpu.MeshAndGeometryProducersAgree"], "the device has no mesh shaders");
    EXPECT_EQ(reasons.size(), 1u);
}

TEST(GpuCheckReport, TheDeviceIsTheOneTheTechniquesTake) {
    // lavapipe listed before the GPU (as on a machine with Mesa installed beside NVIDIA's driver): the GPU is judged.
    json info = infoWith(true);
    const json lavapipe = {
        {"name", "llvmpipe (LLVM 15.0.6, 256 bits)"}, {"vulkan", "1.3"}, {"type", "CPU"}, {"meshShader", false}};
    info["devices"].insert(info["devices"].begin() + 1, lavapipe);
    const json report = buildReport(info, exited(0), {}, nullptr, ProcessRun{}, {});
    EXPECT_EQ(report["device"]["name"], "NVIDIA H100");
    EXPECT_EQ(report["devices"].size(), 2u);
    EXPECT_NE(markdownReport(report).find("not used: the techniques take discrete > integrated > virtual > CPU): "
                                          "llvmpipe (LLVM 15.0.6, 256 bits) (CPU);"),
              std::string::npos)
        << markdownReport(report);
}

TEST(GpuCheckReport, NoDeviceSaysSoAndRunsNothing) {
    json info = infoWith(false);
    info["devices"].erase(1);
    info["vulkanError"] = "cannot create a Vulkan instance: VK_ERROR_INCOMPATIBLE_DRIVER";
    const json report = buildReport(info, exited(1), {}, nullptr, ProcessRun{}, {{"date", "2026-12-07"}});
    EXPECT_EQ(report["verdict"], "no device");
    EXPECT_EQ(report["noDevice"], "cannot create a Vulkan instance: VK_ERROR_INCOMPATIBLE_DRIVER");
    const std::string md = markdownReport(report);
    EXPECT_NE(md.find("**Device**: none: cannot create a Vulkan instance"), std::string::npos) << md;
    EXPECT_NE(md.find("Verdict: no device"), std::string::npos) << md;

    // tyndall info that printed nothing at all (it could not start).
    const json silent = buildReport(nullptr, ProcessRun{}, {}, nullptr, ProcessRun{}, json::object());
    EXPECT_EQ(silent["verdict"], "no device");
    EXPECT_NE(silent["noDevice"].get<std::string>().find("did not start"), std::string::npos) << silent["noDevice"];
}

TEST(GpuCheckReport, AFeatureTestThatSkipsOnADeviceWithTheFeatureFails) {
    const json gtest = gtestJson({{"IsvGpu", "MeshAndGeometryProducersAgree", "skip"}, {"IsvGpu", "Other", "ok"}});
    const std::vector<TestRun> tests = {testRun("tyndall_isv_tests", gtest, 0, kMeshSkipLog)};

    const json without = buildReport(infoWith(false), exited(0), tests, framesJson(2.0, 8.0), exited(0), {});
    EXPECT_EQ(without["verdict"], "pass") << without["problems"];
    EXPECT_EQ(without["tests"]["skipped"], 1);
    EXPECT_EQ(without["tests"]["passed"], 1);

    const json with = buildReport(infoWith(true), exited(0), tests, framesJson(2.0, 8.0), exited(0), {});
    EXPECT_EQ(with["verdict"], "fail");
    ASSERT_FALSE(with["problems"].empty());
    EXPECT_NE(with["problems"][0].get<std::string>().find(
                  "IsvGpu.MeshAndGeometryProducersAgree skipped (\"the device has no mesh shaders\") although the "
                  "device has meshShader"),
              std::string::npos)
        << with["problems"];
    EXPECT_NE(markdownReport(with).find("counted as a failure"), std::string::npos);
}

TEST(GpuCheckReport, FailuresCrashesAndTimeoutsFailTheCheck) {
    const json failed = gtestJson({{"LtsdGpu", "MatchesTheCpu", "test_ltsd.cpp:80: max error 0.3 > 1e-4"}});
    std::vector<TestRun> tests = {testRun("tyndall_ltsd_tests", failed, 1)};
    json report = buildReport(infoWith(true), exited(0), tests, framesJson(2.0, 8.0), exited(0), {});
    EXPECT_EQ(report["verdict"], "fail");
    EXPECT_EQ(report["tests"]["failed"], 1);
    EXPECT_NE(markdownReport(report).find("max error 0.3 > 1e-4"), std::string::npos);

    TestRun crashed = testRun("tyndall_gpu_tests", nullptr, -1);
    crashed.run.signal = 11;
    TestRun hung = testRun("tyndall_wvds_tests", nullptr, -1);
    hung.run.signal = 9;
    hung.run.timedOut = true;
    hung.run.seconds = 300;
    report = buildReport(infoWith(true), exited(0), {crashed, hung}, framesJson(2.0, 8.0), exited(0), {});
    EXPECT_EQ(report["verdict"], "fail");
    const std::string problems = report["problems"].dump();
    EXPECT_NE(problems.find("tyndall_gpu_tests (*): ended by signal 11, no test results"), std::string::npos)
        << problems;
    EXPECT_NE(problems.find("tyndall_wvds_tests (*): timed out after 300 s"), std::string::npos) << problems;
}

TEST(GpuCheckReport, WithoutBenchmarksOnlyTheTestsCount) {
    const std::vector<TestRun> tests = {testRun("tyndall_gpu_tests", gtestJson({{"GpuTest", "A", "ok"}}), 0)};
    const json report = buildReport(infoWith(false), exited(0), tests, nullptr, ProcessRun{}, {});
    EXPECT_EQ(report["verdict"], "pass") << report["problems"];
    EXPECT_EQ(report["frames"]["skipped"], true);
    EXPECT_NE(markdownReport(report).find("Not measured (--no-benchmarks)."), std::string::npos);
}

TEST(GpuCheckReport, FrameTimesAgainstTargetsWithEachPassShare) {
    const std::vector<TestRun> tests = {testRun("tyndall_gpu_tests", gtestJson({{"GpuTest", "A", "ok"}}), 0)};
    const json report = buildReport(infoWith(true), exited(0), tests, framesJson(12.0, 8.0, true), exited(0), {});
    // A missed target is reported, not a failure; the ISV case's error is.
    EXPECT_EQ(report["targetsMissed"], json::array({"ltsd"}));
    const json& ltsd = report["frames"]["cases"][0];
    EXPECT_EQ(ltsd["case"], "ltsd");
    EXPECT_EQ(ltsd["width"], 1920);
    EXPECT_EQ(ltsd["gpuMs"], 12.0);
    EXPECT_EQ(ltsd["met"], false);
    EXPECT_EQ(ltsd["passes"], json({{"primaryHitsMs", 3.0}, {"airLightMs", 9.0}}));
    EXPECT_EQ(report["verdict"], "fail");
    EXPECT_NE(report["problems"].dump().find("frame benchmark isv at 512x512: the view did not run on the GPU"),
              std::string::npos)
        << report["problems"];
    const std::string md = markdownReport(report);
    EXPECT_NE(
        md.find("| ltsd | | 12.0 (9.00) | <= 8.00: **missed** | airLightMs 9.00 (75 %), primaryHitsMs 3.00 (25 %) |"),
        std::string::npos)
        << md;
    EXPECT_EQ(md.find("A CPU device"), std::string::npos) << md;

    json lavapipe = infoWith(false);
    lavapipe["devices"][1]["type"] = "CPU";
    const std::string cpu =
        markdownReport(buildReport(lavapipe, exited(0), tests, framesJson(12.0, 8.0), exited(0), {}));
    EXPECT_NE(cpu.find("**A CPU device**: lavapipe's timestamps"), std::string::npos) << cpu;
    EXPECT_NE(cpu.find("<= 8.00: not judged (a CPU device)"), std::string::npos) << cpu;
}

}  // namespace
}  // namespace tyndall::gpucheck
