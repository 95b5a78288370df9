#include "main_window.h"

#include "image_file.h"

#include "tyndall/core/resources.h"
#include "tyndall/techniques/render.h"

#include <QActionGroup>
#include <QCloseEvent>
#include <QComboBox>
#include <QCoreApplication>
#include <QDesktopServices>
#include <QDialog>
#include <QDir>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileDialog>
#include <QFileInfo>
#include <QKeyEvent>
#include <QLabel>
#include <QMenu>
#include <QMessageBox>
#include <QMimeData>
#include <QPointer>
#include <QProgressDialog>
#include <QPushButton>
#include <QScreen>
#include <QScrollArea>
#include <QSettings>
#include <QSignalBlocker>
#include <QStatusBar>
#include <QTimer>
#include <QToolBar>
#include <QUrl>
#include <QVBoxLayout>
#include <QVulkanInstance>

#include <algorithm>
#include <filesystem>
#include <map>

namespace tyndall::studio {

MainWindow::MainWindow(QVulkanInstance* vulkan, std::vector<std::string> overrides, const QString& ocioConfig)
    : studio_(std::move(overrides)),
      viewport_(new Viewport),
      views_(new ViewsDock(studio_, this)),
      parameters_(new ParametersDock(studio_, this)),
      metrics_(new MetricsDock(studio_, this)),
      inspector_(new InspectorDock(studio_, this)),
      snapshots_(new SnapshotsDock(studio_, this)),
      plots_(new PlotsDock(studio_, this)),
      scene_(new SceneDock(studio_, this)) {
    viewport_->setVulkanInstance(vulkan);
    QCoreApplication::instance()->installEventFilter(new DockWheelGuard(this));
    DockWheelGuard::guard(this);
    QWidget* container = QWidget::createWindowContainer(viewport_, this);
    container->setMinimumSize(320, 240);
    container->setFocusPolicy(Qt::StrongFocus);
    setCentralWidget(container);
    studio_.setViewportSize([this] { return viewport_->pixelSize(); });
    studio_.setPlotFiles([this] { return plots_->files(); });
    studio_.setRecoveryQuestion([this](const QString& path, const QString& autosave) {
        return QMessageBox::question(this, "Recover unsaved changes",
                                     "Tyndall Studio stopped with unsaved changes to " + QFileInfo(path).fileName() +
                                         " (autosaved " + QFileInfo(autosave).lastModified().toString() +
                                         "). Recover them?") == QMessageBox::Yes;
    });

    actions_ = new ActionTable(this);
    addStudioActions(*actions_, *this);
    // The display transform, on the layout toolbar before the wipe's swap (M cycles), and in View > Display.
    display_ = new QComboBox;
    display_->setObjectName("display");
    // As wide as the tonemap box it replaced, whatever the config's names (the popup and the tooltip show them whole):
    // a long view name must not push the animation toolbar's clock off a 1472-pixel window.
    display_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
    display_->setMinimumContentsLength(9);
    connect(display_, &QComboBox::currentIndexChanged, &studio_, [this](int i) {
        if (i >= 0 && display_->itemData(i).isValid()) studio_.setDisplayTransform(display_->itemData(i).toInt());
    });
    QToolBar* layoutBar = actions_->toolbar("layoutToolbar", "Layout");
    QAction* swap = actions_->action("swap");
    layoutBar->insertSeparator(layoutBar->insertWidget(swap, display_));
    displayMenu_ = actions_->menu("&View/Dis&play");
    displayMenu_->setObjectName("displayMenu");
    controller_ = new ViewportController(studio_, *viewport_, *actions_, this);

    placeDocks();
    buildStatusBar();
    connectStudio();
    connect(&studio_, &Studio::colourConfigChanged, this, &MainWindow::rebuildDisplayMenus);
    // The config again, now that the status bar can say why one was passed over.
    studio_.setColourConfig(ColourConfig::load(ocioConfig.toStdString(), "--ocio"));
    refreshRecentMenu();
    updateAnimationActions();
    setAcceptDrops(true);
    setWindowTitle(studio_.title());
}

MainWindow::~MainWindow() {
    studio_.scheduler().cancelAll();
    studio_.waitForBackgroundWork();  // metrics and probes in flight post back to the docks
    QCoreApplication::removePostedEvents(this);
}

void MainWindow::placeDocks() {
    addDockWidget(Qt::LeftDockWidgetArea, views_);
    addDockWidget(Qt::RightDockWidgetArea, parameters_);
    addDockWidget(Qt::RightDockWidgetArea, metrics_);
    addDockWidget(Qt::RightDockWidgetArea, inspector_);
    addDockWidget(Qt::LeftDockWidgetArea, snapshots_);
    addDockWidget(Qt::BottomDockWidgetArea, plots_);
    addDockWidget(Qt::LeftDockWidgetArea, scene_);
    // The default layout: Snapshots behind Views and the Inspector behind Metrics (tabs), so that the Scene dock and
    // the metrics table get the height for their rows; docks wide enough for their captions.
    tabifyDockWidget(views_, snapshots_);
    views_->raise();
    tabifyDockWidget(metrics_, inspector_);
    metrics_->raise();
    // The side docks take the whole height; the plots go under the viewport only.
    setCorner(Qt::BottomLeftCorner, Qt::LeftDockWidgetArea);
    setCorner(Qt::BottomRightCorner, Qt::RightDockWidgetArea);
    defaultDockSizes_ = [this] {
        resizeDocks({views_, scene_}, {220, 480}, Qt::Vertical);
        resizeDocks({parameters_, metrics_}, {380, 300}, Qt::Vertical);
        resizeDocks({views_, parameters_}, {300, 400}, Qt::Horizontal);
        resizeDocks({plots_}, {260}, Qt::Vertical);
    };
    // The window's size and its docks as the user left them (saved on close).
    const QSettings settings;
    if (!restoreGeometry(settings.value("window/geometry").toByteArray())) {
        // The first start: most of the screen, so that the tiles are large enough to judge (1280 x 800 left
        // 190 x 135 tiles on a 1600 x 1000 screen).
        const QRect available = screen()->availableGeometry();
        resize(available.size() * 0.92);
        move(available.center() - rect().center());
    }
    if (restoreState(settings.value("window/state").toByteArray())) defaultDockSizes_ = nullptr;
    keepOnScreen();
}

void MainWindow::keepOnScreen() {
    // A window restored for another screen (or a smaller one) comes back whole on this one, its status bar included.
    const QRect available = screen()->availableGeometry();
    const QRect frame = frameGeometry();
    if (available.contains(frame)) return;
    const QSize margins = frame.size() - size();
    resize(size().boundedTo(available.size() - margins));
    const QRect now = frameGeometry();
    move(std::clamp(now.x(), available.left(), std::max(available.left(), available.right() - now.width() + 1)),
         std::clamp(now.y(), available.top(), std::max(available.top(), available.bottom() - now.height() + 1)));
}

void MainWindow::buildStatusBar() {
    // Created now, so that their messages never resize the viewport. The permanent label says what runs, short:
    // "Ready" only when nothing is queued or running (Studio::status), every view's state in its tooltip.
    renderStatus_ = new QLabel("Ready");
    renderStatus_->setObjectName("renderStatus");
    statusBar()->addPermanentWidget(renderStatus_);
    // What the display does to every view, which the views' captions do not say (E / Shift+E, Ctrl+wheel).
    displayStatus_ = new QLabel;
    displayStatus_->setObjectName("displayStatus");
    displayStatus_->setToolTip(
        "The display exposure offset (E / Shift+E) is added to every view's own exposure (the "
        "Parameters dock's \"view exposure\"); zoom with Ctrl+wheel, Z resets");
    statusBar()->addPermanentWidget(displayStatus_);
    updateDisplay();
}

void MainWindow::connectStudio() {
    connect(&studio_, &Studio::message, statusBar(), &QStatusBar::showMessage);
    connect(&studio_, &Studio::warning, this,
            [this](const QString& title, const QString& text) { QMessageBox::warning(this, title, text); });
    connect(&studio_, &Studio::titleChanged, this, [this] {
        setWindowTitle(studio_.title());
        setWindowModified(studio_.session().modified());
    });
    connect(&studio_, &Studio::displayChanged, this, &MainWindow::updateDisplay);
    connect(&studio_, &Studio::frameComposed, viewport_, &Viewport::setFrame);
    // "Ready" only when nothing is queued or running: the status follows every render, metric and export.
    auto updateStatus = [this] {
        QString details;
        const QString text = studio_.status(&details);
        if (renderStatus_->text() != text) renderStatus_->setText(text);
        if (renderStatus_->toolTip() != details) renderStatus_->setToolTip(details);
    };
    connect(&studio_.comparison(), &ComparisonModel::metricsChanged, this, updateStatus);
    connect(&studio_.comparison(), &ComparisonModel::framesChanged, this, updateStatus);
    connect(&studio_.scheduler(), &RenderScheduler::started, this, updateStatus);
    connect(&studio_.scheduler(), &RenderScheduler::output, this, updateStatus, Qt::QueuedConnection);
    connect(&studio_.renderService(), &RenderService::idleChanged, this, updateStatus, Qt::QueuedConnection);
    connect(&studio_.exporter(), &Exporter::finished, this, updateStatus, Qt::QueuedConnection);
    connect(&studio_, &Studio::viewsRebuilt, this, updateStatus);
    connect(&studio_, &Studio::viewListChanged, this, updateStatus);
    // And a look four times a second for what ends without a signal (a dropped metrics job, a cache read).
    auto* statusPoll = new QTimer(this);
    connect(statusPoll, &QTimer::timeout, this, updateStatus);
    statusPoll->start(250);
    connect(&studio_.files(), &ProjectFiles::recentChanged, this, &MainWindow::refreshRecentMenu);
    connect(&studio_.session(), &Session::projectReplaced, this, &MainWindow::updateAnimationActions);
    connect(&studio_.session(), &Session::sceneChanged, this, &MainWindow::updateAnimationActions);
    connect(&studio_.animation(), &Animation::playingChanged, this, [this](bool playing) {
        QAction* play = actions_->action("playAnimation");
        const QSignalBlocker block(play);
        play->setChecked(playing);
        play->setText(playing ? "&Pause" : "&Play");
    });
    addAnimationClock();
    connect(&studio_.exporter(), &Exporter::finished, this,
            [this](bool ok, const QString& message, const QString& folder) {
                if (ok && message.isEmpty()) {
                    statusBar()->showMessage("Exported the comparison into " + folder, 8000);
                    return;
                }
                if (!ok && message == "cancelled") {
                    statusBar()->showMessage("Export cancelled: nothing was written into " + folder, 8000);
                    return;
                }
                // Not modal: the studio goes on rendering while the user reads it.
                const QString text =
                    ok ? "Exported the comparison into " + folder + ", with these notes:\n\n" + message : message;
                auto* box = new QMessageBox(ok ? QMessageBox::Information : QMessageBox::Critical,
                                            ok ? "Exported, with notes" : "Cannot export", text, QMessageBox::Ok, this);
                box->setObjectName("exportReport");
                box->setAttribute(Qt::WA_DeleteOnClose);
                box->setModal(false);
                box->show();
            });
}

namespace {

// How the box and the menu name a display transform: "sRGB / Standard", or Tyndall's operator.
QString displayLabel(const DisplayTransform& t) {
    if (t.isOcio()) return QString::fromStdString(t.display() + " / " + t.view());
    static const char* names[] = {"Tyndall: sRGB (clamped)", "Tyndall: Reinhard", "Tyndall: ACES fit",
                                  "Tyndall: false colour"};
    return names[int(t.tonemap())];
}

}  // namespace

void MainWindow::rebuildDisplayMenus() {
    const std::vector<DisplayTransform>& transforms = studio_.displayTransforms();
    const QString config = QString::fromStdString(studio_.colourConfig()->describe());
    {
        const QSignalBlocker block(display_);
        display_->clear();
        for (std::size_t i = 0; i < transforms.size(); ++i) {
            if (i > 0 && !transforms[i].isOcio() && transforms[i - 1].isOcio())
                display_->insertSeparator(display_->count());
            display_->addItem(displayLabel(transforms[i]), int(i));
        }
    }
    displayTip_ = QString("Display transform, after the exposure (M cycles): the displays and views of " + config +
                          " (OpenColorIO; --ocio or $OCIO choose another), then Tyndall's own operators: sRGB clamps, "
                          "Reinhard compresses luminance keeping hue, the ACES fit is Narkowicz's, false colour maps "
                          "log2 luminance to viridis");
    // The menu: a submenu per display with its views, then Tyndall's operators; one checked.
    for (QMenu* sub : displayMenu_->findChildren<QMenu*>(Qt::FindDirectChildrenOnly))
        sub->deleteLater();
    displayMenu_->clear();
    delete displayActions_;
    displayActions_ = new QActionGroup(this);
    displayActions_->setExclusive(true);
    QAction* source = displayMenu_->addAction("OpenColorIO: " + config);
    source->setEnabled(false);
    std::map<std::string, QMenu*> displays;
    for (std::size_t i = 0; i < transforms.size(); ++i) {
        const DisplayTransform& t = transforms[i];
        QMenu* into = displayMenu_;
        QString text = displayLabel(t);
        if (t.isOcio()) {
            QMenu*& sub = displays[t.display()];
            if (!sub) sub = displayMenu_->addMenu(QString::fromStdString(t.display()));
            into = sub;
            text = QString::fromStdString(t.view());
        } else if (i > 0 && transforms[i - 1].isOcio()) {
            displayMenu_->addSeparator();
        }
        QAction* a = into->addAction(text);
        a->setCheckable(true);
        a->setData(int(i));
        displayActions_->addAction(a);
        connect(a, &QAction::triggered, &studio_, [this, i] { studio_.setDisplayTransform(int(i)); });
    }
    updateDisplay();
}

void MainWindow::updateDisplay() {
    const CompositorState& state = studio_.compositorState();
    static const char* layouts[] = {"layout:grid", "layout:single", "layout:split"};
    if (QAction* a = actions_ ? actions_->action(layouts[int(state.layout)]) : nullptr; a && !a->isChecked())
        a->setChecked(true);
    const int transform = studio_.displayTransformIndex();
    if (display_) {
        const int item = display_->findData(transform);
        if (item >= 0 && display_->currentIndex() != item) {
            const QSignalBlocker block(display_);
            display_->setCurrentIndex(item);
        }
        // The box is narrow: its tooltip names the whole choice.
        const QString tip = display_->currentText() + "\n\n" + displayTip_;
        if (display_->toolTip() != tip) display_->setToolTip(tip);
    }
    if (displayActions_)
        for (QAction* a : displayActions_->actions())
            if (a->data().toInt() == transform && !a->isChecked()) a->setChecked(true);
    if (!displayStatus_) return;
    const QString text = QString("display exposure offset %1%2 EV  |  zoom %3x")
                             .arg(state.exposureOffset >= 0.0 ? "+" : "")
                             .arg(state.exposureOffset, 0, 'g', 3)
                             .arg(state.zoom, 0, 'g', 3);
    if (displayStatus_->text() != text) displayStatus_->setText(text);
}

void MainWindow::updateAnimationActions() {
    const bool available = studio_.animation().available();
    for (const char* id : {"playAnimation", "stepAnimation", "resetAnimation"})
        if (QAction* a = actions_->action(id); a->isEnabled() != available) a->setEnabled(available);
    QToolBar* bar = actions_->toolbar("animationToolbar", "Animation");
    if (bar->isVisibleTo(this) != available) bar->setVisible(available);
}

void MainWindow::addAnimationClock() {
    QToolBar* bar = actions_->toolbar("animationToolbar", "Animation");
    // The pace: how many steps a frame may advance (docs/isv.md, "Animation").
    auto* pace = new QComboBox(bar);
    pace->setObjectName("animationPace");
    pace->setToolTip(
        "How play advances: in real time (slow views skip steps), or at most this many steps a frame (slow views play "
        "in slow motion, every step shown; fast views still in real time)");
    pace->addItem("real time", 0);
    for (int steps : {1, 2, 4, 8, 16})
        pace->addItem(QString("≤ %1 step%2 a frame").arg(steps).arg(steps > 1 ? "s" : ""), steps);
    pace->setCurrentIndex(pace->findData(studio_.animation().maxStepsPerFrame()));
    pace->setFocusPolicy(Qt::ClickFocus);
    connect(pace, &QComboBox::currentIndexChanged, this,
            [this, pace](int index) { studio_.animation().setMaxStepsPerFrame(pace->itemData(index).toInt()); });
    bar->addWidget(pace);
    // The frame on screen, in steps and simulated seconds; the impulses in its tooltip.
    auto* clock = new QLabel(bar);
    clock->setObjectName("animationClock");
    clock->setContentsMargins(8, 0, 8, 0);
    bar->addWidget(clock);
    auto update = [this, clock] {
        clock->setText(studio_.animation().clockText());
        clock->setToolTip(studio_.animation().impulsesText());
    };
    connect(&studio_.animation(), &Animation::clockChanged, clock, update);
    update();
}

void MainWindow::refreshRecentMenu() {
    QMenu* recent = actions_->menu("&File/Open &recent");
    recent->clear();
    for (const QString& path : studio_.recentProjects())
        recent->addAction(path, this, [this, path] {
            if (confirmDiscard()) openProject(path);
        });
    recent->setEnabled(!recent->isEmpty());
}

// --- Projects and files

bool MainWindow::openProject(const QString& path, bool dialog) {
    QString error;
    if (studio_.openProject(path, &error)) return true;
    if (dialog) QMessageBox::critical(this, "Cannot open the project", error);
    return false;
}

bool MainWindow::openAtStart(const QString& path, const QString& fallback) {
    if (openProject(path, true)) return true;
    studio_.files().addRecent(path);
    if (QFileInfo(path).absoluteFilePath() != QFileInfo(fallback).absoluteFilePath() &&
        studio_.session().path().isEmpty())
        openProject(fallback, true);
    statusBar()->showMessage("Not opened: " + QFileInfo(path).fileName() +
                             " (File > Open Recent opens it again once fixed)");
    return false;
}

bool MainWindow::confirmDiscard() {
    if (!studio_.session().modified()) return true;
    const auto answer =
        QMessageBox::question(this, "Unsaved changes", "The project has unsaved changes. Save them first?",
                              QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
    if (answer == QMessageBox::Cancel) return false;
    // Discarded on purpose: the autosave holds nothing to recover (reopening the file asked to, before), and no new
    // autosave while a file dialog is open.
    if (answer == QMessageBox::Discard) studio_.files().discardChanges();
    if (answer == QMessageBox::Save) {
        QString error;
        if (!studio_.saveProject(&error)) {
            QMessageBox::critical(this, "Cannot save", error);
            return false;
        }
    }
    return true;
}

void MainWindow::openDialog() {
    if (!confirmDiscard()) return;
    const QString path = QFileDialog::getOpenFileName(this, "Open project", QFileInfo(studio_.session().path()).path(),
                                                      "Tyndall projects (*.json)");
    if (!path.isEmpty()) openProject(path);
}

void MainWindow::save() {
    QString error;
    if (!studio_.saveProject(&error)) QMessageBox::critical(this, "Cannot save", error);
}

void MainWindow::saveAsDialog() {
    const QString path =
        QFileDialog::getSaveFileName(this, "Save project as", studio_.session().path(), "Tyndall projects (*.json)");
    QString error;
    if (!path.isEmpty() && !studio_.saveProjectAs(path, &error)) QMessageBox::critical(this, "Cannot save", error);
}

void MainWindow::openImageDialog() {
    const QStringList paths = QFileDialog::getOpenFileNames(
        this, "Open images to compare", QFileInfo(studio_.session().path()).absolutePath(),
        "Images (*.exr *.hdr *.pfm *.png *.jpg *.jpeg *.tif *.tiff *.bmp *.tga)");
    for (const QString& path : paths) {
        QString error;
        if (studio_.openImageView(path, &error) < 0) QMessageBox::warning(this, "Cannot open the image", error);
    }
}

void MainWindow::exportDialog() {
    const QString folder = QFileDialog::getExistingDirectory(this, "Export the comparison into",
                                                             QFileInfo(studio_.session().path()).absolutePath());
    if (!folder.isEmpty()) startExport(folder);
}

void MainWindow::startExport(const QString& folder) {
    Exporter& exporter = studio_.exporter();
    // A progress dialog for the export that starts now, closed when it ends.
    auto connection = std::make_shared<QMetaObject::Connection>();
    *connection = connect(&exporter, &Exporter::started, this, [this, &exporter, folder, connection](int files) {
        disconnect(*connection);
        auto* progress = new QProgressDialog("Exporting the comparison into " + folder, "Cancel", 0, files, this);
        progress->setObjectName("exportProgress");
        progress->setAttribute(Qt::WA_DeleteOnClose);
        progress->setMinimumDuration(0);
        progress->setValue(0);
        connect(progress, &QProgressDialog::canceled, &exporter, &Exporter::cancel);
        connect(&exporter, &Exporter::progress, progress, &QProgressDialog::setValue);
        connect(&exporter, &Exporter::finished, progress, &QProgressDialog::close);
    });
    studio_.startExport(folder);
    disconnect(*connection);  // planning failed: no dialog
}

void MainWindow::closeEvent(QCloseEvent* event) {
    if (!confirmDiscard()) {
        event->ignore();
        return;
    }
    studio_.scheduler().cancelAll();
    studio_.files().removeAutosave();  // saved or discarded on purpose: nothing to recover
    saveLayout();
    event->accept();
}

void MainWindow::showEvent(QShowEvent* event) {
    QMainWindow::showEvent(event);
    // The default dock sizes, once the window has its size (resizeDocks before the first layout is not kept).
    if (defaultDockSizes_)
        QTimer::singleShot(0, this, [this] {
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

void MainWindow::keyPressEvent(QKeyEvent* event) {
    controller_->key(event->key(), event->modifiers(), true);
}

void MainWindow::keyReleaseEvent(QKeyEvent* event) {
    controller_->key(event->key(), event->modifiers(), false);
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
        if (studio_.openImageView(path, &error) < 0) problems << error;
    }
    if (!project.isEmpty() && confirmDiscard()) openProject(project);
    event->acceptProposedAction();
    if (!problems.isEmpty()) QMessageBox::warning(this, "Cannot open", problems.join("\n"));
}

// --- Help

QString MainWindow::shortcutsText() const {
    return actions_->helpHtml(ViewportController::bindings());
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

void MainWindow::showDocumentation() {
    // Installed: <prefix>/share/doc/tyndall beside the data; built: the source tree's docs/.
    const std::filesystem::path root = resourceRoot();
    const QString docs = QString::fromStdString((std::filesystem::is_directory(root / ".." / "doc" / "tyndall")
                                                     ? root / ".." / "doc" / "tyndall"
                                                     : root / "docs")
                                                    .lexically_normal()
                                                    .string());
    if (!QDir(docs).exists() || !QDesktopServices::openUrl(QUrl::fromLocalFile(docs)))
        QMessageBox::information(this, "Documentation",
                                 "The documentation is in docs/ and README.md of the source tree (" + docs + ").");
}

void MainWindow::showAbout() {
    QMessageBox::about(this, "About Tyndall Studio",
                       QString("<b>Tyndall Studio</b> %1<br>Volumetric rendering comparison studio.<br>Qt %2")
                           .arg(QString::fromLatin1(tyndallVersion()), QString::fromLatin1(qVersion())));
}

}  // namespace tyndall::studio
