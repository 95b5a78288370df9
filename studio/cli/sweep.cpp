// `tyndall sweep`: the command, the task runner and the executors (docs/sweeps.md).
#include "sweep.h"

#include "commands.h"
#include "progress.h"

#include "tyndall/core/error.h"
#include "tyndall/core/hash.h"
#include "tyndall/core/output.h"
#include "tyndall/core/text.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

extern char** environ;

namespace tyndall::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string hostName() {
    char name[256] = {};
    if (::gethostname(name, sizeof(name) - 1) != 0) return "?";
    return name;
}

std::string nowText() {
    const std::time_t now = std::time(nullptr);
    char text[32];
    std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    return text;
}

std::string readText(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::optional<json> readJson(const fs::path& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return std::nullopt;
    try {
        return json::parse(readText(path));
    } catch (const json::exception&) {
        return std::nullopt;
    }
}

fs::path marker(const std::string& dir, const SweepTask& task, const char* what) {
    return fs::path(dir) / "tasks" / (task.id + "." + what + ".json");
}

fs::path logOf(const std::string& dir, const SweepTask& task) {
    return fs::path(dir) / "logs" / (task.id + ".log");
}

// 'text' for a POSIX shell.
std::string shellQuoted(const std::string& text) {
    std::string quoted = "'";
    for (char c : text)
        quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

std::string describeTask(const SweepTask& t) {
    std::string text = t.kind == SweepTaskKind::View ? "view '" + t.view + "'" : "reference of '" + t.view + "'";
    if (!t.point.empty()) text += ", " + pointText(t.point);
    if (t.kind == SweepTaskKind::ReferenceShard) {
        text += ", " + std::to_string(t.spp) + " spp";
        if (t.shards > 1) text += " shard " + std::to_string(t.shard) + "/" + std::to_string(t.shards);
    } else {
        text += ", seed " + std::to_string(t.seed) + ", " +
                (t.spp > 0 ? std::to_string(t.spp) + " spp" : formatShort(t.time) + " s");
    }
    return text;
}

bool processAlive(long pid) {
    return pid > 0 && (::kill(pid_t(pid), 0) == 0 || errno == EPERM);
}

// The folder's manifest and plan, written all or nothing; the folders tasks execute in.
void writePlan(const std::string& dir, const SweepPlan& plan) {
    std::error_code ec;
    for (const char* sub : {"tasks", "logs", "references", "plots"})
        fs::create_directories(fs::path(dir) / sub, ec);
    if (ec) throw OutputError("cannot create the folders of " + dir + ": " + ec.message());
    std::string manifest;
    for (const SweepTask& t : plan.tasks)
        manifest += taskToJson(t, plan).dump() + "\n";
    OutputSet files;
    files.stage((fs::path(dir) / "manifest.jsonl").string(), manifest);
    files.stage((fs::path(dir) / "sweep.json").string(), planToJson(plan).dump(2) + "\n");
    files.commit();
}

// --------------------------------------------------------------------------------------------------------------------
// One task, as `tyndall sweep --run-task K --out DIR` runs it (on this machine or a Slurm node).

int runTask(const std::string& dir, int index, int threads) {
    SweepPlan plan = readPlan(dir);
    if (index < 0 || index >= int(plan.tasks.size()))
        throw InputError(InputLocation{"", 0, 0, "--run-task"},
                         "must be a task of the manifest, in [0, " + std::to_string(int(plan.tasks.size()) - 1) + "]");
    const SweepTask& task = plan.tasks[std::size_t(index)];
    if (taskStatus(dir, task).state == TaskState::Done) {
        std::printf("task %d (%s) is done already\n", index, task.id.c_str());
        return kOk;
    }
    // Its output goes to its own log from here on.
    const std::string log = logOf(dir, task).string();
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0) throw OutputError("cannot open the task's log " + log + ": " + std::strerror(errno));
    std::fflush(stdout);
    std::fflush(stderr);
    ::dup2(fd, STDOUT_FILENO);
    ::dup2(fd, STDERR_FILENO);
    ::close(fd);
    std::printf("== %s on %s, pid %ld: task %d %s: %s\n", nowText().c_str(), hostName().c_str(), long(::getpid()),
                index, task.id.c_str(), describeTask(task).c_str());
    std::fflush(stdout);

    std::error_code ec;
    fs::remove(marker(dir, task, "failed"), ec);
    writeFileAtomically(marker(dir, task, "running").string(),
                        json{{"host", hostName()}, {"pid", long(::getpid())}, {"since", nowText()}}.dump() + "\n");
    RenderArgs render;
    render.project = plan.project;
    render.view = task.view;
    render.reference = task.kind == SweepTaskKind::ReferenceShard;
    render.sets = task.sets;  // the size is among them
    if (task.spp > 0) render.spp = task.spp;
    if (task.time > 0.0) render.time = task.time;
    render.seed = task.seed;
    render.threads = threads;
    render.outs = {(fs::path(dir) / task.output()).string()};
    if (render.reference) render.shard = std::to_string(task.shard) + "/" + std::to_string(task.shards);
    const auto start = std::chrono::steady_clock::now();
    const int code = cli::render(render);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fflush(stdout);
    std::fflush(stderr);
    if (code == kOk) {
        const std::string bytes = readText(fs::path(dir) / task.output());
        writeFileAtomically(marker(dir, task, "done").string(), json{{"id", task.id},
                                                                     {"bytes", bytes.size()},
                                                                     {"checksum", hex16(fnv1a(bytes))},
                                                                     {"seconds", seconds},
                                                                     {"host", hostName()},
                                                                     {"finished", nowText()}}
                                                                        .dump() +
                                                                    "\n");
    } else {
        const bool cancelled = renderCancelled();
        writeFileAtomically(marker(dir, task, "failed").string(), json{{"exitCode", code},
                                                                       {"cancelled", cancelled},
                                                                       {"host", hostName()},
                                                                       {"log", log},
                                                                       {"finished", nowText()}}
                                                                          .dump() +
                                                                      "\n");
    }
    fs::remove(marker(dir, task, "running"), ec);
    std::printf("== %s: task %d %s (%.2f s)\n", nowText().c_str(), index, code == kOk ? "done" : "failed", seconds);
    return code;
}

// --------------------------------------------------------------------------------------------------------------------
// The local executor: tasks as child processes, `jobs` at a time.

struct Child {
    pid_t pid;
    const SweepTask* task;
};

pid_t spawnTask(const std::string& self, const std::string& dir, const SweepTask& task, int threads) {
    std::vector<std::string> argv{self,    "sweep", "--run-task", std::to_string(task.index),
                                  "--out", dir,     "--threads",  std::to_string(threads)};
    std::vector<char*> pointers;
    for (std::string& a : argv)
        pointers.push_back(a.data());
    pointers.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    // The task writes its own log; what it prints before (a broken manifest) goes there too.
    const std::string log = logOf(dir, task).string();
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    pid_t pid = 0;
    const int error = posix_spawn(&pid, self.c_str(), &actions, nullptr, pointers.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (error != 0) throw std::runtime_error("cannot start a task (" + self + "): " + std::strerror(error));
    return pid;
}

std::atomic<bool> gSweepInterrupted{false};
void onSweepInterrupt(int) {
    gSweepInterrupted.store(true);
}

int runLocal(const std::string& dir, const SweepPlan& plan, const std::vector<const SweepTask*>& todo, int jobs,
             int threads) {
    const std::string self = selfExecutable();
    const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
    const int total = threads > 0 ? threads : cores;
    const int perTask = std::max(1, total / jobs);
    std::printf("running %zu of %zu tasks here, %d at a time with %d threads each (logs in %s/logs)\n", todo.size(),
                plan.tasks.size(), jobs, perTask, dir.c_str());
    std::fflush(stdout);
    gSweepInterrupted.store(false);
    auto previous = std::signal(SIGINT, onSweepInterrupt);
    ProgressBar bar("sweep");
    std::vector<Child> running;
    std::size_t next = 0, finished = 0;
    std::vector<const SweepTask*> failed, interrupted;
    const bool tty = ::isatty(STDERR_FILENO) != 0;
    while (finished < todo.size()) {
        while (!gSweepInterrupted.load() && next < todo.size() && int(running.size()) < jobs) {
            running.push_back({spawnTask(self, dir, *todo[next], perTask), todo[next]});
            ++next;
        }
        if (running.empty()) break;  // interrupted: nothing more starts
        int status = 0;
        const pid_t pid = ::waitpid(-1, &status, 0);
        if (pid < 0) {
            if (errno == EINTR) continue;
            throw std::runtime_error(std::string("waiting for a task: ") + std::strerror(errno));
        }
        auto it = std::find_if(running.begin(), running.end(), [&](const Child& c) { return c.pid == pid; });
        if (it == running.end()) continue;
        const SweepTask& task = *it->task;
        running.erase(it);
        ++finished;
        const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
        if (!ok) {
            // A task killed before it could say so leaves no marker of its own.
            if (!fs::exists(marker(dir, task, "failed")) && !fs::exists(marker(dir, task, "done"))) {
                const bool signalled = WIFSIGNALED(status);
                const std::string why = signalled ? "killed by signal " + std::to_string(WTERMSIG(status))
                                                  : "exit " + std::to_string(WEXITSTATUS(status));
                // SIGINT or SIGTERM that arrived before the task installed its handlers still cancel it.
                const bool cancelSignal = signalled && (WTERMSIG(status) == SIGINT || WTERMSIG(status) == SIGTERM);
                writeFileAtomically(marker(dir, task, "failed").string(),
                                    json{{"exitCode", WIFEXITED(status) ? WEXITSTATUS(status) : -1},
                                         {"cancelled", gSweepInterrupted.load() || cancelSignal},
                                         {"why", why},
                                         {"host", hostName()},
                                         {"log", logOf(dir, task).string()},
                                         {"finished", nowText()}}
                                            .dump() +
                                        "\n");
                std::error_code ec;
                fs::remove(marker(dir, task, "running"), ec);
            }
        }
        // A task cancelled (SIGINT or SIGTERM) is interrupted, not failed: it runs again.
        const bool cancelled = !ok && taskStatus(dir, task).state == TaskState::Interrupted;
        if (!ok) (cancelled ? interrupted : failed).push_back(&task);
        const char* outcome = ok ? "done" : cancelled ? "CANCELLED" : "FAILED";
        if (tty) {
            bar.update(double(finished) / double(todo.size()));
            if (!ok)
                std::fprintf(stderr, "\r%s: task %d %s (%s), log %s\n", outcome, task.index, task.id.c_str(),
                             describeTask(task).c_str(), logOf(dir, task).c_str());
        } else {
            std::printf("[%zu/%zu] %s task %d %s: %s\n", finished, todo.size(), outcome, task.index, task.id.c_str(),
                        describeTask(task).c_str());
            std::fflush(stdout);
        }
    }
    bar.finish();
    std::signal(SIGINT, previous);
    if (gSweepInterrupted.load()) {
        std::fprintf(stderr,
                     "tyndall: sweep interrupted; run the same command again to resume (finished tasks are "
                     "kept)\n");
        return kFailure;
    }
    if (!failed.empty()) {
        std::fprintf(stderr, "tyndall: %zu task(s) failed; nothing was gathered:\n", failed.size());
        for (const SweepTask* t : failed)
            std::fprintf(stderr, "  task %d %s (%s): log %s\n", t->index, t->id.c_str(), describeTask(*t).c_str(),
                         logOf(dir, *t).c_str());
        std::fprintf(stderr, "fix the cause and run again with --retry-failed\n");
        return kFailure;
    }
    if (!interrupted.empty()) {
        std::fprintf(stderr,
                     "tyndall: %zu task(s) were cancelled; nothing was gathered; run the same command again to "
                     "resume\n",
                     interrupted.size());
        return kFailure;
    }
    return kOk;
}

// --------------------------------------------------------------------------------------------------------------------
// The Slurm executor: one job array of the tasks to run, and a gather job after it.

std::string findOnPath(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path ? path : "");
    for (std::string d; std::getline(dirs, d, ':');) {
        if (d.empty()) continue;
        const fs::path candidate = fs::path(d) / program;
        if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate)) return candidate.string();
    }
    return "";
}

// Runs a command line through the shell; its output and exit code.
std::pair<int, std::string> runShell(const std::string& command) {
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (!pipe) throw std::runtime_error("cannot run " + command);
    std::string output;
    char buffer[4096];
    while (std::size_t n = std::fread(buffer, 1, sizeof(buffer), pipe))
        output.append(buffer, n);
    const int status = ::pclose(pipe);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

// "0-11%4" for a fresh sweep, "3,7,9%4" for the tasks left of a resumed one.
std::string arrayRange(const std::vector<const SweepTask*>& todo, const SweepPlan& plan, int maxRunning) {
    std::string range;
    if (todo.size() == plan.tasks.size()) {
        range = "0-" + std::to_string(plan.tasks.size() - 1);
    } else {
        for (std::size_t i = 0; i < todo.size(); ++i) {
            std::size_t j = i;
            while (j + 1 < todo.size() && todo[j + 1]->index == todo[j]->index + 1)
                ++j;
            range += (range.empty() ? "" : ",") + std::to_string(todo[i]->index);
            if (j > i) range += "-" + std::to_string(todo[j]->index);
            i = j;
        }
    }
    if (maxRunning > 0) range += "%" + std::to_string(maxRunning);
    return range;
}

int submitSlurm(const std::string& dir, const SweepPlan& plan, const std::vector<const SweepTask*>& todo,
                const SweepArgs& args) {
    const std::string sbatch = findOnPath("sbatch");
    if (sbatch.empty() && !args.noSubmit)
        throw InputError(InputLocation{"", 0, 0, "--executor"},
                         "slurm needs sbatch on the PATH (Slurm's client commands, Debian package slurm-client); "
                         "--no-submit writes the batch scripts without it");
    const std::string self = selfExecutable();
    const std::string absDir = fs::absolute(dir).lexically_normal().string();
    const int cpus = args.cpusPerTask > 0 ? args.cpusPerTask : 2;
    std::string options;
    if (!args.partition.empty()) options += "#SBATCH --partition=" + args.partition + "\n";
    if (!args.timeLimit.empty()) options += "#SBATCH --time=" + args.timeLimit + "\n";
    const std::string array =
        "#!/bin/bash\n"
        "# tyndall sweep '" +
        plan.name + "': task $SLURM_ARRAY_TASK_ID of " + absDir +
        "/manifest.jsonl\n"
        "# (its log: logs/<id>.log; Slurm's own output: logs/slurm-<job>_<task>.out).\n"
        "#SBATCH --job-name=tyndall-sweep\n"
        "#SBATCH --array=" +
        arrayRange(todo, plan, args.maxRunning) +
        "\n"
        "#SBATCH --cpus-per-task=" +
        std::to_string(cpus) +
        "\n"
        "#SBATCH --output=" +
        absDir + "/logs/slurm-%A_%a.out\n" + options + "exec " + shellQuoted(self) +
        " sweep --run-task \"$SLURM_ARRAY_TASK_ID\" --out " + shellQuoted(absDir) +
        " --threads \"${SLURM_CPUS_PER_TASK:-" + std::to_string(cpus) + "}\"\n";
    const std::string gather =
        "#!/bin/bash\n"
        "# tyndall sweep '" +
        plan.name +
        "': metrics, tables and plots of every task, after they all succeeded.\n"
        "#SBATCH --job-name=tyndall-sweep-gather\n"
        "#SBATCH --cpus-per-task=" +
        std::to_string(cpus) +
        "\n"
        "#SBATCH --output=" +
        absDir + "/logs/slurm-gather-%j.out\n" + options + "exec " + shellQuoted(self) + " sweep --gather --out " +
        shellQuoted(absDir) + "\n";
    std::error_code ec;
    fs::create_directories(fs::path(dir) / "slurm", ec);
    const std::string arrayScript = (fs::path(absDir) / "slurm" / "array.sh").string();
    const std::string gatherScript = (fs::path(absDir) / "slurm" / "gather.sh").string();
    OutputSet files;
    files.stage(arrayScript, array);
    files.stage(gatherScript, gather);
    files.commit();
    const std::string arrayCall = "sbatch --parsable " + shellQuoted(arrayScript);
    if (args.noSubmit) {
        std::printf(
            "wrote %s and %s; submit them with\n  id=$(%s)\n  sbatch --parsable --dependency=afterok:$id "
            "--kill-on-invalid-dep=yes %s\n",
            arrayScript.c_str(), gatherScript.c_str(), arrayCall.c_str(), shellQuoted(gatherScript).c_str());
        return kOk;
    }
    const auto jobId = [](const std::string& output) {  // "123" or "123;cluster"
        std::string id = output.substr(0, output.find_first_of(";\n"));
        return !id.empty() && id.find_first_not_of("0123456789") == std::string::npos ? id : std::string();
    };
    const auto [arrayCode, arrayOut] = runShell(shellQuoted(sbatch) + " --parsable " + shellQuoted(arrayScript));
    const std::string arrayJob = jobId(arrayOut);
    if (arrayCode != 0 || arrayJob.empty())
        throw std::runtime_error("sbatch refused the task array (exit " + std::to_string(arrayCode) + "): " + arrayOut);
    const auto [gatherCode, gatherOut] = runShell(shellQuoted(sbatch) + " --parsable --dependency=afterok:" + arrayJob +
                                                  " --kill-on-invalid-dep=yes " + shellQuoted(gatherScript));
    const std::string gatherJob = jobId(gatherOut);
    if (gatherCode != 0 || gatherJob.empty())
        throw std::runtime_error("sbatch refused the gather job (exit " + std::to_string(gatherCode) +
                                 "; the array job " + arrayJob + " runs): " + gatherOut);
    writeFileAtomically(
        (fs::path(dir) / "slurm" / "jobs.json").string(),
        json{{"array", arrayJob}, {"gather", gatherJob}, {"tasks", todo.size()}, {"submitted", nowText()}}.dump(2) +
            "\n");
    std::printf(
        "submitted %zu task(s) as Slurm array job %s and the gather job %s (it runs when every task "
        "succeeded); follow it with\n  tyndall sweep --status %s\n",
        todo.size(), arrayJob.c_str(), gatherJob.c_str(), dir.c_str());
    return kOk;
}

// --------------------------------------------------------------------------------------------------------------------

int showStatus(const std::string& dir) {
    const SweepPlan plan = readPlan(dir);
    std::map<TaskState, int> counts;
    std::vector<std::pair<const SweepTask*, TaskStatus>> notable;
    for (const SweepTask& t : plan.tasks) {
        const TaskStatus s = taskStatus(dir, t);
        ++counts[s.state];
        if (s.state != TaskState::Done && s.state != TaskState::Pending) notable.emplace_back(&t, s);
    }
    std::printf("sweep '%s' in %s: %zu tasks: %d done, %d running, %d failed, %d interrupted, %d pending\n",
                plan.name.c_str(), dir.c_str(), plan.tasks.size(), counts[TaskState::Done], counts[TaskState::Running],
                counts[TaskState::Failed], counts[TaskState::Interrupted], counts[TaskState::Pending]);
    if (const auto jobs = readJson(fs::path(dir) / "slurm" / "jobs.json"))
        std::printf("Slurm: array job %s, gather job %s (submitted %s)\n",
                    jobs->value("array", std::string("?")).c_str(), jobs->value("gather", std::string("?")).c_str(),
                    jobs->value("submitted", std::string("?")).c_str());
    for (const auto& [task, s] : notable)
        std::printf("  %-11s task %d %s: %s; %s\n", toString(s.state), task->index, task->id.c_str(),
                    describeTask(*task).c_str(), s.detail.c_str());
    const bool gathered = fs::exists(fs::path(dir) / "results.csv");
    if (counts[TaskState::Done] == int(plan.tasks.size()))
        std::printf(gathered ? "gathered: %s/results.csv\n"
                             : "every task is done; gather with tyndall sweep --gather "
                               "--out %s\n",
                    dir.c_str());
    return kOk;
}

}  // namespace

std::string selfExecutable() {
    // The relocatable bundle runs the program through its own dynamic loader (/proc/self/exe is the loader there); its
    // launcher names itself (packaging/bundle.sh).
    if (const char* launcher = std::getenv("TYNDALL_EXECUTABLE"); launcher && *launcher) return launcher;
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw std::runtime_error("cannot find this program's path (/proc/self/exe): " + ec.message());
    return self.string();
}

const char* toString(TaskState state) {
    switch (state) {
        case TaskState::Pending:
            return "pending";
        case TaskState::Running:
            return "running";
        case TaskState::Interrupted:
            return "interrupted";
        case TaskState::Failed:
            return "failed";
        case TaskState::Done:
            return "done";
    }
    return "?";
}

TaskStatus taskStatus(const std::string& dir, const SweepTask& task) {
    if (const auto done = readJson(marker(dir, task, "done"))) {
        const fs::path output = fs::path(dir) / task.output();
        std::error_code ec;
        if (done->value("id", std::string()) == task.id && fs::is_regular_file(output, ec) &&
            fs::file_size(output, ec) == done->value("bytes", std::uintmax_t(0))) {
            if (hex16(fnv1a(readText(output))) == done->value("checksum", std::string())) return {TaskState::Done, ""};
        }
        return {TaskState::Pending, "its output does not match its record (re-runs)"};
    }
    if (const auto failed = readJson(marker(dir, task, "failed"))) {
        const std::string where = " on " + failed->value("host", std::string("?")) + ", log " +
                                  failed->value("log", logOf(dir, task).string());
        // Cancelled (Ctrl-C, scancel, a time limit: SIGINT or SIGTERM) is not the task's failure: it runs again.
        if (failed->value("cancelled", false)) return {TaskState::Interrupted, "cancelled" + where + " (re-runs)"};
        std::string detail = "exit " + std::to_string(failed->value("exitCode", -1));
        if (failed->contains("why")) detail = failed->value("why", detail);
        return {TaskState::Failed, detail + where};
    }
    if (const auto running = readJson(marker(dir, task, "running"))) {
        const std::string host = running->value("host", std::string("?"));
        const long pid = running->value("pid", 0L);
        if (host == hostName() && !processAlive(pid))
            return {TaskState::Interrupted, "its process " + std::to_string(pid) + " ended without a result (re-runs)"};
        return {TaskState::Running,
                "on " + host + ", pid " + std::to_string(pid) + ", since " + running->value("since", std::string("?"))};
    }
    return {TaskState::Pending, ""};
}

int sweep(const SweepArgs& args) {
    return guarded([&]() -> int {
        if (!args.status.empty()) return showStatus(args.status);
        if (args.out.empty()) throw InputError(InputLocation{"", 0, 0, "--out"}, "name the sweep's output folder");
        if (args.runTask) return runTask(args.out, *args.runTask, args.threads);
        if (args.gather) return gatherSweep(args.out);
        if (args.spec.empty())
            throw InputError(InputLocation{"", 0, 0, "spec"}, "name the sweep spec (SPEC.json; docs/sweeps.md)");
        if (args.executor != "local" && args.executor != "slurm")
            throw InputError(InputLocation{"", 0, 0, "--executor"},
                             "'" + clipForMessage(args.executor) + "' is not an executor: local or slurm");
        if (args.jobs < 1) throw InputError(InputLocation{"", 0, 0, "--jobs"}, "must be at least 1");
        if (fs::exists(args.out) && !fs::is_directory(args.out))
            throw InputError(InputLocation{"", 0, 0, "--out"}, "'" + args.out + "' is a file; name a folder");
        if (fs::exists(fs::path(args.out) / "manifest.jsonl") && !fs::exists(fs::path(args.out) / "sweep.json"))
            throw InputError(InputLocation{"", 0, 0, "--out"},
                             "'" + args.out + "' holds a manifest without its sweep.json");

        const SweepPlan plan = planSweep(args.spec);  // everything is checked before anything runs
        // Running tasks (of Slurm jobs, or another sweep here) read the manifest by line: it must not change under
        // them.
        if (fs::exists(fs::path(args.out) / "manifest.jsonl") && fs::exists(fs::path(args.out) / "sweep.json")) {
            std::optional<SweepPlan> previous;
            try {
                previous = readPlan(args.out);
            } catch (const InputError&) {  // a broken old plan is replaced
            }
            const auto sameTasks = [&] {
                if (previous->tasks.size() != plan.tasks.size()) return false;
                for (std::size_t i = 0; i < plan.tasks.size(); ++i)
                    if (previous->tasks[i].id != plan.tasks[i].id) return false;
                return true;
            };
            if (previous && !sameTasks())
                for (const SweepTask& t : previous->tasks)
                    if (const TaskStatus s = taskStatus(args.out, t); s.state == TaskState::Running)
                        throw InputError(InputLocation{args.spec, 0, 0, ""},
                                         "changes the tasks of the sweep in " + args.out + " while its task " +
                                             std::to_string(t.index) + " is running (" + s.detail +
                                             "); wait for its tasks or cancel them first");
        }
        writePlan(args.out, plan);
        std::vector<const SweepTask*> todo;
        std::vector<std::pair<const SweepTask*, TaskStatus>> failedBefore;
        std::size_t done = 0, running = 0;
        for (const SweepTask& t : plan.tasks) {
            const TaskStatus s = taskStatus(args.out, t);
            if (s.state == TaskState::Done)
                ++done;
            else if (s.state == TaskState::Failed && !args.retryFailed)
                failedBefore.emplace_back(&t, s);
            else if (s.state == TaskState::Running && args.executor == "local")
                throw InputError(InputLocation{"", 0, 0, "--out"},
                                 "task " + std::to_string(t.index) + " is running (" + s.detail +
                                     "); wait for it, or stop it, before running this sweep again");
            else if (s.state == TaskState::Running)  // a Slurm task of an earlier submission: not submitted twice
                ++running;
            else
                todo.push_back(&t);
        }
        if (running > 0)
            std::printf(
                "%zu task(s) are running from an earlier submission and are not submitted again (if one is "
                "not, remove its tasks/<id>.running.json)\n",
                running);
        const std::size_t failed = failedBefore.size();
        std::printf("sweep '%s': %zu tasks (%zu done before, %zu failed before%s), manifest %s/manifest.jsonl\n",
                    plan.name.c_str(), plan.tasks.size(), done, failed,
                    failed > 0 && !args.retryFailed ? ", not re-run without --retry-failed" : "", args.out.c_str());
        for (const auto& [t, s] : failedBefore)
            std::fprintf(stderr, "  failed before: task %d %s (%s): %s\n", t->index, t->id.c_str(),
                         describeTask(*t).c_str(), s.detail.c_str());
        std::fflush(stdout);
        if (args.executor == "slurm") {
            if (!todo.empty()) return submitSlurm(args.out, plan, todo, args);
            if (failed > 0) return int(kFailure);
            if (running > 0) return int(kOk);  // their gather job comes after them
            return gatherSweep(args.out);
        }
        if (!todo.empty())
            if (const int code = runLocal(args.out, plan, todo, args.jobs, args.threads); code != kOk) return code;
        if (failed > 0) {
            std::fprintf(stderr,
                         "tyndall: %zu task(s) failed before; nothing was gathered (--retry-failed runs them "
                         "again)\n",
                         failed);
            return int(kFailure);
        }
        return gatherSweep(args.out);
    });
}

}  // namespace tyndall::cli
