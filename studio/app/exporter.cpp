#include "exporter.h"

#include "plots.h"

#include "tyndall/image/image_io.h"
#include "tyndall/image/metrics.h"

#include <QDir>
#include <QPointer>
#include <QProgressDialog>
#include <QSaveFile>

#include <nlohmann/json.hpp>

#include <atomic>
#include <memory>

namespace tyndall::studio {

Exporter::Exporter(Background& background, QObject* parent) : QObject(parent), background_(background) {}

std::vector<std::function<void()>> Exporter::plan(const QString& folder, const Input& input) {
    QDir dir(folder);
    if (!dir.exists() && !QDir().mkpath(folder)) throw std::runtime_error("cannot create " + folder.toStdString());
    std::vector<std::function<void()>> steps;
    nlohmann::json metrics = nlohmann::json::array();
    std::string csv = metricsCsvHeader() + "\n";
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
        if (pair.against && f.metrics && !f.snapshot && !f.alternate) {
            m.update(metricsToJson(*f.metrics));
            csv += metricsCsvRow(f.name.toStdString(), *f.metrics) + "\n";
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
    steps.push_back(writeText("metrics.json", metrics.dump(2) + "\n"));
    const nlohmann::json display = {{"tonemap", tonemapNames()[std::size_t(input.display.tonemap)]},
                                     {"exposureOffset", input.display.exposureOffset},
                                     {"differenceScale", scale}};
    steps.push_back(writeText("display.json", display.dump(2) + "\n"));
    steps.push_back(writeText("metrics.csv", csv));
    steps.push_back([frame = input.viewport, path = dir.filePath("viewport.png")] {
        if (!frame.save(path)) throw std::runtime_error("cannot write viewport.png");
    });
    // The plots draw with their widgets: here, on the GUI thread (~0.1 s each).
    for (Plot* plot : input.plots)
        for (const char* suffix : {".png", ".svg"}) {
            QString why;
            if (!plot->exportTo(dir.filePath("plot-" + plot->name() + suffix), &why))
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

void Exporter::start(const QString& folder, const Input& input, QWidget* parent) {
    std::vector<std::function<void()>> steps;
    try {
        steps = plan(folder, input);
    } catch (const std::exception& e) {
        emit finished(false, QString::fromStdString(e.what()));
        return;
    }
    // The files are written in the background pool, one after another, with a progress dialog that can cancel:
    // the window stays live (the export froze it for 20-30 s).
    auto* progress =
        new QProgressDialog("Exporting the comparison into " + folder, "Cancel", 0, int(steps.size()), parent);
    progress->setObjectName("exportProgress");
    progress->setAttribute(Qt::WA_DeleteOnClose);
    progress->setMinimumDuration(0);
    progress->setValue(0);
    auto cancelled = std::make_shared<std::atomic<bool>>(false);
    connect(progress, &QProgressDialog::canceled, this, [cancelled] { *cancelled = true; });
    QPointer<QProgressDialog> dialog(progress);
    ++running_;
    background_.run([this, steps = std::move(steps), cancelled, dialog] {
        QString error;
        int done = 0;
        try {
            for (const auto& step : steps) {
                if (*cancelled) {
                    error = "cancelled";
                    break;
                }
                step();
                QMetaObject::invokeMethod(this, [dialog, n = ++done] {
                    if (dialog) dialog->setValue(n);
                }, Qt::QueuedConnection);
            }
        } catch (const std::exception& e) {
            error = QString::fromStdString(e.what());
        }
        QMetaObject::invokeMethod(this, [this, dialog, error] {
            --running_;
            if (dialog) dialog->close();
            emit finished(error.isEmpty(), error.isEmpty() ? notes_.join("\n") : error);
        }, Qt::QueuedConnection);
    });
}

}  // namespace tyndall::studio
