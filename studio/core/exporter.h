// File > Export: every view, its reference and its difference (EXR and PNG), region insets, the viewport (PNG), the
// metrics (JSON and CSV), the display settings and the plots (PNG and SVG) into a folder. A view is exported with its
// reference only as a pair of one state (ComparisonPair), marked "stale" in metrics.json when it is not the current
// one; a view without a pair is listed there with what is missing, and in notes(). A file that cannot be written (an
// image of another size than its reference) is listed there and in the notes with the reason, and the export goes on.
// Everything is written into a hidden folder beside the target and moved into place at the end: an export that fails
// or is cancelled leaves the target folder as it was.
#pragma once

#include "background.h"
#include "compositor.h"

#include <QImage>
#include <QObject>
#include <QStringList>

#include <atomic>
#include <functional>
#include <memory>
#include <vector>

namespace tyndall::studio {

// A plot the export writes as plot-<name>.png and .svg: `write` draws it to a path, the format from its suffix, and
// returns false with the reason. The window's plots are widgets (ui/plots.h); the export only calls them.
struct PlotFile {
    QString name;
    std::function<bool(const QString& path, QString* error)> write;
};

class Exporter : public QObject {
    Q_OBJECT
public:
    Exporter(Background& background, QObject* parent = nullptr);

    // What an export writes, from what the studio shows now.
    struct Input {
        std::vector<ViewFrame> frames;
        CompositorState display;
        QImage viewport;
        std::vector<PlotFile> plots;  // drawn on the GUI thread while the export is planned
    };
    // Writes everything now, on this thread. False with the reason (then nothing was written).
    bool exportNow(const QString& folder, const Input& input, QString* error);
    // The same in the background, a file at a time: started says how many files, progress how many are written,
    // finished how it went (the notes, or the error; "cancelled" after cancel()) and into which folder.
    void start(const QString& folder, const Input& input);
    void cancel();
    bool running() const { return running_ > 0; }
    const QStringList& notes() const { return notes_; }

signals:
    void started(int files);
    void progress(int written);
    void finished(bool ok, const QString& message, const QString& folder);

private:
    struct Report;
    // Each file a step of its own, gathered on the GUI thread (the plots are drawn there), written into `staging` and
    // moved into `folder` by the last step. Throws when the staging folder cannot be made.
    struct Plan {
        QString folder, staging;
        std::vector<std::function<void()>> steps;
        std::shared_ptr<Report> report;
    };
    Plan plan(const QString& folder, const Input& input);

    Background& background_;
    QStringList notes_;
    int running_ = 0;
    std::shared_ptr<std::atomic<bool>> cancelled_;  // of the export in flight
};

}  // namespace tyndall::studio
