// The subcommands of the `tyndall` CLI. Each returns the process exit code: 0 ok, 1 failure, 2 bad input.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace tyndall::cli {

enum ExitCode { kOk = 0, kFailure = 1, kBadInput = 2 };

// Runs a subcommand's body and maps what it throws to an exit code and a message on stderr: InputError 2, an
// environment failure (OutputError, out of memory, cancellation) and anything else 1.
int guarded(const std::function<int()>& body);

struct RenderArgs {
    std::string project;
    std::string view;               // empty with --reference: the whole scene
    bool reference = false;
    std::vector<std::string> sets;  // --set path=value
    std::optional<int> spp;
    std::string size;               // "WxH"
    std::optional<std::uint64_t> seed;
    std::optional<double> time;     // s
    int threads = 0;
    std::vector<std::string> outs;  // .exr and/or .png
    std::optional<double> exposure; // PNG exposure; default: the view's
    // The PNGs' display transform (colour_management.h): Tyndall's operator (tonemap.h) when `tonemap` is given, else
    // `display` and `ocioView` of the OpenColorIO config (`ocio`, else $OCIO, else the shipped one; empty names: the
    // config's defaults).
    std::string tonemap;
    std::string ocio, display, ocioView;
    std::string shard;              // "I/N": the I-th of N equal shares of the samples, with its own seed
};
int render(const RenderArgs& args);

// Whether a render was cancelled (SIGINT or SIGTERM) in this process: a sweep's task records it as such.
bool renderCancelled();

// The seed of shard I of a render whose seed is `seed`: shard 0 keeps it (a one-shard render is the plain one), the
// others are decorrelated by a hash of (seed, I).
std::uint64_t shardSeed(std::uint64_t seed, int shard);

struct MergeArgs {
    std::vector<std::string> images;  // the shards (.exr)
    std::string out;                  // .exr
};
int merge(const MergeArgs& args);

struct ValidateArgs {
    std::vector<std::string> projects;
    std::vector<std::string> sets;
};
int validate(const ValidateArgs& args);

struct CompareArgs {
    std::vector<std::string> images;
    std::string reference;
    std::optional<double> exposure;  // default: the reference's "exposure" metadata, else 0
    std::string region;              // "x,y,w,h"
    std::string json, csv;           // output files
    std::string diff;                // difference image (.png or .exr); with several images, "{name}" is replaced
    std::string diffKind = "signed";
    double diffScale = 0.0;          // 0: 10 % of the reference's mean luminance... see compare()
    std::vector<std::string>
        metrics;                      // extra metrics beyond the standard ones: "flip" (HDR-FLIP, tyndall/image/flip.h)
    // FLIP error maps per image, each by its extension: .exr (channels FLIP and exposure) or .png (the error through
    // the magma colour map, as FLIP's papers show it); "{name}" as --diff.
    std::vector<std::string> flipMaps;
    std::string flipHistogram;        // FLIP's weighted histogram per image (.csv, 100 bins); "{name}" as --diff
    double pixelsPerDegree = 0.0;     // FLIP's observer (0: 67.02, a 0.7 m wide 4K monitor at 0.7 m)
    std::string toneMapper = "aces";  // HDR-FLIP's tone mapper: aces, hable, reinhard
};
int compare(const CompareArgs& args);

struct ProbeArgs {
    std::string project;
    std::string view;
    std::string probe;              // a probe of the view's technique, e.g. "distances"
    std::optional<std::string> pixel;  // "x,y"; absent: the image centre
    std::vector<std::string> sets;  // --set path=value
    std::optional<int> spp;
    std::string size;               // "WxH"
    std::optional<std::uint64_t> seed;
    std::string csv, json;          // output files
};
int probe(const ProbeArgs& args);

struct InfoArgs {
    bool json = false;
    std::string ocio;  // the OpenColorIO config to list (default: $OCIO, else the shipped one)
};
int info(const InfoArgs& args);

struct TablesArgs {
    std::string tables;  // folder holding the tables (default: installed beside the program, or $TYNDALL_TABLES_DIR)
    std::vector<std::string> names;  // e.g. hg, rayleigh, ggx, ggx-aniso; empty: every table in the folder
    bool json = false;
};
int tables(const TablesArgs& args);

struct TablesEvalArgs {
    std::string tables;
    std::string phase;    // project-format phase function, e.g. {"type":"hg","g":0.5}
    std::string polygon;  // JSON list of directions [[x,y,z], ...] in the frame where omega_o is +z
};
int tablesEval(const TablesEvalArgs& args);

// `tyndall plot ltsd-polar|ltsd-error`: the data of the studio's LTSD plots as CSV, for papers (the studio exports
// the drawn plots as PNG and SVG).
struct PlotArgs {
    std::string plot;    // "ltsd-polar" or "ltsd-error"
    std::string tables;  // folder holding the tables
    double g = 0.0;      // ltsd-polar: HG's asymmetry, in (-1, 1)
    int points = 0;      // samples (0: 720 over psi, 101 over g, as the studio draws them)
    std::string out;     // .csv
};
int plot(const PlotArgs& args);

}  // namespace tyndall::cli
