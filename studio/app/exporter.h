// File > Export: every view, its reference and its difference (EXR and PNG), region insets, the viewport (PNG), the
// metrics (JSON and CSV), the display settings and the plots (PNG and SVG) into a folder. A view is exported with its
// reference only as a pair of one state (ComparisonPair), marked "stale" in metrics.json when it is not the current
// one; a view without a pair is listed there with what is missing, and in notes().
#pragma once

#include "background.h"
#include "compositor.h"

#include <QImage>
#include <QObject>
#include <QStringList>

#include <functional>
#include <vector>

class QWidget;

namespace tyndall::studio {

class Plot;

class Exporter : public QObject {
    Q_OBJECT
public:
    Exporter(Background& background, QObject* parent = nullptr);

    // What an export writes, from what the studio shows now.
    struct Input {
        std::vector<ViewFrame> frames;
        CompositorState display;
        QImage viewport;
        std::vector<Plot*> plots;  // drawn on the GUI thread while the export is planned
    };
    // Writes everything now, on this thread. False with the reason.
    bool exportNow(const QString& folder, const Input& input, QString* error);
    // The same in the background with a progress dialog over `parent` that can cancel: finished says how it went
    // (the notes, or the error).
    void start(const QString& folder, const Input& input, QWidget* parent);
    bool running() const { return running_ > 0; }
    const QStringList& notes() const { return notes_; }

signals:
    void finished(bool ok, const QString& message);

private:
    // Each file a step of its own, gathered on the GUI thread (the plots are drawn there); throws when the folder
    // cannot be made or a plot cannot be drawn.
    std::vector<std::function<void()>> plan(const QString& folder, const Input& input);

    Background& background_;
    QStringList notes_;
    int running_ = 0;
};

}  // namespace tyndall::studio
