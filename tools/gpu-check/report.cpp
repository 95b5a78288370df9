#include "report.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

namespace tyndall::gpucheck {

using nlohmann::json;

const std::vector<FeatureTest>& featureTests() {
    static const std::vector<FeatureTest> tests = {
        {"IsvGpu.MeshAndGeometryProducersAgree", "meshShader"},
        {"GpuTest.DoublePrecisionMathAgreesWithTheCpu", "float64"},
        {"GpuTest.ExpintDoubleAgreesWithTheCpu", "float64"},
        {"GraphicsTest.GeometryShaderTurnsPointsIntoSquares", "geometryShader"},
        {"GraphicsTest.DualSourceBlendingAttenuatesEachChannelByTheSecondOutput", "dualSrcBlend"},
    };
    return tests;
}

const std::vector<TestSuite>& gpuTestSuites() {
    // The ray-query backend is checked by VisibilityTest (it runs where the device has ray queries, and checks the
    // BVH fallback everywhere); the mesh-shader producer by IsvGpu.MeshAndGeometryProducersAgree.
    static const std::vector<TestSuite> suites = {
        {"tyndall_gpu_tests", "*"},
        {"tyndall_framework_tests", "GpuAccumulationTest.*"},
        {"tyndall_primary_hits_tests", "*"},
        {"tyndall_ltsd_tests", "LtsdGpu.*"},
        {"tyndall_isv_tests", "IsvGpu.*:IsvLimits.*"},
        {"tyndall_wvds_tests", "WvdsGpu.*"},
        {"tyndall_volume_ris_tests", "VolumeRisGpu.*"},
        {"tyndall_pegoraro_technique_tests", "PegoraroGpu.*"},
    };
    return suites;
}

json skipReasons(const std::string& log) {
    json reasons = json::object();
    std::istringstream in(log);
    std::string line, pending;
    bool inSkip = false;
    while (std::getline(in, line)) {
        if (line.size() >= 9 && line.compare(line.size() - 9, 9, ": Skipped") == 0) {
            inSkip = true;
            pending.clear();
        } else if (line.rfind("[  SKIPPED ] ", 0) == 0) {
            std::string name = line.substr(13);
            name = name.substr(0, name.find(' '));
            if (inSkip && !name.empty() && !reasons.contains(name)) reasons[name] = pending;
            inSkip = false;
        } else if (inSkip) {
            pending += (pending.empty() ? "" : " ") + line;
        }
    }
    return reasons;
}

namespace {

std::string describeEnd(const ProcessRun& run) {
    if (run.exitCode == -1 && run.signal == 0) return "did not start";
    if (run.timedOut) return "timed out after " + std::to_string(int(run.seconds)) + " s";
    if (run.signal != 0) return "ended by signal " + std::to_string(run.signal);
    return "exit " + std::to_string(run.exitCode);
}

ProcessRun runFromJson(const json& j) {
    ProcessRun run;
    run.command = j.value("command", "");
    run.exitCode = j.value("exitCode", -1);
    run.signal = j.value("signal", 0);
    run.timedOut = j.value("timedOut", false);
    run.seconds = j.value("seconds", 0.0);
    run.log = j.value("log", "");
    return run;
}

json runJson(const ProcessRun& run) {
    return {{"command", run.command},   {"exitCode", run.exitCode}, {"signal", run.signal},
            {"timedOut", run.timedOut}, {"seconds", run.seconds},   {"log", run.log}};
}

// The Vulkan device of `tyndall info --json` that the techniques and tests take (gpu::Context::pickDevice): the first
// of the highest type, discrete > integrated > virtual > CPU; null without one.
json chosenGpu(const json& info) {
    if (!info.is_object() || !info.contains("devices")) return nullptr;
    const auto rank = [](const json& d) {
        const std::string type = d.value("type", "");
        return type == "discrete GPU"     ? 4
               : type == "integrated GPU" ? 3
               : type == "virtual GPU"    ? 2
               : type == "CPU"            ? 1
                                          : 0;
    };
    json chosen = nullptr;
    for (const json& d : info["devices"])
        if (d.contains("vulkan") && (chosen.is_null() || rank(d) > rank(chosen))) chosen = d;
    return chosen;
}

json testsJson(const std::vector<TestRun>& tests, const json& device, std::vector<std::string>& problems) {
    json out = {{"passed", 0}, {"failed", 0}, {"skipped", 0}, {"executables", json::array()}};
    for (const TestRun& t : tests) {
        json e = runJson(t.run);
        e["executable"] = t.suite.executable;
        e["filter"] = t.suite.filter;
        e["passed"] = 0;
        e["failed"] = 0;
        e["skipped"] = 0;
        e["failures"] = json::array();
        e["skips"] = json::array();
        const json reasons = skipReasons(t.logText);
        if (t.gtest.is_object() && t.gtest.contains("testsuites")) {
            for (const json& suite : t.gtest["testsuites"]) {
                for (const json& test : suite.value("testsuite", json::array())) {
                    const std::string name = suite.value("name", "") + "." + test.value("name", "");
                    if (test.value("status", "") != "RUN") continue;
                    if (test.contains("failures") && !test["failures"].empty()) {
                        std::string message;
                        for (const json& f : test["failures"])
                            message += (message.empty() ? "" : "\n") + f.value("failure", "");
                        e["failures"].push_back({{"test", name}, {"message", message}});
                        e["failed"] = e["failed"].get<int>() + 1;
                    } else if (test.value("result", "") == "SKIPPED") {
                        const auto feature = std::find_if(featureTests().begin(), featureTests().end(),
                                                          [&](const FeatureTest& f) { return f.test == name; });
                        const bool deviceHasIt = feature != featureTests().end() && device.is_object() &&
                                                 device.value(feature->feature, false);
                        const std::string reason = reasons.value(name, "");
                        e["skips"].push_back({{"test", name}, {"reason", reason}, {"allowed", !deviceHasIt}});
                        if (deviceHasIt) {
                            problems.push_back(name + " skipped (\"" + reason + "\") although the device has " +
                                               feature->feature);
                            e["failed"] = e["failed"].get<int>() + 1;
                        } else {
                            e["skipped"] = e["skipped"].get<int>() + 1;
                        }
                    } else {
                        e["passed"] = e["passed"].get<int>() + 1;
                    }
                }
            }
        }
        for (const json& f : e["failures"])
            problems.push_back(t.suite.executable + ": " + f["test"].get<std::string>() + " failed");
        const bool ended = t.run.exitCode == 0 || (t.run.exitCode == 1 && !e["failures"].empty());
        if (!ended || !t.gtest.is_object()) {
            problems.push_back(t.suite.executable + " (" + t.suite.filter + "): " + describeEnd(t.run) +
                               (t.gtest.is_object() ? "" : ", no test results") + "; see " + t.run.log);
        }
        for (const char* key : {"passed", "failed", "skipped"})
            out[key] = out[key].get<int>() + e[key].get<int>();
        out["executables"].push_back(e);
    }
    return out;
}

// `judge`: whether the targets apply (not on a CPU device, whose compute timestamps read far too low).
json framesJson(const json& frames, const ProcessRun& run, bool judge, std::vector<std::string>& problems) {
    json out = runJson(run);
    out["cases"] = json::array();
    if (frames.is_object() && frames.contains("benchmarks")) {
        for (const json& b : frames["benchmarks"]) {
            // BM_Frame/<case>/<width>x<height>[/manual_time]
            std::vector<std::string> parts;
            std::istringstream name(b.value("name", ""));
            for (std::string part; std::getline(name, part, '/');)
                parts.push_back(part);
            if (parts.size() < 3 || parts[0] != "BM_Frame") continue;
            int width = 0, height = 0;
            std::sscanf(parts[2].c_str(), "%dx%d", &width, &height);
            json c = {{"case", parts[1]}, {"width", width}, {"height", height}};
            if (b.value("error_occurred", false)) {
                c["error"] = b.value("error_message", "");
                problems.push_back("frame benchmark " + parts[1] + " at " + parts[2] + ": " +
                                   c["error"].get<std::string>());
                out["cases"].push_back(c);
                continue;
            }
            c["frames"] = b.value("iterations", 0);
            c["gpuMs"] = b.value("real_time", 0.0);
            c["wallMs"] = b.value("wallMs", 0.0);
            c["device"] = b.value("label", "");
            const double target = b.value("targetMs", 0.0);
            json passes = json::object();
            static const std::vector<std::string> notPasses = {"name",
                                                               "family_index",
                                                               "per_family_instance_index",
                                                               "run_name",
                                                               "run_type",
                                                               "repetitions",
                                                               "repetition_index",
                                                               "threads",
                                                               "iterations",
                                                               "real_time",
                                                               "cpu_time",
                                                               "time_unit",
                                                               "label",
                                                               "wallMs",
                                                               "targetMs",
                                                               "error_occurred",
                                                               "error_message",
                                                               "aggregate_name"};
            for (auto it = b.begin(); it != b.end(); ++it) {
                if (std::find(notPasses.begin(), notPasses.end(), it.key()) != notPasses.end()) continue;
                if (it.value().is_number()) passes[it.key()] = it.value();
            }
            c["passes"] = passes;
            if (target > 0.0) {
                c["targetMs"] = target;
                if (judge) c["met"] = c["gpuMs"].get<double>() <= target;
            }
            out["cases"].push_back(c);
        }
    }
    if (run.exitCode != 0 || !frames.is_object())
        problems.push_back("frame benchmarks: " + describeEnd(run) + (frames.is_object() ? "" : ", no results") +
                           "; see " + run.log);
    return out;
}

std::string fixed(double v, int digits) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", digits, v);
    return text;
}

std::string ms(double v) {
    return v < 10.0 ? fixed(v, 2) : v < 100.0 ? fixed(v, 1) : fixed(v, 0);
}

}  // namespace

json buildReport(const json& info, const ProcessRun& infoRun, const std::vector<TestRun>& tests, const json& frames,
                 const ProcessRun& framesRun, const json& environment) {
    json report;
    report["tyndallGpuCheck"] = 1;
    report["tyndall"] = info.is_object() ? info.value("tyndall", "") : "";
    report["environment"] = environment.is_object() ? environment : json::object();
    report["info"] = runJson(infoRun);
    json devices = json::array();
    if (info.is_object() && info.contains("devices"))
        for (const json& d : info["devices"])
            if (d.contains("vulkan")) devices.push_back(d);
    report["devices"] = devices;
    const json device = chosenGpu(info);
    report["device"] = device;
    std::vector<std::string> problems;
    if (device.is_null()) {
        std::string reason = info.is_object() && info.contains("vulkanError")
                                 ? info["vulkanError"].get<std::string>()
                                 : "tyndall info " + describeEnd(infoRun) + " (see " + infoRun.log + ")";
        report["noDevice"] = reason;
        report["verdict"] = "no device";
        report["problems"] = json::array({"no Vulkan device: " + reason});
        return report;
    }
    report["tests"] = testsJson(tests, device, problems);
    // Frame times only where the benchmark was asked for (not with --no-benchmarks).
    report["frames"] = framesRun.command.empty()
                           ? json{{"cases", json::array()}, {"skipped", true}}
                           : framesJson(frames, framesRun, device.value("type", "") != "CPU", problems);
    json missed = json::array();
    for (const json& c : report["frames"]["cases"])
        if (c.contains("met") && !c["met"].get<bool>()) missed.push_back(c["case"]);
    report["targetsMissed"] = missed;
    report["problems"] = problems;
    report["verdict"] = problems.empty() ? "pass" : "fail";
    return report;
}

std::string markdownReport(const json& r) {
    std::ostringstream md;
    const json& env = r.value("environment", json::object());
    md << "# Tyndall GPU check\n\n";
    md << "- **Date**: " << env.value("date", "?") << "\n";
    md << "- **Tyndall**: " << r.value("tyndall", "?") << " (bundle " << env.value("bundle", "?") << ")\n";
    md << "- **Host**: " << env.value("host", "?") << "\n";
    md << "- **Vulkan driver files**: " << env.value("driverFiles", "(the loader's search)") << "\n";
    const std::string verdict = r.value("verdict", "?");
    if (r.contains("noDevice")) {
        md << "- **Device**: none: " << r["noDevice"].get<std::string>() << "\n\n";
        md << "**Verdict: no device.** Nothing ran on a GPU. `device = auto` views render on the CPU.\n";
        return md.str();
    }
    const json& d = r["device"];
    md << "- **Device**: " << d.value("name", "?") << " (" << d.value("type", "?") << "), Vulkan "
       << d.value("vulkan", "?") << ", driver " << d.value("driver", "?") << "\n";
    md << "- **Features**:";
    for (const char* f : {"float64", "rayQuery", "meshShader", "geometryShader", "timestamps"})
        md << " " << f << " " << (d.value(f, false) ? "yes" : "no") << (std::string(f) == "timestamps" ? "" : ",");
    md << "\n";
    if (r["devices"].size() > 1) {
        md << "- **Other devices** (not used: the techniques take discrete > integrated > virtual > CPU):";
        for (const json& other : r["devices"])
            if (other != d) md << " " << other.value("name", "?") << " (" << other.value("type", "?") << ");";
        md << "\n";
    }
    md << "- **Took**: " << fixed(r.value("seconds", 0.0), 0) << " s\n\n";
    md << "**Verdict: " << verdict << ".**";
    if (!r["problems"].empty()) {
        md << "\n\n";
        for (const json& p : r["problems"])
            md << "- " << p.get<std::string>() << "\n";
    } else {
        md << " Every GPU test passed (or skipped for a feature the device lacks).\n";
    }

    const json& t = r["tests"];
    md << "\n## Tests (validation and synchronisation validation on)\n\n";
    md << "| executable | tests | passed | failed | skipped | time | end |\n|---|---|---:|---:|---:|---:|---|\n";
    for (const json& e : t["executables"]) {
        const ProcessRun run = runFromJson(e);
        md << "| " << e["executable"].get<std::string>() << " | `" << e["filter"].get<std::string>() << "` | "
           << e["passed"] << " | " << e["failed"] << " | " << e["skipped"] << " | " << fixed(run.seconds, 1) << " s | "
           << describeEnd(run) << " |\n";
    }
    md << "| **all** | | " << t["passed"] << " | " << t["failed"] << " | " << t["skipped"] << " | | |\n";
    bool anySkip = false;
    for (const json& e : t["executables"])
        for (const json& s : e["skips"]) {
            if (!anySkip) md << "\nSkipped:\n\n";
            anySkip = true;
            md << "- " << s["test"].get<std::string>() << ": " << s["reason"].get<std::string>()
               << (s["allowed"].get<bool>() ? "" : " **(the device has the feature: counted as a failure)**") << "\n";
        }
    for (const json& e : t["executables"])
        for (const json& f : e["failures"])
            md << "\nFailed: **" << f["test"].get<std::string>() << "**\n\n```\n"
               << f["message"].get<std::string>() << "\n```\n";

    if (r["frames"].value("skipped", false)) {
        md << "\n## Frame times\n\nNot measured (--no-benchmarks).\n";
    } else {
        md << "\n## Frame times\n\nGPU time per frame from the device's timestamps (mean over the timed frames; the "
              "first frame, which compiles the pipelines, is not timed), and in brackets the wall time of a frame with "
              "its "
              "uploads and readback. Targets are issue 37's, at 1920 x 1080.\n\n";
        if (d.value("type", "") == "CPU") {
            md << "**A CPU device**: lavapipe's timestamps of compute passes read far too low once a kernel has run in "
                  "the process (docs/ltsd.md), so here the wall times are the measure.\n\n";
        }
        std::map<std::string, std::map<std::string, json>> bySize;  // case -> "WxH" -> entry
        std::vector<std::string> order;
        for (const json& c : r["frames"]["cases"]) {
            const std::string name = c["case"];
            if (std::find(order.begin(), order.end(), name) == order.end()) order.push_back(name);
            bySize[name][std::to_string(c["width"].get<int>()) + " x " + std::to_string(c["height"].get<int>())] = c;
        }
        std::vector<std::string> sizes;
        for (const auto& [name, entries] : bySize)
            for (const auto& [size, entry] : entries)
                if (std::find(sizes.begin(), sizes.end(), size) == sizes.end()) sizes.push_back(size);
        std::sort(sizes.begin(), sizes.end(), [](const std::string& a, const std::string& b) {
            return std::stoi(a) != std::stoi(b) ? std::stoi(a) < std::stoi(b) : a < b;
        });
        md << "| case |";
        for (const std::string& s : sizes)
            md << " " << s << " (ms) |";
        md << " target | passes at the largest size (ms, share) |\n|---|";
        for (std::size_t i = 0; i < sizes.size(); ++i)
            md << "---:|";
        md << "---|---|\n";
        for (const std::string& name : order) {
            md << "| " << name << " |";
            const json* largest = nullptr;
            for (const std::string& s : sizes) {
                const auto it = bySize[name].find(s);
                if (it == bySize[name].end()) {
                    md << " |";
                    continue;
                }
                const json& c = it->second;
                if (c.contains("error")) {
                    md << " error |";
                    continue;
                }
                md << " " << ms(c["gpuMs"]) << " (" << ms(c["wallMs"]) << ") |";
                largest = &c;
            }
            if (largest && largest->contains("targetMs")) {
                md << " <= " << ms((*largest)["targetMs"]) << ": "
                   << (!largest->contains("met")       ? "not judged (a CPU device)"
                       : (*largest)["met"].get<bool>() ? "met"
                                                       : "**missed**")
                   << " |";
            } else {
                md << " — |";
            }
            if (largest) {
                const double total = (*largest)["gpuMs"];
                std::string passes;
                for (auto it = (*largest)["passes"].begin(); it != (*largest)["passes"].end(); ++it) {
                    const double v = it.value();
                    passes += (passes.empty() ? "" : ", ") + it.key() + " " + ms(v) +
                              (total > 0.0 ? " (" + fixed(100.0 * v / total, 0) + " %)" : "");
                }
                md << " " << (passes.empty() ? "one pass" : passes);
            }
            md << " |\n";
        }
        for (const json& c : r["frames"]["cases"])
            if (c.contains("error"))
                md << "\n- " << c["case"].get<std::string>() << " at " << c["width"] << " x " << c["height"] << ": "
                   << c["error"].get<std::string>() << "\n";
    }
    md << "\n## How it ran\n\n";
    md << "- `" << r["info"]["command"].get<std::string>() << "`: " << describeEnd(runFromJson(r["info"])) << "\n";
    if (r["frames"].contains("command")) md << "- `" << r["frames"]["command"].get<std::string>() << "`\n";
    md << "- library path: `" << env.value("libraryPath", "") << "`\n";
    md << "- logs: " << env.value("logs", "") << "\n";
    return md.str();
}

}  // namespace tyndall::gpucheck
