#include "studio.h"
#include "image_file.h"
#include "trace.h"

#include "shared/camera.h"
#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"
#include "tyndall/framework/shader_params.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <QCoreApplication>
#include <QFile>
#include <QFileInfo>
#include <QTimer>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>

namespace tyndall::studio {

namespace {

// Right after an edit, the frame that would only mark the view as rendering waits this long for the new image.
constexpr qint64 kEditQuietMs = 150;
// An impulse is marked on the views for this long of simulated time after it (the default spring's push peaks at
// 0.24 s and has mostly died out by 1.5 s).
constexpr double kImpulseMarkerSeconds = 1.5;

}  // namespace

QString techniqueDisplayName(const std::string& technique) {
    try {
        return QString::fromStdString(createTechnique(technique)->displayName());
    } catch (const std::exception&) {
        return QString::fromStdString(technique);
    }
}

QString viewLabel(const View& view) {
    try {
        const std::unique_ptr<Technique> technique = createTechnique(view.technique);
        return QString::fromStdString(technique->labelFor(paramsFromJson(*technique, view.parameters, "parameters")));
    } catch (const std::exception&) {
        return techniqueDisplayName(view.technique);
    }
}

Studio::Studio(std::vector<std::string> overrides, QObject* parent)
    : QObject(parent),
      overrides_(std::move(overrides)),
      background_(new Background(this)),
      scheduler_(new RenderScheduler(session_, *background_, this)),
      model_(new ComparisonModel(*background_, this)),
      files_(new ProjectFiles(session_, this)),
      snapshots_(new SnapshotStore(session_, this)),
      exporter_(new Exporter(*background_, this)),
      animation_(new Animation(session_, this)),
      composer_(new Composer(this)) {
    // The data flows one way: session -> scheduler -> model -> composer, docks and exports.
    connect(&session_, &Session::projectReplaced, this, [this] {
        rebuildViews();
        emit titleChanged();
    });
    connect(&session_, &Session::viewChanged, this, [this](int view) {
        trace("edit of view %d", view);
        noteEdit();
        model_->setExposure(view, session_.project().views[std::size_t(view)].exposure);
        model_->setTechniqueLabel(view, viewLabel(session_.project().views[std::size_t(view)]));
        scheduler_->viewEdited(view);
        recompose();
    });
    connect(&session_, &Session::modifiedChanged, this, [this](bool) { emit titleChanged(); });
    connect(&session_, &Session::sceneChanged, this, &Studio::onSceneChanged);
    connect(scheduler_, &RenderScheduler::started, model_, &ComparisonModel::renderStarted);
    connect(scheduler_, &RenderScheduler::failed, model_, &ComparisonModel::renderFailed);
    connect(scheduler_, &RenderScheduler::stopped, model_, &ComparisonModel::renderStopped);
    connect(scheduler_, &RenderScheduler::stateChanged, model_, &ComparisonModel::setState);
    connect(scheduler_, &RenderScheduler::output, this, [this](const RenderOutput& out) {
        model_->addOutput(out);
        if (!out.error.isEmpty() && out.view < model_->size())
            say(model_->frames()[std::size_t(out.view)].name + ": " + out.error);
        if (!out.reference) requestCompose(true);  // a new image is shown at once, even right after an edit
    });
    connect(model_, &ComparisonModel::framesChanged, this, &Studio::recompose);
    connect(files_, &ProjectFiles::autosaveFailed, this, [this](const QString& text) { say(text); });
    connect(composer_, &Composer::composed, this, [this](const QImage& frame) {
        composed_ = frame;
        emit frameComposed(frame);
    });
    // The animation advances only once the views have shown its last frame (coalesced: by the simulated time that
    // passed meanwhile), and its edits replace a progressive view's long render at once (flushDirty).
    animation_->setViewsReady([this] { return scheduler_->viewsCaughtUp(); });
    connect(animation_, &Animation::advancing, this, [this](bool during) { scheduler_->setAnimating(during); });
    connect(animation_, &Animation::refused, this,
            [this](const QString& reason) { say("Animation stopped: " + reason); });
    connect(animation_, &Animation::playingChanged, scheduler_, &RenderScheduler::setPlaying);
    // The impulses' markers follow the scene (an impulse, a step, the camera).
    connect(&session_, &Session::sceneChanged, this, &Studio::updateImpulseMarkers);
    connect(&session_, &Session::projectReplaced, this, &Studio::updateImpulseMarkers);
    // The display transforms of $OCIO's config, else the shipped one; the window says why one was passed over.
    setColourConfig(ColourConfig::load(), false);
}

Studio::~Studio() {
    scheduler_->cancelAll();
    background_->waitForDone();  // metrics in flight post back to the model
    files_->waitForAutosaves();  // and a failed autosave would say so
    QCoreApplication::removePostedEvents(this);
}

// --- The project

bool Studio::openProject(const QString& path, QString* error) {
    QString why;
    scheduler_->cancelAll();
    files_->setOpening(true);
    const bool opened = session_.open(path, &why, overrides_);
    files_->setOpening(false);
    if (!opened) {
        say("Not opened: " + why);
        // The current project stays; its renders start again where they were cancelled.
        if (!session_.project().views.empty()) scheduler_->renderAll();
        if (error) *error = why;
        return false;
    }
    files_->addRecent(path);
    recover(path);
    return true;
}

void Studio::recover(const QString& path) {
    const std::optional<QString> autosave = files_->newerAutosave(path);
    if (!autosave || files_->recovery() == Recovery::Never) return;
    bool recover = files_->recovery() == Recovery::Always;
    if (files_->recovery() == Recovery::Ask) {
        if (!askRecovery_) return;  // nobody to ask: the autosave stays for a later start
        recover = askRecovery_(path, *autosave);
    }
    if (!recover) {
        QFile::remove(*autosave);
        return;
    }
    QString error;
    if (files_->recover(*autosave, &error))
        say("Recovered the unsaved changes of " + QFileInfo(path).fileName());
    else
        emit warning("Cannot recover", error);
}

bool Studio::saveProject(QString* error) {
    if (!session_.save(error)) return false;
    // The snapshots go beside the file; a failure there leaves the project saved and says so.
    QString why;
    if (!snapshots_->save(session_.path(), &why)) {
        if (error) *error = "The project is saved, but not its snapshots: " + why;
        return false;
    }
    return true;
}

bool Studio::saveProjectAs(const QString& path, QString* error) {
    const QString before = session_.path();
    const bool modified = session_.modified();
    if (!session_.saveAs(path, error)) return false;
    // The changes are in the new file: the old file's autosave (and the new one's, if it was not modified) hold
    // nothing to recover.
    if (!before.isEmpty() && QFileInfo(before).absoluteFilePath() != QFileInfo(path).absoluteFilePath())
        files_->removeAutosave(before);
    if (!modified) files_->removeAutosave();
    files_->addRecent(path);
    emit titleChanged();
    QString why;
    if (!snapshots_->save(path, &why)) {
        if (error) *error = "The project is saved, but not its snapshots: " + why;
        return false;
    }
    return true;
}

QString Studio::title() const {
    if (session_.path().isEmpty()) {
        QStringList names;
        for (const ViewFrame& f : model_->frames())
            names << f.name;
        return (names.isEmpty() ? QString() : names.join(", ") + " - ") + "Tyndall Studio";
    }
    const QString name = QString::fromStdString(session_.project().name);
    return (name.isEmpty() ? QString("Tyndall") : name) + " - " + QFileInfo(session_.path()).fileName() +
           "[*] - Tyndall Studio";
}

void Studio::rebuildViews() {
    imageSession_ = false;  // a project opened: its views are compared against its references again
    scheduler_->reset();
    model_->reset(viewInfos());
    scheduler_->renderAll();
    state_.region = QRect();
    state_.current = 0;
    comparedSnapshot_ = -1;
    ++probeGeneration_;  // a probe still running for the previous views is not shown
    QString error;
    if (!snapshots_->load(session_.path(), &error)) say("Snapshots not loaded: " + error);
    emit viewsRebuilt();
    if (model_->size() > 0) emit currentViewChanged(state_.current);
    emit phasesChanged();
    recompose();
}

std::vector<ComparisonModel::ViewInfo> Studio::viewInfos() const {
    std::vector<ComparisonModel::ViewInfo> views;
    const std::vector<View>& project = session_.project().views;
    for (std::size_t i = 0; i < project.size(); ++i)
        views.push_back({QString::fromStdString(project[i].name), viewLabel(project[i]), project[i].exposure,
                         scheduler_->state(int(i))});
    return views;
}

void Studio::followViews() {
    const std::vector<int> oldOf = scheduler_->followViews();
    model_->followViews(viewInfos(), oldOf);
    for (std::size_t i = 0; i < oldOf.size(); ++i)
        if (oldOf[i] < 0) scheduler_->renderView(int(i));
    ++probeGeneration_;  // a probe still running names a view by its old index
    snapshots_->followViews();
    if (comparedSnapshot_ >= 0) compareWithSnapshot(comparedSnapshot_);  // its view may have moved
    emit viewListChanged();
    recompose();
}

void Studio::onSceneChanged() {
    noteEdit();
    // Views added, removed, renamed or given another technique (or an undo of that): the views that did not change
    // keep their images, references and history; the others start again. The current one is kept by name (a new view
    // is selected).
    if (scheduler_->viewsChanged()) {
        const Project& project = session_.project();
        const QString current =
            state_.current < model_->size() ? model_->frames()[std::size_t(state_.current)].name : QString();
        std::set<std::string> before;
        for (const ViewFrame& f : model_->frames())
            before.insert(f.name.toStdString());
        followViews();
        int select = -1;
        for (int i = 0; i < int(project.views.size()); ++i) {
            if (!before.count(project.views[std::size_t(i)].name)) select = i;  // new
            if (select < 0 && QString::fromStdString(project.views[std::size_t(i)].name) == current) select = i;
        }
        selectView(std::max(select, 0));
        emit titleChanged();
        return;
    }
    for (int i = 0; i < int(session_.project().views.size()); ++i) {
        model_->setExposure(i, session_.project().views[std::size_t(i)].exposure);
        model_->setTechniqueLabel(i, viewLabel(session_.project().views[std::size_t(i)]));
    }
    scheduler_->sceneEdited();
    emit phasesChanged();
    recompose();
}

bool Studio::settled() const {
    return scheduler_->settled() && model_->idle() && !exporter_->running();
}

QString Studio::status(QString* details) const {
    QStringList views, references, lines;
    QString firstProgress;
    int stale = 0;
    auto shortName = [](const QString& name) { return name.size() > 24 ? name.left(23) + "…" : name; };
    const std::vector<ViewFrame>& frames = model_->frames();
    for (int i = 0; i < int(frames.size()); ++i) {
        const ViewFrame& f = frames[std::size_t(i)];
        stale += f.metricsStale;
        if (model_->isImage(i)) continue;
        const bool view = f.rendering || scheduler_->busy(i, false);
        const bool reference = f.referenceRendering || scheduler_->busy(i, true);
        if (view) views << f.name;
        QString progress;
        if (reference) {
            references << f.name;
            progress = referenceProgress(f);  // "reference 24/64 spp, ETA 10 s"
            if (progress.isEmpty()) progress = scheduler_->playing() ? "reference after the pause" : "reference queued";
            if (firstProgress.isEmpty()) firstProgress = shortName(f.name) + " " + progress.mid(10);
        }
        QStringList what;
        if (view) what << "rendering";
        if (reference) what << progress;
        if (!f.error.isEmpty()) what << "failed: " + f.error.left(80);
        lines << f.name + ": " + (what.isEmpty() ? QString("ready") : what.join(", "));
    }
    QStringList parts;
    if (animation_->playing()) parts << "Playing";
    if (views.size() == 1) parts << "Rendering " + shortName(views.front());
    if (views.size() > 1) parts << QString("Rendering %1 views").arg(views.size());
    if (references.size() == 1) parts << "reference " + firstProgress;
    if (references.size() > 1) parts << QString("%1 references (%2)").arg(references.size()).arg(firstProgress);
    if (parts.isEmpty() && !model_->idle()) parts << "Computing metrics";
    if (exporter_->running()) parts << "Exporting";
    if (parts.isEmpty() && !settled()) parts << "Working";  // a cached reference being read, a debounce
    QString text = parts.isEmpty() ? QString("Ready") : parts.join(" · ");
    text[0] = text[0].toUpper();
    if (stale > 0) {
        text += QString(" · %1 stale").arg(stale);
        lines << QString(
                     "%1 comparison%2 use the last image and reference of one state until the new reference has "
                     "%3 spp")
                     .arg(stale)
                     .arg(stale > 1 ? "s" : "")
                     .arg(kMinComparedReferenceSpp);
    }
    if (details) *details = lines.join("\n");
    return text;
}

// --- Views

int Studio::openImageView(const QString& path, QString* error) {
    try {
        const ImageFile file = readImageFile(path, colourConfig_.get());
        const int view = model_->addImage(QFileInfo(path).fileName(), file.kind, file.image);
        emit viewListChanged();
        selectView(view);
        if (file.displayReferred)
            say(QFileInfo(path).fileName() +
                " holds display values: decoded with the sRGB curve, its metrics are "
                "approximate (values the display clipped stay at 1)");
        return view;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return -1;
    }
}

bool Studio::openImageSession(const QStringList& paths, QString* error) {
    if (!session_.project().views.empty()) {
        if (error) *error = "a project is open: its views render beside the images (open them as image views)";
        return false;
    }
    QStringList problems;
    int first = -1;
    for (const QString& path : paths) {
        QString why;
        const int view = openImageView(path, &why);
        if (view < 0) problems << why;
        if (first < 0) first = view;
    }
    if (first >= 0) {
        imageSession_ = true;
        model_->chooseReferenceView(first);
        selectView(std::min(first + 1, model_->size() - 1));
        emit titleChanged();
    }
    if (error) *error = problems.join("\n");
    return problems.isEmpty();
}

bool Studio::duplicateView(int view, QString* error) {
    if (model_->isImage(view)) {
        if (error)
            *error = "'" + model_->frames()[std::size_t(view)].name +
                     "' is an image opened from a file, not a view of the project";
        return false;
    }
    return session_.duplicateView(view, error);
}

bool Studio::renameView(int view, const QString& name, QString* error) {
    if (!model_->isImage(view)) return session_.renameView(view, name.toStdString(), error);
    model_->renameImage(view, name);
    emit viewListChanged();
    return true;
}

bool Studio::removeView(int view, QString* error) {
    if (!model_->isImage(view)) return session_.removeView(view, error);
    model_->removeImage(view);  // an image view is not in the project: closed
    emit viewListChanged();
    selectView(std::min(view, model_->size() - 1));
    return true;
}

void Studio::selectView(int view) {
    if (view < 0 || view >= model_->size()) return;
    state_.current = view;
    emit currentViewChanged(view);
    emit phasesChanged();
    recompose();
}

// --- The display

void Studio::setLayoutMode(Layout layout) {
    state_.layout = layout;
    recompose();
}

void Studio::setColourConfig(std::shared_ptr<const ColourConfig> config, bool announce) {
    colourConfig_ = std::move(config);
    for (const std::string& warning : announce ? colourConfig_->warnings() : std::vector<std::string>{}) {
        std::fprintf(stderr, "tyndall-studio: %s\n", warning.c_str());
        say(QString::fromStdString(warning), 30000);
    }
    displayTransforms_.clear();
    for (const std::string& display : colourConfig_->displays())
        for (const std::string& view : colourConfig_->views(display)) {
            try {
                displayTransforms_.emplace_back(colourConfig_, display, view);
            } catch (const InputError& e) {  // a view the config lists but cannot build: said, and left out
                std::fprintf(stderr, "tyndall-studio: %s\n", e.what());
                say(QString::fromStdString(e.what()), 30000);
            }
        }
    for (std::size_t op = 0; op < tonemapNames().size(); ++op)
        displayTransforms_.emplace_back(Tonemap(op));
    const std::string display = colourConfig_->defaultDisplay();
    const std::string view = colourConfig_->defaultView(display);
    state_.displayTransform = Tonemap::Srgb;
    for (const DisplayTransform& t : displayTransforms_)
        if (t.isOcio() && t.display() == display && t.view() == view) state_.displayTransform = t;
    emit colourConfigChanged();
    recompose();
}

int Studio::displayTransformIndex() const {
    for (std::size_t i = 0; i < displayTransforms_.size(); ++i)
        if (displayTransforms_[i] == state_.displayTransform) return int(i);
    return -1;
}

void Studio::setDisplayTransform(int index) {
    if (index < 0 || index >= int(displayTransforms_.size())) return;
    state_.displayTransform = displayTransforms_[std::size_t(index)];
    recompose();
}

void Studio::setTonemap(Tonemap op) {
    state_.displayTransform = op;
    recompose();
}

void Studio::setSmoothPreviews(bool smooth) {
    state_.smoothPreviews = smooth;
    recompose();
}

void Studio::cycleDisplayTransform() {
    setDisplayTransform((displayTransformIndex() + 1) % int(displayTransforms_.size()));
}

void Studio::cycleDifference() {
    state_.diff = DiffMode((int(state_.diff) + 1) % (int(DiffMode::Flip) + 1));
    recompose();
}

void Studio::swapSides() {
    state_.swapped = !state_.swapped;
    recompose();
}

void Studio::offsetExposure(double stops) {
    state_.exposureOffset += stops;
    recompose();
}

void Studio::zoomBy(double steps) {
    state_.zoom = std::clamp(state_.zoom * std::pow(1.25, steps), 1.0, 64.0);
    recompose();
}

void Studio::panBy(QPointF delta) {
    if (model_->frames().empty()) return;
    const std::vector<QRect> rects = viewRects(model_->frames(), state_, viewportSize());
    QRect r;
    for (const QRect& c : rects)
        if (!c.isEmpty()) r = c;
    if (r.width() <= 0) return;
    state_.centre -= QPointF(delta.x() / r.width(), delta.y() / r.height()) / state_.zoom;
    state_.centre = QPointF(std::clamp(state_.centre.x(), 0.0, 1.0), std::clamp(state_.centre.y(), 0.0, 1.0));
    recompose();
}

void Studio::resetZoom() {
    state_.zoom = 1.0;
    state_.centre = QPointF(0.5, 0.5);
    recompose();
}

void Studio::setSplitAt(QPointF position) {
    if (state_.layout != Layout::Split || model_->frames().empty()) return;
    const std::vector<QRect> rects = viewRects(model_->frames(), state_, viewportSize());
    const QRect r = rects[std::size_t(std::clamp(state_.current, 0, int(rects.size()) - 1))];
    if (r.width() <= 0) return;
    state_.split = std::clamp((position.x() - r.x()) / r.width(), 0.0, 1.0);
    recompose();
}

void Studio::centreSplit() {
    state_.split = 0.5;
    recompose();
}

void Studio::showReference(bool show) {
    state_.showReference = show;
    recompose();
}

void Studio::showViewAlone(int view) {
    selectView(view);
    if (state_.layout == Layout::Grid) setLayoutMode(Layout::Single);
    recompose();
}

// --- Composing

QSize Studio::viewportSize() const {
    // Without a window, the size of a small viewport.
    return (viewportSize_ ? viewportSize_() : QSize(640, 480)).expandedTo(QSize(64, 48));
}

void Studio::recompose() {
    // The views the layout shows: every one in the grid; the current one alone (and the view chosen as every view's
    // comparand), which the others' renders then wait for (RenderScheduler::setOnScreen).
    std::vector<bool> onScreen(std::size_t(model_->size()), state_.layout == Layout::Grid);
    if (state_.layout != Layout::Grid && !onScreen.empty()) {
        onScreen[std::size_t(std::clamp(state_.current, 0, model_->size() - 1))] = true;
        if (const int comparand = model_->referenceView(); comparand >= 0 && comparand < model_->size())
            onScreen[std::size_t(comparand)] = true;
    }
    scheduler_->setOnScreen(onScreen);
    emit displayChanged();
    // Once per pass of the event loop, however many changes it brought. Right after an edit, the frame that would only
    // mark the view as rendering waits up to kEditQuietMs: if the new image comes first (the analytic techniques take
    // ~100 ms), that frame is never composed nor presented, and the two cores go to the render.
    if (composeQueued_) return;
    composeQueued_ = true;
    QTimer::singleShot(0, this, [this] { requestCompose(); });
}

void Studio::requestCompose(bool now) {
    if (!composeQueued_) return;
    // Within kEditQuietMs of an edit the frame waits for the rest of it (also one asked for just before the edit).
    const qint64 wait = editClock_.isValid() ? kEditQuietMs - editClock_.elapsed() : 0;
    if (!now && wait > 0) {
        QTimer::singleShot(int(wait), this, [this] { requestCompose(); });
        return;
    }
    composeQueued_ = false;
    composer_->request(model_->frames(), state_, viewportSize());
}

const QImage& Studio::composedFrame() {
    requestCompose(true);
    composed_ = composer_->wait();
    return composed_;
}

// --- Comparands, snapshots, regions

int Studio::takeSnapshot() {
    if (state_.current < 0 || state_.current >= model_->size()) return -1;
    const int index = snapshots_->take(state_.current, model_->frames()[std::size_t(state_.current)].image);
    if (index >= 0) emit snapshotTaken(index);
    return index;
}

void Studio::compareWithSnapshot(int index) {
    const std::vector<Snapshot>& shots = snapshots_->snapshots();
    comparedSnapshot_ = index >= 0 && index < int(shots.size()) ? index : -1;
    if (comparedSnapshot_ < 0) {
        model_->compareWithSnapshot(-1, nullptr, QString());
        return;
    }
    const Snapshot& s = shots[std::size_t(comparedSnapshot_)];
    if (s.view < 0)
        say(s.name + ": its view '" + QString::fromStdString(s.viewName) + "' is gone; nothing to compare it with",
            5000);
    model_->compareWithSnapshot(s.view, s.image, s.name);
}

void Studio::chooseReferenceView(int view) {
    model_->chooseReferenceView(view);
    const int chosen = model_->referenceView();
    say(chosen < 0 ? QString("Comparing against the reference")
                   : "Comparing against view " + model_->frames()[std::size_t(chosen)].name,
        5000);
}

void Studio::toggleReferenceView(int view) {
    chooseReferenceView(view == model_->referenceView() ? -1 : view);
}

void Studio::setRegion(QRect region) {
    state_.region = region;
    model_->setRegion(region);
}

// --- The camera and the animation

void Studio::updateImpulseMarkers() {
    std::vector<ImageMarker> markers;
    const Scene& scene = session_.project().scene;
    const shader::CameraParams camera = toCameraParams(scene.camera);
    for (const ParticleMedium& m : scene.particleMedia) {
        if (!m.simulation) continue;
        for (const ParticleImpulse& impulse : m.simulation->impulses) {
            const double age = (m.simulation->steps - impulse.step) * m.simulation->timeStep;
            if (age < 0.0 || age > kImpulseMarkerSeconds) continue;
            float depth = 0.0f;
            const glm::vec2 pixel = shader::cameraPixel(camera, glm::vec3(impulse.position), depth);
            if (!(depth > 0.0f)) continue;
            // The push's radius at its depth, in pixels (the field of view spans the image height).
            const double radius = impulse.radius / (double(depth) * camera.tanHalfFovY) * 0.5 * camera.height;
            markers.push_back({QPointF(pixel.x, pixel.y), radius, std::max(0.3, 1.0 - age / kImpulseMarkerSeconds),
                               QString("push, step %1").arg(impulse.step)});
        }
    }
    if (markers.size() == state_.markers.size() &&
        std::equal(markers.begin(), markers.end(), state_.markers.begin(), [](const auto& a, const auto& b) {
            return a.centre == b.centre && a.radius == b.radius && a.opacity == b.opacity && a.label == b.label;
        }))
        return;
    state_.markers = std::move(markers);
    recompose();
}

void Studio::orbitCamera(double yaw, double pitch) {
    QString error;
    if (!camera_.orbit(yaw, pitch, &error) && !error.isEmpty()) say(error, 5000);
}

void Studio::dollyCamera(double factor) {
    QString error;
    if (!camera_.dolly(factor, &error) && !error.isEmpty()) say(error, 5000);
}

void Studio::frameScene() {
    QString error;
    if (!camera_.frameScene(&error) && !error.isEmpty()) say(error, 5000);
}

void Studio::stepAnimation() {
    QString error;
    if (!animation_->step(1, &error)) say(error);
}

void Studio::resetAnimation() {
    QString error;
    if (!animation_->reset(&error)) say(error);
}

// --- Picking

bool Studio::viewAt(QPointF position, int& view, QPoint& pixel) const {
    const std::vector<ViewFrame>& frames = model_->frames();
    const std::vector<QRect> rects = viewRects(frames, state_, viewportSize());
    for (std::size_t i = 0; i < rects.size(); ++i) {
        const QRect& r = rects[i];
        if (r.isEmpty() || !r.contains(position.toPoint())) continue;
        const std::shared_ptr<const Image>& img = frames[i].image ? frames[i].image : frames[i].reference;
        if (!img) return false;
        view = int(i);
        const QRectF visible = visiblePart(QSize(img->width(), img->height()), state_);
        pixel = QPoint(
            std::clamp(int(visible.x() + (position.x() - r.x()) / r.width() * visible.width()), 0, img->width() - 1),
            std::clamp(int(visible.y() + (position.y() - r.y()) / r.height() * visible.height()), 0,
                       img->height() - 1));
        return true;
    }
    return false;
}

bool Studio::particlePointAt(QPointF position, int& medium, Vec3& point) const {
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

bool Studio::addImpulseAt(QPointF position, QString* error) {
    int medium;
    Vec3 point;
    if (!particlePointAt(position, medium, point)) {
        if (error) *error = "No particle medium under the cursor";
        return false;
    }
    return animation_->addImpulse(medium, point, error);
}

bool Studio::imagePlaneAxes(QPointF position, const Vec3& point, Vec3& right, Vec3& up) const {
    int view;
    QPoint pixel;
    if (!viewAt(position, view, pixel)) return false;
    const Camera& cam = session_.project().scene.camera;
    const QRect r = viewRects(model_->frames(), state_, viewportSize())[std::size_t(view)];
    const QRectF visible = visiblePart(QSize(cam.width, cam.height), state_);
    const Vec3 forward = glm::normalize(cam.target - cam.position);
    const Vec3 x = glm::normalize(glm::cross(forward, cam.up)), y = glm::cross(x, forward);
    const double depth = glm::dot(point - cam.position, forward);
    const double metresPerPixel =
        2.0 * depth * std::tan(glm::radians(cam.fovY) * 0.5) / cam.height * visible.height() / std::max(1, r.height());
    right = x * metresPerPixel;
    up = y * metresPerPixel;
    return true;
}

void Studio::inspect(QPointF position) {
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
    emit inspected(html + "</table>");

    // The PDF plot, for a technique that samples distances. Making the job and probing (for WVDS a scene preparation
    // with a BVH build) run in the background pool, never on the GUI thread; only the latest hover's answer is shown.
    const std::uint64_t generation = ++probeGeneration_;
    if (model_->isImage(view)) {
        emit probeMessage(model_->frames()[std::size_t(view)].name + " is an image from a file: no probe");
        return;
    }
    background_->run([this, generation, project = session_.project(), path = session_.path().toStdString(),
                      viewName = session_.project().views[std::size_t(view)].name,
                      technique = model_->frames()[std::size_t(view)].technique, pixel] {
        std::optional<ProbeResult> result;
        QString text;
        try {
            RenderJob job = makeViewJob(project, path, viewName);
            bool hasProbe = false;
            for (const ProbeInfo& p : job.technique->probes())
                hasProbe |= p.name == "distances";
            if (hasProbe)
                result = job.technique->probe(job.request, "distances", pixel.x(), pixel.y());
            else
                text = technique + " has no distance probe";
        } catch (const std::exception& e) {
            text = QString::fromStdString(e.what());
        }
        QMetaObject::invokeMethod(
            this,
            [this, generation, result = std::move(result), text] {
                if (generation != probeGeneration_) return;  // a later hover, or another project, replaced it
                if (result)
                    emit probed(*result);
                else
                    emit probeMessage(text);
            },
            Qt::QueuedConnection);
    });
}

// --- Plots and export

void Studio::setLtsdTablesDirectory(const QString& directory) {
    ltsdTables_.setDirectory(directory);
    emit phasesChanged();
}

bool Studio::exportComparison(const QString& folder, QString* error) {
    return exporter_->exportNow(
        folder, {model_->frames(), state_, composedFrame(), plotFiles_ ? plotFiles_() : std::vector<PlotFile>{}},
        error);
}

void Studio::startExport(const QString& folder) {
    exporter_->start(folder,
                     {model_->frames(), state_, composedFrame(), plotFiles_ ? plotFiles_() : std::vector<PlotFile>{}});
}

}  // namespace tyndall::studio
