// The studio's main window: the Vulkan viewport in the centre, the views, parameters and metrics in docks, menus and a
// toolbar. It owns the session (project, undo), the render service and the compositor's state, and re-renders a view
// shortly after each edit of it (debounced) while references refine in the background.
#pragma once

#include "animation.h"
#include "compositor.h"
#include "parameter_panel.h"
#include "plots.h"
#include "render_service.h"
#include "scene_panel.h"
#include "session.h"
#include "composer.h"
#include "viewport.h"

#include <functional>

#include <QElapsedTimer>
#include <QMainWindow>
#include <QTimer>

#include <map>
#include <set>
#include <vector>

class QListWidget;
class QComboBox;
class QLabel;
class QAction;
class QDialog;
class QPushButton;
class QTableWidget;
class QToolBar;
class QThreadPool;
class QVulkanInstance;

namespace tyndall::studio {

class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    // `overrides` apply to every project opened (the command line's --set, e.g. a smaller camera for tests).
    MainWindow(QVulkanInstance* vulkan, std::vector<std::string> overrides = {});
    ~MainWindow() override;

    // Opens a project; on failure keeps the current one and, with `dialog`, says why in a message box. When an autosave
    // of the project is newer than its file (the studio stopped with unsaved changes), offers to recover it.
    bool openProject(const QString& path, bool dialog = true);

    // Crash recovery: every 20 s while there are unsaved changes, the project goes to autosavePath(); a save or a
    // clean close removes it. What openProject does with a newer autosave: ask, always recover, or never.
    // The project is serialised on the GUI thread and written (atomically, with its fsync) by a thread of its own,
    // in order with the removals: a commit's fsync took ~30 ms here, a stall every 20 s. A write that fails says so
    // in the status bar. autosaveNow() returns false when there is nothing to save; waitForAutosaves() waits until
    // the queued writes and removals are on disk.
    enum class Recovery { Ask, Always, Never };
    void setRecovery(Recovery recovery) { recovery_ = recovery; }
    static QString autosavePath(const QString& projectPath);
    // Save As: the new file becomes the project (and a recent one); the old file's autosave is removed.
    bool saveProjectAs(const QString& path, QString* error);
    // Asks whether to save unsaved changes: false on Cancel. Discard removes the autosave (nothing to recover).
    bool confirmDiscard();
    bool autosaveNow();
    void waitForAutosaves();
    QStringList recentProjects() const;

    // Finished references are cached on disk by a hash of what they render (their part of the scene, the reference
    // settings, the project's folder, the version), so that reopening a project does not start from zero.
    static QString referenceCacheFolder();
    QString referenceCachePath(int view) const;
    // Writes every view, its reference and its difference (EXR and PNG), the viewport (PNG) and the metrics (JSON and
    // CSV) into `folder`. Returns false with the reason. A view is exported with its reference only as a pair of one
    // state (ComparisonPair), marked "stale" in metrics.json when it is not the current one; a view without a pair is
    // listed there with what is missing, and in exportNotes().
    bool exportComparison(const QString& folder, QString* error);
    // The same in the background with a progress dialog (File > Export): exportFinished says how it went (the notes,
    // or the error).
    void startExport(const QString& folder);
    const QStringList& exportNotes() const { return exportNotes_; }

    Session& session() { return session_; }
    RenderService& renderService() { return *renderer_; }
    Viewport* viewport() { return viewport_; }
    // Waits for the metrics and reference cache files in flight.
    void waitForBackgroundWork();
    CompositorState& compositorState() { return state_; }
    const std::vector<ViewFrame>& frames() const { return frames_; }
    // The frame of the current state, for exports and tests: waits for it if it is still being composed.
    const QImage& composedFrame();
    // Every view's latest render is final and nothing is queued.
    bool settled() const;

    void setLayoutMode(Layout layout);
    void setTonemap(Tonemap op);
    void selectView(int view);
    void recompose();  // asks for a frame of the current state (composed off the GUI thread)

    // Snapshots (render slots): a copy of the current view's image with its parameters and exposure.
    struct Snapshot {
        QString name;
        int view = 0;
        std::shared_ptr<const Image> image;
        nlohmann::json parameters;
        double exposure = 0.0;
    };
    int takeSnapshot();                    // of the current view; returns its index, -1 without an image
    void compareWithSnapshot(int index);   // its view is compared against it instead of the reference; -1: off
    // Every other view is compared against view `view` instead of the path-traced reference (Shift+1-9); -1: off.
    void chooseReferenceView(int view);
    int referenceView() const { return referenceView_; }
    void restoreSnapshot(int index);       // its parameters and exposure back on its view, as one undoable edit
    const std::vector<Snapshot>& snapshots() const { return snapshots_; }

    // The view and image pixel under a viewport position; false outside every view.
    bool viewAt(QPointF position, int& view, QPoint& pixel) const;
    // What the cursor at `position` shows: the inspector's values and, for a technique with a "distances" probe, the
    // PDF plot.
    void inspect(QPointF position);
    // Camera navigation, each an undoable scene edit: orbit about the target (radians), dolly (factor on the distance),
    // and framing the scene's meshes.
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
    // The convergence plot keeps one point per bucket of spp, four buckets per octave (the newest image of each).
    static int convergenceBucket(int spp);
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

private:
    void buildMenus();
    void updateAnimationActions();  // enabled, and the toolbar shown, only for a project with a particle medium
    bool viewsCaughtUp() const;     // the animation may advance: every view shows (or is done with) the current state
    void rebuildViews();
    void renderView(int view, bool reference);
    void renderAll();
    void flushDirty();
    void onOutput(const RenderOutput& out);
    void onKey(int key, Qt::KeyboardModifiers modifiers, bool pressed);
    void updateTitle();
    void updateMetricsDock();
    void updateMetrics(int view);
    void updateConvergence();
    void updateStatus();  // the references' progress (or "Ready") in the status bar
    QLabel* renderStatus_ = nullptr;
    void refreshSnapshotList();

    Session session_;
    std::vector<std::string> overrides_;
    RenderService* renderer_ = nullptr;
    Viewport* viewport_ = nullptr;
    ParameterPanel* parameters_ = nullptr;
    QListWidget* viewList_ = nullptr;
    QTableWidget* metrics_ = nullptr;  // a row per view; cells change in place (no layout pass per image)
    CompositorState state_;
    std::vector<ViewFrame> frames_;
    std::vector<quint64> generation_, referenceGeneration_;
    std::vector<bool> pending_;           // a technique render of the view is queued or running
    std::vector<bool> referencePending_;  // so is a reference render
    std::vector<bool> progressive_;       // the view's technique sent a progressive image (it may render for long)
    Animation* animation_ = nullptr;
    bool animating_ = false;              // within an edit of the animation's play
    QAction *playAction_ = nullptr, *stepAction_ = nullptr, *resetAction_ = nullptr;
    QToolBar* animationBar_ = nullptr;
    // Ctrl+Shift+drag: the medium whose targets move, their offset at the press, and the metres per viewport pixel.
    int offsetDragMedium_ = -1;
    Vec3 offsetDragStart_{0.0};
    QPointF offsetDragFrom_;
    Vec3 offsetDragRight_{0.0}, offsetDragUp_{0.0};
    std::set<int> dirtyViews_;    // edited views waiting for their render in flight to finish
    std::set<int> dirtyParts_;    // views whose part of the scene changed: their references restart after the debounce
    std::vector<std::string> partKeys_;
    std::vector<std::string> viewKeys_;  // each view's parameters and exposure, to see what a project replacement changed
    ScenePanel* scene_ = nullptr;
    QPointF lastMouse_;
    QTimer debounce_;
    QImage composed_;  // the frame of the current state once composedFrame() waited for it, else the last shown
    Composer* composer_ = nullptr;
    QComboBox* tonemapCombo_ = nullptr;
    bool composeQueued_ = false;
    QElapsedTimer editClock_;  // since the last edit
    void noteEdit();
    void requestCompose(bool now = false);  // hands the queued frame to the composer (now: even right after an edit)
    QThreadPool* background_ = nullptr;  // metrics and reference cache reads and writes
    QThreadPool* autosaves_ = nullptr;   // one thread: the autosave's writes and removals, in order
    void removeAutosave();               // of the current project, queued after its writes
    void inBackground(std::function<void()> work);  // in background_, at the renders' priority
    quint64 nextGeneration_ = 1;

    PlotPanel* plots_ = nullptr;
    ConvergencePlot* convergence_ = nullptr;
    PdfPlot* pdf_ = nullptr;
    PhasePlot *phasePolar_ = nullptr, *phaseCosine_ = nullptr;
    LtsdPolarPlot* ltsdPolar_ = nullptr;
    LtsdErrorPlot* ltsdError_ = nullptr;
    LtsdTables ltsdTables_;
    void updatePhasePlots();  // and the LTSD plots
    std::string viewsKey() const;  // the views' names and techniques: a change of them rebuilds the views
    std::string viewsKey_;
    QLabel* inspector_ = nullptr;
    QListWidget* snapshotList_ = nullptr;
    QPushButton* compareButton_ = nullptr;
    QDialog* shortcuts_ = nullptr;
    QAction* layoutActions_[3] = {};
    QLabel* displayStatus_ = nullptr;
    std::function<void()> defaultDockSizes_;  // applied once shown, unless QSettings restored a layout
    void updateDisplayStatus();
    std::vector<Snapshot> snapshots_;
    int comparedSnapshot_ = -1;
    int referenceView_ = -1;
    void refreshAlternates();
    // The images of each view's current render as it refined, for the convergence plot.
    struct Progress {
        int spp = 0;
        double seconds = 0.0;
        std::shared_ptr<const Image> image;
        double relMSE = -1.0;                    // against `against` (-1: not yet); plotted until a newer one arrives
        std::shared_ptr<const Image> against;    // the reference relMSE was computed against
        std::shared_ptr<const Image> requested;  // the reference of the job in flight for it, if any
        quint64 state = 0;                       // of the image: compared only with a reference of this state
        bool againstAlternate = false;           // `against` is the image of the view chosen with Shift+1-9
    };
    std::vector<std::vector<Progress>> progress_;
    int convergencePending_ = 0;  // relMSE jobs in the background pool
    void plotConvergence();
    QPoint regionStart_;
    QTimer probeTimer_;
    QPointF probePosition_;
    QTimer autosave_;
    Recovery recovery_ = Recovery::Ask;
    bool opening_ = false;
    bool discarded_ = false;  // the user discarded the unsaved changes (Discard on Open): nothing to autosave
    int metricsPending_ = 0;
    quint64 metricsRequests_ = 0;           // metrics jobs started so far
    std::vector<quint64> latestMetrics_;    // per view: the job whose result it shows (an older job's is dropped)
    QMenu* recentMenu_ = nullptr;
    void addRecent(const QString& path);
    std::map<quint64, QString> cachePathOf_;  // reference renders in flight: where their result is cached
    void refreshRecentMenu();
    QStringList exportNotes_;
    int exportsRunning_ = 0;
    // What an export writes, gathered on the GUI thread (the plots are drawn there): each file a step of its own.
    std::vector<std::function<void()>> exportSteps(const QString& folder);
};

// Adds a view's progressive image (anything with an `spp`) to its convergence points: a lower spp than the last
// starts a new render's list; an image in the same bucket of spp as the last replaces it. Each point keeps its image,
// to compute its relMSE again as the reference refines, and a progressive technique sends an image per sample (the
// path tracer as a view): this keeps 20 images up to 64 spp and 36 up to 1024, instead of one per spp (the latency
// bench's process grew by ~16 MB/s while its references refined).
template <typename Point>
void addConvergencePoint(std::vector<Point>& points, Point point) {
    if (!points.empty() && points.back().spp >= point.spp) points.clear();
    if (!points.empty() && MainWindow::convergenceBucket(points.back().spp) == MainWindow::convergenceBucket(point.spp))
        points.pop_back();
    points.push_back(std::move(point));
}

}  // namespace tyndall::studio
