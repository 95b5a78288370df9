// `tyndall sweep`: a spec of renders (a project's views under a grid of --set overrides, seeds and sample counts or
// time budgets) expanded into a manifest of tasks, run by an executor (this machine, or Slurm job arrays), and
// gathered into metrics against references, CSV/JSON and plots. The spec format and the output folder are documented
// in docs/sweeps.md.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tyndall::cli {

struct SweepArgs {
    std::string spec;  // SPEC.json
    std::string out;   // --out DIR
    std::string executor = "local";
    int jobs = 1;                // local: tasks at a time
    int threads = 0;             // local: CPU threads of all tasks together (0: all); --run-task: of the task
    bool retryFailed = false;    // run the tasks that failed before again
    std::string status;          // --status DIR
    bool gather = false;         // --gather: gather --out's finished tasks (the Slurm gather job runs this)
    std::optional<int> runTask;  // --run-task K: run task K of --out's manifest (what executors start)
    // Slurm, passed to sbatch.
    std::string partition;
    std::string timeLimit;
    int cpusPerTask = 0;    // 0: 2
    int maxRunning = 0;     // the array's %M (0: every task at once)
    bool noSubmit = false;  // write the batch scripts and print the sbatch calls without submitting
};
int sweep(const SweepArgs& args);

// ---------------------------------------------------------------------------------------------------------------------
// The plan: what a spec expands to (sweep_spec.cpp).

enum class SweepTaskKind { View, ReferenceShard };

struct SweepTask {
    int index = 0;   // the line in manifest.jsonl, and the Slurm array index
    std::string id;  // 12 hex digits of the hash of everything the render depends on
    SweepTaskKind kind = SweepTaskKind::View;
    std::string view;  // the view rendered, or whose part of the scene the reference renders
    nlohmann::json point = nlohmann::json::object();  // axis -> value of this task's point of the sweep
    std::vector<std::string> sets;                    // every override, in order
    std::uint64_t seed = 0;
    int spp = 0;                // samples per pixel (0: time-bound)
    double time = 0.0;          // s (0: spp-bound)
    int shard = 0, shards = 1;  // a reference's shard
    std::string reference;      // the key of the reference it is compared against, or belongs to
    std::string output() const { return "tasks/" + id + ".exr"; }
};

struct SweepPlan {
    std::string specPath;
    std::string name;
    std::string project;               // absolute
    std::string projectFileHash;       // of the file's text: an edited project re-renders
    std::string size;                  // "WxH" or ""
    std::string measure;               // "spp" or "time"
    std::vector<std::string> axes;     // the swept paths, in the spec's order
    std::vector<std::string> metrics;  // extra metrics ("flip")
    std::string referenceImage;        // a given reference (absolute), else ""
    std::vector<SweepTask> tasks;      // the reference shards, then the views' renders
};

// Reads, validates and expands a spec. Every point, view and reference is checked as `tyndall render` would (the same
// validation as --set) before anything runs; InputError names the spec, the field and what is allowed.
SweepPlan planSweep(const std::string& specPath);

// manifest.jsonl holds one task a line; sweep.json the rest of the plan.
nlohmann::json taskToJson(const SweepTask& task, const SweepPlan& plan);
SweepTask taskFromJson(const nlohmann::json& json, const std::string& file, int line);
nlohmann::json planToJson(const SweepPlan& plan);
// The plan of an output folder (its sweep.json and manifest.jsonl); InputError names the file and line.
SweepPlan readPlan(const std::string& dir);

// Text of a plan for people (sweep_spec.cpp): an axis by its name where it is a technique parameter of every view
// ("views[{view}].parameters.nodes" -> "nodes"), else by its path; a value as it reads back (a string without quotes,
// null empty); a point as "axis = value, ..." (leaving out `except`).
std::string axisName(const std::string& axis);
std::string valueText(const nlohmann::json& value);
std::string pointText(const nlohmann::json& point, const std::string& except = "");

// ---------------------------------------------------------------------------------------------------------------------
// Task states, from the files in the output folder (sweep.cpp).

enum class TaskState { Pending, Running, Interrupted, Failed, Done };
const char* toString(TaskState state);

struct TaskStatus {
    TaskState state = TaskState::Pending;
    std::string detail;  // Failed: the exit code; Running: host, pid and since when; Pending: why it re-runs
};
TaskStatus taskStatus(const std::string& dir, const SweepTask& task);

// This program's path (/proc/self/exe): what the executors start, and where tyndall-plot is looked for.
std::string selfExecutable();

// ---------------------------------------------------------------------------------------------------------------------
// Gathering (sweep_gather.cpp): every task must be Done. Writes results.csv, results.json, references/ (merged shards)
// and plots/ (the equal-time table, plots.json and, through tyndall-plot, PNG and SVG). Returns the exit code.
int gatherSweep(const std::string& dir);

}  // namespace tyndall::cli
