// The studio window's docks, one class each. A dock shows what studio/core's Studio says (its signals) and calls it;
// it holds no state of the studio's own. The main window only creates and places them.
//   ViewsDock        the views (project views, then images opened from files), authoring buttons, an image's comparand
//   ParametersDock   the current view's technique parameters (ParameterPanel)
//   MetricsDock      relMSE, PSNR, reference noise, bias and region relMSE of every view
//   InspectorDock    every view's and reference's values under the cursor
//   SnapshotsDock    render slots: take, compare against, restore
//   PlotsDock        convergence, the PDF probe, phase functions, the LTSD fit (plots.h)
//   SceneDock        the scene's camera, lights and media (ScenePanel)
#pragma once

#include "plots.h"
#include "studio.h"

#include <QDockWidget>

#include <vector>

class QComboBox;
class QLabel;
class QListWidget;
class QPushButton;
class QTableWidget;

namespace tyndall::studio {

class ParameterPanel;
class ScenePanel;

// The mouse wheel scrolls a dock; it changes a spin box, combo box or slider in a dock only when that field has the
// keyboard focus (a click or Tab first). Wheeling down a scrolling Scene dock changed the phase function and a
// simulation's step count under the pointer, an undo step each. Installed on the application once by the window, so
// that panels rebuilt later are covered too.
class DockWheelGuard final : public QObject {
public:
    using QObject::QObject;
    bool eventFilter(QObject* watched, QEvent* event) override;
    // The fields that exist already (later ones are taken care of when they are polished).
    static void guard(QWidget* root);
    static bool guarded(QObject* object);  // a spin box, combo box or slider in a dock
};

class ViewsDock final : public QDockWidget {
    Q_OBJECT
public:
    ViewsDock(Studio& studio, QWidget* parent);
    QListWidget* list() const { return list_; }
    void renameCurrent();  // asks for the name (also: double-click a view)

private:
    void refresh();              // the list from the comparison model's views
    void refreshImageAgainst();  // the comparand row, shown for an image view
    void refreshPartial();       // "partial" and what a view leaves out (its tooltip)
    Studio& studio_;
    QListWidget* list_;
    QComboBox* imageAgainst_;
    QWidget* imageAgainstRow_;
};

class ParametersDock final : public QDockWidget {
    Q_OBJECT
public:
    ParametersDock(Studio& studio, QWidget* parent);
    ParameterPanel* panel() const { return panel_; }

private:
    ParameterPanel* panel_;
};

class MetricsDock final : public QDockWidget {
    Q_OBJECT
public:
    MetricsDock(Studio& studio, QWidget* parent);
    void refresh();  // only the cells whose text changes: a new image costs no layout of the dock

private:
    Studio& studio_;
    QTableWidget* table_;  // a row per view
};

class InspectorDock final : public QDockWidget {
    Q_OBJECT
public:
    InspectorDock(Studio& studio, QWidget* parent);
    QString text() const;

private:
    QLabel* label_;
};

class SnapshotsDock final : public QDockWidget {
    Q_OBJECT
public:
    SnapshotsDock(Studio& studio, QWidget* parent);

private:
    void refresh();
    Studio& studio_;
    QListWidget* list_;
    QPushButton* compare_;
};

class PlotsDock final : public QDockWidget {
    Q_OBJECT
public:
    PlotsDock(Studio& studio, QWidget* parent);
    PlotPanel* panel() const { return panel_; }
    ConvergencePlot* convergence() const { return convergence_; }
    PdfPlot* pdf() const { return pdf_; }
    PhasePlot* phasePolar() const { return phasePolar_; }
    PhasePlot* phaseCosine() const { return phaseCosine_; }
    LtsdPolarPlot* ltsdPolar() const { return ltsdPolar_; }
    LtsdErrorPlot* ltsdError() const { return ltsdError_; }
    // Each plot as the export writes it (plot-<name>.png and .svg).
    std::vector<PlotFile> files() const;

private:
    void plotConvergence();
    void plotPhases();
    Studio& studio_;
    PlotPanel* panel_;
    ConvergencePlot* convergence_;
    PdfPlot* pdf_;
    PhasePlot *phasePolar_, *phaseCosine_;
    LtsdPolarPlot* ltsdPolar_;
    LtsdErrorPlot* ltsdError_;
};

class SceneDock final : public QDockWidget {
    Q_OBJECT
public:
    SceneDock(Studio& studio, QWidget* parent);
    ScenePanel* panel() const { return panel_; }

private:
    ScenePanel* panel_;
};

}  // namespace tyndall::studio
