// Turning a project's view (or its reference) into a render: the part of the scene it covers, its technique and
// parameters, and the metadata every output carries. The CLI and the studio both go through here, so that a view and
// its reference always render the same part of the scene.
#pragma once

#include "tyndall/framework/technique.h"
#include "tyndall/project/project.h"

#include <map>
#include <memory>
#include <optional>
#include <string>

namespace tyndall {

struct RenderJob {
    std::string label;                      // "view 'fog'" or "reference of view 'fog'"
    // Where the job's input errors point when they carry no place of their own: the project file and the field of the
    // job's view ("views[2]"; empty for the reference of the whole scene). makeViewJob, makeReferenceJob, checkJob and
    // runJob fill them into every InputError they pass on, with the label; a technique's fields become the view's
    // ("lights" -> "views[2].lights").
    std::string projectPath;
    std::string field;
    std::unique_ptr<Technique> technique;
    RenderRequest request;
    double exposure = 0.0;                  // the view's exposure, for PNGs and PSNR
    // What the scene holds that this render leaves out, one line each with the reason: a view without its own
    // `lights`/`media` renders only those its technique supports. Also in the metadata as "leftOut".
    std::vector<std::string> leftOut;
    // Written into the image on completion: the view, the project's hash, "leftOut", and for a scene with a particle
    // simulation "animationFrame", the frame it renders ("step 45 (0.75 s)").
    std::map<std::string, std::string> metadata;
};

struct JobOptions {
    std::optional<int> spp;               // overrides the technique's / reference's default; with timeLimit, a cap
    std::optional<double> timeLimit;      // s; alone, the render runs until it (no spp cap)
    std::optional<std::uint64_t> seed;
    int threads = 0;
};

// A technique's parameters from a view's JSON over its defaults; InputError names `field`.key for a bad value.
ParamSet paramsFromJson(const Technique& technique, const nlohmann::json& values, const std::string& field);

// A job that renders view `viewName` with its technique. Throws InputError (field "view") for an unknown view, with the
// nearest name, and when the technique cannot render the view's part.
RenderJob makeViewJob(const Project& project, const std::string& projectPath, const std::string& viewName,
                      const JobOptions& options = {});

// A job that renders the reference of `viewName`'s part, or of the whole scene when viewName is empty, with the
// project's reference settings.
RenderJob makeReferenceJob(const Project& project, const std::string& projectPath, const std::string& viewName,
                           const JobOptions& options = {});

// Every check a render of the job makes, without rendering (Technique::check): what `tyndall validate` runs.
void checkJob(const RenderJob& job);

// Runs the job and stamps the image with the job's metadata, spp, render time and Tyndall's version.
RenderResult runJob(RenderJob& job, const RenderCallbacks& callbacks = {});

// A technique replaces a sample that is NaN or infinite by 0 and counts it (metadata nonFiniteSamples). A few (a
// numerical corner: at most kMaxNonFiniteFraction of the samples) give a warning, returned for the caller to show;
// more mean that the image is not a render of the scene: a std::runtime_error (exit 1), so that nothing is written
// (docs/conventions.md, "Exit codes, outputs and limits"). Returns "" when every sample was finite.
inline constexpr double kMaxNonFiniteFraction = 1e-3;
std::string checkFiniteSamples(const RenderResult& result);

const char* tyndallVersion();

}  // namespace tyndall
