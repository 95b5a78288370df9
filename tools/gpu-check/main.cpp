// tyndall-gpu-check: what packaging/gpu-check.sh runs from an unpacked bundle (docs/gpu.md). Asks `tyndall info
// --json` for the device, runs every GPU test executable of the bundle (validation and synchronisation validation on)
// and the frame-time benchmark, each as a child process through the bundle's launcher with a time limit, and writes
// OUT/gpu-report.json and OUT/gpu-report.md (report.h), with every child's log under OUT/logs.
// Exit status: 0 when the verdict is "pass", 1 otherwise ("fail" or "no device"), 2 for bad arguments.
#include "report.h"

#include <CLI/CLI.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;
using nlohmann::json;
using namespace tyndall::gpucheck;

namespace {

std::string quoted(const std::vector<std::string>& argv) {
    std::string out;
    for (const std::string& a : argv) {
        const bool plain = a.find_first_of(" '\"*?:[]$\\") == std::string::npos && !a.empty();
        out += (out.empty() ? "" : " ") + (plain ? a : "'" + a + "'");
    }
    return out;
}

// Runs argv with `environment` added, stdout and stderr into `log`, in a process group of its own that is killed
// (SIGKILL) after `timeoutSeconds`.
ProcessRun runProcess(const std::vector<std::string>& argv,
                      const std::vector<std::pair<std::string, std::string>>& environment, const fs::path& log,
                      double timeoutSeconds, const fs::path& workingDirectory) {
    ProcessRun run;
    run.command = quoted(argv);
    run.log = log.string();
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid < 0) return run;
    if (pid == 0) {
        setpgid(0, 0);
        const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
            close(fd);
        }
        for (const auto& [name, value] : environment)
            setenv(name.c_str(), value.c_str(), 1);
        if (!workingDirectory.empty() && chdir(workingDirectory.c_str()) != 0) _exit(126);
        std::vector<char*> args;
        for (const std::string& a : argv)
            args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        execv(args[0], args.data());
        std::fprintf(stderr, "tyndall-gpu-check: cannot run %s\n", args[0]);
        _exit(127);
    }
    int status = 0;
    for (;;) {
        const pid_t done = waitpid(pid, &status, WNOHANG);
        if (done == pid) break;
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (elapsed > timeoutSeconds) {
            run.timedOut = true;
            kill(-pid, SIGKILL);
            waitpid(pid, &status, 0);
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (WIFEXITED(status)) run.exitCode = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) run.signal = WTERMSIG(status);
    return run;
}

std::string readText(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

json readJson(const fs::path& path) {
    std::ifstream in(path);
    if (!in) return nullptr;
    try {
        return json::parse(in);
    } catch (const json::exception&) {
        return nullptr;
    }
}

// The JSON document in a program's output (`tyndall info --json` prints nothing before it).
json jsonInText(const std::string& text) {
    const std::size_t start = text.find('{');
    if (start == std::string::npos) return nullptr;
    try {
        return json::parse(text.substr(start, text.rfind('}') + 1 - start));
    } catch (const json::exception&) {
        return nullptr;
    }
}

void writeAtomically(const fs::path& path, const std::string& text) {
    const fs::path temporary = path.string() + ".partial";
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out << text;
        if (!out.flush()) throw std::runtime_error("cannot write " + temporary.string());
    }
    fs::rename(temporary, path);
}

std::string utcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return text;
}

std::string hostName() {
    utsname u{};
    if (uname(&u) != 0) return "?";
    return std::string(u.nodename) + ", " + u.sysname + " " + u.release + " " + u.machine + ", " +
           std::to_string(std::thread::hardware_concurrency()) + " threads";
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{
        "Runs the GPU tests and frame-time benchmarks of a Tyndall bundle and writes gpu-report.json and "
        "gpu-report.md (run it through gpu-check.sh, which finds the driver)"};
    std::string bundle, out, environmentFile, benchFilter = "BM_Frame", benchSizes;
    int benchFrames = 10;
    std::vector<std::string> only;
    bool noTests = false, noBenchmarks = false;
    double testTimeout = 300.0, benchTimeout = 300.0;
    app.add_option("--bundle", bundle, "the unpacked bundle (default: $TYNDALL_BUNDLE, set by its launcher)");
    app.add_option("--out", out, "where the reports and logs go (created)")->required();
    app.add_option("--only", only,
                   "EXECUTABLE[=FILTER]: run only these test executables of the bundle (FILTER: --gtest_filter), "
                   "instead of every GPU test");
    app.add_flag("--no-tests", noTests, "run no tests");
    app.add_flag("--no-benchmarks", noBenchmarks, "run no benchmarks");
    app.add_option("--bench-filter", benchFilter, "--benchmark_filter of the frame-time benchmark");
    app.add_option("--bench-sizes", benchSizes, "frame sizes, e.g. 64x64,128x96 (default 512x512,1920x1080)");
    app.add_option("--bench-frames", benchFrames, "timed frames per case (after one untimed)")
        ->check(CLI::Range(1, 10000));
    app.add_option("--test-timeout", testTimeout, "seconds one test executable may run")->check(CLI::PositiveNumber);
    app.add_option("--bench-timeout", benchTimeout, "seconds the benchmarks may run")->check(CLI::PositiveNumber);
    app.add_option("--environment", environmentFile, "a JSON object of what gpu-check.sh found (driver files ...)");
    CLI11_PARSE(app, argc, argv);

    if (bundle.empty()) {
        if (const char* b = std::getenv("TYNDALL_BUNDLE")) bundle = b;
    }
    if (bundle.empty() || !fs::is_regular_file(fs::path(bundle) / "bin" / "tyndall-exec")) {
        std::fprintf(stderr,
                     "tyndall-gpu-check: --bundle: '%s' is not an unpacked Tyndall bundle (no bin/tyndall-exec)\n",
                     bundle.c_str());
        return 2;
    }
    const auto started = std::chrono::steady_clock::now();
    const fs::path root = fs::absolute(bundle), outDir = fs::absolute(out);
    const fs::path logs = outDir / "logs", results = outDir / "results", scratch = outDir / "scratch";
    for (const fs::path& dir : {outDir, logs, results, scratch})
        fs::create_directories(dir);
    const std::string exec = (root / "bin" / "tyndall-exec").string();

    json environment = json::object();
    if (!environmentFile.empty()) {
        environment = readJson(environmentFile);
        if (!environment.is_object()) {
            std::fprintf(stderr, "tyndall-gpu-check: --environment: '%s' is not a JSON object\n",
                         environmentFile.c_str());
            return 2;
        }
    }
    if (!environment.contains("date")) environment["date"] = utcNow();
    if (!environment.contains("host")) environment["host"] = hostName();
    environment["bundle"] = root.string();
    environment["logs"] = logs.string();

    std::fprintf(stderr, "tyndall-gpu-check: the device\n");
    const ProcessRun infoRun = runProcess({exec, "tyndall", "info", "--json"}, {}, logs / "info.log", 60.0, scratch);
    const json info = jsonInText(readText(logs / "info.log"));

    std::vector<TestRun> tests;
    ProcessRun framesRun;
    json frames;
    const bool haveDevice = info.is_object() && !info.contains("vulkanError");
    if (haveDevice && !noTests) {
        std::vector<TestSuite> suites;
        if (only.empty()) {
            suites = gpuTestSuites();
        } else {
            for (const std::string& o : only) {
                const std::size_t eq = o.find('=');
                suites.push_back({o.substr(0, eq), eq == std::string::npos ? "*" : o.substr(eq + 1)});
            }
        }
        for (const TestSuite& suite : suites) {
            std::fprintf(stderr, "tyndall-gpu-check: %s (%s)\n", suite.executable.c_str(), suite.filter.c_str());
            const fs::path result = results / (suite.executable + ".json"), log = logs / (suite.executable + ".log");
            fs::remove(result);
            const fs::path tmp = scratch / suite.executable;
            fs::create_directories(tmp);
            TestRun t;
            t.suite = suite;
            t.run = runProcess({exec, "tests/" + suite.executable, "--gtest_filter=" + suite.filter,
                                "--gtest_output=json:" + result.string()},
                               {{"TYNDALL_VULKAN_VALIDATION", "1"},
                                {"TYNDALL_ROOT", (root / "share" / "tyndall-tests").string()},
                                {"TYNDALL_TEST_SOURCE_DIR", (root / "share" / "tyndall-tests").string()},
                                {"TYNDALL_TEST_SPIRV_DIR", (root / "libexec" / "tests" / "spirv").string()},
                                {"TYNDALL_TEST_TMP", tmp.string()}},
                               log, testTimeout, tmp);
            t.gtest = readJson(result);
            t.logText = readText(log);
            tests.push_back(std::move(t));
        }
    }
    if (haveDevice && !noBenchmarks) {
        std::fprintf(stderr, "tyndall-gpu-check: frame times\n");
        const fs::path result = results / "frames.json";
        fs::remove(result);
        std::vector<std::pair<std::string, std::string>> env = {{"TYNDALL_BENCH_FRAMES", std::to_string(benchFrames)}};
        if (!benchSizes.empty()) env.emplace_back("TYNDALL_BENCH_SIZES", benchSizes);
        framesRun = runProcess({exec, "bench/tyndall_gpu_frames_bench", "--benchmark_filter=" + benchFilter,
                                "--benchmark_out=" + result.string(), "--benchmark_out_format=json"},
                               env, logs / "frames.log", benchTimeout, scratch);
        frames = readJson(result);
    }

    json report = buildReport(info, infoRun, tests, frames, framesRun, environment);
    report["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    try {
        writeAtomically(outDir / "gpu-report.json", report.dump(2) + "\n");
        writeAtomically(outDir / "gpu-report.md", markdownReport(report));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "tyndall-gpu-check: %s\n", e.what());
        return 1;
    }
    std::fprintf(stderr, "tyndall-gpu-check: %s; wrote %s and %s\n", report["verdict"].get<std::string>().c_str(),
                 (outDir / "gpu-report.json").c_str(), (outDir / "gpu-report.md").c_str());
    for (const json& p : report["problems"])
        std::fprintf(stderr, "  %s\n", p.get<std::string>().c_str());
    return report["verdict"] == "pass" ? 0 : 1;
}
