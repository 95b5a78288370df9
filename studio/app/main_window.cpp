#include "main_window.h"
#include "trace.h"
#include "image_file.h"

#include "tyndall/core/geometry.h"
#include "tyndall/core/phase_eval.h"
#include "tyndall/image/image_io.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCloseEvent>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QMimeData>
#include <QShowEvent>
#include <QComboBox>
#include <QDesktopServices>
#include <QDialog>
#include <QInputDialog>
#include <QLineEdit>
#include <QMenu>
#include <QScrollArea>
#include <QUrl>

#include <QSettings>
#include <QSignalBlocker>
#include <QDir>
#include <QDockWidget>
#include <QFileDialog>
#include <QFileInfo>
#include <QGuiApplication>
#include <QKeyEvent>
#include <QLabel>
#include <QHeaderView>
#include <QListWidget>
#include <QMenuBar>
#include <QHBoxLayout>
#include <QMessageBox>
#include <QPushButton>
#include <QVBoxLayout>
#include <QStatusBar>
#include <QTableWidget>
#include <QToolBar>
#include <QVulkanInstance>

#include <nlohmann/json.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace tyndall::studio {

namespace {

// Right after an edit, the frame that would only mark the view as rendering waits this long for the new image.
constexpr qint64 kEditQuietMs = 150;

QString displayNameOf(const std::string& technique) {
    try {
        return QString::fromStdString(createTechnique(technique)->displayName());
    } catch (const std::exception&) {
        return QString::fromStdString(technique);
    }
}

}  // namespace

MainWindow::MainWindow(QVulkanInstance* vulkan, std::vector<std::string> overrides)
    : overrides_(std::move(overrides)) {
    background_ = new Background(this);
    scheduler_ = new RenderScheduler(session_, *background_, this);
    model_ = new ComparisonModel(*background_, this);
    files_ = new ProjectFiles(session_, this);
    snapshots_ = new SnapshotStore(session_, this);
    exporter_ = new Exporter(*background_, this);
    animation_ = new Animation(session_, this);
    composer_ = new Composer(this);
    viewport_ = new Viewport;
    viewport_->setVulkanInstance(vulkan);
    QWidget* container = QWidget::createWindowContainer(viewport_, this);
    container->setMinimumSize(320, 240);
    container->setFocusPolicy(Qt::StrongFocus);
    setCentralWidget(container);

    auto* viewsDock = new QDockWidget("Views", this);
    viewsDock->setObjectName("viewsDock");
    viewList_ = new QListWidget;
    viewList_->setObjectName("viewList");
    // Authoring: each an undoable edit of the project.
    auto* viewsWidget = new QWidget;
    auto* viewsLayout = new QVBoxLayout(viewsWidget);
    viewsLayout->setContentsMargins(0, 0, 0, 0);
    viewsLayout->addWidget(viewList_);
    auto* viewButtons = new QHBoxLayout;
    auto* addView = new QPushButton("Add");
    addView->setObjectName("addView");
    addView->setToolTip("Add a view with a technique (its default part: the lights and media it supports)");
    auto* techniques = new QMenu(addView);
    for (const std::string& name : techniqueNames())
        techniques->addAction(displayNameOf(name) + "  (" + QString::fromStdString(name) + ")", this, [this, name] {
            QString error;
            if (!session_.addView(name, &error)) QMessageBox::warning(this, "Cannot add the view", error);
        });
    addView->setMenu(techniques);
    // A button for an edit of the selected view; a refused edit says why.
    // An image view (opened from a file) is not in the project: Remove closes it, Duplicate does not apply.
    auto viewEdit = [this](const QString& text, const QString& tip, bool (Session::*edit)(int, QString*)) {
        auto* button = new QPushButton(text);
        button->setToolTip(tip);
        connect(button, &QPushButton::clicked, this, [this, text, edit] {
            QString error;
            if (model_->isImage(state_.current)) {
                if (edit == &Session::removeView) {
                    const int view = state_.current;
                    model_->removeImage(view);
                    refreshViewList();
                    selectView(std::min(view, model_->size() - 1));
                    return;
                }
                error = "'" + model_->frames()[std::size_t(state_.current)].name +
                        "' is an image opened from a file, not a view of the project";
            } else if ((session_.*edit)(state_.current, &error)) {
                return;
            }
            if (!error.isEmpty()) QMessageBox::warning(this, "Cannot " + text.toLower() + " the view", error);
        });
        return button;
    };
    QPushButton* duplicateView =
        viewEdit("Duplicate", "Duplicate the selected view, with its parameters", &Session::duplicateView);
    auto* renameView = new QPushButton("Rename");
    renameView->setToolTip("Rename the selected view (also: double-click it)");
    auto rename = [this] {
        if (state_.current < 0 || state_.current >= model_->size()) return;
        bool ok = false;
        const QString name = QInputDialog::getText(this, "Rename the view", "Name:", QLineEdit::Normal,
                                                   model_->frames()[std::size_t(state_.current)].name, &ok);
        QString error;
        if (ok && model_->isImage(state_.current)) {
            model_->renameImage(state_.current, name);
            refreshViewList();
        } else if (ok && !session_.renameView(state_.current, name.toStdString(), &error) && !error.isEmpty()) {
            QMessageBox::warning(this, "Cannot rename the view", error);
        }
    };
    connect(renameView, &QPushButton::clicked, this, rename);
    connect(viewList_, &QListWidget::itemDoubleClicked, this, rename);
    QPushButton* removeView = viewEdit("Remove", "Remove the selected view (undoable)", &Session::removeView);
    for (QPushButton* b : {addView, duplicateView, renameView, removeView}) viewButtons->addWidget(b);
    viewsLayout->addLayout(viewButtons);
    // An image view's comparand: the reference of one of the project's views.
    imageAgainst_ = new QComboBox;
    imageAgainst_->setObjectName("imageAgainst");
    imageAgainst_->setToolTip("The image is compared against the reference of this view (its part of the scene)");
    imageAgainstRow_ = new QWidget;
    auto* againstLayout = new QHBoxLayout(imageAgainstRow_);
    againstLayout->setContentsMargins(0, 0, 0, 0);
    againstLayout->addWidget(new QLabel("Compare with the reference of"));
    againstLayout->addWidget(imageAgainst_, 1);
    imageAgainstRow_->setVisible(false);
    viewsLayout->addWidget(imageAgainstRow_);
    connect(imageAgainst_, &QComboBox::activated, this, [this](int index) {
        model_->setImageAgainst(state_.current, index);
    });
    viewsDock->setWidget(viewsWidget);
    addDockWidget(Qt::LeftDockWidgetArea, viewsDock);

    auto* paramsDock = new QDockWidget("Parameters", this);
    paramsDock->setObjectName("parametersDock");
    parameters_ = new ParameterPanel(session_);
    // In a scroll area: another view's parameters (more or fewer rows) never resize the dock.
    auto* paramsScroll = new QScrollArea;
    paramsScroll->setWidgetResizable(true);
    paramsScroll->setWidget(parameters_);
    paramsDock->setWidget(paramsScroll);
    connect(parameters_, &ParameterPanel::techniqueRefused, this,
            [this](const QString& reason) { statusBar()->showMessage(reason, 10000); });
    addDockWidget(Qt::RightDockWidgetArea, paramsDock);

    auto* metricsDock = new QDockWidget("Metrics", this);
    metricsDock->setObjectName("metricsDock");
    metrics_ = new QTableWidget(0, 5);
    metrics_->setObjectName("metrics");
    metrics_->setHorizontalHeaderLabels({"relMSE", "PSNR", "ref. noise", "bias %", "region relMSE"});
    metrics_->horizontalHeaderItem(0)->setToolTip("relative MSE of the view against its reference");
    metrics_->horizontalHeaderItem(2)->setToolTip(
        "relMSE of the reference's own noise (from its variance): a view's relMSE near it is noise, above it is bias");
    metrics_->horizontalHeaderItem(3)->setToolTip("the view's mean luminance minus the reference's, in %");
    metrics_->setEditTriggers(QAbstractItemView::NoEditTriggers);
    metrics_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
    metrics_->horizontalHeader()->setStretchLastSection(true);
    metrics_->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Preferred);  // new numbers never resize the viewport
    metricsDock->setWidget(metrics_);
    addDockWidget(Qt::RightDockWidgetArea, metricsDock);

    auto* inspectorDock = new QDockWidget("Inspector", this);
    inspectorDock->setObjectName("inspectorDock");
    inspector_ = new QLabel("Move the cursor over a view");
    inspector_->setObjectName("inspector");
    inspector_->setTextFormat(Qt::RichText);
    inspector_->setAlignment(Qt::AlignTop | Qt::AlignLeft);
    inspector_->setTextInteractionFlags(Qt::TextSelectableByMouse);  // values can be copied
    // In a scroll area: a row of three values per view and its reference is wider than the dock, and a clipped
    // column (the reference's) would hide what the user came for.
    auto* inspectorScroll = new QScrollArea;
    inspectorScroll->setObjectName("inspectorScroll");
    inspectorScroll->setWidgetResizable(true);
    inspectorScroll->setWidget(inspector_);
    inspectorDock->setWidget(inspectorScroll);
    addDockWidget(Qt::RightDockWidgetArea, inspectorDock);

    auto* snapshotsDock = new QDockWidget("Snapshots", this);
    snapshotsDock->setObjectName("snapshotsDock");
    auto* snapshotsWidget = new QWidget;
    auto* snapshotsLayout = new QVBoxLayout(snapshotsWidget);
    snapshotList_ = new QListWidget;
    snapshotList_->setObjectName("snapshotList");
    auto* buttons = new QHBoxLayout;
    auto* take = new QPushButton("Take");
    auto* compare = new QPushButton("Compare");
    compare->setObjectName("compareSnapshot");
    compare->setCheckable(true);
    compareButton_ = compare;
    auto* restore = new QPushButton("Restore");
    take->setToolTip("Keep the current view's image with its parameters (K)");
    compare->setToolTip("Compare the live view against the selected snapshot instead of the reference");
    restore->setToolTip("Put the selected snapshot's parameters back on its view (undoable)");
    buttons->addWidget(take);
    buttons->addWidget(compare);
    buttons->addWidget(restore);
    snapshotsLayout->addWidget(snapshotList_);
    snapshotsLayout->addLayout(buttons);
    snapshotsDock->setWidget(snapshotsWidget);
    addDockWidget(Qt::LeftDockWidgetArea, snapshotsDock);
    connect(take, &QPushButton::clicked, this, [this] { takeSnapshot(); });
    connect(compare, &QPushButton::toggled, this,
            [this](bool on) { compareWithSnapshot(on ? snapshotList_->currentRow() : -1); });
    connect(restore, &QPushButton::clicked, this, [this] { restoreSnapshot(snapshotList_->currentRow()); });

    auto* plotsDock = new QDockWidget("Plots", this);
    plotsDock->setObjectName("plotsDock");
    plots_ = new PlotPanel;
    convergence_ = new ConvergencePlot;
    pdf_ = new PdfPlot;
    phasePolar_ = new PhasePlot(PhasePlot::Kind::Polar);
    phaseCosine_ = new PhasePlot(PhasePlot::Kind::OverCosine);
    ltsdPolar_ = new LtsdPolarPlot;
    ltsdError_ = new LtsdErrorPlot;
    plots_->addPlot(convergence_);
    plots_->addPlot(pdf_);
    plots_->addPlot(phasePolar_);
    plots_->addPlot(phaseCosine_);
    plots_->addPlot(ltsdPolar_);
    plots_->addPlot(ltsdError_);
    plotsDock->setWidget(plots_);
    addDockWidget(Qt::BottomDockWidgetArea, plotsDock);

    probeTimer_.setSingleShot(true);
    probeTimer_.setInterval(60);
    connect(&probeTimer_, &QTimer::timeout, this, [this] { inspect(probePosition_); });

    auto* sceneDock = new QDockWidget("Scene", this);
    sceneDock->setObjectName("sceneDock");
    scene_ = new ScenePanel(session_);
    scene_->setAnimation(animation_);
    sceneDock->setWidget(scene_);
    addDockWidget(Qt::LeftDockWidgetArea, sceneDock);

    buildMenus();

    // The animation advances only once the views have shown its last frame (coalesced: by the simulated time that
    // passed meanwhile), and its edits replace a progressive view's long render at once (flushDirty).
    animation_->setViewsReady([this] { return scheduler_->viewsCaughtUp(); });
    connect(animation_, &Animation::advancing, this, [this](bool during) { scheduler_->setAnimating(during); });
    connect(animation_, &Animation::refused, this,
            [this](const QString& reason) { statusBar()->showMessage("Animation stopped: " + reason, 10000); });
    connect(animation_, &Animation::playingChanged, this, [this](bool playing) {
        const QSignalBlocker block(playAction_);
        playAction_->setChecked(playing);
        playAction_->setText(playing ? "&Pause" : "&Play");
    });
    connect(&session_, &Session::projectReplaced, this, &MainWindow::updateAnimationActions);
    connect(&session_, &Session::sceneChanged, this, &MainWindow::updateAnimationActions);
    updateAnimationActions();

    connect(viewList_, &QListWidget::currentRowChanged, this, [this](int row) {
        if (row < 0) return;
        state_.current = row;
        parameters_->showView(model_->isImage(row) ? -1 : row);  // an image has no parameters
        refreshImageAgainst();
        updatePhasePlots();
        recompose();
    });
    // The data flows one way: session -> scheduler -> model -> viewport, docks and exports.
    connect(&session_, &Session::projectReplaced, this, [this] {
        rebuildViews(true);
        updateTitle();
    });
    connect(&session_, &Session::viewChanged, this, [this](int view) {
        trace("edit of view %d", view);
        noteEdit();
        model_->setExposure(view, session_.project().views[std::size_t(view)].exposure);
        scheduler_->viewEdited(view);
        recompose();
    });
    connect(&session_, &Session::modifiedChanged, this, [this](bool) { updateTitle(); });
    connect(&session_, &Session::sceneChanged, this, &MainWindow::onSceneChanged);
    connect(scheduler_, &RenderScheduler::started, model_, &ComparisonModel::renderStarted);
    connect(scheduler_, &RenderScheduler::failed, model_, &ComparisonModel::renderFailed);
    connect(scheduler_, &RenderScheduler::stateChanged, model_, &ComparisonModel::setState);
    connect(scheduler_, &RenderScheduler::output, this, [this](const RenderOutput& out) {
        model_->addOutput(out);
        if (!out.error.isEmpty() && out.view < model_->size())
            statusBar()->showMessage(model_->frames()[std::size_t(out.view)].name + ": " + out.error, 10000);
        if (!out.reference) requestCompose(true);  // a new image is shown at once, even right after an edit
    });
    connect(model_, &ComparisonModel::framesChanged, this, &MainWindow::recompose);
    connect(model_, &ComparisonModel::metricsChanged, this, &MainWindow::updateMetricsDock);
    connect(model_, &ComparisonModel::convergenceChanged, this, &MainWindow::plotConvergence);
    connect(snapshots_, &SnapshotStore::changed, this, &MainWindow::refreshSnapshotList);
    connect(exporter_, &Exporter::finished, this, &MainWindow::exportFinished);
    connect(files_, &ProjectFiles::autosaveFailed, this, [this](const QString& message) {
        statusBar()->showMessage(message, 10000);
    });
    connect(files_, &ProjectFiles::recentChanged, this, &MainWindow::refreshRecentMenu);
    connect(composer_, &Composer::composed, this, [this](const QImage& frame) {
        composed_ = frame;
        viewport_->setFrame(frame);
    });

    connect(viewport_, &Viewport::resized, this, [this](QSize) { recompose(); });
    connect(viewport_, &Viewport::keyPressed, this,
            [this](int key, Qt::KeyboardModifiers m) { onKey(key, m, true); });
    connect(viewport_, &Viewport::keyReleased, this,
            [this](int key, Qt::KeyboardModifiers m) { onKey(key, m, false); });
    auto dragDivider = [this](QPointF position, Qt::MouseButtons buttons) {
        if (state_.layout != Layout::Split || !(buttons & Qt::LeftButton) || model_->frames().empty()) return;
        const std::vector<QRect> rects = viewRects(model_->frames(), state_, viewport_->pixelSize());
        const QRect r = rects[std::size_t(std::clamp(state_.current, 0, int(rects.size()) - 1))];
        if (r.width() <= 0) return;
        state_.split = std::clamp((position.x() - r.x()) / r.width(), 0.0, 1.0);
        recompose();
    };
    connect(viewport_, &Viewport::wheelTurned, this, [this](double steps) {
        if (QGuiApplication::keyboardModifiers() & Qt::ControlModifier) {
            state_.zoom = std::clamp(state_.zoom * std::pow(1.25, steps), 1.0, 64.0);  // every view zooms together
            recompose();
            return;
        }
        dollyCamera(std::pow(0.9, steps));
    });
    connect(viewport_, &Viewport::mousePressed, this, [this, dragDivider](QPointF position, Qt::MouseButtons buttons) {
        lastMouse_ = position;
        offsetDragMedium_ = -1;
        const Qt::KeyboardModifiers modifiers = QGuiApplication::keyboardModifiers();
        if (modifiers & Qt::AltModifier) return;  // camera navigation
        if ((modifiers & Qt::ControlModifier) && (buttons & Qt::LeftButton)) {
            int medium;
            Vec3 point;
            if (!particlePointAt(position, medium, point)) return;
            if (modifiers & Qt::ShiftModifier) {  // moving the region of targets: in the image plane at that depth
                const Camera& cam = session_.project().scene.camera;
                const std::vector<QRect> rects = viewRects(model_->frames(), state_, viewport_->pixelSize());
                int view;
                QPoint pixel;
                if (!viewAt(position, view, pixel)) return;
                const QRect r = rects[std::size_t(view)];
                const QRectF visible = visiblePart(QSize(cam.width, cam.height), state_);
                const Vec3 forward = glm::normalize(cam.target - cam.position);
                const Vec3 right = glm::normalize(glm::cross(forward, cam.up)), up = glm::cross(right, forward);
                const double depth = glm::dot(point - cam.position, forward);
                const double metresPerPixel = 2.0 * depth * std::tan(glm::radians(cam.fovY) * 0.5) / cam.height *
                                              visible.height() / std::max(1, r.height());
                const auto& sim = session_.project().scene.particleMedia[std::size_t(medium)].simulation;
                offsetDragMedium_ = medium;
                offsetDragStart_ = sim ? sim->offset : Vec3(0.0);
                offsetDragFrom_ = position;
                offsetDragRight_ = right * metresPerPixel;
                offsetDragUp_ = up * metresPerPixel;
                return;
            }
            QString error;
            if (!addImpulseAt(position, &error) && !error.isEmpty()) statusBar()->showMessage(error, 10000);
            return;
        }
        dragDivider(position, buttons);
        int view;
        QPoint pixel;
        if ((buttons & Qt::RightButton) && viewAt(position, view, pixel)) regionStart_ = pixel;
    });
    connect(viewport_, &Viewport::mouseMoved, this, [this, dragDivider](QPointF position, Qt::MouseButtons buttons) {
        const QPointF delta = position - lastMouse_;
        lastMouse_ = position;
        if ((QGuiApplication::keyboardModifiers() & Qt::AltModifier) && (buttons & Qt::LeftButton)) {
            orbitCamera(-delta.x() * 0.01, -delta.y() * 0.01);
            return;
        }
        if (offsetDragMedium_ >= 0 && (buttons & Qt::LeftButton)) {
            const QPointF moved = position - offsetDragFrom_;
            const Vec3 offset = offsetDragStart_ + moved.x() * offsetDragRight_ - moved.y() * offsetDragUp_;
            QString error;
            if (!animation_->setOffset(offsetDragMedium_, offset, &error, 3)) statusBar()->showMessage(error, 5000);
            return;
        }
        if ((buttons & Qt::MiddleButton) && !model_->frames().empty()) {  // pan every view together
            const std::vector<QRect> rects = viewRects(model_->frames(), state_, viewport_->pixelSize());
            QRect r;
            for (const QRect& c : rects)
                if (!c.isEmpty()) r = c;
            if (r.width() > 0) {
                state_.centre -= QPointF(delta.x() / r.width(), delta.y() / r.height()) / state_.zoom;
                state_.centre = QPointF(std::clamp(state_.centre.x(), 0.0, 1.0), std::clamp(state_.centre.y(), 0.0, 1.0));
                recompose();
            }
            return;
        }
        dragDivider(position, buttons);
        int view;
        QPoint pixel;
        if ((buttons & Qt::RightButton) && viewAt(position, view, pixel))
            setRegion(QRect(regionStart_, pixel).normalized());
        probePosition_ = position;
        if (!probeTimer_.isActive()) probeTimer_.start();
    });
    connect(viewport_, &Viewport::mouseDoubleClicked, this, [this](QPointF) {
        state_.split = 0.5;
        recompose();
    });
    refreshRecentMenu();
    // Created now, so that its messages never resize the viewport. The permanent label says what renders: "Ready" only
    // when every reference is done and no comparison is stale.
    renderStatus_ = new QLabel("Ready");
    renderStatus_->setObjectName("renderStatus");
    statusBar()->addPermanentWidget(renderStatus_);
    // What the display does to every view, which the views' captions do not say (E / Shift+E, Ctrl+wheel).
    displayStatus_ = new QLabel;
    displayStatus_->setObjectName("displayStatus");
    displayStatus_->setToolTip("The display exposure offset (E / Shift+E) is added to every view's own exposure (the "
                               "Parameters dock's \"view exposure\"); zoom with Ctrl+wheel, Z resets");
    statusBar()->addPermanentWidget(displayStatus_);
    updateDisplayStatus();
    setAcceptDrops(true);
    resize(1280, 800);
    // The default layout: Snapshots behind Views and the Inspector behind Metrics (tabs), so that the Scene dock and
    // the metrics table get the height for their rows; docks wide enough for their captions.
    tabifyDockWidget(viewsDock, snapshotsDock);
    viewsDock->raise();
    tabifyDockWidget(metricsDock, inspectorDock);
    metricsDock->raise();
    // The side docks take the whole height; the plots go under the viewport only.
    setCorner(Qt::BottomLeftCorner, Qt::LeftDockWidgetArea);
    setCorner(Qt::BottomRightCorner, Qt::RightDockWidgetArea);
    defaultDockSizes_ = [=, this] {
        resizeDocks({viewsDock, sceneDock}, {220, 480}, Qt::Vertical);
        resizeDocks({paramsDock, metricsDock}, {380, 300}, Qt::Vertical);
        resizeDocks({viewsDock, paramsDock}, {300, 400}, Qt::Horizontal);
        resizeDocks({plotsDock}, {260}, Qt::Vertical);
    };
    // The window's size and its docks as the user left them (saved on close).
    const QSettings settings;
    restoreGeometry(settings.value("window/geometry").toByteArray());
    if (restoreState(settings.value("window/state").toByteArray())) defaultDockSizes_ = nullptr;
    updateTitle();
}

void MainWindow::showEvent(QShowEvent* event) {
    QMainWindow::showEvent(event);
    // The default dock sizes, once the window has its size (resizeDocks before the first layout is not kept).
    if (defaultDockSizes_) QTimer::singleShot(0, this, [this] {
        if (!defaultDockSizes_) return;
        defaultDockSizes_();
        defaultDockSizes_ = nullptr;
    });
}

void MainWindow::saveLayout() const {
    QSettings settings;
    settings.setValue("window/geometry", saveGeometry());
    settings.setValue("window/state", saveState());
}

MainWindow::~MainWindow() {
    scheduler_->cancelAll();
    background_->waitForDone();  // metrics in flight post back to the model
    files_->waitForAutosaves();  // and a failed autosave would say so
    QCoreApplication::removePostedEvents(this);
}

void MainWindow::buildMenus() {
    QMenu* file = menuBar()->addMenu("&File");
    QAction* open = file->addAction("&Open...", this, [this] {
        if (!confirmDiscard()) return;
        const QString path = QFileDialog::getOpenFileName(this, "Open project", QFileInfo(session_.path()).path(),
                                                          "Tyndall projects (*.json)");
        if (!path.isEmpty()) openProject(path);
    });
    open->setShortcut(QKeySequence::Open);
    QAction* save = file->addAction("&Save", this, [this] {
        QString error;
        if (!saveProject(&error)) QMessageBox::critical(this, "Cannot save", error);
    });
    save->setShortcut(QKeySequence::Save);
    QAction* saveAs = file->addAction("Save &as...", this, [this] {
        const QString path = QFileDialog::getSaveFileName(this, "Save project as", session_.path(),
                                                          "Tyndall projects (*.json)");
        QString error;
        if (!path.isEmpty() && !saveProjectAs(path, &error)) QMessageBox::critical(this, "Cannot save", error);
    });
    saveAs->setShortcut(QKeySequence::SaveAs);
    recentMenu_ = file->addMenu("Open &recent");
    QAction* openImage = file->addAction("Open &image...", this, [this] {
        const QStringList paths = QFileDialog::getOpenFileNames(
            this, "Open images to compare", QFileInfo(session_.path()).absolutePath(),
            "Images (*.exr *.hdr *.pfm *.png *.jpg *.jpeg *.tif *.tiff *.bmp *.tga)");
        for (const QString& path : paths) {
            QString error;
            if (openImageView(path, &error) < 0) QMessageBox::warning(this, "Cannot open the image", error);
        }
    });
    openImage->setShortcut(QKeySequence("Ctrl+I"));
    openImage->setToolTip("Open EXR, HDR or PNG images (also by drag and drop) as views that take part in every "
                          "comparison");
    file->addSeparator();
    file->addAction("&Export comparison...", this, [this] {
        const QString folder = QFileDialog::getExistingDirectory(this, "Export the comparison into",
                                                                 QFileInfo(session_.path()).absolutePath());
        if (!folder.isEmpty()) startExport(folder);
    });
    connect(this, &MainWindow::exportFinished, this, [this](bool ok, const QString& message) {
        if (ok && message.isEmpty()) {
            statusBar()->showMessage("Exported the comparison", 5000);
            return;
        }
        // Not modal: the studio goes on rendering while the user reads it.
        auto* box = new QMessageBox(ok ? QMessageBox::Information : QMessageBox::Critical,
                                    ok ? "Exported, with notes" : "Cannot export", message, QMessageBox::Ok, this);
        box->setObjectName("exportReport");
        box->setAttribute(Qt::WA_DeleteOnClose);
        box->setModal(false);
        box->show();
    });
    file->addAction("Clear the reference cache", this, [] { QDir(referenceCacheFolder()).removeRecursively(); });
    file->addSeparator();
    QAction* quit = file->addAction("&Quit", this, &QWidget::close);
    quit->setShortcut(QKeySequence::Quit);

    QMenu* edit = menuBar()->addMenu("&Edit");
    QAction* undo = session_.undoStack()->createUndoAction(this, "&Undo");
    undo->setShortcut(QKeySequence::Undo);
    QAction* redo = session_.undoStack()->createRedoAction(this, "&Redo");
    QList<QKeySequence> redoKeys = QKeySequence::keyBindings(QKeySequence::Redo);
    for (const QKeySequence& key : {QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")})
        if (!redoKeys.contains(key)) redoKeys << key;  // both, on every platform
    redo->setShortcuts(redoKeys);
    edit->addAction(undo);
    edit->addAction(redo);

    QMenu* view = menuBar()->addMenu("&View");
    QToolBar* toolbar = addToolBar("Layout");
    toolbar->setObjectName("layoutToolbar");
    auto* layouts = new QActionGroup(this);
    auto addLayout = [&](const QString& name, Layout layout, const QString& key) {
        QAction* a = view->addAction(name, this, [this, layout] { setLayoutMode(layout); });
        a->setCheckable(true);
        a->setShortcut(QKeySequence(key));
        a->setShortcutContext(Qt::ApplicationShortcut);
        a->setChecked(layout == Layout::Grid);
        layoutActions_[int(layout)] = a;
        layouts->addAction(a);
        toolbar->addAction(a);
    };
    addLayout("&Grid", Layout::Grid, "G");
    addLayout("&Single", Layout::Single, "S");
    addLayout("Split (&wipe)", Layout::Split, "W");
    view->addSeparator();
    QAction* diff = view->addAction("Cycle &difference (off, signed, absolute, relative)", this, [this] {
        state_.diff = DiffMode((int(state_.diff) + 1) % 4);
        recompose();
    });
    diff->setShortcut(QKeySequence("D"));
    diff->setShortcutContext(Qt::ApplicationShortcut);
    toolbar->addAction(diff);

    // The display transform of every view (differences keep their own maps).
    toolbar->addSeparator();
    tonemapCombo_ = new QComboBox;
    tonemapCombo_->setObjectName("tonemap");
    tonemapCombo_->setToolTip("Tonemap operator, after the exposure (M cycles): sRGB clamps; Reinhard compresses "
                              "luminance, keeping hue; ACES is Narkowicz's filmic fit; false colour maps log2 "
                              "luminance to viridis");
    for (const std::string& name : tonemapNames()) tonemapCombo_->addItem(QString::fromStdString(name));
    connect(tonemapCombo_, &QComboBox::currentIndexChanged, this, [this](int i) { setTonemap(Tonemap(i)); });
    toolbar->addWidget(tonemapCombo_);
    QAction* cycleTonemap = view->addAction("Cycle &tonemap operator (sRGB, Reinhard, ACES, false colour)", this,
                                            [this] { onKey(Qt::Key_M, Qt::NoModifier, true); });
    cycleTonemap->setShortcut(QKeySequence("M"));
    cycleTonemap->setShortcutContext(Qt::ApplicationShortcut);
    for (QAction* a : {undo, redo, save, open, saveAs}) a->setShortcutContext(Qt::ApplicationShortcut);

    // Every key the viewport knows is an action in a menu: listed there and in the shortcuts overlay, and never
    // swallowed by the Views list's keyboard search when it has the focus. (Typing in a spin box still types.)
    auto key = [this](QMenu* menu, const QString& text, const QKeySequence& sequence, std::function<void()> run) {
        QAction* a = menu->addAction(text, this, std::move(run));
        a->setShortcut(sequence);
        a->setShortcutContext(Qt::ApplicationShortcut);
        return a;
    };
    QAction* swap = key(view, "Swap the wipe's sides", QKeySequence("T"), [this] {
        state_.swapped = !state_.swapped;
        recompose();
    });
    toolbar->addAction(swap);
    view->addSeparator();
    key(view, "Display exposure offset +0.5 EV (all views)", QKeySequence("E"),
        [this] { onKey(Qt::Key_E, Qt::NoModifier, true); });
    key(view, "Display exposure offset -0.5 EV (all views)", QKeySequence("Shift+E"),
        [this] { onKey(Qt::Key_E, Qt::ShiftModifier, true); });
    key(view, "Reset zoom and pan", QKeySequence("Z"), [this] { onKey(Qt::Key_Z, Qt::NoModifier, true); });
    key(view, "Clear the metrics region", QKeySequence("Esc"), [this] { setRegion(QRect()); })
        ->setShortcutContext(Qt::WindowShortcut);  // not in dialogs
    QMenu* views = view->addMenu("&Views");
    for (int i = 0; i < 9; ++i) {
        key(views, QString("Show view %1 alone").arg(i + 1), QKeySequence(QString::number(i + 1)),
            [this, i] { onKey(Qt::Key_1 + i, Qt::NoModifier, true); });
    }
    views->addSeparator();
    for (int i = 0; i < 9; ++i)
        key(views, QString("Compare every view against view %1 (again: the reference)").arg(i + 1),
            QKeySequence(QString("Shift+%1").arg(i + 1)),
            [this, i] { chooseReferenceView(i == model_->referenceView() ? -1 : i); });

    QMenu* scene = menuBar()->addMenu("&Camera");
    key(scene, "&Frame the scene", QKeySequence("F"), [this] { frameScene(); });
    QMenu* snapshots = menuBar()->addMenu("S&napshots");
    key(snapshots, "&Take a snapshot of the current view", QKeySequence("K"), [this] { takeSnapshot(); });

    // The particle simulation: shown only for a project with a particle medium (updateAnimationActions).
    QMenu* animation = menuBar()->addMenu("&Animation");
    animationBar_ = addToolBar("Animation");
    animationBar_->setObjectName("animationToolbar");
    playAction_ = key(animation, "&Play", QKeySequence("P"), [this] { animation_->togglePlay(); });
    playAction_->setObjectName("playAnimation");
    playAction_->setCheckable(true);
    playAction_->setToolTip("Play or pause the particle simulation (P): it advances at the wall clock's rate, by as "
                            "many steps as passed, each time the views have shown the last frame");
    stepAction_ = key(animation, "&Step", QKeySequence("."), [this] {
        QString error;
        if (!animation_->step(1, &error)) statusBar()->showMessage(error, 10000);
    });
    stepAction_->setObjectName("stepAnimation");
    resetAction_ = key(animation, "&Reset (step 0, no impulses, targets back)", QKeySequence("Ctrl+R"), [this] {
        QString error;
        if (!animation_->reset(&error)) statusBar()->showMessage(error, 10000);
    });
    resetAction_->setObjectName("resetAnimation");
    for (QAction* a : {playAction_, stepAction_, resetAction_}) animationBar_->addAction(a);

    QMenu* help = menuBar()->addMenu("&Help");
    QAction* keys = key(help, "&Keyboard and mouse shortcuts", QKeySequence::HelpContents, [this] { showShortcuts(); });
    keys->setShortcuts({QKeySequence(Qt::Key_F1), QKeySequence("?")});
    help->addAction("&Documentation", this, [this] {
        const QString docs = QStringLiteral(TYNDALL_DOCS_DIR);
        if (!QDir(docs).exists() || !QDesktopServices::openUrl(QUrl::fromLocalFile(docs)))
            QMessageBox::information(this, "Documentation",
                                     "The documentation is in docs/ and README.md of the source tree (" + docs + ").");
    });
    help->addAction("&About Tyndall Studio", this, [this] {
        QMessageBox::about(this, "About Tyndall Studio",
                           QString("<b>Tyndall Studio</b> %1<br>Volumetric rendering comparison studio.<br>Qt %2")
                               .arg(QString::fromLatin1(tyndallVersion()), QString::fromLatin1(qVersion())));
    });
}

QString MainWindow::shortcutsText() {
    // The menus' shortcuts, then what only the mouse or a held key does.
    QString html = "<table cellspacing=4>";
    std::function<void(QMenu*, const QString&)> walk = [&](QMenu* menu, const QString& path) {
        for (QAction* a : menu->actions()) {
            if (a->menu()) {
                walk(a->menu(), path + " > " + a->menu()->title().remove('&'));
                continue;
            }
            if (a->shortcuts().isEmpty()) continue;
            QStringList keys;
            for (const QKeySequence& k : a->shortcuts()) keys << k.toString(QKeySequence::NativeText);
            html += "<tr><td><b>" + keys.join(", ").toHtmlEscaped() + "</b></td><td>" +
                    QString(a->text()).remove('&').toHtmlEscaped() + "</td><td><i>" + path.toHtmlEscaped() +
                    "</i></td></tr>";
        }
    };
    for (QAction* a : menuBar()->actions())
        if (a->menu()) walk(a->menu(), a->menu()->title().remove('&'));
    const char* mouse[][2] = {
        {"Shift (held)", "Show the reference (single layout)"},
        {"Alt+drag", "Orbit the camera"},
        {"Wheel", "Dolly the camera"},
        {"Ctrl+wheel", "Zoom every view"},
        {"Middle drag", "Pan every view"},
        {"Right drag", "Draw a region: metrics over it"},
        {"Drag / double-click", "Move the wipe's divider / centre it"},
        {"Ctrl+click", "Particle medium: an impulse under the cursor (at the current step; the medium steps once)"},
        {"Ctrl+Shift+drag", "Particle medium: move its region of targets (simulation offset)"},
    };
    for (const auto& m : mouse)
        html += QString("<tr><td><b>%1</b></td><td>%2</td><td><i>viewport</i></td></tr>").arg(QString::fromUtf8(m[0]), QString::fromUtf8(m[1]));
    return html + "</table>";
}

void MainWindow::showShortcuts() {
    if (!shortcuts_) {
        shortcuts_ = new QDialog(this);
        shortcuts_->setObjectName("shortcutsOverlay");
        shortcuts_->setWindowTitle("Keyboard and mouse shortcuts");
        auto* layout = new QVBoxLayout(shortcuts_);
        auto* scroll = new QScrollArea;
        auto* text = new QLabel;
        text->setObjectName("shortcutsText");
        text->setTextFormat(Qt::RichText);
        scroll->setWidget(text);
        scroll->setWidgetResizable(true);
        layout->addWidget(scroll);
        auto* close = new QPushButton("Close");
        connect(close, &QPushButton::clicked, shortcuts_, &QDialog::close);
        layout->addWidget(close);
        shortcuts_->resize(640, 720);
    }
    shortcuts_->findChild<QLabel*>("shortcutsText")->setText(shortcutsText());
    shortcuts_->show();
    shortcuts_->raise();
}

bool MainWindow::openProject(const QString& path, bool dialog) {
    QString error;
    scheduler_->cancelAll();
    files_->setOpening(true);
    const bool opened = session_.open(path, &error, overrides_);
    files_->setOpening(false);
    if (!opened) {
        if (dialog) QMessageBox::critical(this, "Cannot open the project", error);
        statusBar()->showMessage("Not opened: " + error, 10000);
        // The current project stays; its renders start again where they were cancelled.
        if (!session_.project().views.empty()) scheduler_->renderAll();
        return false;
    }
    files_->addRecent(path);
    const std::optional<QString> autosave = files_->newerAutosave(path);
    if (autosave && files_->recovery() != Recovery::Never) {
        bool recover = files_->recovery() == Recovery::Always;
        if (files_->recovery() == Recovery::Ask)
            recover = QMessageBox::question(this, "Recover unsaved changes",
                                            "Tyndall Studio stopped with unsaved changes to " +
                                                QFileInfo(path).fileName() + " (autosaved " +
                                                QFileInfo(*autosave).lastModified().toString() +
                                                "). Recover them?") == QMessageBox::Yes;
        if (recover) {
            if (files_->recover(*autosave, &error))
                statusBar()->showMessage("Recovered the unsaved changes of " + QFileInfo(path).fileName(), 10000);
            else
                QMessageBox::warning(this, "Cannot recover", error);
        } else {
            QFile::remove(*autosave);
        }
    }
    return true;
}

bool MainWindow::saveProject(QString* error) {
    if (!session_.save(error)) return false;
    // The snapshots go beside the file; a failure there leaves the project saved and says so.
    QString why;
    if (!snapshots_->save(session_.path(), &why)) {
        if (error) *error = "The project is saved, but not its snapshots: " + why;
        return false;
    }
    return true;
}

bool MainWindow::saveProjectAs(const QString& path, QString* error) {
    const QString before = session_.path();
    const bool modified = session_.modified();
    if (!session_.saveAs(path, error)) return false;
    // The changes are in the new file: the old file's autosave (and the new one's, if it was not modified) hold
    // nothing to recover.
    if (!before.isEmpty() && QFileInfo(before).absoluteFilePath() != QFileInfo(path).absoluteFilePath())
        files_->removeAutosave(before);
    if (!modified) files_->removeAutosave();
    files_->addRecent(path);
    updateTitle();
    QString why;
    if (!snapshots_->save(path, &why)) {
        if (error) *error = "The project is saved, but not its snapshots: " + why;
        return false;
    }
    return true;
}

bool MainWindow::confirmDiscard() {
    if (!session_.modified()) return true;
    const auto answer = QMessageBox::question(this, "Unsaved changes",
                                              "The project has unsaved changes. Save them first?",
                                              QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
    if (answer == QMessageBox::Cancel) return false;
    // Discarded on purpose: the autosave holds nothing to recover (reopening the file asked to, before), and no new
    // autosave while a file dialog is open.
    if (answer == QMessageBox::Discard) files_->discardChanges();
    if (answer == QMessageBox::Save) {
        QString error;
        if (!saveProject(&error)) {
            QMessageBox::critical(this, "Cannot save", error);
            return false;
        }
    }
    return true;
}

void MainWindow::closeEvent(QCloseEvent* event) {
    if (!confirmDiscard()) {
        event->ignore();
        return;
    }
    scheduler_->cancelAll();
    files_->removeAutosave();  // saved or discarded on purpose: nothing to recover
    saveLayout();
    event->accept();
}

void MainWindow::rebuildViews(bool projectOpened) {
    const Project& project = session_.project();
    scheduler_->reset();
    std::vector<ComparisonModel::ViewInfo> views;
    for (std::size_t i = 0; i < project.views.size(); ++i) {
        const View& v = project.views[i];
        views.push_back({QString::fromStdString(v.name), displayNameOf(v.technique), v.exposure, scheduler_->state(int(i))});
    }
    model_->reset(views);
    scheduler_->renderAll();
    state_.region = QRect();
    comparedSnapshot_ = -1;
    QString error;
    if (!projectOpened)
        snapshots_->followViews();
    else if (!snapshots_->load(session_.path(), &error))
        statusBar()->showMessage("Snapshots not loaded: " + error, 10000);
    // Nothing of the previous project stays on screen: the inspector, the pdf plot, the snapshot comparison.
    inspector_->setText("Move the cursor over a view");
    ++probeGeneration_;  // a probe still running for the previous views is not shown
    pdf_->showMessage("Move the cursor over a view whose technique samples distances (WVDS).");
    {
        const QSignalBlocker block(compareButton_);
        compareButton_->setChecked(false);
    }
    refreshViewList();
    state_.current = 0;
    if (model_->size() > 0) viewList_->setCurrentRow(0);
    parameters_->showView(model_->size() > 0 ? 0 : -1);
    plotConvergence();
    updateMetricsDock();
    updatePhasePlots();
    recompose();
}

void MainWindow::onSceneChanged() {
    noteEdit();
    // Views added, removed, renamed or given another technique (or an undo of that): the views start again, the
    // current one kept by name (a new view is selected).
    if (scheduler_->viewsChanged()) {
        const Project& project = session_.project();
        const QString current =
            state_.current < model_->size() ? model_->frames()[std::size_t(state_.current)].name : QString();
        std::set<std::string> before;
        for (const ViewFrame& f : model_->frames()) before.insert(f.name.toStdString());
        rebuildViews(false);
        int select = -1;
        for (int i = 0; i < int(project.views.size()); ++i) {
            if (!before.count(project.views[std::size_t(i)].name)) select = i;  // new
            if (select < 0 && QString::fromStdString(project.views[std::size_t(i)].name) == current) select = i;
        }
        selectView(std::max(select, 0));
        updateTitle();
        return;
    }
    for (int i = 0; i < int(session_.project().views.size()); ++i)
        model_->setExposure(i, session_.project().views[std::size_t(i)].exposure);
    scheduler_->sceneEdited();
    updatePhasePlots();
    recompose();
}

bool MainWindow::settled() const {
    return scheduler_->settled() && model_->idle() && !exporter_->running();
}

void MainWindow::plotConvergence() {
    std::vector<QString> names;
    std::vector<std::vector<ConvergencePoint>> points;
    model_->convergenceSeries(names, points);
    convergence_->setSeries(names, points);
}

void MainWindow::updateStatus() {
    if (!renderStatus_) return;
    const QString text = model_->status();
    if (renderStatus_->text() != text) renderStatus_->setText(text);
}

void MainWindow::noteEdit() { editClock_.start(); }

void MainWindow::refreshViewList() {
    const QSignalBlocker block(viewList_);
    const int row = viewList_->currentRow();
    viewList_->clear();
    for (const ViewFrame& f : model_->frames())
        viewList_->addItem(QString("%1  %2  (%3)").arg(viewList_->count() + 1).arg(f.name, f.technique));
    if (row >= 0 && row < viewList_->count()) viewList_->setCurrentRow(row);
}

void MainWindow::refreshImageAgainst() {
    const bool image = model_->isImage(state_.current);
    imageAgainstRow_->setVisible(image);
    if (!image) return;
    const QSignalBlocker block(imageAgainst_);
    imageAgainst_->clear();
    for (int i = 0; i < model_->projectViews(); ++i) imageAgainst_->addItem(model_->frames()[std::size_t(i)].name);
    imageAgainst_->setCurrentIndex(model_->imageAgainst(state_.current));
}

int MainWindow::openImageView(const QString& path, QString* error) {
    try {
        const ImageFile file = readImageFile(path);
        const int view = model_->addImage(QFileInfo(path).fileName(), file.kind, file.image);
        refreshViewList();
        selectView(view);
        if (file.displayReferred)
            statusBar()->showMessage(QFileInfo(path).fileName() + " holds display values: decoded with the sRGB curve, "
                                     "its metrics are approximate (values the display clipped stay at 1)", 10000);
        return view;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return -1;
    }
}

void MainWindow::dragEnterEvent(QDragEnterEvent* event) {
    const QList<QUrl> urls = event->mimeData()->urls();
    const bool usable = !urls.isEmpty() && std::all_of(urls.begin(), urls.end(), [](const QUrl& url) {
        return url.isLocalFile() && (isImageFile(url.toLocalFile()) || url.toLocalFile().endsWith(".json"));
    });
    if (usable) event->acceptProposedAction();
}

void MainWindow::dropEvent(QDropEvent* event) {
    // Projects open (the last one dropped), images become views; each failure says why.
    QStringList problems;
    QString project;
    for (const QUrl& url : event->mimeData()->urls()) {
        const QString path = url.toLocalFile();
        if (path.endsWith(".json")) {
            project = path;
            continue;
        }
        QString error;
        if (openImageView(path, &error) < 0) problems << error;
    }
    if (!project.isEmpty() && confirmDiscard()) openProject(project);
    event->acceptProposedAction();
    if (!problems.isEmpty()) QMessageBox::warning(this, "Cannot open", problems.join("\n"));
}

void MainWindow::orbitCamera(double yaw, double pitch) {
    QString error;
    if (!camera_.orbit(yaw, pitch, &error) && !error.isEmpty()) statusBar()->showMessage(error, 5000);
}

void MainWindow::dollyCamera(double factor) {
    QString error;
    if (!camera_.dolly(factor, &error) && !error.isEmpty()) statusBar()->showMessage(error, 5000);
}

void MainWindow::frameScene() {
    QString error;
    if (!camera_.frameScene(&error) && !error.isEmpty()) statusBar()->showMessage(error, 5000);
}

int MainWindow::takeSnapshot() {
    if (state_.current < 0 || state_.current >= model_->size()) return -1;
    const int index = snapshots_->take(state_.current, model_->frames()[std::size_t(state_.current)].image);
    if (index >= 0) snapshotList_->setCurrentRow(index);
    return index;
}

void MainWindow::compareWithSnapshot(int index) {
    const std::vector<Snapshot>& shots = snapshots_->snapshots();
    comparedSnapshot_ = index >= 0 && index < int(shots.size()) ? index : -1;
    if (comparedSnapshot_ < 0) {
        model_->compareWithSnapshot(-1, nullptr, QString());
        return;
    }
    const Snapshot& s = shots[std::size_t(comparedSnapshot_)];
    if (s.view < 0) statusBar()->showMessage(s.name + ": its view '" + QString::fromStdString(s.viewName) +
                                             "' is gone; nothing to compare it with", 5000);
    model_->compareWithSnapshot(s.view, s.image, s.name);
}

void MainWindow::chooseReferenceView(int view) {
    model_->chooseReferenceView(view);
    const int chosen = model_->referenceView();
    statusBar()->showMessage(chosen < 0 ? QString("Comparing against the reference")
                                        : "Comparing against view " + model_->frames()[std::size_t(chosen)].name,
                             5000);
}

void MainWindow::restoreSnapshot(int index) { snapshots_->restore(index); }

void MainWindow::setRegion(QRect region) {
    state_.region = region;
    model_->setRegion(region);
}

bool MainWindow::exportComparison(const QString& folder, QString* error) {
    return exporter_->exportNow(folder, {model_->frames(), state_, composedFrame(), plots_->plots()}, error);
}

void MainWindow::startExport(const QString& folder) {
    exporter_->start(folder, {model_->frames(), state_, composedFrame(), plots_->plots()}, this);
}

void MainWindow::updateMetricsDock() {
    if (metrics_->rowCount() != int(model_->frames().size())) metrics_->setRowCount(int(model_->frames().size()));
    // Only cells whose text changes are touched, so that a new image costs no layout of the dock.
    auto set = [this](int row, int column, const QString& text) {
        QTableWidgetItem* item = metrics_->item(row, column);
        if (!item) {
            item = new QTableWidgetItem;
            item->setTextAlignment(column == 0 ? Qt::AlignLeft | Qt::AlignVCenter : Qt::AlignRight | Qt::AlignVCenter);
            metrics_->setItem(row, column, item);
        }
        if (item->text() != text) item->setText(text);
    };
    for (int row = 0; row < int(model_->frames().size()); ++row) {
        const ViewFrame& f = model_->frames()[std::size_t(row)];
        QTableWidgetItem* header = metrics_->verticalHeaderItem(row);
        if (!header || header->text() != f.name) metrics_->setVerticalHeaderItem(row, new QTableWidgetItem(f.name));
        if (!f.metrics) {
            // Why there are no numbers: short in the cell (a long text would widen the column past the dock), whole
            // in its tooltip.
            const QString why = incomparable(f);
            set(row, 0, why.isEmpty() ? QString("waiting") : why.section(':', 0, 0));
            metrics_->item(row, 0)->setToolTip(why);
            for (int c = 1; c < 5; ++c) set(row, c, "");
            continue;
        }
        if (QTableWidgetItem* first = metrics_->item(row, 0)) first->setToolTip(QString());
        // A stale pair's numbers stay, marked, until the new reference arrives.
        set(row, 0, QString::number(f.metrics->relMSE, 'g', 3) + (f.metricsStale ? " (stale)" : ""));
        set(row, 1, QString::number(f.metrics->psnr, 'g', 4));
        set(row, 2, f.metrics->referenceNoiseRelMSE ? QString::number(*f.metrics->referenceNoiseRelMSE, 'g', 3) : "-");
        set(row, 3, QString::number(f.metrics->energyBias, 'g', 3));
        set(row, 4, f.regionMetrics ? QString::number(f.regionMetrics->relMSE, 'g', 3) : "-");
    }
    updateStatus();
}

void MainWindow::updatePhasePlots() {
    // Every medium of the project, the current view's own first and bold.
    const Project& project = session_.project();
    std::vector<std::string> own;
    if (state_.current >= 0 && state_.current < int(project.views.size())) {
        try {
            own = resolvePart(techniqueCatalogue(), project, project.views[std::size_t(state_.current)]).media;
        } catch (const std::exception&) {
        }
    }
    std::vector<PhaseCurve> curves;
    auto add = [&](const std::string& name, const PhaseFunction& phase) {
        const bool selected = std::find(own.begin(), own.end(), name) != own.end();
        PhaseCurve c{QString::fromStdString(name + " (" + toString(phase.kind) + ")"),
                     [phase](double mu) { return phaseValue(phase, mu); }, selected};
        curves.insert(selected ? curves.begin() : curves.end(), std::move(c));
    };
    for (const HomogeneousMedium& m : project.scene.media) add(m.name, m.phase);
    for (const ParticleMedium& m : project.scene.particleMedia) add(m.name, m.phase);
    phasePolar_->setCurves(curves);
    phaseCosine_->setCurves(std::move(curves));

    // The LTSD plots: the view's first medium (a technique such as LTSD handles one at a time).
    LtsdFit fit;
    const QString view = state_.current >= 0 && state_.current < int(project.views.size())
                             ? QString::fromStdString(project.views[std::size_t(state_.current)].name)
                             : QString();
    if (view.isEmpty()) {
        fit.message = "No view selected.";
    } else if (own.empty()) {
        fit.message = "View '" + view + "' has no medium.";
    } else {
        const PhaseFunction* phase = nullptr;
        for (const HomogeneousMedium& m : project.scene.media)
            if (m.name == own.front()) phase = &m.phase;
        for (const ParticleMedium& m : project.scene.particleMedia)
            if (m.name == own.front()) phase = &m.phase;
        if (phase)
            fit = ltsdFitOf(QString::fromStdString(own.front()), view, *phase, ltsdTables_);
        else
            fit.message = "View '" + view + "' names medium '" + QString::fromStdString(own.front()) +
                          "', which the scene does not have.";
    }
    ltsdPolar_->showFit(fit);
    ltsdError_->showFit(fit);
}

void MainWindow::setLtsdTablesDirectory(const QString& directory) {
    ltsdTables_.setDirectory(directory);
    updatePhasePlots();
}

void MainWindow::updateDisplayStatus() {
    if (!displayStatus_) return;
    const QString text = QString("display exposure offset %1%2 EV  |  zoom %3x")
                             .arg(state_.exposureOffset >= 0.0 ? "+" : "")
                             .arg(state_.exposureOffset, 0, 'g', 3)
                             .arg(state_.zoom, 0, 'g', 3);
    if (displayStatus_->text() != text) displayStatus_->setText(text);
}

void MainWindow::recompose() {
    updateDisplayStatus();
    // Once per pass of the event loop, however many changes it brought. Right after an edit, the frame that would only
    // mark the view as rendering waits up to kEditQuietMs: if the new image comes first (the analytic techniques take
    // ~100 ms), that frame is never composed nor presented, and the two cores go to the render.
    if (composeQueued_) return;
    composeQueued_ = true;
    QTimer::singleShot(0, this, [this] { requestCompose(); });
}

void MainWindow::requestCompose(bool now) {
    if (!composeQueued_) return;
    // Within kEditQuietMs of an edit the frame waits for the rest of it (also one asked for just before the edit).
    const qint64 wait = editClock_.isValid() ? kEditQuietMs - editClock_.elapsed() : 0;
    if (!now && wait > 0) {
        QTimer::singleShot(int(wait), this, [this] { requestCompose(); });
        return;
    }
    composeQueued_ = false;
    const QSize size = viewport_->pixelSize().expandedTo(QSize(64, 48));
    composer_->request(model_->frames(), state_, size);
}

const QImage& MainWindow::composedFrame() {
    requestCompose(true);
    composed_ = composer_->wait();
    return composed_;
}

void MainWindow::setLayoutMode(Layout layout) {
    state_.layout = layout;
    if (QAction* a = layoutActions_[int(layout)]; a && !a->isChecked()) a->setChecked(true);  // the toolbar follows
    recompose();
}

void MainWindow::selectView(int view) {
    if (view < 0 || view >= int(model_->frames().size())) return;
    viewList_->setCurrentRow(view);
}

void MainWindow::onKey(int key, Qt::KeyboardModifiers modifiers, bool pressed) {
    if (key == Qt::Key_Shift) {
        state_.showReference = pressed;
        recompose();
        return;
    }
    if (!pressed) return;
    static const int shifted[] = {Qt::Key_Exclam,    Qt::Key_At,        Qt::Key_NumberSign,
                                  Qt::Key_Dollar,    Qt::Key_Percent,   Qt::Key_AsciiCircum,
                                  Qt::Key_Ampersand, Qt::Key_Asterisk,  Qt::Key_ParenLeft};
    int chosen = -1;
    if ((modifiers & Qt::ShiftModifier) && key >= Qt::Key_1 && key <= Qt::Key_9) chosen = key - Qt::Key_1;
    for (int i = 0; i < 9; ++i)
        if (key == shifted[i]) chosen = i;
    if (chosen >= 0) {
        chooseReferenceView(chosen == model_->referenceView() ? -1 : chosen);  // the same again: back to the reference
        return;
    }
    if (key >= Qt::Key_1 && key <= Qt::Key_9) {
        selectView(key - Qt::Key_1);
        if (state_.layout == Layout::Grid) setLayoutMode(Layout::Single);
        recompose();
    } else if (key == Qt::Key_T) {
        state_.swapped = !state_.swapped;
        recompose();
    } else if (key == Qt::Key_E) {
        state_.exposureOffset += (modifiers & Qt::ShiftModifier) ? -0.5 : 0.5;
        recompose();
    } else if (key == Qt::Key_G) {
        setLayoutMode(Layout::Grid);
    } else if (key == Qt::Key_S) {
        setLayoutMode(Layout::Single);
    } else if (key == Qt::Key_W) {
        setLayoutMode(Layout::Split);
    } else if (key == Qt::Key_D) {
        state_.diff = DiffMode((int(state_.diff) + 1) % 4);
        recompose();
    } else if (key == Qt::Key_M) {
        setTonemap(Tonemap((int(state_.tonemap) + 1) % int(tonemapNames().size())));
    } else if (key == Qt::Key_Z) {
        state_.zoom = 1.0;
        state_.centre = QPointF(0.5, 0.5);
        recompose();
    } else if (key == Qt::Key_F) {
        frameScene();
    } else if (key == Qt::Key_K) {
        takeSnapshot();
    } else if (key == Qt::Key_Escape) {
        setRegion(QRect());
    } else if (animation_->available() && key == Qt::Key_P) {
        animation_->togglePlay();
    } else if (animation_->available() && key == Qt::Key_Period) {
        stepAction_->trigger();
    } else if (animation_->available() && key == Qt::Key_R && (modifiers & Qt::ControlModifier)) {
        resetAction_->trigger();
    }
}

void MainWindow::setTonemap(Tonemap op) {
    state_.tonemap = op;
    if (tonemapCombo_->currentIndex() != int(op)) {
        const QSignalBlocker block(tonemapCombo_);
        tonemapCombo_->setCurrentIndex(int(op));
    }
    recompose();
}

void MainWindow::keyPressEvent(QKeyEvent* event) {
    onKey(event->key(), event->modifiers(), true);
}

void MainWindow::keyReleaseEvent(QKeyEvent* event) {
    onKey(event->key(), event->modifiers(), false);
}

void MainWindow::updateTitle() {
    const QString name = QString::fromStdString(session_.project().name);
    setWindowTitle((name.isEmpty() ? QString("Tyndall") : name) + " - " +
                   QFileInfo(session_.path()).fileName() + "[*] - Tyndall Studio");
    setWindowModified(session_.modified());
}

void MainWindow::updateAnimationActions() {
    const bool available = animation_->available();
    for (QAction* a : {playAction_, stepAction_, resetAction_})
        if (a && a->isEnabled() != available) a->setEnabled(available);
    if (animationBar_ && animationBar_->isVisibleTo(this) != available) animationBar_->setVisible(available);
}

bool MainWindow::particlePointAt(QPointF position, int& medium, Vec3& point) const {
    int view;
    QPoint pixel;
    if (!viewAt(position, view, pixel) || model_->isImage(view)) return false;
    const Project& project = session_.project();
    std::vector<std::string> own;
    try {
        own = resolvePart(techniqueCatalogue(), project, project.views[std::size_t(view)]).media;
    } catch (const std::exception&) {
    }
    const std::vector<ParticleMedium>& media = project.scene.particleMedia;
    auto renders = [&](const ParticleMedium& m) { return std::find(own.begin(), own.end(), m.name) != own.end(); };
    const bool any = std::any_of(media.begin(), media.end(), renders);
    const Camera& cam = project.scene.camera;
    double nearest = std::numeric_limits<double>::infinity();
    bool nearestHit = false;
    medium = -1;
    for (std::size_t i = 0; i < media.size(); ++i) {
        if (any && !renders(media[i])) continue;
        bool hit = false;
        const std::optional<Vec3> p =
            impulsePoint(cam, media[i].allParticles(), pixel.x() + 0.5, pixel.y() + 0.5, &hit);
        if (!p) continue;
        const double distance = glm::length(*p - cam.position);
        // A medium the ray meets beats one it misses; then the nearest.
        if (medium >= 0 && (nearestHit && !hit)) continue;
        if (medium >= 0 && hit == nearestHit && distance >= nearest) continue;
        medium = int(i);
        point = *p;
        nearest = distance;
        nearestHit = hit;
    }
    return medium >= 0;
}

bool MainWindow::addImpulseAt(QPointF position, QString* error) {
    int medium;
    Vec3 point;
    if (!particlePointAt(position, medium, point)) {
        if (error) *error = "No particle medium under the cursor";
        return false;
    }
    return animation_->addImpulse(medium, point, error);
}

bool MainWindow::viewAt(QPointF position, int& view, QPoint& pixel) const {
    const std::vector<QRect> rects = viewRects(model_->frames(), state_, viewport_->pixelSize().expandedTo(QSize(64, 48)));
    for (std::size_t i = 0; i < rects.size(); ++i) {
        const QRect& r = rects[i];
        if (r.isEmpty() || !r.contains(position.toPoint())) continue;
        const std::shared_ptr<const Image>& img = model_->frames()[i].image ? model_->frames()[i].image : model_->frames()[i].reference;
        if (!img) return false;
        view = int(i);
        const QRectF visible = visiblePart(QSize(img->width(), img->height()), state_);
        pixel = QPoint(std::clamp(int(visible.x() + (position.x() - r.x()) / r.width() * visible.width()), 0,
                                  img->width() - 1),
                       std::clamp(int(visible.y() + (position.y() - r.y()) / r.height() * visible.height()), 0,
                                  img->height() - 1));
        return true;
    }
    return false;
}

QString MainWindow::inspectorText() const {
    return inspector_->text();
}

void MainWindow::inspect(QPointF position) {
    int view;
    QPoint pixel;
    if (!viewAt(position, view, pixel)) return;
    auto rgb = [&](const std::shared_ptr<const Image>& img) {
        if (!img || pixel.x() >= img->width() || pixel.y() >= img->height()) return QString("-");
        return QString("%1, %2, %3")
            .arg(img->at(pixel.x(), pixel.y(), 0), 0, 'g', 4)
            .arg(img->at(pixel.x(), pixel.y(), 1), 0, 'g', 4)
            .arg(img->at(pixel.x(), pixel.y(), 2), 0, 'g', 4);
    };
    QString html = QString("<b>pixel %1, %2</b><table cellspacing=3>").arg(pixel.x()).arg(pixel.y());
    for (const ViewFrame& f : model_->frames())
        html += "<tr><td>" + f.name.toHtmlEscaped() + "</td><td>" + rgb(f.image) + "</td><td>ref " + rgb(f.reference) +
                "</td></tr>";
    inspector_->setText(html + "</table>");

    // The PDF plot, for a technique that samples distances. Making the job and probing (for WVDS a scene preparation
    // with a BVH build) run in the background pool, never on the GUI thread; only the latest hover's answer is shown.
    const std::uint64_t generation = ++probeGeneration_;
    if (model_->isImage(view)) {
        pdf_->showMessage(model_->frames()[std::size_t(view)].name + " is an image from a file: no probe");
        return;
    }
    background_->run([this, generation, project = session_.project(), path = session_.path().toStdString(),
                      viewName = session_.project().views[std::size_t(view)].name,
                      technique = model_->frames()[std::size_t(view)].technique, pixel] {
        std::optional<ProbeResult> result;
        QString message;
        try {
            RenderJob job = makeViewJob(project, path, viewName);
            bool hasProbe = false;
            for (const ProbeInfo& p : job.technique->probes())
                hasProbe |= p.name == "distances";
            if (hasProbe)
                result = job.technique->probe(job.request, "distances", pixel.x(), pixel.y());
            else
                message = technique + " has no distance probe";
        } catch (const std::exception& e) {
            message = QString::fromStdString(e.what());
        }
        QMetaObject::invokeMethod(
            this,
            [this, generation, result = std::move(result), message] {
                if (generation != probeGeneration_) return;  // a later hover, or another project, replaced it
                if (result)
                    pdf_->showProbe(*result);
                else
                    pdf_->showMessage(message);
            },
            Qt::QueuedConnection);
    });
}

void MainWindow::refreshRecentMenu() {
    if (!recentMenu_) return;
    recentMenu_->clear();
    for (const QString& path : recentProjects())
        recentMenu_->addAction(path, this, [this, path] {
            if (confirmDiscard()) openProject(path);
        });
    recentMenu_->setEnabled(!recentMenu_->isEmpty());
}

void MainWindow::refreshSnapshotList() {
    snapshotList_->clear();
    for (const Snapshot& s : snapshots_->snapshots()) {
        QString params = QString::fromStdString(s.parameters.dump());
        if (params.size() > 60) params = params.left(57) + "...";
        snapshotList_->addItem(s.name + (s.view < 0 ? "  (its view is gone)  " : "  ") + params);
    }
}

}  // namespace tyndall::studio
