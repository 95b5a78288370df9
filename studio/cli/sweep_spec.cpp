// Sweep specs: reading, validating and expanding them into tasks (docs/sweeps.md).
#include "sweep.h"

#include "tyndall/core/error.h"
#include "tyndall/core/hash.h"
#include "tyndall/core/text.h"
#include "tyndall/framework/technique.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace tyndall::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kMaxTasks = 100000;
constexpr int kMaxRangeCount = 1000;

struct SpecField {
    const std::string& file;
    std::string path;  // "grid[\"media[fog].phase.g\"][2]"
    InputError error(const std::string& message) const { return InputError(InputLocation{file, 0, 0, path}, message); }
    SpecField operator[](const std::string& key) const { return {file, path.empty() ? key : path + "." + key}; }
    SpecField operator[](std::size_t i) const { return {file, path + "[" + std::to_string(i) + "]"}; }
    SpecField quoted(const std::string& key) const { return {file, path + "[\"" + key + "\"]"}; }
};

std::string describe(const json& value) {
    return clipForMessage(value.dump(), 60);
}

void checkKeys(const json& object, const SpecField& field, const std::vector<std::string>& known) {
    if (!object.is_object()) throw field.error("must be an object, got " + describe(object));
    for (const auto& [key, value] : object.items()) {
        if (std::find(known.begin(), known.end(), key) != known.end()) continue;
        std::string message = "unknown key '" + clipForMessage(key) + "'";
        if (const std::string near = nearestName(key, known); !near.empty())
            message += "; did you mean '" + near + "'?";
        std::string list;
        for (const std::string& k : known)
            list += (list.empty() ? "" : ", ") + k;
        throw field.error(message + " (allowed: " + list + ")");
    }
}

std::string readString(const json& value, const SpecField& field) {
    if (!value.is_string()) throw field.error("must be a string, got " + describe(value));
    return value.get<std::string>();
}

// An integer in [lo, hi] (a JSON integer, or a float with an integer value).
long long readInteger(const json& value, const SpecField& field, long long lo, long long hi) {
    double number = 0.0;
    if (value.is_number_unsigned()) {
        const auto u = value.get<std::uint64_t>();
        if (u > std::uint64_t(hi))
            throw field.error("must be at most " + std::to_string(hi) + ", got " + describe(value));
        number = double(u);
        if (number >= double(lo)) return static_cast<long long>(u);
    } else if (value.is_number()) {
        number = value.get<double>();
    } else {
        throw field.error("must be an integer, got " + describe(value));
    }
    if (!(std::floor(number) == number) || number < double(lo) || number > double(hi))
        throw field.error("must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                          describe(value));
    return static_cast<long long>(number);
}

std::uint64_t readSeed(const json& value, const SpecField& field) {
    if (value.is_number_unsigned()) return value.get<std::uint64_t>();
    if (value.is_number_integer() && value.get<long long>() >= 0) return std::uint64_t(value.get<long long>());
    throw field.error("must be an integer in [0, 18446744073709551615], got " + describe(value));
}

double readPositive(const json& value, const SpecField& field) {
    if (!value.is_number() || !(value.get<double>() > 0.0) || !std::isfinite(value.get<double>()))
        throw field.error("must be a positive number, got " + describe(value));
    return value.get<double>();
}

// One value or a non-empty list of them.
std::vector<json> oneOrMore(const json& value, const SpecField& field) {
    if (!value.is_array()) return {value};
    if (value.empty()) throw field.error("must not be empty");
    return std::vector<json>(value.begin(), value.end());
}

// A grid axis: a list of values, or a range {"from", "to", "count", "scale": "linear" | "log", "integer": bool}.
std::vector<json> axisValues(const json& value, const SpecField& field) {
    if (value.is_array()) {
        if (value.empty()) throw field.error("must list at least one value");
        return std::vector<json>(value.begin(), value.end());
    }
    if (!value.is_object())
        throw field.error("must be a list of values or a range {\"from\", \"to\", \"count\"}, got " + describe(value));
    checkKeys(value, field, {"from", "to", "count", "scale", "integer"});
    for (const char* key : {"from", "to", "count"})
        if (!value.contains(key)) throw field.error(std::string("a range needs \"") + key + "\"");
    const auto number = [&](const char* key) {
        const json& v = value[key];
        if (!v.is_number() || !std::isfinite(v.get<double>()))
            throw field[key].error("must be a finite number, got " + describe(v));
        return v.get<double>();
    };
    const double from = number("from"), to = number("to");
    const int count = int(readInteger(value["count"], field["count"], 1, kMaxRangeCount));
    const std::string scale = value.contains("scale") ? readString(value["scale"], field["scale"]) : "linear";
    if (scale != "linear" && scale != "log")
        throw field["scale"].error("must be \"linear\" or \"log\", got '" + clipForMessage(scale) + "'");
    if (scale == "log" && !(from > 0.0 && to > 0.0)) throw field.error("a log range needs \"from\" and \"to\" above 0");
    bool integer = false;
    if (value.contains("integer")) {
        if (!value["integer"].is_boolean()) throw field["integer"].error("must be true or false");
        integer = value["integer"].get<bool>();
    }
    std::vector<json> values;
    for (int i = 0; i < count; ++i) {
        const double t = count == 1 ? 0.0 : double(i) / double(count - 1);
        double v = scale == "log" ? from * std::pow(to / from, t) : from + (to - from) * t;
        if (i == count - 1 && count > 1) v = to;  // the end exactly
        if (integer) {
            const json rounded = static_cast<long long>(std::llround(v));
            if (std::find(values.begin(), values.end(), rounded) == values.end()) values.push_back(rounded);
        } else {
            values.push_back(v);
        }
    }
    return values;
}

// "views[{view}].parameters.nodes" for view "N 8" -> "views[N 8].parameters.nodes".
std::string forView(std::string path, const std::string& view) {
    for (std::size_t at = path.find("{view}"); at != std::string::npos; at = path.find("{view}", at + view.size()))
        path.replace(at, 6, view);
    return path;
}

// The key of the reference a view's render is compared against: everything the reference of its part depends on (the
// project without its views' techniques and names, the part, the image size, the reference's samples and seed).
std::string referenceKey(const Project& project, const View& view, int spp, int shards, std::uint64_t seed) {
    json scene = projectToJson(project);
    scene.erase("views");
    scene.erase("name");
    json part = json::object();
    const ScenePart p = resolvePart(techniqueCatalogue(), project, view);
    part["lights"] = p.lights;
    part["media"] = p.media;
    const std::string text = scene.dump() + "|" + part.dump() + "|" + std::to_string(spp) + "|" +
                             std::to_string(shards) + "|" + std::to_string(seed);
    return hex16(fnv1a(text)).substr(0, 12);
}

std::string taskHash(const SweepTask& task, const SweepPlan& plan) {
    json inputs{{"kind", task.kind == SweepTaskKind::View ? "view" : "reference"},
                {"project", plan.project},
                {"projectFile", plan.projectFileHash},
                {"view", task.view},
                {"sets", task.sets},
                {"seed", task.seed},
                {"spp", task.spp},
                {"time", task.time},
                {"shard", task.shard},
                {"shards", task.shards}};
    return hex16(fnv1a(inputs.dump())).substr(0, 12);
}

// The InputError of loading or checking the project at one point of the sweep, as an error of the spec: the field of
// the axis whose override it names (or of the point), with the project's message.
// the axis whose override it names, or else the first whose override alone fails (a value that breaks a rule is
// reported at the project's field, "media[0].phase.g"), with the project's message; the spec's when none is to blame.
InputError pointError(const InputError& e, const SpecField& spec,
                      const std::vector<std::pair<std::string, SpecField>>& axes, const std::vector<std::string>& fixed,
                      const nlohmann::json& point, const std::string& project, const std::string& view,
                      const std::string& where) {
    const std::string& field = e.where().field;
    for (const auto& [path, axisField] : axes)
        if (field == "--set " + forView(path, view) || field == forView(path, view))
            return axisField.error(where + ": " + e.what());
    for (const auto& [path, axisField] : axes) {
        if (!point.contains(path)) continue;
        std::vector<std::string> sets = fixed;
        sets.push_back(forView(path, view) + "=" + point[path].dump());
        try {
            checkJob(makeViewJob(loadProject(techniqueCatalogue(), project, sets), project, view));
        } catch (const InputError&) {
            return axisField.error(where + ": " + e.what());
        }
    }
    return spec.error(where + ": " + e.what());
}

// Whether an axis applies to a view: "views[{view}].parameters.NAME" only to the views whose technique has parameter
// NAME (a sweep of LTSD's node count leaves Volume-RIS beside it at one point); every other axis to every view.
bool axisApplies(const std::string& axis, const std::string& technique) {
    const std::string prefix = "views[{view}].parameters.";
    if (axis.rfind(prefix, 0) != 0) return true;
    std::string name = axis.substr(prefix.size());
    name = name.substr(0, name.find_first_of(".["));
    const auto params = createTechnique(technique)->parameters();
    return std::any_of(params.begin(), params.end(), [&](const ParamInfo& p) { return p.name == name; });
}

}  // namespace

SweepPlan planSweep(const std::string& specPath) {
    SweepPlan plan;
    plan.specPath = specPath;
    const json spec = readJsonFile(specPath, "sweep spec");
    const SpecField root{specPath, ""};
    checkKeys(spec, root,
              {"tyndallSweep", "name", "project", "size", "views", "set", "grid", "points", "seeds", "spp", "time",
               "reference", "metrics"});
    if (!spec.contains("tyndallSweep") || spec["tyndallSweep"] != 1)
        throw root["tyndallSweep"].error("a sweep spec starts with \"tyndallSweep\": 1");
    plan.name = spec.contains("name") ? readString(spec["name"], root["name"]) : fs::path(specPath).stem().string();
    if (!spec.contains("project")) throw root["project"].error("name the project file (relative to the spec)");
    const fs::path specDir = fs::absolute(fs::path(specPath)).parent_path();
    plan.project = (specDir / readString(spec["project"], root["project"])).lexically_normal().string();
    plan.projectFileHash = hex16(fnv1a(readProjectText(plan.project)));

    std::vector<std::string> fixed;
    if (spec.contains("set"))
        for (std::size_t i = 0; const json& s : oneOrMore(spec["set"], root["set"])) {
            const std::string text = readString(s, root["set"][i++]);
            if (text.find('=') == std::string::npos)
                throw root["set"][i - 1].error("must be path=value, got '" + clipForMessage(text) + "'");
            fixed.push_back(text);
        }
    if (spec.contains("size")) {
        plan.size = readString(spec["size"], root["size"]);
        int w = 0, h = 0;
        char x = 0, rest = 0;
        std::istringstream in(plan.size);
        if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> rest) || w < 1 || h < 1 || w > 16384 || h > 16384)
            throw root["size"].error("must be WIDTHxHEIGHT with sides in [1, 16384], e.g. 128x96, got '" +
                                     clipForMessage(plan.size) + "'");
        fixed.push_back("camera.width=" + std::to_string(w));
        fixed.push_back("camera.height=" + std::to_string(h));
    }

    // The project under the fixed overrides: the views to render, and the reference's defaults.
    Project base;
    try {
        base = loadProject(techniqueCatalogue(), plan.project, fixed);
    } catch (const InputError& e) {
        throw root["project"].error(e.what());
    }
    std::vector<std::string> views;
    if (spec.contains("views")) {
        for (std::size_t i = 0; const json& v : oneOrMore(spec["views"], root["views"])) {
            const SpecField field = root["views"][i++];
            const std::string name = readString(v, field);
            const bool known =
                std::any_of(base.views.begin(), base.views.end(), [&](const View& w) { return w.name == name; });
            if (!known) {
                std::vector<std::string> names;
                for (const View& w : base.views)
                    names.push_back(w.name);
                std::string message = "the project has no view '" + clipForMessage(name) + "'";
                if (const std::string near = nearestName(name, names); !near.empty())
                    message += "; did you mean '" + near + "'?";
                throw field.error(message);
            }
            if (std::find(views.begin(), views.end(), name) != views.end()) throw field.error("names a view twice");
            views.push_back(name);
        }
    } else {
        for (const View& w : base.views)
            views.push_back(w.name);
    }
    if (views.empty()) throw root["views"].error("the project has no views to sweep");

    // The points: the product of the grid's axes, times the listed points.
    std::vector<std::pair<std::string, SpecField>> axisFields;
    std::vector<std::vector<json>> gridValues;
    if (spec.contains("grid")) {
        if (!spec["grid"].is_object()) throw root["grid"].error("must be an object: {\"path\": [values] or a range}");
        for (const auto& [path, values] : spec["grid"].items()) {
            const SpecField field = root["grid"].quoted(path);
            if (path.empty() || path.find('=') != std::string::npos)
                throw field.error("must be a --set path such as media[fog].phase.g");
            plan.axes.push_back(path);
            axisFields.emplace_back(path, field);
            gridValues.push_back(axisValues(values, field));
        }
    }
    std::vector<json> listed;
    if (spec.contains("points")) {
        const json& points = spec["points"];
        if (!points.is_array() || points.empty())
            throw root["points"].error("must be a non-empty list of {\"path\": value} objects");
        std::vector<std::string> keys;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const SpecField field = root["points"][i];
            if (!points[i].is_object() || points[i].empty())
                throw field.error("must be an object {\"path\": value, ...}, got " + describe(points[i]));
            std::vector<std::string> these;
            for (const auto& [path, value] : points[i].items())
                these.push_back(path);
            if (i == 0) {
                keys = these;
                for (const std::string& path : keys) {
                    if (std::find(plan.axes.begin(), plan.axes.end(), path) != plan.axes.end())
                        throw field.quoted(path).error("is an axis of the grid too");
                    plan.axes.push_back(path);
                    axisFields.emplace_back(path, root["points"].quoted(path));
                }
            } else if (these != keys) {
                throw field.error("must set the same paths as points[0]");
            }
            listed.push_back(points[i]);
        }
    }
    std::vector<json> points{json::object()};
    for (std::size_t a = 0; a < gridValues.size(); ++a) {
        std::vector<json> next;
        for (const json& p : points)
            for (const json& v : gridValues[a]) {
                json q = p;
                q[plan.axes[a]] = v;
                next.push_back(q);
            }
        points = std::move(next);
    }
    if (!listed.empty()) {
        std::vector<json> next;
        for (const json& p : points)
            for (const json& l : listed) {
                json q = p;
                q.update(l);
                next.push_back(q);
            }
        points = std::move(next);
    }

    std::vector<std::uint64_t> seeds{1};
    if (spec.contains("seeds")) {
        const json& s = spec["seeds"];
        seeds.clear();
        if (s.is_object()) {
            checkKeys(s, root["seeds"], {"first", "count"});
            const std::uint64_t first = s.contains("first") ? readSeed(s["first"], root["seeds"]["first"]) : 1;
            if (!s.contains("count")) throw root["seeds"]["count"].error("give the number of seeds");
            const int count = int(readInteger(s["count"], root["seeds"]["count"], 1, 10000));
            for (int i = 0; i < count; ++i)
                seeds.push_back(first + std::uint64_t(i));
        } else {
            for (std::size_t i = 0; const json& v : oneOrMore(s, root["seeds"])) {
                seeds.push_back(readSeed(v, root["seeds"][i++]));
                if (std::count(seeds.begin(), seeds.end(), seeds.back()) > 1)
                    throw root["seeds"][i - 1].error("lists seed " + std::to_string(seeds.back()) + " twice");
            }
        }
    }

    if (spec.contains("spp") == spec.contains("time"))
        throw root.error("give either \"spp\" (samples per pixel per task) or \"time\" (seconds per task), not " +
                         std::string(spec.contains("spp") ? "both" : "neither"));
    std::vector<int> sppLevels;
    std::vector<double> timeLevels;
    if (spec.contains("spp")) {
        plan.measure = "spp";
        for (std::size_t i = 0; const json& v : oneOrMore(spec["spp"], root["spp"]))
            sppLevels.push_back(int(readInteger(v, root["spp"][i++], 1, 1 << 20)));
    } else {
        plan.measure = "time";
        for (std::size_t i = 0; const json& v : oneOrMore(spec["time"], root["time"]))
            timeLevels.push_back(readPositive(v, root["time"][i++]));
    }

    int refSpp = base.reference.spp, refShards = 1;
    std::uint64_t refSeed = base.reference.seed;
    if (spec.contains("reference")) {
        const json& r = spec["reference"];
        const SpecField field = root["reference"];
        checkKeys(r, field, {"spp", "shards", "seed", "image"});
        if (r.contains("image")) {
            if (r.size() > 1) throw field.error("a given \"image\" takes no spp, shards or seed");
            plan.referenceImage = (specDir / readString(r["image"], field["image"])).lexically_normal().string();
            if (!fs::is_regular_file(plan.referenceImage))
                throw field["image"].error("'" + plan.referenceImage + "' is not a file");
        }
        if (r.contains("spp")) refSpp = int(readInteger(r["spp"], field["spp"], 1, 1 << 20));
        if (r.contains("shards")) refShards = int(readInteger(r["shards"], field["shards"], 1, 4096));
        if (r.contains("seed")) refSeed = readSeed(r["seed"], field["seed"]);
        if (refShards > refSpp)
            throw field["shards"].error("leaves shards without samples (" + std::to_string(refSpp) + " spp in " +
                                        std::to_string(refShards) + " shards)");
    }
    if (spec.contains("metrics"))
        for (std::size_t i = 0; const json& m : oneOrMore(spec["metrics"], root["metrics"])) {
            const std::string name = readString(m, root["metrics"][i++]);
            if (name != "flip")
                throw root["metrics"][i - 1].error("'" + clipForMessage(name) +
                                                   "' is not an extra metric; the one there is: flip (RMSE, relMSE, "
                                                   "MAPE, PSNR and the bias are always computed)");
            plan.metrics.push_back(name);
        }

    const std::size_t levels = std::max(sppLevels.size(), timeLevels.size());
    if (double(points.size()) * double(views.size()) * double(levels) * double(seeds.size()) > kMaxTasks)
        throw root.error("expands to more than " + std::to_string(kMaxTasks) + " renders; split the sweep");

    // Which axes apply to which views; an axis that applies to none is a mistake.
    std::map<std::string, std::string> techniqueOf;
    for (const View& v : base.views)
        techniqueOf[v.name] = v.technique;
    for (const auto& axisField : axisFields) {
        const std::string& axis = axisField.first;  // (clang 14 cannot capture a structured binding)
        if (std::any_of(views.begin(), views.end(),
                        [&](const std::string& v) { return axisApplies(axis, techniqueOf[v]); }))
            continue;
        std::string list;
        for (const std::string& v : views)
            list += (list.empty() ? "" : ", ") + v + " (" + techniqueOf[v] + ")";
        throw axisField.second.error("no swept view's technique has this parameter (views: " + list + ")");
    }

    // Expand, checking each point and view as `tyndall render` would.
    std::vector<SweepTask> references, renders;
    std::set<std::string> referenceKeys;
    std::set<std::string> expanded;  // view and point, once each
    for (const json& fullPoint : points) {
        for (const std::string& view : views) {
            json point = json::object();
            for (const auto& [path, value] : fullPoint.items())
                if (axisApplies(path, techniqueOf[view])) point[path] = value;
            if (!expanded.insert(view + "|" + point.dump()).second) continue;
            std::string where = point.empty() ? "" : "at";
            for (const auto& [path, value] : point.items())
                where += " " + path + " = " + clipForMessage(valueText(value));
            std::vector<std::string> sets = fixed;
            for (const auto& [path, value] : point.items())
                sets.push_back(forView(path, view) + "=" + value.dump());
            const std::string context = "view '" + view + "'" + (where.empty() ? "" : " " + where);
            std::string key;
            try {
                const Project project = loadProject(techniqueCatalogue(), plan.project, sets);
                checkJob(makeViewJob(project, plan.project, view));
                const View& v = *std::find_if(project.views.begin(), project.views.end(),
                                              [&](const View& w) { return w.name == view; });
                // With a given image, every render must have the same key (checked below): it names that image.
                key = referenceKey(project, v, refSpp, refShards, refSeed);
                if (!plan.referenceImage.empty()) {
                    referenceKeys.insert(key);
                    key = "given";
                } else if (referenceKeys.insert(key).second) {
                    checkJob(makeReferenceJob(project, plan.project, view));
                    for (int s = 0; s < refShards; ++s) {
                        SweepTask t;
                        t.kind = SweepTaskKind::ReferenceShard;
                        t.view = view;
                        t.point = point;
                        t.sets = sets;
                        t.seed = refSeed;
                        t.spp = refSpp;
                        t.shard = s;
                        t.shards = refShards;
                        t.reference = key;
                        references.push_back(t);
                    }
                }
            } catch (const InputError& e) {
                throw pointError(e, root, axisFields, fixed, point, plan.project, view, context);
            }
            for (std::size_t l = 0; l < levels; ++l)
                for (std::uint64_t seed : seeds) {
                    SweepTask t;
                    t.view = view;
                    t.point = point;
                    t.sets = sets;
                    t.seed = seed;
                    t.spp = sppLevels.empty() ? 0 : sppLevels[l];
                    t.time = timeLevels.empty() ? 0.0 : timeLevels[l];
                    t.reference = key;
                    renders.push_back(t);
                }
        }
    }
    // One given image can only be the reference of a sweep whose renders all share one reference.
    if (referenceKeys.size() > 1 && !plan.referenceImage.empty())
        throw root["reference"]["image"].error(
            "one image cannot be the reference of every render: the views or points of this sweep render " +
            std::to_string(referenceKeys.size()) + " different parts or scenes; give {\"spp\", \"shards\"} instead");
    plan.tasks = std::move(references);
    plan.tasks.insert(plan.tasks.end(), renders.begin(), renders.end());
    std::set<std::string> ids;
    for (std::size_t i = 0; i < plan.tasks.size(); ++i) {
        SweepTask& t = plan.tasks[i];
        t.index = int(i);
        t.id = taskHash(t, plan);
        if (!ids.insert(t.id).second)
            throw root.error("renders one image twice (task " + t.id + ", view '" + t.view +
                             "'): two points or seeds are the same");
    }
    return plan;
}

std::string axisName(const std::string& axis) {
    const std::string prefix = "views[{view}].parameters.";
    return axis.rfind(prefix, 0) == 0 ? axis.substr(prefix.size()) : axis;
}

std::string valueText(const json& value) {
    if (value.is_null()) return "";
    if (value.is_number_float()) return formatNumber(value.get<double>());
    if (value.is_string()) return value.get<std::string>();
    return value.dump();
}

std::string pointText(const json& point, const std::string& except) {
    std::string text;
    for (const auto& [path, value] : point.items())
        if (path != except) text += (text.empty() ? "" : ", ") + axisName(path) + " = " + valueText(value);
    return text;
}

json taskToJson(const SweepTask& t, const SweepPlan& plan) {
    json j{{"index", t.index},    {"id", t.id},       {"kind", t.kind == SweepTaskKind::View ? "view" : "reference"},
           {"view", t.view},      {"point", t.point}, {"project", plan.project},
           {"sets", t.sets},      {"seed", t.seed},   {"reference", t.reference},
           {"output", t.output()}};
    if (t.spp > 0) j["spp"] = t.spp;
    if (t.time > 0.0) j["time"] = t.time;
    if (t.kind == SweepTaskKind::ReferenceShard) j["shard"] = std::to_string(t.shard) + "/" + std::to_string(t.shards);
    return j;
}

SweepTask taskFromJson(const json& j, const std::string& file, int line) {
    const auto bad = [&](const std::string& why) {
        return InputError(InputLocation{file, line, 0, ""}, "not a task of tyndall sweep: " + why);
    };
    try {
        SweepTask t;
        t.index = j.at("index").get<int>();
        t.id = j.at("id").get<std::string>();
        const std::string kind = j.at("kind").get<std::string>();
        if (kind != "view" && kind != "reference") throw bad("kind '" + clipForMessage(kind) + "'");
        t.kind = kind == "view" ? SweepTaskKind::View : SweepTaskKind::ReferenceShard;
        t.view = j.at("view").get<std::string>();
        t.point = j.at("point");
        t.sets = j.at("sets").get<std::vector<std::string>>();
        t.seed = j.at("seed").get<std::uint64_t>();
        t.reference = j.at("reference").get<std::string>();
        if (j.contains("spp")) t.spp = j["spp"].get<int>();
        if (j.contains("time")) t.time = j["time"].get<double>();
        if (j.contains("shard")) {
            const std::string s = j["shard"].get<std::string>();
            const std::size_t slash = s.find('/');
            if (slash == std::string::npos) throw bad("shard '" + clipForMessage(s) + "'");
            t.shard = std::stoi(s.substr(0, slash));
            t.shards = std::stoi(s.substr(slash + 1));
        }
        if (t.id.size() != 12 || t.id.find_first_not_of("0123456789abcdef") != std::string::npos)
            throw bad("id '" + clipForMessage(t.id) + "'");
        if ((t.spp > 0) == (t.time > 0.0)) throw bad("needs spp or time");
        return t;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw bad(e.what());
    }
}

json planToJson(const SweepPlan& plan) {
    return json{{"tyndallSweepRun", 1},
                {"name", plan.name},
                {"spec", fs::absolute(plan.specPath).lexically_normal().string()},
                {"project", plan.project},
                {"projectFileHash", plan.projectFileHash},
                {"size", plan.size},
                {"measure", plan.measure},
                {"axes", plan.axes},
                {"metrics", plan.metrics},
                {"referenceImage", plan.referenceImage},
                {"tasks", plan.tasks.size()}};
}

SweepPlan readPlan(const std::string& dir) {
    const std::string planFile = (fs::path(dir) / "sweep.json").string();
    if (!fs::is_regular_file(planFile))
        throw InputError(
            InputLocation{dir, 0, 0, ""},
            "is not the output folder of a sweep (it has no sweep.json; run tyndall sweep SPEC --out " + dir + ")");
    const json j = readJsonFile(planFile, "sweep plan");
    SweepPlan plan;
    try {
        if (j.at("tyndallSweepRun") != 1) throw std::runtime_error("tyndallSweepRun is not 1");
        plan.specPath = j.at("spec").get<std::string>();
        plan.name = j.at("name").get<std::string>();
        plan.project = j.at("project").get<std::string>();
        plan.projectFileHash = j.at("projectFileHash").get<std::string>();
        plan.size = j.at("size").get<std::string>();
        plan.measure = j.at("measure").get<std::string>();
        plan.axes = j.at("axes").get<std::vector<std::string>>();
        plan.metrics = j.at("metrics").get<std::vector<std::string>>();
        plan.referenceImage = j.at("referenceImage").get<std::string>();
    } catch (const std::exception& e) {
        throw InputError(InputLocation{planFile, 0, 0, ""}, std::string("not a sweep plan: ") + e.what());
    }
    const std::string manifest = (fs::path(dir) / "manifest.jsonl").string();
    std::ifstream in(manifest);
    if (!in) throw InputError(InputLocation{manifest, 0, 0, ""}, "cannot read the manifest");
    std::string text;
    for (int line = 1; std::getline(in, text); ++line) {
        if (text.empty()) continue;
        json j2;
        try {
            j2 = json::parse(text);
        } catch (const json::exception& e) {
            throw InputError(InputLocation{manifest, line, 0, ""}, std::string("malformed JSON: ") + e.what());
        }
        plan.tasks.push_back(taskFromJson(j2, manifest, line));
        if (plan.tasks.back().index != int(plan.tasks.size()) - 1)
            throw InputError(InputLocation{manifest, line, 0, "index"}, "tasks must be listed in index order");
    }
    return plan;
}

}  // namespace tyndall::cli
