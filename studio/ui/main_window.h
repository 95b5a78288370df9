// The studio's main window: the Vulkan viewport in the centre, the docks (docks.h) around it, the menus and toolbars
// from one action table (actions.h). It creates, places and connects; what the studio shows and does is
// studio/core's Studio (docs/architecture.md, "Studio"), what the mouse does over the viewport the
// ViewportController's. What needs a person is here: the file dialogs, the questions, the message boxes.
#pragma once

#include "actions.h"
#include "docks.h"
#include "studio.h"
#include "viewport.h"
#include "viewport_controller.h"

#include <QMainWindow>

#include <functional>
#include <string>
#include <vector>

class QActionGroup;
class QComboBox;
class QMenu;
class QDialog;
class QLabel;
class QVulkanInstance;

namespace tyndall::studio {

class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    // `overrides` apply to every project opened (the command line's --set, e.g. a smaller camera for tests).
    // `ocioConfig`: the OpenColorIO config of the display transforms (--ocio; empty: $OCIO, else the shipped one).
    MainWindow(QVulkanInstance* vulkan, std::vector<std::string> overrides = {}, const QString& ocioConfig = {});
    ~MainWindow() override;

    Studio& studio() { return studio_; }
    Viewport* viewport() { return viewport_; }
    const ActionTable& actions() const { return *actions_; }

    // Opens a project; on failure keeps the current one and, with `dialog`, says why in a message box. When an autosave
    // of the project is newer than its file, asks whether to recover it (Studio::setRecovery says when not to ask).
    bool openProject(const QString& path, bool dialog = true);
    // The project named on the command line: a file that does not open is reported (a dialog, and the status bar) and
    // the studio stays, on `fallback` (the bundled default project), with the file in the recent list to open again
    // once fixed. False when `path` did not open.
    bool openAtStart(const QString& path, const QString& fallback);
    // Asks whether to save unsaved changes: false on Cancel. Discard removes the autosave (nothing to recover).
    bool confirmDiscard();
    // The actions' dialogs: open, save (a failure in a box), save as, open images, export into a folder.
    void openDialog();
    void save();
    void saveAsDialog();
    void openImageDialog();
    void exportDialog();
    // Export in the background with a progress dialog that can cancel; a message box or the status bar says how it
    // went.
    void startExport(const QString& folder);
    // Help: every action's keys and the viewport's mouse bindings, in a window (F1 or ?).
    void showShortcuts();
    QString shortcutsText() const;
    void showDocumentation();
    void showAbout();

    // The docks' content, for tests and tools.
    QString inspectorText() const { return inspector_->text(); }
    ScenePanel* scenePanel() { return scene_->panel(); }
    PlotPanel* plots() { return plots_->panel(); }
    ConvergencePlot* convergencePlot() { return plots_->convergence(); }
    PdfPlot* pdfPlot() { return plots_->pdf(); }
    PhasePlot* phasePolarPlot() { return plots_->phasePolar(); }
    PhasePlot* phaseCosinePlot() { return plots_->phaseCosine(); }
    LtsdPolarPlot* ltsdPolarPlot() { return plots_->ltsdPolar(); }
    LtsdErrorPlot* ltsdErrorPlot() { return plots_->ltsdError(); }

    // The window's geometry and dock layout go to QSettings on close and come back on the next start.
    void saveLayout() const;

protected:
    void closeEvent(QCloseEvent* event) override;
    void showEvent(QShowEvent* event) override;
    void keyPressEvent(QKeyEvent* event) override;
    void keyReleaseEvent(QKeyEvent* event) override;
    void dragEnterEvent(QDragEnterEvent* event) override;  // projects and images dropped on the window
    void dropEvent(QDropEvent* event) override;

private:
    void keepOnScreen();
    void placeDocks();
    void buildStatusBar();
    void connectStudio();
    void updateDisplay();  // what follows the display state: the layout actions, the display box and menu, the status
    // The Display box and the View > Display menu: the config's displays and views, then Tyndall's own operators.
    void rebuildDisplayMenus();
    void addAnimationClock();       // the animation toolbar's pace and its step / simulated time
    void updateAnimationActions();  // enabled, and the toolbar shown, only for a project with a particle medium
    void refreshRecentMenu();

    Studio studio_;
    Viewport* viewport_;
    ActionTable* actions_ = nullptr;
    ViewportController* controller_ = nullptr;
    ViewsDock* views_;
    ParametersDock* parameters_;
    MetricsDock* metrics_;
    InspectorDock* inspector_;
    SnapshotsDock* snapshots_;
    PlotsDock* plots_;
    SceneDock* scene_;
    QComboBox* display_ = nullptr;
    QString displayTip_;  // what the box offers (its tooltip, after the current choice)
    QMenu* displayMenu_ = nullptr;
    QActionGroup* displayActions_ = nullptr;
    QLabel* renderStatus_ = nullptr;
    QLabel* displayStatus_ = nullptr;
    QDialog* shortcuts_ = nullptr;
    std::function<void()> defaultDockSizes_;  // applied once shown, unless QSettings restored a layout
};

}  // namespace tyndall::studio
