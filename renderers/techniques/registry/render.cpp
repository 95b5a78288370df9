#include "tyndall/techniques/render.h"

#include "tyndall/core/error.h"
#include "tyndall/core/params.h"
#include "tyndall/core/text.h"
#include "tyndall/techniques/registry.h"

#include <cstdio>
#include <filesystem>

namespace tyndall {

const char* tyndallVersion() { return TYNDALL_VERSION; }

namespace {

const View& findView(const Project& project, const std::string& name) {
    std::vector<std::string> names;
    for (const View& v : project.views) {
        if (v.name == name) return v;
        names.push_back(v.name);
    }
    std::string message = "no view named '" + clipForMessage(name) + "'";
    std::string nearest = nearestName(name, names);
    if (!nearest.empty()) message += "; did you mean '" + nearest + "'?";
    message += names.empty() ? " The project has no views." : " Views:";
    for (const std::string& n : names) message += " " + n;
    throw InputError(InputLocation{"", 0, 0, "view"}, message);
}

// How the field of an error raised inside a job relates to the project: while the job is made, fields are the
// project's own ("camera"); once a technique checks or renders, they are relative to the view's part ("lights" is the
// view's lights, views[i].lights).
enum class Fields { Project, OfTheView };

// An InputError raised while a job is made, checked or run, with what it lacks filled in: the project file, the field
// of the job's part (views[i] for a view; nothing more for the reference of the whole scene) and the job's label in
// the message. Errors that already name a file keep it (an OBJ file, a table).
InputError inContext(const InputError& e, const std::string& file, const std::string& viewField,
                     const std::string& label, Fields fields) {
    InputLocation where = e.where();
    std::string message = e.message();
    if (where.file.empty()) where.file = file;
    if (where.field.empty()) {
        where.field = viewField;
    } else if (fields == Fields::OfTheView && !viewField.empty()) {
        where.field = viewField + "." + where.field;
    }
    if (!label.empty() && message.find(label) == std::string::npos) message = label + ": " + message;
    return InputError(where, message);
}

template <typename F>
decltype(auto) withContext(const std::string& file, const std::string& viewField, const std::string& label,
                           Fields fields, F&& body) {
    try {
        return body();
    } catch (const InputError& e) {
        throw inContext(e, file, viewField, label, fields);
    }
}

std::string viewField(const Project& project, const View& view) {
    return "views[" + std::to_string(&view - project.views.data()) + "]";
}

std::string projectDirOf(const std::string& projectPath) {
    std::filesystem::path dir = std::filesystem::path(projectPath).parent_path();
    return dir.empty() ? std::string(".") : dir.string();
}

void applyOptions(RenderRequest& request, const JobOptions& options) {
    if (options.spp) request.spp = *options.spp;
    if (options.timeLimit) {
        request.timeLimit = *options.timeLimit;
        // A time bound means "until this time": the project's or technique's spp no longer stops it first.
        if (!options.spp) request.spp = RenderRequest::kUnboundedSpp;
    }
    if (options.seed) request.seed = *options.seed;
    request.threads = options.threads;
}

void checkSupported(const Technique& technique, const Scene& scene, const std::string& label) {
    std::vector<std::string> missing = technique.unsupported(scene);
    if (missing.empty()) return;
    std::string message = technique.name() + " cannot render the part of the scene of " + label + ":";
    for (const std::string& m : missing) message += "\n  " + m;
    throw InputError(message);  // the job's context adds the file and views[i]
}

void checkImageSize(const Camera& camera) {
    const long long pixels = (long long)camera.width * camera.height;
    if (pixels > (1LL << 26))
        throw InputError(InputLocation{"", 0, 0, "camera"},
                         "an image of " + std::to_string(camera.width) + " x " + std::to_string(camera.height) +
                             " pixels is too large to render; at most 67 million pixels (e.g. 8192 x 8192)");
}

// What resolving the view's part left out of the scene (nothing when the view names its lights and media).
void noteLeftOut(RenderJob& job, const Project& project, const View& view, const Technique& viewTechnique) {
    if (view.part) return;
    job.leftOut = viewTechnique.leftOut(project.scene);
    if (job.leftOut.empty()) return;
    std::string joined;
    for (const std::string& line : job.leftOut) joined += (joined.empty() ? "" : "; ") + line;
    job.metadata["leftOut"] = joined;
}

// Which frame of the particle animation the job renders, for the image's caption and metadata ("animationFrame"):
// "step 45 (0.75 s)", each simulated medium by name when there are several.
void noteAnimationFrame(RenderJob& job) {
    std::vector<const ParticleMedium*> simulated;
    for (const ParticleMedium& m : job.request.scene.particleMedia)
        if (m.simulation) simulated.push_back(&m);
    std::string frame;
    for (const ParticleMedium* m : simulated) {
        char text[96];
        std::snprintf(text, sizeof(text), "step %d (%.2f s)", m->simulation->steps,
                      m->simulation->steps * m->simulation->timeStep);
        frame += (frame.empty() ? "" : "; ") + (simulated.size() > 1 ? m->name + " " : std::string()) + text;
    }
    if (!frame.empty()) job.metadata["animationFrame"] = frame;
}

void fillViewJob(RenderJob& job, const Project& project, const std::string& projectPath, const View& view,
                 const JobOptions& options) {
    job.technique = createTechnique(view.technique);
    job.request.scene = resolvePart(techniqueCatalogue(), project, view).apply(project.scene);
    checkSupported(*job.technique, job.request.scene, job.label);
    checkImageSize(job.request.scene.camera);
    job.request.params = paramsFromJson(*job.technique, view.parameters, "views." + view.name + ".parameters");
    job.request.projectDir = projectDirOf(projectPath);
    job.request.seed = project.reference.seed;
    applyOptions(job.request, options);
    job.exposure = view.exposure;
    job.metadata["view"] = view.name;
    job.metadata["projectHash"] = projectHash(project);
    noteLeftOut(job, project, view, *job.technique);
    noteAnimationFrame(job);
}

// The reference of `view`'s part, or of the whole scene when it is null.
void fillReferenceJob(RenderJob& job, const Project& project, const std::string& projectPath, const View* view,
                      const JobOptions& options) {
    job.technique = createTechnique("reference");
    if (!view) {
        job.request.scene = project.scene;
    } else {
        job.request.scene = resolvePart(techniqueCatalogue(), project, *view).apply(project.scene);
        job.exposure = view->exposure;
        job.metadata["view"] = view->name;
        noteLeftOut(job, project, *view, *createTechnique(view->technique));
    }
    checkImageSize(job.request.scene.camera);
    job.request.params = job.technique->defaultParams();
    const ReferenceSettings& ref = project.reference;
    job.request.params.set("mode", std::string(ref.mode == ReferenceSettings::Mode::Multiple ? "multiple" : "single"));
    job.request.params.set("maxDepth", std::int64_t(ref.maxDepth));
    job.request.spp = ref.spp;
    job.request.seed = ref.seed;
    job.request.projectDir = projectDirOf(projectPath);
    applyOptions(job.request, options);
    job.metadata["reference"] = "true";
    job.metadata["projectHash"] = projectHash(project);
    noteAnimationFrame(job);
}

}  // namespace

ParamSet paramsFromJson(const Technique& technique, const nlohmann::json& values, const std::string& field) {
    ParamSet params = technique.defaultParams();
    for (const auto& [key, value] : values.items()) {
        ParamValue v;
        if (value.is_boolean())
            v = value.get<bool>();
        else if (value.is_number_integer())
            v = value.get<std::int64_t>();
        else if (value.is_number())
            v = value.get<double>();
        else if (value.is_string())
            v = value.get<std::string>();
        else if (value.is_array() && value.size() == 3)
            v = Rgb(value[0].get<double>(), value[1].get<double>(), value[2].get<double>());
        else
            throw InputError(InputLocation{"", 0, 0, field + "." + key}, "unsupported value " + value.dump());
        try {
            params.set(key, v);
        } catch (const InputError& e) {
            throw InputError(InputLocation{"", 0, 0, field + "." + key}, e.message());
        }
    }
    return params;
}

RenderJob makeViewJob(const Project& project, const std::string& projectPath, const std::string& viewName,
                      const JobOptions& options) {
    const View& view =
        withContext(projectPath, "", "", Fields::Project, [&]() -> const View& { return findView(project, viewName); });
    RenderJob job;
    job.label = "view '" + view.name + "'";
    job.projectPath = projectPath;
    job.field = viewField(project, view);
    return withContext(projectPath, job.field, job.label, Fields::Project, [&] {
        fillViewJob(job, project, projectPath, view, options);
        return std::move(job);
    });
}

RenderJob makeReferenceJob(const Project& project, const std::string& projectPath, const std::string& viewName,
                           const JobOptions& options) {
    RenderJob job;
    job.projectPath = projectPath;
    const View* view = nullptr;
    if (!viewName.empty()) {
        view = &withContext(projectPath, "", "", Fields::Project,
                            [&]() -> const View& { return findView(project, viewName); });
        job.field = viewField(project, *view);
    }
    job.label = view ? "the reference of view '" + view->name + "'" : "the reference of the whole scene";
    return withContext(projectPath, job.field, job.label, Fields::Project, [&] {
        fillReferenceJob(job, project, projectPath, view, options);
        return std::move(job);
    });
}

void checkJob(const RenderJob& job) {
    withContext(job.projectPath, job.field, job.label, Fields::OfTheView, [&] { job.technique->check(job.request); });
}

RenderResult runJob(RenderJob& job, const RenderCallbacks& callbacks) {
    RenderResult result = withContext(job.projectPath, job.field, job.label, Fields::OfTheView,
                                      [&] { return job.technique->render(job.request, callbacks); });
    for (const auto& [key, value] : job.metadata) result.image.metadata[key] = value;
    result.image.metadata["technique"] = job.technique->name();
    result.image.metadata["spp"] = std::to_string(result.spp);
    result.image.metadata["renderTime"] = std::to_string(result.seconds);
    result.image.metadata["seed"] = std::to_string(job.request.seed);
    result.image.metadata["exposure"] = std::to_string(job.exposure);
    result.image.metadata["tyndallVersion"] = tyndallVersion();
    nlohmann::json params = nlohmann::json::object();
    for (const auto& [key, value] : job.request.params.values()) params[key] = toString(value);
    result.image.metadata["parameters"] = params.dump();
    return result;
}

std::string checkFiniteSamples(const RenderResult& result) {
    const auto it = result.image.metadata.find("nonFiniteSamples");
    if (it == result.image.metadata.end() || it->second == "0") return "";
    const double count = std::strtod(it->second.c_str(), nullptr);
    const double samples = double(result.image.width()) * double(result.image.height()) * double(std::max(result.spp, 1));
    char fraction[32], limit[32];
    std::snprintf(fraction, sizeof fraction, "%.3g %%", 100.0 * count / std::max(samples, 1.0));
    std::snprintf(limit, sizeof limit, "%.3g %%", 100.0 * kMaxNonFiniteFraction);
    if (!(count <= kMaxNonFiniteFraction * samples))
        throw std::runtime_error("the render failed: " + it->second + " samples (" + fraction +
                                 ") were not finite, above the limit of " + limit + "; nothing was written. This is a "
                                 "defect of Tyndall, or a value at the edge of the limits: please report the project");
    return it->second + " samples (" + fraction + ") were not finite and count as 0 (metadata nonFiniteSamples)";
}

}  // namespace tyndall
