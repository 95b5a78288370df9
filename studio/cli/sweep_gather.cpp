// Gathering a sweep: references merged from their shards, every render's metrics against its reference, the results
// as CSV and JSON, the equal-time table, and the plots (docs/sweeps.md, "Outputs").
#include "sweep.h"

#include "commands.h"

#include "tyndall/core/error.h"
#include "tyndall/core/output.h"
#include "tyndall/core/text.h"
#include "tyndall/image/flip.h"
#include "tyndall/image/image_io.h"
#include "tyndall/image/merge.h"
#include "tyndall/image/metrics.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <set>

namespace tyndall::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Row {
    const SweepTask* task;
    std::string technique;
    Metrics metrics;
    double renderTime = 0.0;
    int spp = 0;
    std::optional<double> flipMean;
    std::string reference;  // relative to the folder
};

std::string csvField(const std::string& text) {
    if (text.find_first_of(",\"\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text)
        quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
}

double metadataNumber(const Image& image, const char* key, double fallback) {
    const auto it = image.metadata.find(key);
    if (it == image.metadata.end()) return fallback;
    char* end = nullptr;
    const double value = std::strtod(it->second.c_str(), &end);
    return end != it->second.c_str() && std::isfinite(value) ? value : fallback;
}

// "media[fog].phase.g" -> "media-fog-phase-g".
std::string slug(const std::string& text) {
    std::string out;
    for (char c : text) {
        if (std::isalnum(static_cast<unsigned char>(c)))
            out += char(std::tolower(static_cast<unsigned char>(c)));
        else if (!out.empty() && out.back() != '-')
            out += '-';
    }
    while (!out.empty() && out.back() == '-')
        out.pop_back();
    return out.empty() ? "axis" : out;
}

std::string levelText(const SweepTask& t) {
    return t.spp > 0 ? std::to_string(t.spp) + " spp" : formatShort(t.time) + " s";
}

// The mean over seeds of one (view, point, level).
struct Cell {
    std::string view;
    json point;
    const SweepTask* first = nullptr;
    std::vector<double> relMSE, times;
    double mean() const {
        double s = 0.0;
        for (double v : relMSE)
            s += v;
        return s / double(relMSE.size());
    }
    double meanTime() const {
        double s = 0.0;
        for (double v : times)
            s += v;
        return s / double(times.size());
    }
    // The standard error of the mean over seeds (0 with one seed).
    double standardError() const {
        const std::size_t n = relMSE.size();
        if (n < 2) return 0.0;
        const double m = mean();
        double s = 0.0;
        for (double v : relMSE)
            s += (v - m) * (v - m);
        return std::sqrt(s / double(n - 1) / double(n));
    }
};

struct Series {
    std::string label;
    std::vector<double> x, y, error;
    std::vector<double> order;  // the points are joined in this order (the spp or time budget: a render time measured
                                // on a busy machine need not grow with them)
};

json seriesJson(const std::vector<Series>& series) {
    json out = json::array();
    for (const Series& s : series)
        out.push_back({{"label", s.label}, {"x", s.x}, {"y", s.y}, {"yError", s.error}});
    return out;
}

void sortSeries(Series& s) {
    std::vector<std::size_t> order(s.x.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return s.order[a] < s.order[b]; });
    Series sorted{s.label, {}, {}, {}, {}};
    for (std::size_t i : order) {
        sorted.x.push_back(s.x[i]);
        sorted.y.push_back(s.y[i]);
        sorted.error.push_back(s.error[i]);
        sorted.order.push_back(s.order[i]);
    }
    s = sorted;
}

// A curve's value at time t, linear in log-log on the first segment between its points (in their order) that spans t;
// none outside them.
std::optional<double> interpolateLogLog(const Series& s, double t) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (std::abs(s.x[i] - t) <= 1e-9 * t) return s.y[i];
        if (i + 1 < s.x.size() && std::min(s.x[i], s.x[i + 1]) < t && t < std::max(s.x[i], s.x[i + 1]) &&
            s.x[i] > 0.0 && s.y[i] > 0.0 && s.y[i + 1] > 0.0) {
            const double f = std::log(t / s.x[i]) / std::log(s.x[i + 1] / s.x[i]);
            return std::exp(std::log(s.y[i]) + f * (std::log(s.y[i + 1]) - std::log(s.y[i])));
        }
    }
    return std::nullopt;
}

// tyndall-plot: $TYNDALL_PLOT, else beside this program (installed), else the build tree's studio/plot.
std::string findPlotProgram() {
    if (const char* env = std::getenv("TYNDALL_PLOT"); env && *env) return env;
    const fs::path self = selfExecutable();
    for (const fs::path& candidate :
         {self.parent_path() / "tyndall-plot", self.parent_path().parent_path() / "plot" / "tyndall-plot"})
        if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    return "";
}

}  // namespace

int gatherSweep(const std::string& dir) {
    const SweepPlan plan = readPlan(dir);
    std::vector<std::string> missing;
    for (const SweepTask& t : plan.tasks)
        if (const TaskStatus s = taskStatus(dir, t); s.state != TaskState::Done)
            missing.push_back("task " + std::to_string(t.index) + " " + t.id + " (view '" + t.view +
                              "'): " + toString(s.state) + (s.detail.empty() ? "" : "; " + s.detail));
    if (!missing.empty()) {
        std::fprintf(stderr, "tyndall: cannot gather '%s': %zu of %zu tasks are not done; nothing was written:\n",
                     plan.name.c_str(), missing.size(), plan.tasks.size());
        for (const std::string& m : missing)
            std::fprintf(stderr, "  %s\n", m.c_str());
        return kFailure;
    }

    OutputSet files;  // the references, results and tables appear together or not at all
    // The references: each a merge of its shards, or the given image.
    std::map<std::string, Image> references;
    std::map<std::string, std::string> referenceFiles;
    if (!plan.referenceImage.empty()) {
        references.emplace("given", readLinearExr(plan.referenceImage, "reference.image"));
        referenceFiles["given"] = plan.referenceImage;
    }
    std::map<std::string, std::vector<const SweepTask*>> shards;
    for (const SweepTask& t : plan.tasks)
        if (t.kind == SweepTaskKind::ReferenceShard) shards[t.reference].push_back(&t);
    for (const auto& [key, parts] : shards) {
        std::vector<Image> images;
        std::vector<std::string> paths;
        for (const SweepTask* t : parts) {
            paths.push_back((fs::path(dir) / t->output()).string());
            images.push_back(readLinearExr(paths.back(), "reference shard"));
        }
        Image merged = images.size() == 1 ? images[0] : mergeRenders(images, paths);
        const std::string file = "references/" + key + ".exr";
        files.stage((fs::path(dir) / file).string(), encodeImage(merged, file));
        referenceFiles[key] = file;
        references.emplace(key, std::move(merged));
    }

    // Every render against its reference.
    std::vector<Row> rows;
    for (const SweepTask& t : plan.tasks) {
        if (t.kind != SweepTaskKind::View) continue;
        const std::string path = (fs::path(dir) / t.output()).string();
        const Image image = readLinearExr(path, "task " + t.id);
        const Image& reference = references.at(t.reference);
        Row row{&t,
                image.metadata.count("technique") ? image.metadata.at("technique") : "",
                {},
                0.0,
                0,
                {},
                referenceFiles.at(t.reference)};
        try {
            row.metrics = computeMetrics(image, reference, metadataNumber(image, "exposure", 0.0));
        } catch (const InputError& e) {
            throw InputError(InputLocation{path, 0, 0, ""},
                             e.message() + " (against the reference " + row.reference + ")");
        }
        row.renderTime = metadataNumber(image, "renderTime", 0.0);
        row.spp = int(metadataNumber(image, "spp", 0.0));
        if (std::find(plan.metrics.begin(), plan.metrics.end(), "flip") != plan.metrics.end())
            row.flipMean = flipStatistics(hdrFlip(reference, image).error).mean;
        rows.push_back(row);
    }
    const bool flip = std::find(plan.metrics.begin(), plan.metrics.end(), "flip") != plan.metrics.end();

    // results.csv and results.json.
    std::string csv = "id,view,technique";
    for (const std::string& axis : plan.axes)
        csv += "," + csvField(axis);
    csv += ",seed,spp,timeBudget,renderTime,rmse,relMSE,mape,psnr,bias,referenceNoiseRelMSE";
    if (flip) csv += ",flipMean";
    csv += ",image,reference\n";
    json results{{"name", plan.name},       {"spec", plan.specPath}, {"project", plan.project},
                 {"measure", plan.measure}, {"axes", plan.axes},     {"references", json::array()},
                 {"renders", json::array()}};
    for (const auto& [key, file] : referenceFiles) {
        const Image& r = references.at(key);
        results["references"].push_back({{"key", key},
                                         {"image", file},
                                         {"spp", int(metadataNumber(r, "spp", 0.0))},
                                         {"renderTime", metadataNumber(r, "renderTime", 0.0)},
                                         {"shards", shards.count(key) ? shards.at(key).size() : 0}});
    }
    for (const Row& r : rows) {
        const SweepTask& t = *r.task;
        csv += t.id + "," + csvField(t.view) + "," + csvField(r.technique);
        for (const std::string& axis : plan.axes)
            csv += "," + csvField(valueText(t.point.value(axis, json())));
        const std::string noise = r.metrics.referenceNoiseRelMSE ? formatNumber(*r.metrics.referenceNoiseRelMSE) : "";
        csv += "," + std::to_string(t.seed) + "," + std::to_string(r.spp) + "," +
               (t.time > 0.0 ? formatNumber(t.time) : "") + "," + formatNumber(r.renderTime) + "," +
               formatNumber(r.metrics.rmse) + "," + formatNumber(r.metrics.relMSE) + "," +
               formatNumber(r.metrics.mape) + "," + formatNumber(r.metrics.psnr) + "," +
               formatNumber(r.metrics.energyBias) + "," + noise;
        if (flip) csv += "," + formatNumber(r.flipMean.value_or(0.0));
        csv += "," + csvField(t.output()) + "," + csvField(r.reference) + "\n";
        json entry = metricsToJson(r.metrics);
        entry.update(json{{"id", t.id},
                          {"view", t.view},
                          {"technique", r.technique},
                          {"point", t.point},
                          {"seed", t.seed},
                          {"spp", r.spp},
                          {"renderTime", r.renderTime},
                          {"image", t.output()},
                          {"reference", r.reference}});
        if (t.time > 0.0) entry["timeBudget"] = t.time;
        if (r.flipMean) entry["flipMean"] = *r.flipMean;
        results["renders"].push_back(entry);
    }

    // Means over seeds per (view, point, level).
    std::map<std::string, Cell> cells;
    std::vector<std::string> cellOrder;
    for (const Row& r : rows) {
        const SweepTask& t = *r.task;
        const std::string key = t.view + "|" + t.point.dump() + "|" + levelText(t);
        auto [it, added] = cells.try_emplace(key);
        if (added) {
            it->second.view = t.view;
            it->second.point = t.point;
            it->second.first = &t;
            cellOrder.push_back(key);
        }
        it->second.relMSE.push_back(r.metrics.relMSE);
        it->second.times.push_back(r.renderTime);
    }
    // Each cell a point of the curve named curveOf(cell), at xOf(cell), joined in the order of orderOf(cell) (xOf's).
    const auto seriesOver = [&](const std::function<std::string(const Cell&)>& curveOf,
                                const std::function<double(const Cell&)>& xOf,
                                const std::function<double(const Cell&)>& orderOf = nullptr) {
        std::vector<Series> series;
        std::map<std::string, std::size_t> index;
        for (const std::string& key : cellOrder) {
            const Cell& c = cells.at(key);
            const std::string label = curveOf(c);
            auto [it, added] = index.try_emplace(label, series.size());
            if (added) series.push_back(Series{label, {}, {}, {}, {}});
            Series& s = series[it->second];
            s.x.push_back(xOf(c));
            s.order.push_back(orderOf ? orderOf(c) : s.x.back());
            s.y.push_back(c.mean());
            s.error.push_back(c.standardError());
        }
        for (Series& s : series)
            sortSeries(s);
        return series;
    };
    std::set<std::string> levels;
    for (const auto& [key, c] : cells)
        levels.insert(levelText(*c.first));
    const auto withPoint = [](std::string label, const std::string& point) {
        return point.empty() ? label : label + " (" + point + ")";
    };

    // Every plot: relMSE (mean over seeds) on a log axis against something.
    json plots = json::array();
    const auto addPlot = [&](const std::string& file, const std::string& what, const std::string& xLabel, bool logX,
                             const std::vector<Series>& series) {
        plots.push_back({{"file", file},
                         {"title", plan.name + ": " + what},
                         {"xLabel", xLabel},
                         {"yLabel", "relMSE (mean over seeds)"},
                         {"xLog", logX},
                         {"yLog", true},
                         {"series", seriesJson(series)}});
    };
    for (const std::string& axis : plan.axes) {
        std::set<double> values;
        bool numeric = true;
        for (const auto& [key, c] : cells) {
            const json v = c.point.value(axis, json());  // null: the axis does not apply to the view
            if (!v.is_null() && !v.is_number())
                numeric = false;
            else if (v.is_number())
                values.insert(v.get<double>());
        }
        if (!numeric || values.size() < 2) continue;
        const bool logX = *values.begin() > 0.0 && *values.rbegin() / *values.begin() >= 10.0;
        auto series = seriesOver(
            [&](const Cell& c) {
                if (!c.point.contains(axis)) return std::string();  // left out below
                std::string label = withPoint(c.view, pointText(c.point, axis));
                return levels.size() > 1 ? label + ", " + levelText(*c.first) : label;
            },
            [&](const Cell& c) { return c.point.contains(axis) ? c.point.at(axis).get<double>() : 0.0; });
        std::erase_if(series, [](const Series& s) { return s.label.empty(); });
        addPlot("error-vs-" + slug(axisName(axis)), "error against " + axisName(axis), axisName(axis), logX, series);
    }
    // Error against time: a curve per view and point through its sample counts or time budgets. With one of those,
    // a technique's parameters (axes "views[...]...") are what trades time for error: a curve per view and scene
    // point through them instead (LTSD's node count, the paper's Fig. 10).
    const auto level = [](const Cell& c) { return c.first->spp > 0 ? double(c.first->spp) : c.first->time; };
    const auto isTechniqueAxis = [](const std::string& axis) { return axis.rfind("views[", 0) == 0; };
    std::string techniqueAxis;
    for (const std::string& axis : plan.axes)
        if (isTechniqueAxis(axis) && techniqueAxis.empty()) techniqueAxis = axis;
    const bool throughTechnique = levels.size() == 1 && !techniqueAxis.empty();
    const auto timeSeries = seriesOver(
        [&](const Cell& c) {
            if (!throughTechnique) return withPoint(c.view, pointText(c.point));
            json scene = json::object();
            for (const auto& [path, value] : c.point.items())
                if (!isTechniqueAxis(path)) scene[path] = value;
            const std::string label = withPoint(c.view, pointText(scene));
            return c.point.contains(techniqueAxis) ? label + ", over " + axisName(techniqueAxis) : label;
        },
        [](const Cell& c) { return c.meanTime(); },
        [&](const Cell& c) {
            if (!throughTechnique) return level(c);
            const json v = c.point.value(techniqueAxis, json());
            return v.is_number() ? v.get<double>() : c.meanTime();
        });
    addPlot("error-vs-time", "error against render time", "render time (s, mean over seeds)", true, timeSeries);
    if (plan.measure == "spp" && levels.size() > 1) {
        addPlot("error-vs-spp", "error against samples per pixel", "samples per pixel", true,
                seriesOver([&](const Cell& c) { return withPoint(c.view, pointText(c.point)); },
                           [](const Cell& c) { return double(c.first->spp); }));
    }

    // The equal-time table. With time budgets, every render had the same time: a row per view and point, a column per
    // budget, each cell its mean relMSE over the seeds and (in the Markdown) the mean time the renders took. With
    // sample counts, each curve of the error-against-time plot at four times spread in log over the renders' times,
    // interpolated in log-log between its points; "-" outside them.
    std::string tableCsv = "curve", tableMd = "| curve |", rule = "|---|";
    if (plan.measure == "time") {
        std::set<double> budgets;
        std::map<std::string, std::map<double, const Cell*>> rowsOf;
        std::vector<std::string> rowOrder;
        for (const std::string& key : cellOrder) {
            const Cell& c = cells.at(key);
            budgets.insert(c.first->time);
            const std::string label = withPoint(c.view, pointText(c.point));
            if (!rowsOf.count(label)) rowOrder.push_back(label);
            rowsOf[label][c.first->time] = &c;
        }
        for (double t : budgets) {
            tableCsv += ",relMSE at " + formatShort(t) + " s,mean time at " + formatShort(t) + " s";
            tableMd += " relMSE at " + formatShort(t) + " s (time taken) |";
            rule += "---|";
        }
        tableCsv += "\n";
        tableMd += "\n" + rule + "\n";
        for (const std::string& label : rowOrder) {
            tableCsv += csvField(label);
            tableMd += "| " + label + " |";
            for (double t : budgets) {
                const auto it = rowsOf[label].find(t);
                if (it == rowsOf[label].end()) {
                    tableCsv += ",,";
                    tableMd += " - |";
                    continue;
                }
                tableCsv += "," + formatNumber(it->second->mean()) + "," + formatNumber(it->second->meanTime());
                tableMd += " " + formatShort(it->second->mean()) + " (" + formatShort(it->second->meanTime()) + " s) |";
            }
            tableCsv += "\n";
            tableMd += "\n";
        }
        tableMd +=
            "\nEach render was given the time budget of its column (a technique whose first pass takes longer "
            "renders one pass); relMSE is the mean over the seeds.\n";
    } else {
        // Over the times every curve reaches when there are such (two curves or more), else over all of them.
        std::vector<double> times;
        double lo = 1e300, hi = 0.0, commonLo = 0.0, commonHi = 1e300;
        int spanning = 0;
        for (const Series& s : timeSeries) {
            double slo = 1e300, shi = 0.0;
            for (double x : s.x)
                if (x > 0.0) slo = std::min(slo, x), shi = std::max(shi, x);
            if (shi <= 0.0) continue;
            lo = std::min(lo, slo), hi = std::max(hi, shi);
            commonLo = std::max(commonLo, slo), commonHi = std::min(commonHi, shi);
            ++spanning;
        }
        if (spanning >= 2 && commonHi > commonLo * 1.0001) lo = commonLo, hi = commonHi;
        if (hi > 0.0) {
            const int n = hi > lo * 1.0001 ? 4 : 1;
            for (int i = 0; i < n; ++i)
                times.push_back(n == 1 ? lo : lo * std::pow(hi / lo, double(i) / (n - 1)));
        }
        for (double t : times) {
            tableCsv += ",relMSE at " + formatShort(t) + " s";
            tableMd += " relMSE at " + formatShort(t) + " s |";
            rule += "---|";
        }
        tableCsv += "\n";
        tableMd += "\n" + rule + "\n";
        for (const Series& s : timeSeries) {
            tableCsv += csvField(s.label);
            tableMd += "| " + s.label + " |";
            for (double t : times) {
                const auto v = interpolateLogLog(s, t);
                tableCsv += "," + (v ? formatNumber(*v) : std::string());
                tableMd += " " + (v ? formatShort(*v) : std::string("-")) + " |";
            }
            tableCsv += "\n";
            tableMd += "\n";
        }
        tableMd +=
            "\nEach curve of the error-against-time plot at times spread over the times all curves reach (or, where "
            "they share none, over all renders' mean times), interpolated in log-log between its points; - outside "
            "a curve.\n";
    }

    files.stage((fs::path(dir) / "results.csv").string(), csv);
    files.stage((fs::path(dir) / "results.json").string(), results.dump(2) + "\n");
    files.stage((fs::path(dir) / "plots" / "equal-time.csv").string(), tableCsv);
    files.stage((fs::path(dir) / "plots" / "equal-time.md").string(), tableMd);
    const std::string plotsJson = (fs::path(dir) / "plots" / "plots.json").string();
    files.stage(plotsJson, json{{"plots", plots}}.dump(2) + "\n");
    files.commit();
    std::printf("gathered %zu renders against %zu reference(s): %s/results.csv, results.json, plots/equal-time.md\n",
                rows.size(), referenceFiles.size(), dir.c_str());

    // The plots as PNG and SVG, drawn by tyndall-plot (Qt and QCustomPlot, offscreen; the CLI itself has no Qt).
    const std::string plotter = findPlotProgram();
    if (plotter.empty()) {
        std::fprintf(stderr,
                     "tyndall: warning: tyndall-plot was not found (it is built with the studio; or set "
                     "TYNDALL_PLOT): the plots' data is in %s, no PNG or SVG was drawn\n",
                     plotsJson.c_str());
        return kOk;
    }
    std::fflush(stdout);
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::execl(plotter.c_str(), plotter.c_str(), plotsJson.c_str(), static_cast<char*>(nullptr));
        std::fprintf(stderr, "tyndall: cannot run %s: %s\n", plotter.c_str(), std::strerror(errno));
        ::_exit(127);
    }
    int status = 0;
    if (pid < 0 || ::waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::fprintf(stderr, "tyndall: the plots were not drawn (%s failed); their data is in %s\n", plotter.c_str(),
                     plotsJson.c_str());
        return kFailure;
    }
    return kOk;
}

}  // namespace tyndall::cli
