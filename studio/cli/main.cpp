// tyndall: the headless command line of Tyndall. Renders views and references, validates projects, compares images,
// and reads techniques' probes.
#include "commands.h"
#include "sweep.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <string>

namespace {

// CLI11 converts "-1" to 2^64 - 1 for an unsigned option and accepts "nan" for a double: these validators refuse
// what the conversions would change silently.
const CLI::Validator kSeed(
    [](const std::string& text) -> std::string {
        if (text.empty() || text.size() > 20 || text.find_first_not_of("0123456789") != std::string::npos ||
            (text.size() == 20 && text > "18446744073709551615"))
            return "must be an integer in [0, 18446744073709551615], got '" + text.substr(0, 40) + "'";
        return "";
    },
    "UINT64");

const CLI::Validator kFinite(
    [](const std::string& text) -> std::string {
        std::size_t end = 0;
        double value = 0.0;
        try {
            value = std::stod(text, &end);
        } catch (const std::exception&) {
            return "must be a number, got '" + text.substr(0, 40) + "'";
        }
        if (end != text.size() || !std::isfinite(value)) return "must be a finite number, got '" + text.substr(0, 40) + "'";
        return "";
    },
    "FINITE");

}  // namespace

int main(int argc, char** argv) {
    using namespace tyndall::cli;
    CLI::App app{"Tyndall: render, validate and compare volumetric rendering techniques"};
    app.require_subcommand(1);
    app.set_version_flag("--version", TYNDALL_VERSION);

    RenderArgs render;
    CLI::App* renderCmd = app.add_subcommand("render", "render a view, or the reference, of a project to images");
    renderCmd->add_option("project", render.project, "project file (.json)")->required();
    renderCmd->add_option("--view", render.view, "the view to render (with --reference: the view whose part of the scene the reference renders)");
    renderCmd->add_flag("--reference", render.reference, "render the reference instead of the view's technique");
    renderCmd->add_option("--set", render.sets, "override a project field: path=value, e.g. media[0].sigma_s=[0.1,0.1,0.1]");
    renderCmd->add_option("--spp", render.spp, "samples per pixel");
    renderCmd->add_option("--size", render.size, "image size WIDTHxHEIGHT");
    renderCmd->add_option("--seed", render.seed, "random seed")->check(kSeed);
    renderCmd->add_option("--time", render.time,
                          "render until this many seconds (progressive techniques; --spp beside it is a cap)");
    renderCmd->add_option("--threads", render.threads, "CPU threads (0: all)")->check(CLI::Range(0, 4096));
    renderCmd->add_option("--out,-o", render.outs, "output image(s): .exr (float + metadata) or .png (tonemapped)");
    renderCmd->add_option("--exposure", render.exposure, "exposure in stops for PNG output (default: the view's)")
        ->check(kFinite);
    renderCmd->add_option("--display", render.display,
                          "OpenColorIO display of PNG output, after the exposure (default: the config's default "
                          "display; tyndall info lists them)");
    renderCmd->add_option("--ocio-view", render.ocioView,
                          "OpenColorIO view of that display (default: the display's default view; --view names the "
                          "project's view)");
    renderCmd->add_option("--ocio", render.ocio,
                          "OpenColorIO config file (default: $OCIO, else the shipped config, else OpenColorIO's raw "
                          "config)");
    renderCmd->add_option("--tonemap", render.tonemap,
                          "Tyndall's own display transform of PNG output instead of OpenColorIO's: srgb (clamped), "
                          "reinhard, aces (Narkowicz's fit), falsecolour (log2 luminance in viridis, -10 to +2 EV)");

    renderCmd->add_option(
        "--shard", render.shard,
        "I/N: render the I-th (from 0) of N equal shares of the samples per pixel, with a seed derived "
        "from the render's and I; merge the shards with tyndall merge");

    MergeArgs mergeArgs;
    CLI::App* mergeCmd = app.add_subcommand(
        "merge",
        "merge shards of one render (tyndall render --shard I/N) into one image: spp-weighted means, pooled "
        "variance, summed times");
    mergeCmd->add_option("images", mergeArgs.images, "the shards (.exr)")->required();
    mergeCmd->add_option("--out,-o", mergeArgs.out, "the merged image (.exr)")->required();

    SweepArgs sweepArgs;
    CLI::App* sweepCmd = app.add_subcommand(
        "sweep",
        "render a sweep (docs/sweeps.md): views under a grid of --set overrides, seeds and sample counts or time "
        "budgets, on this machine or on Slurm; gathered into metrics against references, CSV, JSON and plots");
    sweepCmd->add_option("spec", sweepArgs.spec, "the sweep spec (.json)");
    sweepCmd->add_option("--out,-o", sweepArgs.out,
                         "the output folder: manifest.jsonl, tasks/, logs/, references/, results.csv, results.json, "
                         "plots/ (a re-run resumes: finished tasks are kept)");
    sweepCmd->add_option("--executor", sweepArgs.executor,
                         "local (default: this machine) or slurm (a job array and a "
                         "gather job, through sbatch)");
    sweepCmd->add_option("--jobs,-j", sweepArgs.jobs, "local: tasks at a time (default 1)")->check(CLI::Range(1, 256));
    sweepCmd->add_option("--threads", sweepArgs.threads, "CPU threads of the tasks together (0: all)")
        ->check(CLI::Range(0, 4096));
    sweepCmd->add_flag("--retry-failed", sweepArgs.retryFailed, "run the tasks that failed before again");
    sweepCmd->add_option("--status", sweepArgs.status,
                         "show the done, running, failed and pending tasks of a sweep's "
                         "output folder, and the logs of the failed ones");
    sweepCmd->add_flag("--gather", sweepArgs.gather,
                       "gather the finished tasks of --out (the Slurm gather job runs "
                       "this)");
    sweepCmd->add_option("--run-task", sweepArgs.runTask, "run task K of --out's manifest (what the executors start)")
        ->check(CLI::Range(0, 1 << 30));
    sweepCmd->add_option("--partition", sweepArgs.partition, "slurm: the partition (sbatch --partition)");
    sweepCmd->add_option("--time", sweepArgs.timeLimit, "slurm: each task's time limit (sbatch --time, e.g. 30:00)");
    sweepCmd->add_option("--cpus-per-task", sweepArgs.cpusPerTask, "slurm: CPUs of each task (default 2)")
        ->check(CLI::Range(1, 4096));
    sweepCmd
        ->add_option("--max-running", sweepArgs.maxRunning,
                     "slurm: tasks running at once (the array's %M; "
                     "default: no limit)")
        ->check(CLI::Range(1, 1 << 20));
    sweepCmd->add_flag("--no-submit", sweepArgs.noSubmit,
                       "slurm: write the batch scripts and print the sbatch calls, without submitting");

    ValidateArgs validate;
    CLI::App* validateCmd = app.add_subcommand("validate", "check project files; each problem names the file, the field and what is allowed");
    validateCmd->add_option("projects", validate.projects, "project files")->required();
    validateCmd->add_option("--set", validate.sets, "override a project field: path=value");

    CompareArgs compare;
    CLI::App* compareCmd = app.add_subcommand("compare", "error metrics of images against a reference image");
    compareCmd->add_option("images", compare.images, "images to compare (.exr)")->required();
    compareCmd->add_option("--reference,-r", compare.reference, "the reference image (.exr)")->required();
    compareCmd->add_option("--exposure", compare.exposure, "exposure in stops for PSNR (default: the reference's)")
        ->check(kFinite);
    compareCmd->add_option("--region", compare.region, "x,y,width,height in pixels");
    compareCmd->add_option("--json", compare.json, "write the metrics as JSON");
    compareCmd->add_option("--csv", compare.csv, "write the metrics as CSV");
    compareCmd->add_option("--diff", compare.diff, "write a false-colour difference image ({name} is replaced by each image's name)");
    compareCmd->add_option("--diff-kind", compare.diffKind, "signed, absolute or relative");
    compareCmd->add_option("--metric", compare.metrics,
                           "an extra metric: flip (HDR-FLIP: mean, weighted median and quartiles of its error map)");
    compareCmd->add_option("--flip-map", compare.flipMaps,
                           "with --metric flip: write each image's FLIP error map, as .exr (channels FLIP, exposure) "
                           "or .png (the error in the magma colour map); repeatable; {name} is replaced by each "
                           "image's name");
    compareCmd->add_option(
        "--flip-histogram", compare.flipHistogram,
        "with --metric flip: write each image's weighted FLIP histogram as .csv (100 bins: low, high, "
        "pixels, weightedShare; {name} is replaced by each image's name)");
    compareCmd
        ->add_option("--ppd", compare.pixelsPerDegree,
                     "FLIP's observer in pixels per degree (default 67.02: a 0.7 m wide 4K monitor at 0.7 m)")
        ->check(kFinite);
    compareCmd->add_option("--tone-mapper", compare.toneMapper,
                           "HDR-FLIP's tone mapper: aces (default), hable, reinhard");
    compareCmd->add_option("--diff-scale", compare.diffScale, "difference at the ends of the colour map (default: 10% of the reference's mean luminance)")
        ->check(kFinite);

    ProbeArgs probe;
    CLI::App* probeCmd = app.add_subcommand("probe", "the data behind a technique's plots at a pixel, e.g. sampled-distance histograms and pdfs");
    probeCmd->add_option("project", probe.project, "project file (.json)")->required();
    probeCmd->add_option("--view", probe.view, "the view whose technique and part of the scene to probe")->required();
    probeCmd->add_option("--probe", probe.probe, "the probe's name (tyndall info lists them)")->required();
    probeCmd->add_option("--pixel", probe.pixel, "x,y in pixels (default: the image centre)");
    probeCmd->add_option("--set", probe.sets, "override a project field: path=value");
    probeCmd->add_option("--spp", probe.spp, "samples per pixel, for probes that render");
    probeCmd->add_option("--size", probe.size, "image size WIDTHxHEIGHT");
    probeCmd->add_option("--seed", probe.seed, "random seed")->check(kSeed);
    probeCmd->add_option("--csv", probe.csv, "write the series as CSV (series,x,y)");
    probeCmd->add_option("--json", probe.json, "write the result as JSON");

    InfoArgs info;
    CLI::App* infoCmd =
        app.add_subcommand("info", "devices, version, OpenColorIO displays and views, techniques and their parameters");
    infoCmd->add_flag("--json", info.json, "print as JSON");
    infoCmd->add_option("--ocio", info.ocio,
                        "OpenColorIO config whose displays and views to list (default: $OCIO, else "
                        "the shipped config)");

    TablesArgs tablesArgs;
    CLI::App* tablesCmd = app.add_subcommand(
        "tables", "the fitted tables (LTSD of phase functions, LTC of GGX): layout, provenance and error summary "
                  "(docs/tables.md)");
    tablesCmd->add_option("names", tablesArgs.names,
                          "tables to describe in detail, with their error against g or alpha (e.g. hg, ggx-aniso); "
                          "default: a summary of every table");
    tablesCmd->add_option("--tables", tablesArgs.tables, "folder holding the tables (default: installed with tyndall; or $TYNDALL_TABLES_DIR)");
    tablesCmd->add_flag("--json", tablesArgs.json, "print as JSON");
    tablesCmd->require_subcommand(0, 1);
    TablesEvalArgs evalArgs;
    CLI::App* evalCmd = tablesCmd->add_subcommand(
        "eval", "the LTSD value of a phase function's integral over a spherical polygon, against adaptive quadrature (JSON)");
    evalCmd->add_option("--tables", evalArgs.tables, "folder holding the tables");
    evalCmd->add_option("--phase", evalArgs.phase, "phase function as in a project, e.g. '{\"type\":\"hg\",\"g\":0.5}'")->required();
    evalCmd->add_option("--polygon", evalArgs.polygon,
                        "vertices as directions in the frame where omega_o (towards the viewer) is +z, e.g. "
                        "'[[0.1,0,-1],[0,0.1,-1],[-0.1,-0.1,-1]]'; convex, inside a hemisphere, at most 9")
        ->required();

    PlotArgs plotArgs;
    CLI::App* plotCmd = app.add_subcommand("plot", "the data of the studio's plots as CSV, e.g. for papers");
    plotCmd->require_subcommand(1);
    CLI::App* polarCmd = plotCmd->add_subcommand(
        "ltsd-polar", "HG against its LTSD fit in a plane through omega_o (the LTSD paper's Fig. 12): psi,phase,fitted,hemisphere");
    polarCmd->add_option("--g", plotArgs.g, "HG's asymmetry, in (-1, 1)")->required()->check(kFinite);
    CLI::App* errorCmd = plotCmd->add_subcommand("ltsd-error", "the LTSD fit's error against g: g,tvUpper,tvLower,bound");
    for (CLI::App* cmd : {polarCmd, errorCmd}) {
        cmd->add_option("--out,-o", plotArgs.out, "output file (.csv)")->required();
        cmd->add_option("--tables", plotArgs.tables, "folder holding the tables (default: installed with tyndall; or $TYNDALL_TABLES_DIR)");
        cmd->add_option("--points", plotArgs.points, "samples (default: 720 over psi, 101 over g, as the studio draws them)");
    }

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        int code = app.exit(e);
        return code == 0 ? 0 : kBadInput;
    }
    if (renderCmd->parsed()) return tyndall::cli::render(render);
    if (validateCmd->parsed()) return tyndall::cli::validate(validate);
    if (mergeCmd->parsed()) return tyndall::cli::merge(mergeArgs);
    if (sweepCmd->parsed()) return tyndall::cli::sweep(sweepArgs);
    if (compareCmd->parsed()) return tyndall::cli::compare(compare);
    if (probeCmd->parsed()) return tyndall::cli::probe(probe);
    if (infoCmd->parsed()) return tyndall::cli::info(info);
    if (evalCmd->parsed()) {
        if (evalArgs.tables.empty()) evalArgs.tables = tablesArgs.tables;
        return tyndall::cli::tablesEval(evalArgs);
    }
    if (tablesCmd->parsed()) return tyndall::cli::tables(tablesArgs);
    if (polarCmd->parsed() || errorCmd->parsed()) {
        plotArgs.plot = polarCmd->parsed() ? "ltsd-polar" : "ltsd-error";
        return tyndall::cli::plot(plotArgs);
    }
    return kBadInput;
}
