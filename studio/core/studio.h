// The studio without its window: every part of studio/core, wired so that the data flows one way
// (docs/architecture.md, "Studio"),
//
//   Session (project, undo) -> RenderScheduler (what renders when) -> ComparisonModel (images, references, staleness,
//   metrics, convergence) -> Composer (frames for the viewport), Exporter
//
// with ProjectFiles (autosave, recovery, recent files), SnapshotStore (render slots saved beside the project),
// CameraController (navigation as scene edits) and Animation (the particle simulation) beside them, and what the user
// does to them: open and save, select and author views, the display (layout, difference, tonemap, zoom, wipe), the
// comparand, snapshots, regions, picking, the Inspector's values and probe, the phase-function curves, export.
//
// The window (studio/ui) only shows what it says and calls it; a test or a tool drives it without one (test/core).
// What needs the user (a message box, a question) is a signal or a callback the window provides.
#pragma once

#include "animation.h"
#include "background.h"
#include "camera_controller.h"
#include "comparison_model.h"
#include "composer.h"
#include "compositor.h"
#include "exporter.h"
#include "phase_curves.h"
#include "project_files.h"
#include "render_scheduler.h"
#include "session.h"
#include "snapshot_store.h"

#include <QElapsedTimer>
#include <QImage>
#include <QObject>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace tyndall::studio {

// A technique's display name ("WVDS box"), or its registry name when there is no such technique.
QString techniqueDisplayName(const std::string& technique);
// A view's label: its technique's with what of its parameters changes what the image is ("LTSD (ratio shadows)").
QString viewLabel(const View& view);

class Studio : public QObject {
    Q_OBJECT
public:
    // `overrides` apply to every project opened (the command line's --set, e.g. a smaller camera for tests).
    explicit Studio(std::vector<std::string> overrides = {}, QObject* parent = nullptr);
    ~Studio() override;

    // The parts.
    Session& session() { return session_; }
    const Session& session() const { return session_; }
    RenderScheduler& scheduler() { return *scheduler_; }
    RenderService& renderService() { return scheduler_->service(); }
    ComparisonModel& comparison() { return *model_; }
    const ComparisonModel& comparison() const { return *model_; }
    ProjectFiles& files() { return *files_; }
    SnapshotStore& snapshotStore() { return *snapshots_; }
    Exporter& exporter() { return *exporter_; }
    Animation& animation() { return *animation_; }
    Background& background() { return *background_; }
    const std::vector<ViewFrame>& frames() const { return model_->frames(); }
    const std::vector<Snapshot>& snapshots() const { return snapshots_->snapshots(); }
    CompositorState& compositorState() { return state_; }
    const CompositorState& compositorState() const { return state_; }

    // --- The project
    // Opens a project, keeping the current one on failure (renders go on) with the reason. When an autosave of the
    // project is newer than its file (the studio stopped with unsaved changes), recovers it as `recovery` says; Ask
    // asks `askRecovery` (the window's question; without one, nothing is recovered and the autosave stays).
    bool openProject(const QString& path, QString* error);
    using Recovery = ProjectFiles::Recovery;
    void setRecovery(Recovery recovery) { files_->setRecovery(recovery); }
    void setRecoveryQuestion(std::function<bool(const QString& path, const QString& autosave)> ask) {
        askRecovery_ = std::move(ask);
    }
    static QString autosavePath(const QString& projectPath) { return ProjectFiles::autosavePath(projectPath); }
    // Save: the project file (keeping the user's text where nothing changed) and its snapshots beside it.
    bool saveProject(QString* error);
    // Save As: the new file becomes the project (and a recent one); the old file's autosave is removed.
    bool saveProjectAs(const QString& path, QString* error);
    bool autosaveNow() { return files_->autosaveNow(); }
    void waitForAutosaves() { files_->waitForAutosaves(); }
    QStringList recentProjects() const { return files_->recentProjects(); }
    // "<project name> - <file>[*] - Tyndall Studio", for the window (with [*] where the modified mark goes).
    QString title() const;
    static QString referenceCacheFolder() { return RenderScheduler::referenceCacheFolder(); }
    QString referenceCachePath(int view) const { return scheduler_->referenceCachePath(view); }

    // --- Views
    // Opens an image file (EXR, HDR, PNG, ...; image_file.h) as a read-only view after the project's, compared against
    // the reference of the first view and selectable as every view's comparand (Shift+N). Returns its index, or -1
    // with the reason.
    int openImageView(const QString& path, QString* error);
    // An image-only session (tev-like), in a studio without a project (refused when one is open): the images open as
    // views and nothing renders, the first image every other's reference (Shift+1-9 chooses another). False with the
    // reasons of the images that did not open (those that did stay).
    bool openImageSession(const QStringList& paths, QString* error);
    bool imageSession() const { return imageSession_; }
    // Authoring of the view `view`, undoable for a project view; an image view can be renamed and removed (closed),
    // not duplicated. False with the reason (empty: nothing to do).
    bool duplicateView(int view, QString* error);
    bool renameView(int view, const QString& name, QString* error);
    bool removeView(int view, QString* error);
    void selectView(int view);  // the current view (the parameters, the phase plots, the single layout's view)
    int currentView() const { return state_.current; }
    // Every view's latest render is final, nothing is queued, and no metrics or export job is in flight.
    bool settled() const;
    // What the studio is doing, for the status bar: "Ready" exactly when settled(), else what runs in a short form
    // ("Rendering light shaft · reference glow 24/64 spp, ETA 10 s", "Rendering 3 views · 2 references (glow
    // queued)") and how many comparisons are stale ("· 1 stale"). `details` gets a line per view (the tooltip).
    QString status(QString* details = nullptr) const;
    // Waits for the metrics and reference cache files in flight.
    void waitForBackgroundWork() { background_->waitForDone(); }

    // --- The display (compositor.h): each asks for a frame of the new state.
    void setLayoutMode(Layout layout);
    // The display transforms on offer: each display and view of the OpenColorIO config, then Tyndall's own operators
    // (sRGB, Reinhard, the ACES fit, false colour). The config is $OCIO's, else the shipped one (ColourConfig::load,
    // quietly) until setColourConfig, which shows the config's default display and view and, with `announce`, says
    // its warnings (a config passed over, and why) on the status bar and stderr.
    const std::shared_ptr<const ColourConfig>& colourConfig() const { return colourConfig_; }
    void setColourConfig(std::shared_ptr<const ColourConfig> config, bool announce = true);
    const std::vector<DisplayTransform>& displayTransforms() const { return displayTransforms_; }
    int displayTransformIndex() const;  // of the current one in displayTransforms()
    void setDisplayTransform(int index);
    void setTonemap(Tonemap op);          // Tyndall's own operator
    void setSmoothPreviews(bool smooth);  // reduced images scaled up bilinearly, else nearest
    void cycleDisplayTransform();         // M
    void cycleDifference();  // off, signed, absolute, relative
    void swapSides();        // of the wipe
    void offsetExposure(double stops);
    void zoomBy(double steps);  // every view together, 1.25x a step, within 1-64x
    void panBy(QPointF viewportPixels);
    void resetZoom();
    void setSplitAt(QPointF position);  // the wipe's divider under a viewport position (split layout)
    void centreSplit();
    void showReference(bool show);  // Shift held: the reference in place of the view (single layout)
    void showViewAlone(int view);   // keys 1-9: that view, in the single layout from the grid

    // --- Composing: frames of the current state, composed off the GUI thread, once per pass of the event loop.
    // The viewport's size in pixels (the window's; a fixed size without one).
    void setViewportSize(std::function<QSize()> size) { viewportSize_ = std::move(size); }
    QSize viewportSize() const;
    void recompose();
    // The frame of the current state, for exports and tests: waits for it if it is still being composed.
    const QImage& composedFrame();

    // --- Comparands, snapshots, regions
    int takeSnapshot();                   // of the current view; its index, -1 without an image
    void compareWithSnapshot(int index);  // -1: the reference again
    int comparedSnapshot() const { return comparedSnapshot_; }
    void restoreSnapshot(int index) { snapshots_->restore(index); }  // one undoable edit of its view
    // Every other view is compared against view `view` instead of the path-traced reference (Shift+1-9); -1: off.
    void chooseReferenceView(int view);
    void toggleReferenceView(int view);  // the same view again: back to the reference
    int referenceView() const { return model_->referenceView(); }
    void setRegion(QRect region);  // metrics over it (image pixels; empty: none)

    // --- The camera and the animation: a refused move says why (message).
    void orbitCamera(double yaw, double pitch);
    void dollyCamera(double factor);
    void frameScene();
    void stepAnimation();
    void resetAnimation();

    // --- Picking
    // The view and image pixel under a viewport position; false outside every view.
    bool viewAt(QPointF position, int& view, QPoint& pixel) const;
    // The particle medium under a viewport position and the point an impulse there goes to: of the view's particle
    // media (every one when it renders none), the one whose particle the ray meets nearest; false over no view or
    // without a particle medium.
    bool particlePointAt(QPointF position, int& medium, Vec3& point) const;
    bool addImpulseAt(QPointF position, QString* error);
    // The metres a viewport pixel spans at `point`'s depth, along the camera's right and up axes, for a drag of a
    // particle medium's targets in the image plane (Ctrl+Shift+drag); false over no view.
    bool imagePlaneAxes(QPointF position, const Vec3& point, Vec3& right, Vec3& up) const;
    // What the cursor at `position` shows: every view's and reference's values there at once (inspected) and, for a
    // technique with a "distances" probe, its answer from the background pool (probed; an older hover's is dropped).
    void inspect(QPointF position);

    // --- Plots' data
    std::vector<PhaseCurve> phaseCurves() const {
        return tyndall::studio::phaseCurves(session_.project(), state_.current);
    }
    LtsdFit ltsdFit() { return ltsdFitOfView(session_.project(), state_.current, ltsdTables_); }
    // Where the LTSD fit reads its tables ("": the default search, ltsdTablesDirectory); read again now.
    void setLtsdTablesDirectory(const QString& directory);

    // --- Export (exporter.h) of what the studio shows now, with the plots `plotFiles` gives (the window's).
    void setPlotFiles(std::function<std::vector<PlotFile>()> plots) { plotFiles_ = std::move(plots); }
    bool exportComparison(const QString& folder, QString* error);
    void startExport(const QString& folder);  // in the background: exporter().finished says how it went
    const QStringList& exportNotes() const { return exporter_->notes(); }

    // A message for the status bar (what the studio refused and why, what it did).
    void say(const QString& text, int timeoutMs = 10000) { emit message(text, timeoutMs); }

signals:
    void message(const QString& text, int timeoutMs);
    void warning(const QString& title, const QString& text);  // needs the user's attention (a dialog)
    void titleChanged();
    void viewsRebuilt();                // the views start again (a project opened)
    void viewListChanged();             // views authored (added, renamed, removed), image views opened or closed
    void currentViewChanged(int view);  // also after viewsRebuilt
    void displayChanged();              // the compositor's state (layout, tonemap, exposure offset, zoom, ...)
    void colourConfigChanged();         // displayTransforms() are another config's
    void phasesChanged();               // the phase curves or the LTSD fit to plot
    void snapshotTaken(int index);
    void frameComposed(const QImage& frame);
    void inspected(const QString& html);
    void probed(const ProbeResult& result);
    void probeMessage(const QString& message);  // why there is no probe (or the project changed: none yet)

private:
    void rebuildViews();  // a project opened: every view starts again
    void followViews();   // after an authoring of the views: what did not change keeps its renders
    std::vector<ComparisonModel::ViewInfo> viewInfos() const;  // the project's views, for the comparison model
    void onSceneChanged();
    // The markers of the impulses of the last kImpulseMarkerSeconds of simulated time, on the current camera.
    void updateImpulseMarkers();
    void noteEdit() { editClock_.start(); }
    void requestCompose(bool now = false);  // hands the queued frame to the composer (now: even right after an edit)
    void recover(const QString& path);

    Session session_;
    std::vector<std::string> overrides_;
    Background* background_;
    RenderScheduler* scheduler_;
    ComparisonModel* model_;
    ProjectFiles* files_;
    SnapshotStore* snapshots_;
    Exporter* exporter_;
    Animation* animation_;
    Composer* composer_;
    CameraController camera_{session_};
    CompositorState state_;
    std::shared_ptr<const ColourConfig> colourConfig_;
    std::vector<DisplayTransform> displayTransforms_;
    LtsdTables ltsdTables_;
    std::function<QSize()> viewportSize_;
    std::function<std::vector<PlotFile>()> plotFiles_;
    std::function<bool(const QString&, const QString&)> askRecovery_;

    QImage composed_;  // the frame of the current state once composedFrame() waited for it, else the last shown
    bool composeQueued_ = false;
    QElapsedTimer editClock_;  // since the last edit
    int comparedSnapshot_ = -1;
    bool imageSession_ = false;          // images only, no project (openImageSession)
    std::uint64_t probeGeneration_ = 0;  // the latest Inspector probe; older answers are dropped
};

}  // namespace tyndall::studio
