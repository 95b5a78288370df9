#include "exporter.h"

#include "tyndall/core/text.h"
#include "tyndall/image/flip.h"
#include "tyndall/image/image_io.h"
#include "tyndall/image/metrics.h"

#include <QDir>
#include <QFileInfo>
#include <QSaveFile>
#include <QUuid>

#include <nlohmann/json.hpp>

#include <atomic>
#include <map>
#include <memory>
#include <optional>

namespace tyndall::studio {

// What the steps of one export share (they run one after another on one thread): what could not be written and why.
struct Exporter::Report {
    QStringList notes;                          // known when planned: views without a pair, stale pairs
    std::vector<QString> views;                 // their names, in metrics.json's order
    std::map<std::size_t, QStringList> failed;  // per view: what could not be written, and why
    QStringList plotsFailed;

    QStringList summary() const {
        QStringList lines = notes;
        for (const auto& [view, what] : failed)
            lines << views[view] + ": not exported: " + what.join("; ");
        lines << plotsFailed;
        return lines;
    }
};

namespace {

// An image as an EXR with the view's exposure now: the image may have been rendered before an edit of the exposure,
// which renders nothing (RenderScheduler), and `tyndall compare` reads the exposure back as its default.
void writeExrWithExposure(const Image& image, const std::string& path, double exposure) {
    Image stamped = image;
    stamped.metadata["exposure"] = std::to_string(exposure);
    writeImage(stamped, path, exposure);
}

std::string describe(const Region& r) {
    return std::to_string(r.width) + "x" + std::to_string(r.height) + " at " + std::to_string(r.x) + "," +
           std::to_string(r.y);
}

// Moves what the staging folder holds into `folder`: the folder itself when there is none yet (one rename), else file
// by file, replacing files of an earlier export of the same names.
void moveIntoPlace(const QString& staging, const QString& folder) {
    if (!QFileInfo::exists(folder)) {
        if (!QDir().rename(staging, folder))
            throw std::runtime_error("cannot move the export into " + folder.toStdString());
        return;
    }
    const QDir from(staging), to(folder);
    for (const QString& name : from.entryList(QDir::Files)) {
        const QString target = to.filePath(name);
        if (QFileInfo::exists(target) && !QFile::remove(target))
            throw std::runtime_error("cannot replace " + target.toStdString());
        if (!QFile::rename(from.filePath(name), target))
            throw std::runtime_error("cannot move " + name.toStdString() + " into " + folder.toStdString());
    }
    QDir(staging).removeRecursively();
}

}  // namespace

Exporter::Exporter(Background& background, QObject* parent) : QObject(parent), background_(background) {}

Exporter::Plan Exporter::plan(const QString& target, const Input& input) {
    // Everything is written into a hidden folder beside the target and moved into place at the end: a failure or a
    // cancel leaves the target as it was, never half written.
    Plan plan;
    plan.folder = QDir::cleanPath(QFileInfo(target).absoluteFilePath());
    const QFileInfo info(plan.folder);
    if (info.exists() && !info.isDir())
        throw std::runtime_error(plan.folder.toStdString() + " is a file, not a folder");
    const QString parent = info.absolutePath();
    if (!QDir().mkpath(parent)) throw std::runtime_error("cannot create " + parent.toStdString());
    plan.staging =
        QDir(parent).filePath("." + info.fileName() + ".export-" + QUuid::createUuid().toString(QUuid::Id128).left(8));
    if (!QDir().mkpath(plan.staging)) throw std::runtime_error("cannot write into " + parent.toStdString());
    const QDir dir(plan.staging);
    auto report = std::make_shared<Report>();
    plan.report = report;
    std::vector<std::function<void()>>& steps = plan.steps;

    nlohmann::json metrics = nlohmann::json::array();
    struct MetricsRow {
        std::size_t entry;
        std::shared_ptr<const Image> image, against;
        double exposure;
        std::optional<Metrics> known;
        // HDR-FLIP's error map of the pair: the model's when it is of that pair, else made by the view's FLIP step
        // (or by the metrics step, when that failed).
        std::shared_ptr<std::shared_ptr<const std::vector<float>>> flip;
    };
    std::vector<MetricsRow> rows;
    const double scale = sharedDifferenceScale(input.frames);
    const DisplayTransform transform = input.display.displayTransform;  // the PNGs' (and the viewport's)
    for (const ViewFrame& f : input.frames) {
        const std::size_t entry = metrics.size();
        report->views.push_back(f.name);
        // A file of one view that cannot be written (an image of another size than its reference, a channel missing)
        // is listed with the reason; the export goes on with the others.
        auto viewStep = [&steps, report, entry](const QString& what, std::function<void()> write) {
            steps.push_back([report, entry, what, write = std::move(write)] {
                try {
                    write();
                } catch (const std::exception& e) {
                    report->failed[entry] << what + " (" + QString::fromStdString(e.what()) + ")";
                }
            });
        };
        const std::string stem = dir.filePath(f.name).toStdString();
        // PNGs as the viewport shows them: the view's exposure with the E / Shift+E offset, and the operator.
        const double own = f.exposure, exposure = f.exposure + input.display.exposureOffset;
        // A view and its reference only as a pair of one state: the last such pair while the reference of an edit
        // renders (marked stale); the image alone, said so, before the first one. Without a reference (an image-only
        // session), against the view chosen as every view's reference (Shift+1-9).
        const bool againstView = !f.reference && f.alternate;
        const ComparisonPair pair = againstView ? comparisonPair(f) : referencePair(f);
        const std::shared_ptr<const Image> image = pair.image ? pair.image : f.image;
        if (image) {
            viewStep("the image", [image, stem, own] { writeExrWithExposure(*image, stem + ".exr", own); });
            viewStep("the image's PNG",
                     [image, stem, exposure, transform] { writeImage(*image, stem + ".png", exposure, transform); });
        }
        const std::shared_ptr<const Image> against = pair.against;
        if (against) {
            viewStep("the reference",
                     [against, stem, own] { writeExrWithExposure(*against, stem + "-reference.exr", own); });
            viewStep("the reference's PNG", [against, stem, exposure, transform] {
                writeImage(*against, stem + "-reference.png", exposure, transform);
            });
            viewStep("the difference", [image, against, stem, scale] {
                writeImage(differenceImage(*image, *against, DifferenceKind::Signed, scale), stem + "-diff.png");
            });
        }
        auto flip = std::make_shared<std::shared_ptr<const std::vector<float>>>(
            image && against && f.flipMap && f.flipImage == image && f.flipAgainst == against ? f.flipMap : nullptr);
        if (image && against) {
            // The FLIP view (D's fifth mode): the error map through magma, and its values as an EXR.
            viewStep("the FLIP map", [image, against, stem, flip] {
                if (!*flip) *flip = std::make_shared<const std::vector<float>>(hdrFlip(*against, *image).error);
                writeImage(flipColourMap(**flip, image->width(), image->height()), stem + "-flip.png");
                Image map(image->width(), image->height(), {"FLIP"});
                std::copy((*flip)->begin(), (*flip)->end(), map.data());
                map.metadata["flip.colourMap"] = "magma, in " + stem + "-flip.png";
                writeImage(map, stem + "-flip.exr");
            });
        }
        nlohmann::json m = {{"view", f.name.toStdString()}};
        if (!image) {
            m["missing"] = "no image yet";
            report->notes << f.name + ": no image yet, nothing exported";
        } else if (!against) {
            m["missing"] = "the reference is not ready";
            report->notes << f.name + ": the reference is not ready, the image is exported alone";
        } else {
            if (againstView) m["against"] = f.alternateName.toStdString();
            m["partHash"] = image->metadata.count("partHash") ? image->metadata.at("partHash") : "";
            m["stale"] = pair.stale;
            if (pair.stale) report->notes << f.name + ": the last image and reference of one state (stale)";
        }
        // The metrics of the exported pair: the model's when they are of that pair, else computed with the files (the
        // model's new ones were in flight).
        if (against) {
            std::optional<Metrics> known;
            if (f.metrics && f.metricsImage == image && f.metricsAgainst == against) known = f.metrics;
            rows.push_back({entry, image, against, own, known, flip});
        }
        metrics.push_back(m);
        // Region insets: the region of the view and of its reference, when a region is drawn.
        const QRect region =
            image ? input.display.region.intersected(QRect(0, 0, image->width(), image->height())) : QRect();
        if (region.isEmpty()) continue;
        const QString insets = dir.filePath(f.name);
        viewStep("the region's insets", [image, against, insets, region, exposure, transform] {
            if (!toDisplay(*image, exposure, transform).copy(region).save(insets + "-region.png"))
                throw std::runtime_error("cannot write the image's inset");
            if (against &&
                !toDisplay(*against, exposure, transform).copy(region).save(insets + "-reference-region.png"))
                throw std::runtime_error("cannot write the reference's inset");
        });
    }
    auto writeText = [dir](const QString& name, const std::string& text) {
        return [path = dir.filePath(name), text] {
            QSaveFile file(path);
            if (!file.open(QIODevice::WriteOnly) || file.write(text.data(), qint64(text.size())) < 0 || !file.commit())
                throw std::runtime_error("cannot write " + path.toStdString());
        };
    };
    // The plots draw with their widgets: here, on the GUI thread (~0.1 s each).
    for (const PlotFile& plot : input.plots)
        for (const char* suffix : {".png", ".svg"}) {
            QString why;
            if (!plot.write(dir.filePath("plot-" + plot.name + suffix), &why))
                report->plotsFailed << "plot " + plot.name + suffix + ": not exported (" + why + ")";
        }
    // metrics.json and .csv after the views' files: they list what could not be written.
    const QRect region = input.display.region;
    steps.push_back([rows = std::move(rows), metrics, writeText, report, region]() mutable {
        std::string csv = metricsCsvHeader() + ",flip\n";
        for (const MetricsRow& row : rows) {
            nlohmann::json& entry = metrics[row.entry];
            const std::string view = entry["view"].get<std::string>();
            try {
                const Metrics m = row.known ? *row.known : computeMetrics(*row.image, *row.against, row.exposure);
                entry.update(metricsToJson(m));
                // HDR-FLIP's summary as FLIP's papers report it (the mean, the weighted median and quartiles).
                if (!*row.flip)
                    *row.flip = std::make_shared<const std::vector<float>>(hdrFlip(*row.against, *row.image).error);
                const std::vector<float>& flipMap = **row.flip;
                const FlipStatistics flip = flipStatistics(flipMap);
                entry["flip"] = {{"mean", flip.mean},
                                 {"weightedMedian", flip.weightedMedian},
                                 {"weightedFirstQuartile", flip.weightedFirstQuartile},
                                 {"weightedThirdQuartile", flip.weightedThirdQuartile},
                                 {"maximum", flip.maximum}};
                csv += metricsCsvRow(view, m) + "," + formatNumber(flip.mean) + "\n";
                // The region's metrics beside the whole image's, as the metrics dock shows them.
                const QRect r = region.intersected(QRect(0, 0, row.image->width(), row.image->height()));
                if (!r.isEmpty()) {
                    const Region part{r.x(), r.y(), r.width(), r.height()};
                    const Metrics inRegion = computeMetrics(*row.image, *row.against, row.exposure, part);
                    entry["region"] = metricsToJson(inRegion);
                    entry["region"]["x"] = part.x;
                    entry["region"]["y"] = part.y;
                    entry["region"]["width"] = part.width;
                    entry["region"]["height"] = part.height;
                    const double regionFlip =
                        flipRegionMean(flipMap, row.image->width(), part.x, part.y, part.width, part.height);
                    entry["region"]["flip"] = {{"mean", regionFlip}};
                    csv += metricsCsvRow(view + " (region " + describe(part) + ")", inRegion) + "," +
                           formatNumber(regionFlip) + "\n";
                }
            } catch (const std::exception& e) {
                report->failed[row.entry] << "the metrics (" + QString::fromStdString(e.what()) + ")";
            }
        }
        for (const auto& [view, what] : report->failed) {
            nlohmann::json& list = metrics[view]["notExported"] = nlohmann::json::array();
            for (const QString& w : what)
                list.push_back(w.toStdString());
        }
        writeText("metrics.json", metrics.dump(2) + "\n")();
        writeText("metrics.csv", csv)();
    });
    // How the PNGs show the linear values: the OpenColorIO config, display and view, or Tyndall's own operator.
    nlohmann::json display = {{"exposureOffset", input.display.exposureOffset}, {"differenceScale", scale}};
    if (transform.isOcio()) {
        display["display"] = transform.display();
        display["view"] = transform.view();
        display["ocioConfig"] = transform.config()->file().empty() ? "raw" : transform.config()->file();
    } else {
        display["tonemap"] = transform.name();
    }
    steps.push_back(writeText("display.json", display.dump(2) + "\n"));
    steps.push_back([frame = input.viewport, path = dir.filePath("viewport.png")] {
        if (!frame.save(path)) throw std::runtime_error("cannot write viewport.png");
    });
    steps.push_back([staging = plan.staging, folder = plan.folder] { moveIntoPlace(staging, folder); });
    return plan;
}

bool Exporter::exportNow(const QString& folder, const Input& input, QString* error) {
    Plan p;
    try {
        p = plan(folder, input);
        for (const auto& step : p.steps)
            step();
        notes_ = p.report->summary();
        return true;
    } catch (const std::exception& e) {
        if (!p.staging.isEmpty()) QDir(p.staging).removeRecursively();
        if (error) *error = "Nothing was exported into " + folder + ": " + QString::fromStdString(e.what());
        return false;
    }
}

void Exporter::start(const QString& folder, const Input& input) {
    Plan p;
    try {
        p = plan(folder, input);
    } catch (const std::exception& e) {
        if (!p.staging.isEmpty()) QDir(p.staging).removeRecursively();
        emit finished(false, "Nothing was exported into " + folder + ": " + QString::fromStdString(e.what()), folder);
        return;
    }
    // The files are written in the background pool, one after another: the window stays live (the export froze it
    // for 20-30 s), and the window's progress dialog can cancel between two files.
    auto cancelled = std::make_shared<std::atomic<bool>>(false);
    cancelled_ = cancelled;
    ++running_;
    emit started(int(p.steps.size()));
    background_.run([this, p = std::move(p), cancelled] {
        QString error;
        int done = 0;
        try {
            for (const auto& step : p.steps) {
                if (*cancelled) {
                    error = "cancelled";
                    break;
                }
                step();
                QMetaObject::invokeMethod(
                    this, [this, n = ++done] { emit progress(n); }, Qt::QueuedConnection);
            }
        } catch (const std::exception& e) {
            error = "Nothing was exported into " + p.folder + ": " + QString::fromStdString(e.what());
        }
        if (!error.isEmpty()) QDir(p.staging).removeRecursively();
        QMetaObject::invokeMethod(
            this,
            [this, error, report = p.report, folder = p.folder] {
                --running_;
                if (error.isEmpty()) notes_ = report->summary();
                emit finished(error.isEmpty(), error.isEmpty() ? notes_.join("\n") : error, folder);
            },
            Qt::QueuedConnection);
    });
}

void Exporter::cancel() {
    if (cancelled_) *cancelled_ = true;
}

}  // namespace tyndall::studio
