#include "exporter.h"

#include "tyndall/image/image_io.h"
#include "tyndall/image/metrics.h"

#include <QDir>
#include <QSaveFile>

#include <nlohmann/json.hpp>

#include <atomic>
#include <memory>
#include <optional>

namespace tyndall::studio {

Exporter::Exporter(Background& background, QObject* parent) : QObject(parent), background_(background) {}

std::vector<std::function<void()>> Exporter::plan(const QString& folder, const Input& input) {
    QDir dir(folder);
    if (!dir.exists() && !QDir().mkpath(folder)) throw std::runtime_error("cannot create " + folder.toStdString());
    std::vector<std::function<void()>> steps;
    nlohmann::json metrics = nlohmann::json::array();
    struct MetricsRow {
        std::size_t entry;
        std::string view;
        std::shared_ptr<const Image> image, against;
        double exposure;
        std::optional<Metrics> known;
    };
    std::vector<MetricsRow> rows;
    const double scale = sharedDifferenceScale(input.frames);
    const Tonemap tonemap = input.display.tonemap;
    notes_.clear();
    for (const ViewFrame& f : input.frames) {
        const std::string stem = dir.filePath(f.name).toStdString();
        // PNGs as the viewport shows them: the view's exposure with the E / Shift+E offset, and the operator.
        const double own = f.exposure, exposure = f.exposure + input.display.exposureOffset;
        // A view and its reference only as a pair of one state: the last such pair while the reference of an edit
        // renders (marked stale); the image alone, said so, before the first one.
        const ComparisonPair pair = referencePair(f);
        const std::shared_ptr<const Image> image = pair.image ? pair.image : f.image;
        if (image) {
            steps.push_back([image, stem, own] { writeImage(*image, stem + ".exr", own); });
            steps.push_back([image, stem, exposure, tonemap] { writeImage(*image, stem + ".png", exposure, tonemap); });
        }
        if (pair.against) {
            const std::shared_ptr<const Image> against = pair.against;
            steps.push_back([against, stem, own] { writeImage(*against, stem + "-reference.exr", own); });
            steps.push_back([against, stem, exposure, tonemap] {
                writeImage(*against, stem + "-reference.png", exposure, tonemap);
            });
            steps.push_back([image, against, stem, scale] {
                writeImage(differenceImage(*image, *against, DifferenceKind::Signed, scale), stem + "-diff.png");
            });
        }
        nlohmann::json m = {{"view", f.name.toStdString()}};
        if (!image) {
            m["missing"] = "no image yet";
            notes_ << f.name + ": no image yet, nothing exported";
        } else if (!pair.against) {
            m["missing"] = "the reference is not ready";
            notes_ << f.name + ": the reference is not ready, the image is exported alone";
        } else {
            m["partHash"] = image->metadata.count("partHash") ? image->metadata.at("partHash") : "";
            m["stale"] = pair.stale;
            if (pair.stale) notes_ << f.name + ": the last image and reference of one state (stale)";
        }
        // The metrics of the exported pair: the model's when they are of that pair, else computed with the files (they
        // were left out while the model's were in flight, or while the view was compared with a snapshot).
        if (pair.against) {
            std::optional<Metrics> known;
            if (f.metrics && !f.snapshot && !f.alternate) known = f.metrics;
            rows.push_back({metrics.size(), f.name.toStdString(), image, pair.against, own, known});
        }
        metrics.push_back(m);
        // Region insets: the region of the view and of its reference, when a region is drawn.
        const QRect region =
            image ? input.display.region.intersected(QRect(0, 0, image->width(), image->height())) : QRect();
        if (region.isEmpty()) continue;
        const QString insets = dir.filePath(f.name);
        const std::shared_ptr<const Image> against = pair.against;
        steps.push_back([image, against, insets, region, exposure, tonemap] {
            toDisplay(*image, exposure, tonemap).copy(region).save(insets + "-region.png");
            if (against) toDisplay(*against, exposure, tonemap).copy(region).save(insets + "-reference-region.png");
        });
    }
    auto writeText = [dir](const QString& name, const std::string& text) {
        return [path = dir.filePath(name), text] {
            QSaveFile file(path);
            if (!file.open(QIODevice::WriteOnly) || file.write(text.data(), qint64(text.size())) < 0 || !file.commit())
                throw std::runtime_error("cannot write " + path.toStdString());
        };
    };
    steps.push_back([rows = std::move(rows), metrics, writeText]() mutable {
        std::string csv = metricsCsvHeader() + "\n";
        for (const MetricsRow& row : rows) {
            const Metrics m = row.known ? *row.known : computeMetrics(*row.image, *row.against, row.exposure);
            metrics[row.entry].update(metricsToJson(m));
            csv += metricsCsvRow(row.view, m) + "\n";
        }
        writeText("metrics.json", metrics.dump(2) + "\n")();
        writeText("metrics.csv", csv)();
    });
    const nlohmann::json display = {{"tonemap", tonemapNames()[std::size_t(input.display.tonemap)]},
                                     {"exposureOffset", input.display.exposureOffset},
                                     {"differenceScale", scale}};
    steps.push_back(writeText("display.json", display.dump(2) + "\n"));
    steps.push_back([frame = input.viewport, path = dir.filePath("viewport.png")] {
        if (!frame.save(path)) throw std::runtime_error("cannot write viewport.png");
    });
    // The plots draw with their widgets: here, on the GUI thread (~0.1 s each).
    for (const PlotFile& plot : input.plots)
        for (const char* suffix : {".png", ".svg"}) {
            QString why;
            if (!plot.write(dir.filePath("plot-" + plot.name + suffix), &why))
                throw std::runtime_error(why.toStdString());
        }
    return steps;
}

bool Exporter::exportNow(const QString& folder, const Input& input, QString* error) {
    try {
        for (const auto& step : plan(folder, input))
            step();
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

void Exporter::start(const QString& folder, const Input& input) {
    std::vector<std::function<void()>> steps;
    try {
        steps = plan(folder, input);
    } catch (const std::exception& e) {
        emit finished(false, QString::fromStdString(e.what()));
        return;
    }
    // The files are written in the background pool, one after another: the window stays live (the export froze it
    // for 20-30 s), and the window's progress dialog can cancel between two files.
    auto cancelled = std::make_shared<std::atomic<bool>>(false);
    cancelled_ = cancelled;
    ++running_;
    emit started(int(steps.size()));
    background_.run([this, steps = std::move(steps), cancelled] {
        QString error;
        int done = 0;
        try {
            for (const auto& step : steps) {
                if (*cancelled) {
                    error = "cancelled";
                    break;
                }
                step();
                QMetaObject::invokeMethod(
                    this, [this, n = ++done] { emit progress(n); }, Qt::QueuedConnection);
            }
        } catch (const std::exception& e) {
            error = QString::fromStdString(e.what());
        }
        QMetaObject::invokeMethod(
            this,
            [this, error] {
                --running_;
                emit finished(error.isEmpty(), error.isEmpty() ? notes_.join("\n") : error);
            },
            Qt::QueuedConnection);
    });
}

void Exporter::cancel() {
    if (cancelled_) *cancelled_ = true;
}

}  // namespace tyndall::studio
