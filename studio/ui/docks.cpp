#include "docks.h"
#include "parameter_panel.h"
#include "scene_panel.h"

#include "tyndall/techniques/registry.h"

#include <QAbstractSlider>
#include <QAbstractSpinBox>
#include <QComboBox>
#include <QCoreApplication>
#include <QEvent>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QMenu>
#include <QMessageBox>
#include <QPushButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QSignalBlocker>
#include <QTableWidget>
#include <QVBoxLayout>

#include <cmath>

namespace tyndall::studio {

namespace {

// A dock whose content scrolls: other rows (another view's parameters, a wide row of values) never resize it.
QScrollArea* scrolling(QWidget* content, const QString& name = QString()) {
    auto* scroll = new QScrollArea;
    if (!name.isEmpty()) scroll->setObjectName(name);
    scroll->setWidgetResizable(true);
    scroll->setWidget(content);
    return scroll;
}

}  // namespace

// --- Views

ViewsDock::ViewsDock(Studio& studio, QWidget* parent)
    : QDockWidget("Views", parent),
      studio_(studio),
      list_(new QListWidget),
      imageAgainst_(new QComboBox),
      imageAgainstRow_(new QWidget) {
    setObjectName("viewsDock");
    list_->setObjectName("viewList");
    auto* content = new QWidget;
    auto* layout = new QVBoxLayout(content);
    layout->setContentsMargins(0, 0, 0, 0);
    layout->addWidget(list_);
    // Authoring: each an undoable edit of the project; a refused edit says why.
    auto* buttons = new QHBoxLayout;
    auto* add = new QPushButton("Add");
    add->setObjectName("addView");
    add->setToolTip("Add a view with a technique (its default part: the lights and media it supports)");
    auto* techniques = new QMenu(add);
    techniques->setObjectName("addViewMenu");
    techniques->setToolTipsVisible(true);
    for (const std::string& name : techniqueNames()) {
        QAction* action = techniques->addAction(techniqueDisplayName(name) + "  (" + QString::fromStdString(name) + ")",
                                                this, [this, name] {
                                                    QString error;
                                                    if (!studio_.session().addView(name, &error))
                                                        QMessageBox::warning(this, "Cannot add the view", error);
                                                });
        action->setData(QString::fromStdString(name));
    }
    // A technique that can render nothing of this scene (ISV without a particle medium) is offered disabled, with why.
    connect(techniques, &QMenu::aboutToShow, this, [this, techniques] {
        for (QAction* action : techniques->actions()) {
            QString why;
            const bool can = studio_.session().canAddView(action->data().toString().toStdString(), &why);
            action->setEnabled(can);
            action->setToolTip(can ? QString() : why);
        }
    });
    add->setMenu(techniques);
    auto edit = [this](const QString& text, const QString& tip, bool (Studio::*apply)(int, QString*)) {
        auto* button = new QPushButton(text);
        button->setToolTip(tip);
        connect(button, &QPushButton::clicked, this, [this, text, apply] {
            QString error;
            if (!(studio_.*apply)(studio_.currentView(), &error) && !error.isEmpty())
                QMessageBox::warning(this, "Cannot " + text.toLower() + " the view", error);
        });
        return button;
    };
    auto* rename = new QPushButton("Rename");
    rename->setToolTip("Rename the selected view (also: double-click it)");
    connect(rename, &QPushButton::clicked, this, &ViewsDock::renameCurrent);
    connect(list_, &QListWidget::itemDoubleClicked, this, &ViewsDock::renameCurrent);
    // An image view (opened from a file) is not in the project: Remove closes it, Duplicate does not apply.
    for (QPushButton* b :
         {add, edit("Duplicate", "Duplicate the selected view, with its parameters", &Studio::duplicateView), rename,
          edit("Remove", "Remove the selected view (undoable)", &Studio::removeView)})
        buttons->addWidget(b);
    layout->addLayout(buttons);
    // An image view's comparand: the reference of one of the project's views.
    imageAgainst_->setObjectName("imageAgainst");
    imageAgainst_->setToolTip("The image is compared against the reference of this view (its part of the scene)");
    auto* againstLayout = new QHBoxLayout(imageAgainstRow_);
    againstLayout->setContentsMargins(0, 0, 0, 0);
    againstLayout->addWidget(new QLabel("Compare with the reference of"));
    againstLayout->addWidget(imageAgainst_, 1);
    imageAgainstRow_->setVisible(false);
    layout->addWidget(imageAgainstRow_);
    connect(imageAgainst_, &QComboBox::activated, this,
            [this](int index) { studio_.comparison().setImageAgainst(studio_.currentView(), index); });
    setWidget(content);

    connect(list_, &QListWidget::currentRowChanged, this, [this](int row) {
        if (row >= 0) studio_.selectView(row);
    });
    connect(&studio_, &Studio::viewsRebuilt, this, &ViewsDock::refresh);
    connect(&studio_, &Studio::viewListChanged, this, &ViewsDock::refresh);
    connect(&studio_.comparison(), &ComparisonModel::framesChanged, this, &ViewsDock::refreshPartial);
    connect(&studio_, &Studio::currentViewChanged, this, [this](int view) {
        if (list_->currentRow() != view) {
            const QSignalBlocker block(list_);
            list_->setCurrentRow(view);
        }
        refreshImageAgainst();
    });
}

void ViewsDock::renameCurrent() {
    const int view = studio_.currentView();
    if (view < 0 || view >= studio_.comparison().size()) return;
    bool ok = false;
    const QString name = QInputDialog::getText(this, "Rename the view", "Name:", QLineEdit::Normal,
                                               studio_.frames()[std::size_t(view)].name, &ok);
    QString error;
    if (ok && !studio_.renameView(view, name, &error) && !error.isEmpty())
        QMessageBox::warning(this, "Cannot rename the view", error);
}

void ViewsDock::refresh() {
    const QSignalBlocker block(list_);
    list_->clear();
    for (const ViewFrame& f : studio_.frames())
        list_->addItem(QString("%1  %2  (%3)").arg(list_->count() + 1).arg(f.name, f.technique));
    if (studio_.currentView() < list_->count()) list_->setCurrentRow(studio_.currentView());
    refreshImageAgainst();
    refreshPartial();
}

void ViewsDock::refreshPartial() {
    // A view that renders only part of the scene (its technique cannot render a light or medium, and the view does
    // not choose its own): "partial" in the list, and what it leaves out and why in the item's tooltip.
    const std::vector<ViewFrame>& frames = studio_.frames();
    for (int i = 0; i < list_->count() && i < int(frames.size()); ++i) {
        const ViewFrame& f = frames[std::size_t(i)];
        const Image* shown = f.image ? f.image.get() : f.reference.get();
        const QString leftOut = shown && shown->metadata.count("leftOut")
                                    ? QString::fromStdString(shown->metadata.at("leftOut"))
                                    : QString();
        QListWidgetItem* item = list_->item(i);
        const QString text = QString("%1  %2  (%3)").arg(i + 1).arg(f.name, f.technique) +
                             (leftOut.isEmpty() ? QString() : "  - partial");
        const QString tip = leftOut.isEmpty() ? QString()
                                              : "Renders part of the scene: it leaves out " + leftOut +
                                                    ". Choose the view's lights and media in the Parameters dock.";
        if (item->text() != text) item->setText(text);
        if (item->toolTip() != tip) item->setToolTip(tip);
    }
}

void ViewsDock::refreshImageAgainst() {
    const ComparisonModel& model = studio_.comparison();
    const bool image = model.isImage(studio_.currentView());
    imageAgainstRow_->setVisible(image);
    if (!image) return;
    const QSignalBlocker block(imageAgainst_);
    imageAgainst_->clear();
    for (int i = 0; i < model.projectViews(); ++i)
        imageAgainst_->addItem(model.frames()[std::size_t(i)].name);
    imageAgainst_->setCurrentIndex(model.imageAgainst(studio_.currentView()));
}

// --- Parameters

ParametersDock::ParametersDock(Studio& studio, QWidget* parent)
    : QDockWidget("Parameters", parent), panel_(new ParameterPanel(studio.session())) {
    setObjectName("parametersDock");
    setWidget(scrolling(panel_));
    connect(panel_, &ParameterPanel::techniqueRefused, &studio,
            [&studio](const QString& reason) { studio.say(reason); });
    // An image has no parameters.
    connect(&studio, &Studio::currentViewChanged, this,
            [this, &studio](int view) { panel_->showView(studio.comparison().isImage(view) ? -1 : view); });
    connect(&studio, &Studio::viewsRebuilt, this,
            [this, &studio] { panel_->showView(studio.comparison().size() > 0 ? 0 : -1); });
}

// --- Metrics

MetricsDock::MetricsDock(Studio& studio, QWidget* parent)
    : QDockWidget("Metrics", parent), studio_(studio), table_(new QTableWidget(0, 7)) {
    setObjectName("metricsDock");
    table_->setObjectName("metrics");
    table_->setHorizontalHeaderLabels(
        {"relMSE", "PSNR", "FLIP", "ref. noise", "bias %", "region relMSE", "region FLIP"});
    table_->horizontalHeaderItem(2)->setToolTip(
        "HDR-FLIP's mean perceptual error against the reference, 0 (cannot be told apart) to 1 (docs/flip.md); "
        "computed after the other numbers, in the background");
    table_->horizontalHeaderItem(0)->setToolTip("relative MSE of the view against its reference");
    table_->horizontalHeaderItem(3)->setToolTip(
        "relMSE of the reference's own noise (from its variance): a view's relMSE near it is noise, above it is bias");
    table_->horizontalHeaderItem(4)->setToolTip("the view's mean luminance minus the reference's, in %");
    table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
    table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    table_->horizontalHeader()->setStretchLastSection(true);
    table_->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Preferred);  // new numbers never resize the viewport
    setWidget(table_);
    connect(&studio_.comparison(), &ComparisonModel::metricsChanged, this, &MetricsDock::refresh);
    connect(&studio_, &Studio::viewsRebuilt, this, &MetricsDock::refresh);
}

void MetricsDock::refresh() {
    const std::vector<ViewFrame>& frames = studio_.frames();
    if (table_->rowCount() != int(frames.size())) table_->setRowCount(int(frames.size()));
    auto set = [this](int row, int column, const QString& text) {
        QTableWidgetItem* item = table_->item(row, column);
        if (!item) {
            item = new QTableWidgetItem;
            item->setTextAlignment(column == 0 ? Qt::AlignLeft | Qt::AlignVCenter : Qt::AlignRight | Qt::AlignVCenter);
            table_->setItem(row, column, item);
        }
        if (item->text() != text) item->setText(text);
    };
    for (int row = 0; row < int(frames.size()); ++row) {
        const ViewFrame& f = frames[std::size_t(row)];
        QTableWidgetItem* header = table_->verticalHeaderItem(row);
        if (!header || header->text() != f.name) table_->setVerticalHeaderItem(row, new QTableWidgetItem(f.name));
        if (!f.metrics) {
            // Why there are no numbers: short in the cell (a long text would widen the column past the dock), whole
            // in its tooltip.
            const QString why = incomparable(f);
            set(row, 0,
                f.chosenReference ? QString("reference")
                : why.isEmpty()   ? QString("waiting")
                                  : why.section(':', 0, 0));
            table_->item(row, 0)->setToolTip(why);
            for (int c = 1; c < table_->columnCount(); ++c)
                set(row, c, "");
            continue;
        }
        if (QTableWidgetItem* first = table_->item(row, 0)) first->setToolTip(QString());
        // A stale pair's numbers stay, marked, until the new reference arrives.
        set(row, 0, QString::number(f.metrics->relMSE, 'g', 3) + (f.metricsStale ? " (stale)" : ""));
        set(row, 1, std::isfinite(f.metrics->psnr) ? QString::number(f.metrics->psnr, 'g', 4) : QString("identical"));
        // FLIP of the metrics' pair, else "..." (on its way: computed once nothing renders).
        const bool flip = f.flipIsCurrent();
        set(row, 2, flip ? QString::number(*f.flip, 'g', 3) : QString("..."));
        set(row, 3, f.metrics->referenceNoiseRelMSE ? QString::number(*f.metrics->referenceNoiseRelMSE, 'g', 3) : "-");
        set(row, 4, QString::number(f.metrics->energyBias, 'g', 3));
        set(row, 5, f.regionMetrics ? QString::number(f.regionMetrics->relMSE, 'g', 3) : "-");
        set(row, 6, f.regionMetrics && f.regionFlip && flip ? QString::number(*f.regionFlip, 'g', 3) : "-");
    }
}

// --- Inspector

InspectorDock::InspectorDock(Studio& studio, QWidget* parent)
    : QDockWidget("Inspector", parent), label_(new QLabel("Move the cursor over a view")) {
    setObjectName("inspectorDock");
    label_->setObjectName("inspector");
    label_->setTextFormat(Qt::RichText);
    label_->setAlignment(Qt::AlignTop | Qt::AlignLeft);
    label_->setTextInteractionFlags(Qt::TextSelectableByMouse);  // values can be copied
    // In a scroll area: a row of three values per view and its reference is wider than the dock, and a clipped
    // column (the reference's) would hide what the user came for.
    setWidget(scrolling(label_, "inspectorScroll"));
    connect(&studio, &Studio::inspected, label_, &QLabel::setText);
    // Nothing of the previous project stays on screen.
    connect(&studio, &Studio::viewsRebuilt, this, [this] { label_->setText("Move the cursor over a view"); });
}

QString InspectorDock::text() const {
    return label_->text();
}

// --- Snapshots

SnapshotsDock::SnapshotsDock(Studio& studio, QWidget* parent)
    : QDockWidget("Snapshots", parent), studio_(studio), list_(new QListWidget), compare_(new QPushButton("Compare")) {
    setObjectName("snapshotsDock");
    list_->setObjectName("snapshotList");
    auto* content = new QWidget;
    auto* layout = new QVBoxLayout(content);
    auto* buttons = new QHBoxLayout;
    auto* take = new QPushButton("Take");
    compare_->setObjectName("compareSnapshot");
    compare_->setCheckable(true);
    auto* restore = new QPushButton("Restore");
    take->setToolTip("Keep the current view's image with its parameters (K)");
    compare_->setToolTip("Compare the live view against the selected snapshot instead of the reference");
    restore->setToolTip("Put the selected snapshot's parameters back on its view (undoable)");
    for (QPushButton* b : {take, compare_, restore})
        buttons->addWidget(b);
    layout->addWidget(list_);
    layout->addLayout(buttons);
    setWidget(content);
    connect(take, &QPushButton::clicked, this, [this] { studio_.takeSnapshot(); });
    connect(compare_, &QPushButton::toggled, this,
            [this](bool on) { studio_.compareWithSnapshot(on ? list_->currentRow() : -1); });
    connect(restore, &QPushButton::clicked, this, [this] { studio_.restoreSnapshot(list_->currentRow()); });
    connect(&studio_.snapshotStore(), &SnapshotStore::changed, this, &SnapshotsDock::refresh);
    connect(&studio_, &Studio::snapshotTaken, list_, [this](int index) { list_->setCurrentRow(index); });
    connect(&studio_, &Studio::viewsRebuilt, this, [this] {
        const QSignalBlocker block(compare_);
        compare_->setChecked(false);
    });
}

void SnapshotsDock::refresh() {
    list_->clear();
    for (const Snapshot& s : studio_.snapshots()) {
        QString params = QString::fromStdString(s.parameters.dump());
        if (params.size() > 60) params = params.left(57) + "...";
        list_->addItem(s.name + (s.view < 0 ? "  (its view is gone)  " : "  ") + params);
    }
}

// --- Plots

PlotsDock::PlotsDock(Studio& studio, QWidget* parent)
    : QDockWidget("Plots", parent),
      studio_(studio),
      panel_(new PlotPanel),
      convergence_(new ConvergencePlot),
      pdf_(new PdfPlot),
      phasePolar_(new PhasePlot(PhasePlot::Kind::Polar)),
      phaseCosine_(new PhasePlot(PhasePlot::Kind::OverCosine)),
      ltsdPolar_(new LtsdPolarPlot),
      ltsdError_(new LtsdErrorPlot) {
    setObjectName("plotsDock");
    for (Plot* plot :
         std::initializer_list<Plot*>{convergence_, pdf_, phasePolar_, phaseCosine_, ltsdPolar_, ltsdError_})
        panel_->addPlot(plot);
    setWidget(panel_);
    connect(&studio_.comparison(), &ComparisonModel::convergenceChanged, this, &PlotsDock::plotConvergence);
    connect(&studio_, &Studio::phasesChanged, this, &PlotsDock::plotPhases);
    connect(&studio_, &Studio::probed, pdf_, &PdfPlot::showProbe);
    connect(&studio_, &Studio::probeMessage, pdf_, &PdfPlot::showMessage);
    connect(&studio_, &Studio::viewsRebuilt, this, [this] {
        pdf_->showMessage("Move the cursor over a view whose technique samples distances (WVDS).");
        plotConvergence();
    });
}

std::vector<PlotFile> PlotsDock::files() const {
    std::vector<PlotFile> files;
    for (Plot* plot : panel_->plots())
        files.push_back(
            {plot->name(), [plot](const QString& path, QString* error) { return plot->exportTo(path, error); }});
    return files;
}

void PlotsDock::plotConvergence() {
    std::vector<QString> names;
    std::vector<std::vector<ConvergencePoint>> points;
    studio_.comparison().convergenceSeries(names, points);
    convergence_->setSeries(names, points);
}

void PlotsDock::plotPhases() {
    std::vector<PhaseCurve> curves = studio_.phaseCurves();
    phasePolar_->setCurves(curves);
    phaseCosine_->setCurves(std::move(curves));
    const LtsdFit fit = studio_.ltsdFit();
    ltsdPolar_->showFit(fit);
    ltsdError_->showFit(fit);
}

// --- Scene

SceneDock::SceneDock(Studio& studio, QWidget* parent)
    : QDockWidget("Scene", parent), panel_(new ScenePanel(studio.session())) {
    setObjectName("sceneDock");
    panel_->setAnimation(&studio.animation());
    setWidget(panel_);
}

bool DockWheelGuard::guarded(QObject* object) {
    auto* widget = qobject_cast<QWidget*>(object);
    if (!widget || qobject_cast<QScrollBar*>(widget)) return false;
    if (!qobject_cast<QAbstractSpinBox*>(widget) && !qobject_cast<QComboBox*>(widget) &&
        !qobject_cast<QAbstractSlider*>(widget))
        return false;
    for (QWidget* w = widget->parentWidget(); w; w = w->parentWidget())
        if (qobject_cast<QDockWidget*>(w)) return true;
    return false;
}

void DockWheelGuard::guard(QWidget* root) {
    for (QWidget* w : root->findChildren<QWidget*>())
        if (guarded(w) && w->focusPolicy() == Qt::WheelFocus) w->setFocusPolicy(Qt::StrongFocus);
}

bool DockWheelGuard::eventFilter(QObject* watched, QEvent* event) {
    if (event->type() == QEvent::Polish && guarded(watched)) {
        // Not focused by the wheel itself (Qt::WheelFocus would give it the focus, then the value).
        auto* widget = static_cast<QWidget*>(watched);
        if (widget->focusPolicy() == Qt::WheelFocus) widget->setFocusPolicy(Qt::StrongFocus);
    } else if (event->type() == QEvent::Wheel && guarded(watched)) {
        auto* widget = static_cast<QWidget*>(watched);
        if (!widget->hasFocus()) {
            // To the field's parent instead, and so on up to the dock's scroll area, which scrolls.
            if (QWidget* parent = widget->parentWidget()) QCoreApplication::sendEvent(parent, event);
            return true;
        }
    }
    return QObject::eventFilter(watched, event);
}

}  // namespace tyndall::studio
