// The studio's main window: the Vulkan viewport in the centre, the views, parameters, metrics, snapshots, plots and
// scene in docks, menus and a toolbar. It wires the studio's parts together and holds no logic of its own; the data
// flows one way (docs/architecture.md, "Studio"):
//
//   Session (project, undo) -> RenderScheduler (what renders when) -> ComparisonModel (images, references, staleness,
//   metrics, convergence) -> Composer / viewport, docks, Exporter
//
// with ProjectFiles (autosave, recovery, recent files), SnapshotStore (render slots saved beside the project),
// CameraController (navigation as scene edits) and Animation (the particle simulation) beside them.
#pragma once

#include "animation.h"
#include "background.h"
#include "camera_controller.h"
#include "comparison_model.h"
#include "compositor.h"
#include "exporter.h"
#include "parameter_panel.h"
#include "plots.h"
#include "project_files.h"
#include "render_scheduler.h"
#include "scene_panel.h"
#include "session.h"
#include "snapshot_store.h"
#include "composer.h"
#include "viewport.h"

#include <cstdint>
#include <functional>

#include <QElapsedTimer>
#include <QMainWindow>
#include <QTimer>

#include <vector>

class QListWidget;
class QComboBox;
class QLabel;
class QAction;
class QDialog;
class QPushButton;
class QTableWidget;
class QToolBar;
class QVulkanInstance;

namespace tyndall::studio {

class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    // `overrides` apply to every project opened (the command line's --set, e.g. a smaller camera for tests).
    MainWindow(QVulkanInstance* vulkan, std::vector<std::string> overrides = {});
    ~MainWindow() override;

    // Opens a project; on failure keeps the current one and, with `dialog`, says why in a message box. When an autosave
    // of the project is newer than its file (the studio stopped with unsaved changes), offers to recover it (Recovery).
    bool openProject(const QString& path, bool dialog = true);

    using Recovery = ProjectFiles::Recovery;
    void setRecovery(Recovery recovery) { files_->setRecovery(recovery); }
    static QString autosavePath(const QString& projectPath) { return ProjectFiles::autosavePath(projectPath); }
    // Save: the project file (keeping the user's text where nothing changed) and its snapshots beside it.
    bool saveProject(QString* error);
    // Save As: the new file becomes the project (and a recent one); the old file's autosave is removed.
    bool saveProjectAs(const QString& path, QString* error);
    // Asks whether to save unsaved changes: false on Cancel. Discard removes the autosave (nothing to recover).
    bool confirmDiscard();
    bool autosaveNow() { return files_->autosaveNow(); }
    void waitForAutosaves() { files_->waitForAutosaves(); }
    QStringList recentProjects() const { return files_->recentProjects(); }

    static QString referenceCacheFolder() { return RenderScheduler::referenceCacheFolder(); }
    QString referenceCachePath(int view) const { return scheduler_->referenceCachePath(view); }
    // Export (exporter.h) of what the studio shows now; startExport in the background with a progress dialog
    // (File > Export), exportFinished saying how it went.
    bool exportComparison(const QString& folder, QString* error);
    void startExport(const QString& folder);
    const QStringList& exportNotes() const { return exporter_->notes(); }

    // Opens an image file (EXR, HDR, PNG, ...; image_file.h) as a read-only view after the project's, compared
    // against the reference of the first view (the Views dock chooses another) and selectable as every view's
    // comparand (Shift+N). Also File > Open image (Ctrl+I), drag and drop, and the command line (tyndall-studio
    // a.exr b.exr). Returns its index, or -1 with the reason.
    int openImageView(const QString& path, QString* error);

    Session& session() { return session_; }
    RenderService& renderService() { return scheduler_->service(); }
    RenderScheduler& scheduler() { return *scheduler_; }
    ComparisonModel& comparison() { return *model_; }
    Viewport* viewport() { return viewport_; }
    // Waits for the metrics and reference cache files in flight.
    void waitForBackgroundWork() { background_->waitForDone(); }
    CompositorState& compositorState() { return state_; }
    const std::vector<ViewFrame>& frames() const { return model_->frames(); }
    // The frame of the current state, for exports and tests: waits for it if it is still being composed.
    const QImage& composedFrame();
    // Every view's latest render is final and nothing is queued.
    bool settled() const;

    void setLayoutMode(Layout layout);
    void setTonemap(Tonemap op);
    void selectView(int view);
    void recompose();  // asks for a frame of the current state (composed off the GUI thread)

    // Snapshots (snapshot_store.h) of the current view; compared against instead of the reference; put back.
    int takeSnapshot();                    // returns its index, -1 without an image
    void compareWithSnapshot(int index);   // -1: off
    // Every other view is compared against view `view` instead of the path-traced reference (Shift+1-9); -1: off.
    void chooseReferenceView(int view);
    int referenceView() const { return model_->referenceView(); }
    void restoreSnapshot(int index);       // its parameters and exposure back on its view, as one undoable edit
    const std::vector<Snapshot>& snapshots() const { return snapshots_->snapshots(); }

    // The view and image pixel under a viewport position; false outside every view.
    bool viewAt(QPointF position, int& view, QPoint& pixel) const;
    // What the cursor at `position` shows: the inspector's values at once and, for a technique with a "distances"
    // probe, the PDF plot when the probe, run in the background pool, answers (waitForBackgroundWork, then the event
    // loop).
    void inspect(QPointF position);
    // Camera navigation (camera_controller.h); a refused move says why in the status bar.
    void orbitCamera(double yaw, double pitch);
    void dollyCamera(double factor);
    void frameScene();
    ScenePanel* scenePanel() { return scene_; }

    // The particle simulation (Animation menu and toolbar: play / pause P, step ., reset Ctrl+R). A Ctrl+click on a
    // view adds an impulse where the camera ray meets its particle medium (impulsePoint); Ctrl+Shift+drag moves the
    // medium's region of targets (simulation.offset) in the image plane.
    Animation& animation() { return *animation_; }
    // The particle medium under a viewport position and the point an impulse there goes to: of the view's particle
    // media (every one when it renders none), the one whose particle the ray meets nearest; false over no view or
    // without a particle medium.
    bool particlePointAt(QPointF position, int& medium, Vec3& point) const;
    bool addImpulseAt(QPointF position, QString* error);

    // Metrics over `region` (image pixels; empty: none) of every view.
    void setRegion(QRect region);
    QString inspectorText() const;
    PlotPanel* plots() { return plots_; }
    ConvergencePlot* convergencePlot() { return convergence_; }
    static int convergenceBucket(int spp) { return ComparisonModel::convergenceBucket(spp); }
    PdfPlot* pdfPlot() { return pdf_; }
    // The project's media's phase functions (the current view's first): polar and over cos theta.
    PhasePlot* phasePolarPlot() { return phasePolar_; }
    PhasePlot* phaseCosinePlot() { return phaseCosine_; }
    // The selected view's (first) medium's phase function against its LTSD fit, and the fit's error over g.
    LtsdPolarPlot* ltsdPolarPlot() { return ltsdPolar_; }
    LtsdErrorPlot* ltsdErrorPlot() { return ltsdError_; }
    // Where the LTSD plots read their tables ("": the default search, ltsdTablesDirectory); read again now.
    void setLtsdTablesDirectory(const QString& directory);

    // The window's geometry and dock layout go to QSettings on close and come back on the next start.
    void saveLayout() const;

    // Help: every menu shortcut and the viewport's mouse bindings, in a window (F1 or ?).
    void showShortcuts();
    QString shortcutsText();

signals:
    void exportFinished(bool ok, const QString& message);

protected:
    void closeEvent(QCloseEvent* event) override;
    void showEvent(QShowEvent* event) override;
    void keyPressEvent(QKeyEvent* event) override;
    void keyReleaseEvent(QKeyEvent* event) override;
    void dragEnterEvent(QDragEnterEvent* event) override;  // projects and images dropped on the window
    void dropEvent(QDropEvent* event) override;

private:
    void refreshViewList();
    void refreshImageAgainst();  // the comparand row of the Views dock, shown for an image view
    void buildDocks();
    void buildMenus();
    void connectViewport();
    void updateAnimationActions();  // enabled, and the toolbar shown, only for a project with a particle medium
    // The views' list, the model and the renders start again; the snapshots are read from the project's folder (a
    // project opened) or follow their views (views added, removed, renamed: unsaved snapshots are kept).
    void rebuildViews(bool projectOpened);
    void onSceneChanged();
    void onKey(int key, Qt::KeyboardModifiers modifiers, bool pressed);
    void updateTitle();
    void updateMetricsDock();
    void updateStatus();  // the references' progress (or "Ready") in the status bar
    void updateDisplayStatus();
    void refreshSnapshotList();
    void refreshRecentMenu();
    void updatePhasePlots();  // and the LTSD plots
    void plotConvergence();
    void noteEdit();
    void requestCompose(bool now = false);  // hands the queued frame to the composer (now: even right after an edit)

    Session session_;
    std::vector<std::string> overrides_;
    Background* background_ = nullptr;
    RenderScheduler* scheduler_ = nullptr;
    ComparisonModel* model_ = nullptr;
    ProjectFiles* files_ = nullptr;
    SnapshotStore* snapshots_ = nullptr;
    Exporter* exporter_ = nullptr;
    CameraController camera_{session_};
    Animation* animation_ = nullptr;
    Composer* composer_ = nullptr;
    CompositorState state_;

    Viewport* viewport_ = nullptr;
    ParameterPanel* parameters_ = nullptr;
    QListWidget* viewList_ = nullptr;
    QComboBox* imageAgainst_ = nullptr;
    QWidget* imageAgainstRow_ = nullptr;
    QTableWidget* metrics_ = nullptr;  // a row per view; cells change in place (no layout pass per image)
    ScenePanel* scene_ = nullptr;
    QLabel* inspector_ = nullptr;
    QListWidget* snapshotList_ = nullptr;
    QPushButton* compareButton_ = nullptr;
    QDialog* shortcuts_ = nullptr;
    QAction* layoutActions_[3] = {};
    QLabel* renderStatus_ = nullptr;
    QLabel* displayStatus_ = nullptr;
    QComboBox* tonemapCombo_ = nullptr;
    QMenu* recentMenu_ = nullptr;
    QAction *playAction_ = nullptr, *stepAction_ = nullptr, *resetAction_ = nullptr;
    QToolBar* animationBar_ = nullptr;
    PlotPanel* plots_ = nullptr;
    ConvergencePlot* convergence_ = nullptr;
    PdfPlot* pdf_ = nullptr;
    std::uint64_t probeGeneration_ = 0;  // the latest Inspector probe; older answers are dropped
    PhasePlot *phasePolar_ = nullptr, *phaseCosine_ = nullptr;
    LtsdPolarPlot* ltsdPolar_ = nullptr;
    LtsdErrorPlot* ltsdError_ = nullptr;
    LtsdTables ltsdTables_;
    std::function<void()> defaultDockSizes_;  // applied once shown, unless QSettings restored a layout

    // Mouse state: the last position, a region's first corner, the probe's debounce, and the Ctrl+Shift+drag of a
    // particle medium's targets (the medium, its offset at the press, the metres per viewport pixel).
    QPointF lastMouse_;
    QPoint regionStart_;
    QTimer probeTimer_;
    QPointF probePosition_;
    int offsetDragMedium_ = -1;
    Vec3 offsetDragStart_{0.0};
    QPointF offsetDragFrom_;
    Vec3 offsetDragRight_{0.0}, offsetDragUp_{0.0};

    QImage composed_;  // the frame of the current state once composedFrame() waited for it, else the last shown
    bool composeQueued_ = false;
    QElapsedTimer editClock_;  // since the last edit
    int comparedSnapshot_ = -1;
};

}  // namespace tyndall::studio
