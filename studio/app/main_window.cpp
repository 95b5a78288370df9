#include "main_window.h"
#include "trace.h"

#include "tyndall/geometry.h"
#include "tyndall/image_io.h"
#include "tyndall/phase_eval.h"
#include "tyndall/render.h"

#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCloseEvent>
#include <QShowEvent>
#include <QComboBox>
#include <QCryptographicHash>
#include <QDateTime>
#include <QDesktopServices>
#include <QDialog>
#include <QInputDialog>
#include <QLineEdit>
#include <QMenu>
#include <QScrollArea>
#include <QUrl>
#include <QThreadPool>

#include <QSettings>
#include <QSignalBlocker>
#include <QStandardPaths>
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
#include <QPointer>
#include <QProgressDialog>
#include <QSaveFile>
#include <QStatusBar>
#include <QTableWidget>
#include <QToolBar>
#include <QVulkanInstance>

#include <nlohmann/json.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>

namespace tyndall::studio {

namespace {

// References restart this long after the last edit of their part.
constexpr int kDebounceMs = 300;
constexpr qint64 kEditQuietMs = 150;

// What a view's render depends on in the scene: the camera, the surfaces and its part's lights and media, as JSON.
std::string partKeyOf(const Project& project, const View& view) {
    nlohmann::json j = projectToJson(project);
    ScenePart part;
    try {
        part = resolvePart(project, view);
    } catch (const std::exception&) {
        return j.dump();
    }
    nlohmann::json key = {{"camera", j["camera"]}, {"meshes", j.value("meshes", nlohmann::json())},
                          {"materials", j.value("materials", nlohmann::json())}, {"reference", j["reference"]}};
    for (const char* group : {"lights", "media", "particleMedia"}) {
        if (!j.contains(group)) continue;
        const std::vector<std::string>& names = std::string(group) == "lights" ? part.lights : part.media;
        for (const auto& e : j[group])
            if (std::find(names.begin(), names.end(), e.value("name", "")) != names.end()) key[group].push_back(e);
    }
    return key.dump();
}

// The state of a view's part of the scene, from its part key: images of one state are comparable.
quint64 stateOfKey(const std::string& partKey) {
    const QByteArray hash = QCryptographicHash::hash(QByteArray::fromStdString(partKey), QCryptographicHash::Sha1);
    quint64 state = 0;
    for (int i = 0; i < 8; ++i)
        state = (state << 8) | quint8(hash[i]);
    return state == 0 ? 1 : state;  // 0 means "no image"
}

QString stateName(quint64 state) {
    return QString("%1").arg(state, 16, 16, QLatin1Char('0'));
}

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
    renderer_ = new RenderService(this);
    animation_ = new Animation(session_, this);
    composer_ = new Composer(this);
    // Not the global pool: Qt's raster engine splits large fills over the global pool and waits for them, so a
    // widget's paint would wait behind a 100 ms metrics job.
    background_ = new QThreadPool(this);
    background_->setMaxThreadCount(2);
    autosaves_ = new QThreadPool(this);
    autosaves_->setMaxThreadCount(1);
    autosaves_->setExpiryTimeout(-1);
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
    auto viewEdit = [this](const QString& text, const QString& tip, bool (Session::*edit)(int, QString*)) {
        auto* button = new QPushButton(text);
        button->setToolTip(tip);
        connect(button, &QPushButton::clicked, this, [this, text, edit] {
            QString error;
            if (!(session_.*edit)(state_.current, &error) && !error.isEmpty())
                QMessageBox::warning(this, "Cannot " + text.toLower() + " the view", error);
        });
        return button;
    };
    QPushButton* duplicateView =
        viewEdit("Duplicate", "Duplicate the selected view, with its parameters", &Session::duplicateView);
    auto* renameView = new QPushButton("Rename");
    renameView->setToolTip("Rename the selected view (also: double-click it)");
    auto rename = [this] {
        if (state_.current < 0 || state_.current >= int(frames_.size())) return;
        bool ok = false;
        const QString name = QInputDialog::getText(this, "Rename the view", "Name:", QLineEdit::Normal,
                                                   frames_[std::size_t(state_.current)].name, &ok);
        QString error;
        if (ok && !session_.renameView(state_.current, name.toStdString(), &error) && !error.isEmpty())
            QMessageBox::warning(this, "Cannot rename the view", error);
    };
    connect(renameView, &QPushButton::clicked, this, rename);
    connect(viewList_, &QListWidget::itemDoubleClicked, this, rename);
    QPushButton* removeView = viewEdit("Remove", "Remove the selected view (undoable)", &Session::removeView);
    for (QPushButton* b : {addView, duplicateView, renameView, removeView}) viewButtons->addWidget(b);
    viewsLayout->addLayout(viewButtons);
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
    inspector_->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Preferred);
    inspectorDock->setWidget(inspector_);
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
    animation_->setViewsReady([this] { return viewsCaughtUp(); });
    connect(animation_, &Animation::advancing, this, [this](bool during) { animating_ = during; });
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
        parameters_->showView(row);
        updatePhasePlots();
        recompose();
    });
    connect(&session_, &Session::projectReplaced, this, [this] {
        rebuildViews();
        renderAll();
        updateTitle();
    });
    connect(&session_, &Session::viewChanged, this, [this](int view) {
        trace("edit of view %d", view);
        noteEdit();
        const View& v = session_.project().views[std::size_t(view)];
        // The metrics of the image shown depend on the exposure (PSNR), not on the parameters: a parameter edit
        // leaves them to its own image, instead of recomputing the old one's while the new one renders.
        const bool exposureChanged = frames_[std::size_t(view)].exposure != v.exposure;
        frames_[std::size_t(view)].exposure = v.exposure;
        viewKeys_[std::size_t(view)] = v.parameters.dump() + "/" + std::to_string(v.exposure);
        if (exposureChanged) updateMetrics(view);
        dirtyViews_.insert(view);
        flushDirty();
        recompose();
    });
    connect(&session_, &Session::modifiedChanged, this, [this](bool) { updateTitle(); });
    connect(&session_, &Session::sceneChanged, this, [this] {
        noteEdit();
        // Views added, removed, renamed or given another technique (or an undo of that): the views start again,
        // the current one kept by name (a new view is selected).
        if (viewsKey() != viewsKey_) {
            const Project& project = session_.project();
            const QString current = state_.current < int(frames_.size()) ? frames_[std::size_t(state_.current)].name
                                                                         : QString();
            std::set<std::string> before;
            for (const ViewFrame& f : frames_) before.insert(f.name.toStdString());
            rebuildViews();
            renderAll();
            int select = -1;
            for (int i = 0; i < int(project.views.size()); ++i) {
                if (!before.count(project.views[std::size_t(i)].name)) select = i;  // new
                if (select < 0 && QString::fromStdString(project.views[std::size_t(i)].name) == current) select = i;
            }
            selectView(std::max(select, 0));
            updateTitle();
            return;
        }
        // Only views whose part of the scene changed render again, with their references; views whose parameters
        // changed (a whole project replaced: recovery, or its undo) render again alone.
        for (int i = 0; i < int(frames_.size()); ++i) {
            const View& view = session_.project().views[std::size_t(i)];
            const std::string key = partKeyOf(session_.project(), view);
            const std::string viewKey = view.parameters.dump() + "/" + std::to_string(view.exposure);
            if (viewKey != viewKeys_[std::size_t(i)]) {
                viewKeys_[std::size_t(i)] = viewKey;
                frames_[std::size_t(i)].exposure = view.exposure;
                dirtyViews_.insert(i);
            }
            if (key == partKeys_[std::size_t(i)]) continue;
            partKeys_[std::size_t(i)] = key;
            frames_[std::size_t(i)].state = stateOfKey(key);
            dirtyViews_.insert(i);
            dirtyParts_.insert(i);
        }
        flushDirty();
        if (!dirtyParts_.empty()) debounce_.start();
        updatePhasePlots();
        recompose();
    });
    connect(renderer_, &RenderService::output, this, &MainWindow::onOutput);
    connect(composer_, &Composer::composed, this, [this](const QImage& frame) {
        composed_ = frame;
        viewport_->setFrame(frame);
    });

    debounce_.setSingleShot(true);
    debounce_.setInterval(kDebounceMs);
    // References restart once the edits of their part pause (a drag would otherwise restart them at every step).
    connect(&debounce_, &QTimer::timeout, this, [this] {
        for (int view : dirtyParts_)
            renderView(view, true);
        dirtyParts_.clear();
    });

    connect(viewport_, &Viewport::resized, this, [this](QSize) { recompose(); });
    connect(viewport_, &Viewport::keyPressed, this,
            [this](int key, Qt::KeyboardModifiers m) { onKey(key, m, true); });
    connect(viewport_, &Viewport::keyReleased, this,
            [this](int key, Qt::KeyboardModifiers m) { onKey(key, m, false); });
    auto dragDivider = [this](QPointF position, Qt::MouseButtons buttons) {
        if (state_.layout != Layout::Split || !(buttons & Qt::LeftButton) || frames_.empty()) return;
        const std::vector<QRect> rects = viewRects(frames_, state_, viewport_->pixelSize());
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
                const std::vector<QRect> rects = viewRects(frames_, state_, viewport_->pixelSize());
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
        if ((buttons & Qt::MiddleButton) && !frames_.empty()) {  // pan every view together
            const std::vector<QRect> rects = viewRects(frames_, state_, viewport_->pixelSize());
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
    autosave_.setInterval(20000);
    connect(&autosave_, &QTimer::timeout, this, [this] { autosaveNow(); });
    autosave_.start();
    // Changes discarded on purpose stay unsaved until the next project or edit.
    connect(session_.undoStack(), &QUndoStack::indexChanged, this, [this] { discarded_ = false; });
    connect(&session_, &Session::projectReplaced, this, [this] { discarded_ = false; });
    connect(&session_, &Session::modifiedChanged, this, [this](bool modified) {
        // Saved, or undone back to the file: nothing to recover. (Opening a project is neither.)
        if (!modified && !opening_) removeAutosave();
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
    renderer_->cancelAll();
    background_->waitForDone();  // metrics in flight post back to this window
    autosaves_->waitForDone();   // and a failed autosave would say so
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
        if (!session_.save(&error)) QMessageBox::critical(this, "Cannot save", error);
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
            [this, i] { chooseReferenceView(i == referenceView_ ? -1 : i); });

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
    renderer_->cancelAll();
    opening_ = true;
    const bool opened = session_.open(path, &error, overrides_);
    opening_ = false;
    if (!opened) {
        if (dialog) QMessageBox::critical(this, "Cannot open the project", error);
        statusBar()->showMessage("Not opened: " + error, 10000);
        // The current project stays; its renders start again where they were cancelled.
        if (!session_.project().views.empty()) renderAll();
        return false;
    }
    addRecent(path);
    // An autosave newer than the file: the studio stopped with unsaved changes. (This window's own writes and
    // removals of it come first.)
    waitForAutosaves();
    const QFileInfo autosave(autosavePath(path)), file(path);
    if (autosave.exists() && autosave.lastModified() >= file.lastModified() && recovery_ != Recovery::Never) {
        bool recover = recovery_ == Recovery::Always;
        if (recovery_ == Recovery::Ask)
            recover = QMessageBox::question(this, "Recover unsaved changes",
                                            "Tyndall Studio stopped with unsaved changes to " + file.fileName() +
                                                " (autosaved " + autosave.lastModified().toString() +
                                                "). Recover them?") == QMessageBox::Yes;
        if (recover) {
            QFile in(autosave.filePath());
            try {
                if (!in.open(QIODevice::ReadOnly)) throw std::runtime_error("cannot read the autosave");
                const nlohmann::json j = nlohmann::json::parse(in.readAll().toStdString());
                // One undoable edit on top of the file's version: the title shows it unsaved, undo goes back.
                session_.editProjectJson(j, "recover unsaved changes");
                statusBar()->showMessage("Recovered the unsaved changes of " + file.fileName(), 10000);
            } catch (const std::exception& e) {
                QMessageBox::warning(this, "Cannot recover", QString::fromStdString(e.what()));
            }
        } else {
            QFile::remove(autosave.filePath());
        }
    }
    return true;
}

QString MainWindow::autosavePath(const QString& projectPath) {
    const QString dir = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave";
    QDir().mkpath(dir);
    const QByteArray hash =
        QCryptographicHash::hash(QFileInfo(projectPath).absoluteFilePath().toUtf8(), QCryptographicHash::Sha1).toHex();
    return dir + "/" + QFileInfo(projectPath).completeBaseName() + "-" + QString::fromLatin1(hash.left(12)) + ".json";
}

bool MainWindow::autosaveNow() {
    if (!session_.modified() || session_.path().isEmpty() || discarded_) return false;
    const QString path = autosavePath(session_.path());
    auto text = std::make_shared<const std::string>(projectToJson(session_.project()).dump(2) + "\n");
    QPointer<MainWindow> window(this);
    autosaves_->start([path, text, window] {
        QSaveFile file(path);
        if (file.open(QIODevice::WriteOnly) && file.write(text->data(), qint64(text->size())) >= 0 && file.commit())
            return;
        const QString message = "Autosave failed: cannot write " + path + " (" + file.errorString() + ")";
        QMetaObject::invokeMethod(
            qApp,
            [window, message] {
                if (window) window->statusBar()->showMessage(message, 10000);
            },
            Qt::QueuedConnection);
    });
    return true;
}

void MainWindow::waitForAutosaves() { autosaves_->waitForDone(); }

void MainWindow::removeAutosave() {
    if (session_.path().isEmpty()) return;
    autosaves_->start([path = autosavePath(session_.path())] { QFile::remove(path); });
}

QStringList MainWindow::recentProjects() const {
    return QSettings().value("recentProjects").toStringList();
}

void MainWindow::addRecent(const QString& path) {
    QStringList recent = recentProjects();
    const QString absolute = QFileInfo(path).absoluteFilePath();
    recent.removeAll(absolute);
    recent.prepend(absolute);
    while (recent.size() > 8)
        recent.removeLast();
    QSettings().setValue("recentProjects", recent);
    refreshRecentMenu();
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

std::string MainWindow::viewsKey() const {
    std::string key;
    for (const View& v : session_.project().views) key += v.name + "\n" + v.technique + "\n";
    return key;
}

void MainWindow::rebuildViews() {
    const Project& project = session_.project();
    viewsKey_ = viewsKey();
    frames_.assign(project.views.size(), ViewFrame{});
    generation_.assign(project.views.size(), 0);
    referenceGeneration_.assign(project.views.size(), 0);
    pending_.assign(project.views.size(), false);
    latestMetrics_.assign(project.views.size(), 0);
    referencePending_.assign(project.views.size(), false);
    progressive_.assign(project.views.size(), false);
    partKeys_.clear();
    viewKeys_.clear();
    for (const View& v : project.views) {
        partKeys_.push_back(partKeyOf(project, v));
        viewKeys_.push_back(v.parameters.dump() + "/" + std::to_string(v.exposure));
    }
    progress_.assign(project.views.size(), {});
    snapshots_.clear();
    comparedSnapshot_ = -1;
    referenceView_ = -1;
    state_.region = QRect();
    refreshSnapshotList();
    // Nothing of the previous project stays on screen: the inspector, the pdf plot, the snapshot comparison.
    inspector_->setText("Move the cursor over a view");
    pdf_->showMessage("Move the cursor over a view whose technique samples distances (WVDS).");
    {
        const QSignalBlocker block(compareButton_);
        compareButton_->setChecked(false);
    }
    viewList_->clear();
    for (std::size_t i = 0; i < project.views.size(); ++i) {
        const View& v = project.views[i];
        frames_[i].name = QString::fromStdString(v.name);
        frames_[i].technique = displayNameOf(v.technique);
        frames_[i].exposure = v.exposure;
        frames_[i].state = stateOfKey(partKeys_[i]);
        viewList_->addItem(QString("%1  %2  (%3)").arg(i + 1).arg(frames_[i].name, frames_[i].technique));
    }
    state_.current = 0;
    if (!frames_.empty()) viewList_->setCurrentRow(0);
    parameters_->showView(frames_.empty() ? -1 : 0);
    plotConvergence();
    updateMetricsDock();
    updatePhasePlots();
}

void MainWindow::renderView(int view, bool reference) {
    const Project& project = session_.project();
    const std::string& name = project.views[std::size_t(view)].name;
    RenderTask task;
    task.view = view;
    task.reference = reference;
    task.generation = nextGeneration_++;
    task.state = frames_[std::size_t(view)].state;
    try {
        task.job = std::make_shared<RenderJob>(reference ? makeReferenceJob(project, session_.path().toStdString(), name)
                                                         : makeViewJob(project, session_.path().toStdString(), name));
        // Every image carries the state of its part (exports pair a view with its reference by it).
        task.job->metadata["partHash"] = stateName(task.state).toStdString();
    } catch (const std::exception& e) {
        frames_[std::size_t(view)].error = QString::fromStdString(e.what());
        recompose();
        return;
    }
    (reference ? referenceGeneration_ : generation_)[std::size_t(view)] = task.generation;
    if (!reference) {
        pending_[std::size_t(view)] = true;
        frames_[std::size_t(view)].rendering = true;
        trace("view %d: job made", view);
        renderer_->submit(std::move(task));
        return;
    }
    referencePending_[std::size_t(view)] = true;
    frames_[std::size_t(view)].referenceRendering = true;
    frames_[std::size_t(view)].referenceEta = -1.0;
    frames_[std::size_t(view)].referenceTargetSpp = task.job->request.spp;
    updateStatus();
    // A finished reference of exactly this part of the scene may be on disk already.
    const QString cached = referenceCachePath(view);
    cachePathOf_[task.generation] = cached;
    if (QFile::exists(cached)) {
        // Read in the background (an EXR of 512 x 512 takes ~10 ms, more while renders run); an unreadable file is
        // removed and the reference rendered after all.
        renderer_->cancelReference(view);
        inBackground([this, task, cached] {
            RenderOutput out;
            out.view = task.view;
            out.reference = true;
            out.generation = task.generation;
            out.state = task.state;
            try {
                auto image = std::make_shared<Image>(readImage(cached.toStdString()));
                out.spp = image->metadata.count("spp") ? std::atoi(image->metadata.at("spp").c_str()) : 0;
                out.image = std::move(image);
                out.final = true;
                out.cached = true;
            } catch (const std::exception&) {
                QFile::remove(cached);
                QMetaObject::invokeMethod(this, [this, task] {
                    if (std::size_t(task.view) < referenceGeneration_.size() &&
                        task.generation == referenceGeneration_[std::size_t(task.view)])
                        renderer_->submit(task);
                }, Qt::QueuedConnection);
                return;
            }
            QMetaObject::invokeMethod(this, [this, out] { onOutput(out); }, Qt::QueuedConnection);
        });
        return;
    }
    renderer_->submit(std::move(task));
}

QString MainWindow::referenceCacheFolder() {
    return QStandardPaths::writableLocation(QStandardPaths::CacheLocation) + "/references";
}

QString MainWindow::referenceCachePath(int view) const {
    // Everything the reference's image depends on: its part of the scene, the reference settings (in the part key),
    // where relative files resolve, and the renderer's version.
    const std::string key = partKeyOf(session_.project(), session_.project().views[std::size_t(view)]) + "|" +
                            QFileInfo(session_.path()).absolutePath().toStdString() + "|" + tyndallVersion();
    const QByteArray hash = QCryptographicHash::hash(QByteArray::fromStdString(key), QCryptographicHash::Sha1).toHex();
    return referenceCacheFolder() + "/" + QString::fromLatin1(hash) + ".exr";
}

void MainWindow::flushDirty() {
    // While the animation plays, a progressive view (the path tracer as a view, whose render may take minutes) is not
    // waited for: play advances only once it has shown an image of its state, and then its render in flight is
    // replaced at once. It is submitted before the others, so that the worker (newest first) renders the fast ones
    // first.
    if (animating_) {
        for (auto it = dirtyViews_.begin(); it != dirtyViews_.end();) {
            if (!progressive_[std::size_t(*it)]) {
                ++it;
                continue;
            }
            const int view = *it;
            it = dirtyViews_.erase(it);
            renderView(view, false);
        }
    }
    // An edited view renders at once when it is not rendering; otherwise when its render in flight is done, so that
    // a drag shows a new image at the rate the technique renders and the last state always renders.
    for (auto it = dirtyViews_.begin(); it != dirtyViews_.end();) {
        if (pending_[std::size_t(*it)]) {
            ++it;
            continue;
        }
        const int view = *it;
        it = dirtyViews_.erase(it);
        renderView(view, false);
    }
}

void MainWindow::renderAll() {
    for (int i = 0; i < int(frames_.size()); ++i)
        renderView(i, false);
    for (int i = 0; i < int(frames_.size()); ++i)
        renderView(i, true);
    recompose();
}

bool MainWindow::settled() const {
    for (bool p : pending_)
        if (p) return false;
    for (bool p : referencePending_)
        if (p) return false;
    return renderer_->idle() && exportsRunning_ == 0 && dirtyViews_.empty() && dirtyParts_.empty() && !debounce_.isActive() &&
           metricsPending_ == 0 && convergencePending_ == 0;
}

void MainWindow::onOutput(const RenderOutput& out) {
    trace("%s %d: image received (%d spp)", out.reference ? "reference" : "view", out.view, out.spp);
    if (out.view < 0 || out.view >= int(frames_.size())) return;
    const std::vector<quint64>& generations = out.reference ? referenceGeneration_ : generation_;
    if (out.generation != generations[std::size_t(out.view)]) return;  // stale: a newer render is on its way
    if (!out.reference && !out.final && out.image) progressive_[std::size_t(out.view)] = true;
    ViewFrame& f = frames_[std::size_t(out.view)];
    if (!out.error.isEmpty()) {
        f.error = out.error;
        statusBar()->showMessage(f.name + ": " + out.error, 10000);
    } else if (out.reference) {
        f.reference = out.image;
        f.referenceState = out.state;
        f.referenceSpp = out.spp;
        f.referenceCached = out.cached;
        if (out.targetSpp > 0) f.referenceTargetSpp = out.targetSpp;
        // Estimated from this render's own pace (an interrupted reference starts again from zero).
        f.referenceEta = out.final || out.spp <= 0 || f.referenceTargetSpp <= out.spp
                             ? -1.0
                             : out.seconds / out.spp * (f.referenceTargetSpp - out.spp);
        // A finished reference goes to the disk cache (atomically), so that reopening the project starts from it.
        const auto path = cachePathOf_.find(out.generation);
        if (out.final && !out.cached && path != cachePathOf_.end() && out.image) {
            // Written in the thread pool (an EXR of 512 x 512 takes ~0.2 s), atomically, so a reader never sees half.
            QDir().mkpath(referenceCacheFolder());
            const std::shared_ptr<const Image> image = out.image;
            const std::string file = path->second.toStdString();
            inBackground([image, file] {
                try {
                    writeImage(*image, file);
                } catch (const std::exception&) {
                }
            });
        }
        if (out.final) cachePathOf_.erase(out.generation);
    } else {
        f.image = out.image;
        f.imageState = out.state;
        f.spp = out.spp;
        f.seconds = out.seconds;
        f.error.clear();
    }
    if (!out.reference && out.final) {
        pending_[std::size_t(out.view)] = false;
        f.rendering = false;
        if (dirtyViews_.count(out.view)) QTimer::singleShot(0, this, [this] { flushDirty(); });
    }
    if (out.reference && out.final) {
        referencePending_[std::size_t(out.view)] = false;
        f.referenceRendering = false;
    }
    if (f.image && f.reference && f.imageState == f.referenceState) {
        f.pairImage = f.image;  // the newest pair of one state: what comparisons use while the other catches up
        f.pairReference = f.reference;
    }
    if (!out.reference && out.image) {
        Progress point{out.spp, out.seconds, out.image};
        point.state = out.state;
        addConvergencePoint(progress_[std::size_t(out.view)], std::move(point));
    }
    if (!out.reference && out.view == referenceView_) refreshAlternates();
    updateMetrics(out.view);
    updateConvergence();
    updateMetricsDock();
    recompose();
    if (!out.reference) requestCompose(true);  // a new image is shown at once, even right after an edit
}

int MainWindow::convergenceBucket(int spp) {
    return spp > 0 ? int(std::floor(4.0 * std::log2(double(spp)))) : -1;
}

void MainWindow::updateMetrics(int view) {
    // Off the GUI thread (a 512 x 512 comparison takes ~100 ms with the renders on both cores); the result is kept only
    // if the view still shows the same two images.
    ViewFrame& f = frames_[std::size_t(view)];
    f.metrics.reset();
    f.regionMetrics.reset();
    const ComparisonPair pair = comparisonPair(f);
    f.metricsStale = pair.stale;
    const std::shared_ptr<const Image> image = pair.image, against = pair.against;
    if (!image || !against || image->width() != against->width() || image->height() != against->height()) return;
    const double exposure = f.exposure;
    const QRect region = state_.region.intersected(QRect(0, 0, image->width(), image->height()));
    ++metricsPending_;
    const quint64 request = ++metricsRequests_;
    latestMetrics_[std::size_t(view)] = request;
    inBackground([this, view, image, against, exposure, region, request] {
        std::optional<Metrics> whole, part;
        try {
            whole = computeMetrics(*image, *against, exposure);
            if (!region.isEmpty())
                part = computeMetrics(*image, *against, exposure, {region.x(), region.y(), region.width(), region.height()});
        } catch (const std::exception&) {
        }
        QMetaObject::invokeMethod(this, [this, view, image, against, whole, part, request] {
            --metricsPending_;
            if (view >= int(frames_.size())) return;
            // Stale: a later request for this view (a new image, reference, exposure or region) may finish first, in
            // the pool's order, and must not be overwritten by this one.
            if (latestMetrics_[std::size_t(view)] != request) return;
            ViewFrame& f = frames_[std::size_t(view)];
            const ComparisonPair now = comparisonPair(f);
            if (now.image != image || now.against != against) return;
            f.metrics = whole;
            f.regionMetrics = part;
            updateMetricsDock();
            recompose();
        }, Qt::QueuedConnection);
    });
}

void MainWindow::updateConvergence() {
    // The relMSE of each progressive image against its view's reference, without tonemapping. A new reference makes
    // every image of its view stale, and each costs ~4 ms at 512 x 512, so they are computed in the background pool
    // (the GUI thread computed them before: 5 ms per image in a slider drag, more as a reference refined).
    struct Item {
        std::size_t view, index;
        std::shared_ptr<const Image> image, reference;
        bool alternate = false;
        double relMSE = 0.0;
    };
    std::vector<Item> items;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
        // Against the view chosen as every view's reference (Shift+1-9), else the reference of the image's state.
        const bool alternate = bool(frames_[i].alternate);
        const std::shared_ptr<const Image>& reference = alternate ? frames_[i].alternate : frames_[i].reference;
        if (!reference) continue;
        for (std::size_t k = 0; k < progress_[i].size(); ++k) {
            Progress& p = progress_[i][k];
            if (!alternate && p.state != frames_[i].referenceState) continue;  // only images of one state compare
            if (p.image->width() != reference->width() || p.image->height() != reference->height()) continue;
            if (p.against == reference || p.requested == reference) continue;
            p.requested = reference;
            items.push_back({i, k, p.image, reference, alternate});
        }
    }
    plotConvergence();
    if (items.empty()) return;
    ++convergencePending_;
    inBackground([this, items = std::move(items)]() mutable {
        for (Item& item : items) {
            const Image &a = *item.image, &r = *item.reference;
            double sum = 0.0;
            for (int y = 0; y < a.height(); ++y)
                for (int x = 0; x < a.width(); ++x)
                    for (int c = 0; c < 3; ++c) {
                        const double ref = r.at(x, y, c), d = a.at(x, y, c) - ref;
                        sum += d * d / (ref * ref + 0.01);  // relMSE, as in metrics.h
                    }
            item.relMSE = sum / (3.0 * a.width() * a.height());
        }
        QMetaObject::invokeMethod(this, [this, items = std::move(items)] {
            --convergencePending_;
            for (const Item& item : items) {
                // The view may have started a new render (its images cleared) since the job was made.
                if (item.view >= progress_.size() || item.index >= progress_[item.view].size()) continue;
                Progress& p = progress_[item.view][item.index];
                if (p.image != item.image) continue;
                p.relMSE = item.relMSE;
                p.against = item.reference;
                p.againstAlternate = item.alternate;
                if (p.requested == item.reference) p.requested.reset();
            }
            plotConvergence();
        }, Qt::QueuedConnection);
    });
}

void MainWindow::plotConvergence() {
    std::vector<QString> names;
    std::vector<std::vector<ConvergencePoint>> points;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
        names.push_back(frames_[i].name);
        points.emplace_back();
        const ViewFrame& f = frames_[i];
        for (const Progress& p : progress_[i]) {
            const bool valid = f.alternate ? p.againstAlternate && p.against == f.alternate
                                           : !p.againstAlternate && p.against && p.state == f.referenceState;
            if (p.relMSE >= 0.0 && valid) points.back().push_back({p.spp, p.seconds, p.relMSE});
        }
    }
    convergence_->setSeries(names, points);
}

void MainWindow::updateMetricsDock() {
    if (metrics_->rowCount() != int(frames_.size())) metrics_->setRowCount(int(frames_.size()));
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
    for (int row = 0; row < int(frames_.size()); ++row) {
        const ViewFrame& f = frames_[std::size_t(row)];
        QTableWidgetItem* header = metrics_->verticalHeaderItem(row);
        if (!header || header->text() != f.name) metrics_->setVerticalHeaderItem(row, new QTableWidgetItem(f.name));
        if (!f.metrics) {
            set(row, 0, "waiting");
            for (int c = 1; c < 5; ++c) set(row, c, "");
            continue;
        }
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
            own = resolvePart(project, project.views[std::size_t(state_.current)]).media;
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

void MainWindow::updateStatus() {
    if (!renderStatus_) return;
    QStringList references;
    int stale = 0;
    for (const ViewFrame& f : frames_) {
        if (f.referenceRendering) references << f.name + ": " + referenceProgress(f);
        stale += f.metricsStale;
    }
    QString text = references.isEmpty() ? QString("Ready") : references.join("; ");
    if (stale > 0)
        text += QString(" | %1 comparison%2 stale (the last matching pair) until %3 reference%2 %4")
                    .arg(stale)
                    .arg(stale > 1 ? "s" : "")
                    .arg(stale > 1 ? "their" : "its")
                    .arg(stale > 1 ? "arrive" : "arrives");
    if (renderStatus_->text() != text) renderStatus_->setText(text);
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

void MainWindow::noteEdit() { editClock_.start(); }

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
    composer_->request(frames_, state_, size);
}

void MainWindow::waitForBackgroundWork() { background_->waitForDone(); }

void MainWindow::inBackground(std::function<void()> work) {
    background_->start([work = std::move(work)] {
        // Below the GUI and no higher than the renders, which an edit is waiting for (at nice 5, the metrics of each
        // progressive image took the CPU from the next pass). The pool's threads keep the value.
        lowerCurrentThreadPriority(10);
        work();
    });
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
    if (view < 0 || view >= int(frames_.size())) return;
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
        chooseReferenceView(chosen == referenceView_ ? -1 : chosen);  // the same again: back to the reference
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

bool MainWindow::saveProjectAs(const QString& path, QString* error) {
    const QString before = session_.path();
    const bool modified = session_.modified();
    if (!session_.saveAs(path, error)) return false;
    // The changes are in the new file: the old file's autosave (and the new one's, if it was not modified) hold
    // nothing to recover.
    if (!before.isEmpty() && QFileInfo(before).absoluteFilePath() != QFileInfo(path).absoluteFilePath())
        autosaves_->start([old = autosavePath(before)] { QFile::remove(old); });
    if (!modified) removeAutosave();
    addRecent(path);
    updateTitle();
    return true;
}

bool MainWindow::confirmDiscard() {
    if (!session_.modified()) return true;
    const auto answer = QMessageBox::question(this, "Unsaved changes",
                                              "The project has unsaved changes. Save them first?",
                                              QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
    if (answer == QMessageBox::Cancel) return false;
    // Discarded on purpose: the autosave holds nothing to recover (reopening the file asked to, before).
    if (answer == QMessageBox::Discard) {
        removeAutosave();
        discarded_ = true;  // and no new autosave while a file dialog is open
    }
    if (answer == QMessageBox::Save) {
        QString error;
        if (!session_.save(&error)) {
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
    renderer_->cancelAll();
    removeAutosave();  // saved or discarded on purpose: nothing to recover
    saveLayout();
    event->accept();
}

void MainWindow::orbitCamera(double yaw, double pitch) {
    const Camera& cam = session_.project().scene.camera;
    const Vec3 up = glm::normalize(cam.up);
    Vec3 offset = cam.position - cam.target;
    const double distance = glm::length(offset);
    if (!(distance > 0.0)) return;
    // Yaw about the up hint, then pitch about the camera's right axis, kept away from the poles.
    offset = glm::dmat3(glm::rotate(glm::dmat4(1.0), yaw, up)) * offset;
    const Vec3 right = glm::normalize(glm::cross(-offset, up));
    const Vec3 pitched = glm::dmat3(glm::rotate(glm::dmat4(1.0), pitch, right)) * offset;
    if (std::abs(glm::dot(glm::normalize(pitched), up)) < 0.98) offset = pitched;
    const Vec3 p = cam.target + offset;
    QString error;
    if (!session_.editScene({"camera.position=[" + std::to_string(p.x) + "," + std::to_string(p.y) + "," +
                             std::to_string(p.z) + "]"},
                            "orbit", &error, 1))
        statusBar()->showMessage(error, 5000);
}

void MainWindow::dollyCamera(double factor) {
    const Camera& cam = session_.project().scene.camera;
    const Vec3 p = cam.target + (cam.position - cam.target) * factor;
    QString error;
    if (!session_.editScene({"camera.position=[" + std::to_string(p.x) + "," + std::to_string(p.y) + "," +
                             std::to_string(p.z) + "]"},
                            "dolly", &error, 2))
        statusBar()->showMessage(error, 5000);
}

void MainWindow::frameScene() {
    const Project& project = session_.project();
    Vec3 lo(1e300), hi(-1e300);
    const std::string dir = QFileInfo(session_.path()).path().toStdString();
    for (const Mesh& mesh : project.scene.meshes) {
        try {
            for (const glm::vec3& v : buildMesh(mesh, dir).positions) {
                lo = glm::min(lo, Vec3(v));
                hi = glm::max(hi, Vec3(v));
            }
        } catch (const std::exception&) {
        }
    }
    if (!(lo.x <= hi.x)) return;
    const Camera& cam = project.scene.camera;
    const Vec3 centre = 0.5 * (lo + hi);
    const double radius = 0.5 * glm::length(hi - lo);
    const Vec3 dirToCamera = glm::normalize(cam.position - cam.target);
    const double distance = radius / std::sin(glm::radians(cam.fovY) * 0.5);
    const Vec3 p = centre + dirToCamera * distance;
    auto vec = [](const Vec3& v) {
        return "[" + std::to_string(v.x) + "," + std::to_string(v.y) + "," + std::to_string(v.z) + "]";
    };
    QString error;
    if (!session_.editScene({"camera.position=" + vec(p), "camera.target=" + vec(centre)}, "frame the scene", &error))
        statusBar()->showMessage(error, 5000);
}

int MainWindow::takeSnapshot() {
    if (state_.current < 0 || state_.current >= int(frames_.size())) return -1;
    const ViewFrame& f = frames_[std::size_t(state_.current)];
    if (!f.image) return -1;
    const View& view = session_.project().views[std::size_t(state_.current)];
    Snapshot shot;
    shot.view = state_.current;
    shot.image = f.image;
    shot.parameters = view.parameters;
    shot.exposure = view.exposure;
    shot.name = QString("%1 #%2").arg(f.name).arg(snapshots_.size() + 1);
    snapshots_.push_back(shot);
    refreshSnapshotList();
    snapshotList_->setCurrentRow(int(snapshots_.size()) - 1);
    return int(snapshots_.size()) - 1;
}

void MainWindow::refreshSnapshotList() {
    snapshotList_->clear();
    for (const Snapshot& s : snapshots_) {
        QString params = QString::fromStdString(s.parameters.dump());
        if (params.size() > 60) params = params.left(57) + "...";
        snapshotList_->addItem(s.name + "  " + params);
    }
}

void MainWindow::compareWithSnapshot(int index) {
    for (ViewFrame& f : frames_) {
        f.snapshot.reset();
        f.snapshotName.clear();
    }
    comparedSnapshot_ = index >= 0 && index < int(snapshots_.size()) ? index : -1;
    if (comparedSnapshot_ >= 0) {
        const Snapshot& s = snapshots_[std::size_t(comparedSnapshot_)];
        frames_[std::size_t(s.view)].snapshot = s.image;
        frames_[std::size_t(s.view)].snapshotName = s.name;
    }
    for (int i = 0; i < int(frames_.size()); ++i)
        updateMetrics(i);
    updateMetricsDock();
    recompose();
}

void MainWindow::chooseReferenceView(int view) {
    referenceView_ = view >= 0 && view < int(frames_.size()) ? view : -1;
    refreshAlternates();
    statusBar()->showMessage(referenceView_ < 0 ? QString("Comparing against the reference")
                                                : "Comparing against view " + frames_[std::size_t(referenceView_)].name,
                             5000);
}

void MainWindow::refreshAlternates() {
    for (int i = 0; i < int(frames_.size()); ++i) {
        ViewFrame& f = frames_[std::size_t(i)];
        const bool use = referenceView_ >= 0 && i != referenceView_;
        const std::shared_ptr<const Image> alternate = use ? frames_[std::size_t(referenceView_)].image : nullptr;
        if (alternate == f.alternate) continue;
        f.alternate = alternate;
        f.alternateName = use ? frames_[std::size_t(referenceView_)].name : QString();
        updateMetrics(i);
    }
    updateConvergence();  // the plot follows the choice, too
    updateMetricsDock();
    recompose();
}

void MainWindow::restoreSnapshot(int index) {
    if (index < 0 || index >= int(snapshots_.size())) return;
    const Snapshot& s = snapshots_[std::size_t(index)];
    const nlohmann::json current = session_.project().views[std::size_t(s.view)].parameters;
    session_.undoStack()->beginMacro("restore " + s.name);
    for (const auto& [key, value] : current.items())
        if (!s.parameters.contains(key)) session_.setParameter(s.view, key, nlohmann::json());
    for (const auto& [key, value] : s.parameters.items())
        session_.setParameter(s.view, key, value);
    session_.setExposure(s.view, s.exposure);
    session_.undoStack()->endMacro();
}

void MainWindow::updateAnimationActions() {
    const bool available = animation_->available();
    for (QAction* a : {playAction_, stepAction_, resetAction_})
        if (a && a->isEnabled() != available) a->setEnabled(available);
    if (animationBar_ && animationBar_->isVisibleTo(this) != available) animationBar_->setVisible(available);
}

bool MainWindow::viewsCaughtUp() const {
    for (std::size_t i = 0; i < frames_.size(); ++i) {
        if (dirtyViews_.count(int(i))) return false;
        if (!pending_[i]) continue;
        // A progressive view has caught up once it shows a pass of the current state.
        if (progressive_[i] && frames_[i].image && frames_[i].imageState == frames_[i].state) continue;
        return false;
    }
    return true;
}

bool MainWindow::particlePointAt(QPointF position, int& medium, Vec3& point) const {
    int view;
    QPoint pixel;
    if (!viewAt(position, view, pixel)) return false;
    const Project& project = session_.project();
    std::vector<std::string> own;
    try {
        own = resolvePart(project, project.views[std::size_t(view)]).media;
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
    const std::vector<QRect> rects = viewRects(frames_, state_, viewport_->pixelSize().expandedTo(QSize(64, 48)));
    for (std::size_t i = 0; i < rects.size(); ++i) {
        const QRect& r = rects[i];
        if (r.isEmpty() || !r.contains(position.toPoint())) continue;
        const std::shared_ptr<const Image>& img = frames_[i].image ? frames_[i].image : frames_[i].reference;
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
    for (const ViewFrame& f : frames_)
        html += "<tr><td>" + f.name.toHtmlEscaped() + "</td><td>" + rgb(f.image) + "</td><td>ref " + rgb(f.reference) +
                "</td></tr>";
    inspector_->setText(html + "</table>");

    // The PDF plot, for a technique that samples distances.
    const Project& project = session_.project();
    try {
        RenderJob job = makeViewJob(project, session_.path().toStdString(), project.views[std::size_t(view)].name);
        bool hasProbe = false;
        for (const ProbeInfo& p : job.technique->probes())
            hasProbe |= p.name == "distances";
        if (!hasProbe) {
            pdf_->showMessage(frames_[std::size_t(view)].technique + " has no distance probe");
            return;
        }
        pdf_->showProbe(job.technique->probe(job.request, "distances", pixel.x(), pixel.y()));
    } catch (const std::exception& e) {
        pdf_->showMessage(QString::fromStdString(e.what()));
    }
}

void MainWindow::setRegion(QRect region) {
    state_.region = region;
    for (int i = 0; i < int(frames_.size()); ++i)
        updateMetrics(i);
    updateMetricsDock();
    recompose();
}

std::vector<std::function<void()>> MainWindow::exportSteps(const QString& folder) {
    QDir dir(folder);
    if (!dir.exists() && !QDir().mkpath(folder)) throw std::runtime_error("cannot create " + folder.toStdString());
    std::vector<std::function<void()>> steps;
    nlohmann::json metrics = nlohmann::json::array();
    std::string csv = metricsCsvHeader() + "\n";
    const double scale = sharedDifferenceScale(frames_);
    const Tonemap tonemap = state_.tonemap;
    exportNotes_.clear();
    for (const ViewFrame& f : frames_) {
        const std::string stem = dir.filePath(f.name).toStdString();
        // PNGs as the viewport shows them: the view's exposure with the E / Shift+E offset, and the operator.
        const double own = f.exposure, exposure = f.exposure + state_.exposureOffset;
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
            exportNotes_ << f.name + ": no image yet, nothing exported";
        } else if (!pair.against) {
            m["missing"] = "the reference is not ready";
            exportNotes_ << f.name + ": the reference is not ready, the image is exported alone";
        } else {
            m["partHash"] = image->metadata.count("partHash") ? image->metadata.at("partHash") : "";
            m["stale"] = pair.stale;
            if (pair.stale) exportNotes_ << f.name + ": the last image and reference of one state (stale)";
        }
        if (pair.against && f.metrics && !f.snapshot && !f.alternate) {
            m.update(metricsToJson(*f.metrics));
            csv += metricsCsvRow(f.name.toStdString(), *f.metrics) + "\n";
        }
        metrics.push_back(m);
        // Region insets: the region of the view and of its reference, when a region is drawn.
        const QRect region = image ? state_.region.intersected(QRect(0, 0, image->width(), image->height())) : QRect();
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
    const nlohmann::json display = {{"tonemap", tonemapNames()[std::size_t(state_.tonemap)]},
                                     {"exposureOffset", state_.exposureOffset},
                                     {"differenceScale", scale}};
    steps.push_back(writeText("display.json", display.dump(2) + "\n"));
    steps.push_back(writeText("metrics.csv", csv));
    steps.push_back([frame = composedFrame(), path = dir.filePath("viewport.png")] {
        if (!frame.save(path)) throw std::runtime_error("cannot write viewport.png");
    });
    // The plots draw with their widgets: here, on the GUI thread (~0.1 s each).
    for (Plot* plot : plots_->plots())
        for (const char* suffix : {".png", ".svg"}) {
            QString why;
            if (!plot->exportTo(dir.filePath("plot-" + plot->name() + suffix), &why))
                throw std::runtime_error(why.toStdString());
        }
    return steps;
}

bool MainWindow::exportComparison(const QString& folder, QString* error) {
    try {
        for (const auto& step : exportSteps(folder))
            step();
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

void MainWindow::startExport(const QString& folder) {
    std::vector<std::function<void()>> steps;
    try {
        steps = exportSteps(folder);
    } catch (const std::exception& e) {
        emit exportFinished(false, QString::fromStdString(e.what()));
        return;
    }
    // The files are written in the background pool, one after another, with a progress dialog that can cancel:
    // the window stays live (the export froze it for 20-30 s).
    auto* progress = new QProgressDialog("Exporting the comparison into " + folder, "Cancel", 0, int(steps.size()), this);
    progress->setObjectName("exportProgress");
    progress->setAttribute(Qt::WA_DeleteOnClose);
    progress->setMinimumDuration(0);
    progress->setValue(0);
    auto cancelled = std::make_shared<std::atomic<bool>>(false);
    connect(progress, &QProgressDialog::canceled, this, [cancelled] { *cancelled = true; });
    QPointer<QProgressDialog> dialog(progress);
    ++exportsRunning_;
    inBackground([this, steps = std::move(steps), cancelled, dialog] {
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
            --exportsRunning_;
            if (dialog) dialog->close();
            emit exportFinished(error.isEmpty(), error.isEmpty() ? exportNotes_.join("\n") : error);
        }, Qt::QueuedConnection);
    });
}

}  // namespace tyndall::studio
