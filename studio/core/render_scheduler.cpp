#include "render_scheduler.h"

#include "trace.h"

#include "tyndall/gpu/context.h"
#include "tyndall/image/image_io.h"
#include "tyndall/techniques/registry.h"

#include <QCryptographicHash>
#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QStandardPaths>

#include <nlohmann/json.hpp>

#include <algorithm>

namespace tyndall::studio {

namespace {

// References restart this long after the last edit of their part.
constexpr int kDebounceMs = 300;
// A view's render in flight is let finish for a newer state (a drag then shows an image at the rate the technique
// renders) only while it is shorter than this: a longer one is cancelled, so that a typed value that is slow to
// render (LTSD nodes = 1 in 2.7 s) does not hold back the value that replaced it.
constexpr qint64 kSupersedeMs = 1000;

// What a view's render depends on in the scene: the camera, the surfaces and its part's lights and media, as JSON.
// `j` is projectToJson(project), made once for all the views of an edit (a drag edits the scene at every step).
std::string partKeyOf(const nlohmann::json& j, const Project& project, const View& view) {
    ScenePart part;
    try {
        part = resolvePart(techniqueCatalogue(), project, view);
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

// What a view's own render depends on besides its part: its parameters. Not its exposure: images are linear radiance,
// and the exposure applies where they are shown, compared (PSNR) and exported.
std::string viewKeyOf(const View& view) {
    return view.parameters.dump();
}

// The state of a view's part of the scene, from its part key: images of one state are comparable.
quint64 stateOfKey(const std::string& partKey) {
    const QByteArray hash = QCryptographicHash::hash(QByteArray::fromStdString(partKey), QCryptographicHash::Sha1);
    quint64 state = 0;
    for (int i = 0; i < 8; ++i)
        state = (state << 8) | quint8(hash[i]);
    return state == 0 ? 1 : state;  // 0 means "no image"
}

// A view's progressive resolution, on the steady clock.
ResolutionSchedule newSchedule() {
    return ResolutionSchedule([] {
        static const QElapsedTimer start = [] {
            QElapsedTimer t;
            t.start();
            return t;
        }();
        return double(start.nsecsElapsed()) * 1e-9;
    });
}

}  // namespace

QString stateName(quint64 state) {
    return QString("%1").arg(state, 16, 16, QLatin1Char('0'));
}

RenderScheduler::RenderScheduler(Session& session, Background& background, QObject* parent)
    : QObject(parent), session_(session), background_(background) {
    service_ = new RenderService(this);
    connect(service_, &RenderService::output, this, &RenderScheduler::onOutput);
    debounce_.setSingleShot(true);
    debounce_.setInterval(kDebounceMs);
    // References restart once the edits of their part pause (a drag would otherwise restart them at every step).
    connect(&debounce_, &QTimer::timeout, this, [this] {
        if (playing_) return;  // setPlaying(false) starts them
        // The views off screen once those on screen show a full image of their state (else a stage of theirs would
        // interrupt one, and its work would be lost), then the references.
        const bool onScreenWaits = !onScreenCaughtUp();
        bool offScreenLeft = false;
        for (auto it = dirtyViews_.begin(); it != dirtyViews_.end();) {
            const int view = *it;
            if (onScreen_[std::size_t(view)] || onScreenWaits) {
                offScreenLeft |= !onScreen_[std::size_t(view)];
                ++it;
                continue;
            }
            it = dirtyViews_.erase(it);
            render(view, false);
        }
        if (offScreenLeft) debounce_.start();
        for (int view : dirtyParts_)
            render(view, true);
        dirtyParts_.clear();
    });
}

void RenderScheduler::setPlaying(bool playing) {
    if (playing_ == playing) return;
    playing_ = playing;
    if (playing) {
        // The references of parts already changed are out of date: their cores go to the views.
        for (int view : dirtyParts_)
            holdReference(view);
    } else if (!dirtyParts_.empty() || !dirtyViews_.empty()) {
        debounce_.start();
    }
}

bool RenderScheduler::onScreenCaughtUp() const {
    for (std::size_t v = 0; v < onScreen_.size(); ++v) {
        if (!onScreen_[v]) continue;
        if (dirtyViews_.count(int(v)) || (pending_[v] && shownState_[v] != states_[v])) return false;
    }
    return true;
}

void RenderScheduler::setOnScreen(const std::vector<bool>& onScreen) {
    if (onScreen.size() != onScreen_.size() || onScreen == onScreen_) return;
    std::vector<int> came;
    for (std::size_t v = 0; v < onScreen.size(); ++v)
        if (onScreen[v] && !onScreen_[v]) came.push_back(int(v));
    onScreen_ = onScreen;
    // A view that comes on screen while its render made off screen (at full resolution, behind the others) is in
    // flight starts again from its first reduced stage; one whose edit waits for the debounce renders now.
    for (int view : came) {
        const std::size_t v = std::size_t(view);
        if (!dirtyViews_.count(view) && pending_[v] && renderedHidden_[v] && shownState_[v] != states_[v])
            render(view, false);
    }
    if (!came.empty()) flushDirty();
}

void RenderScheduler::holdView(int view) {
    const std::size_t v = std::size_t(view);
    if (!pending_[v]) return;
    trace("view %d: render off screen stopped", view);
    service_->cancelView(ids_[v]);
    generation_[v] = nextGeneration_++;  // an output already on its way is dropped
    pending_[v] = false;
    emit stopped(view, false);
}

void RenderScheduler::holdReference(int view) {
    const std::size_t v = std::size_t(view);
    if (!referencePending_[v]) return;
    service_->cancelReference(ids_[v]);
    referenceGeneration_[v] = nextGeneration_++;  // an output already on its way is dropped
    referencePending_[v] = false;
    emit stopped(view, true);
}

RenderScheduler::~RenderScheduler() { service_->cancelAll(); }

std::string RenderScheduler::viewsKey() const {
    std::string key;
    for (const View& v : session_.project().views) key += v.name + "\n" + v.technique + "\n";
    return key;
}

bool RenderScheduler::viewsChanged() const { return viewsKey() != viewsKey_; }

quint64 RenderScheduler::state(int view) const {
    return view >= 0 && view < int(states_.size()) ? states_[std::size_t(view)] : 0;
}

void RenderScheduler::reset() {
    service_->cancelAll();
    const Project& project = session_.project();
    const std::size_t n = project.views.size();
    viewsKey_ = viewsKey();
    partKeys_.clear();
    viewKeys_.clear();
    states_.clear();
    ids_.clear();
    techniques_.clear();
    names_.clear();
    const nlohmann::json json = projectToJson(project);
    for (const View& v : project.views) {
        partKeys_.push_back(partKeyOf(json, project, v));
        viewKeys_.push_back(viewKeyOf(v));
        states_.push_back(stateOfKey(partKeys_.back()));
        ids_.push_back(nextId_++);
        techniques_.push_back(v.technique);
        names_.push_back(v.name);
    }
    generation_.assign(n, 0);
    referenceGeneration_.assign(n, 0);
    pending_.assign(n, false);
    referencePending_.assign(n, false);
    progressive_.assign(n, false);
    onScreen_.assign(n, true);
    renderedHidden_.assign(n, false);
    shownState_.assign(n, 0);
    shownGeneration_.assign(n, 0);
    submitted_.assign(n, QElapsedTimer());
    lastSeconds_.assign(n, -1.0);
    schedules_.assign(n, newSchedule());
    dirtyViews_.clear();
    dirtyParts_.clear();
    sppShown_.clear();
    debounce_.stop();
}

std::vector<int> RenderScheduler::followViews() {
    const Project& project = session_.project();
    const std::size_t n = project.views.size();
    const nlohmann::json json = projectToJson(project);
    std::vector<std::string> partKeys, viewKeys;
    for (const View& v : project.views) {
        partKeys.push_back(partKeyOf(json, project, v));
        viewKeys.push_back(viewKeyOf(v));
    }
    // Which view each one was: the same name with the same renders first, then one renamed (the first unclaimed
    // view with the same technique, part and parameters whose name is gone; a duplicate renders anew, since its
    // original keeps the name).
    std::vector<int> oldOf(n, -1);
    std::vector<bool> claimed(ids_.size(), false);
    std::set<std::string> newNames, oldNames(names_.begin(), names_.end());
    for (const View& v : project.views)
        newNames.insert(v.name);
    auto claim = [&](std::size_t i, bool renamed) {
        for (std::size_t o = 0; o < ids_.size(); ++o) {
            const bool candidate = renamed ? !newNames.count(names_[o]) : names_[o] == project.views[i].name;
            if (claimed[o] || !candidate || techniques_[o] != project.views[i].technique ||
                partKeys_[o] != partKeys[i] || viewKeys_[o] != viewKeys[i])
                continue;
            oldOf[i] = int(o);
            claimed[o] = true;
            return;
        }
    };
    for (std::size_t i = 0; i < n; ++i)
        claim(i, false);
    for (std::size_t i = 0; i < n; ++i)
        if (oldOf[i] < 0 && !oldNames.count(project.views[i].name)) claim(i, true);
    // The views that are gone: their renders stop.
    for (std::size_t o = 0; o < ids_.size(); ++o)
        if (!claimed[o]) service_->cancelView(ids_[o]);

    auto follow = [&](auto& values, auto fresh) {
        std::remove_reference_t<decltype(values)> next;
        for (std::size_t i = 0; i < n; ++i)
            next.push_back(oldOf[i] >= 0 ? values[std::size_t(oldOf[i])] : fresh);
        values = std::move(next);
    };
    follow(generation_, quint64(0));
    follow(referenceGeneration_, quint64(0));
    follow(pending_, false);
    follow(referencePending_, false);
    follow(progressive_, false);
    follow(onScreen_, true);
    follow(renderedHidden_, false);
    follow(shownState_, quint64(0));
    follow(shownGeneration_, quint64(0));
    follow(submitted_, QElapsedTimer());
    follow(lastSeconds_, -1.0);
    follow(schedules_, newSchedule());
    follow(ids_, -1);
    std::set<int> dirtyViews, dirtyParts;
    for (std::size_t i = 0; i < n; ++i) {
        if (ids_[i] < 0) ids_[i] = nextId_++;
        if (oldOf[i] >= 0 && dirtyViews_.count(oldOf[i])) dirtyViews.insert(int(i));
        if (oldOf[i] >= 0 && dirtyParts_.count(oldOf[i])) dirtyParts.insert(int(i));
    }
    dirtyViews_ = std::move(dirtyViews);
    dirtyParts_ = std::move(dirtyParts);
    partKeys_ = std::move(partKeys);
    viewKeys_ = std::move(viewKeys);
    states_.clear();
    techniques_.clear();
    names_.clear();
    for (std::size_t i = 0; i < n; ++i) {
        states_.push_back(stateOfKey(partKeys_[i]));
        techniques_.push_back(project.views[i].technique);
        names_.push_back(project.views[i].name);
    }
    viewsKey_ = viewsKey();
    return oldOf;
}

int RenderScheduler::indexOfId(int id) const {
    const auto it = std::find(ids_.begin(), ids_.end(), id);
    return it == ids_.end() ? -1 : int(it - ids_.begin());
}

void RenderScheduler::renderView(int view) {
    if (view < 0 || view >= int(states_.size())) return;
    render(view, false);
    render(view, true);
}

void RenderScheduler::renderAll() {
    for (int i = 0; i < int(states_.size()); ++i)
        render(i, false);
    for (int i = 0; i < int(states_.size()); ++i)
        render(i, true);
}

void RenderScheduler::cancelAll() { service_->cancelAll(); }

void RenderScheduler::viewEdited(int view) {
    if (view < 0 || view >= int(viewKeys_.size())) return;
    std::string key = viewKeyOf(session_.project().views[std::size_t(view)]);
    if (key == viewKeys_[std::size_t(view)]) return;  // its exposure: only the display changes
    viewKeys_[std::size_t(view)] = std::move(key);
    dirtyViews_.insert(view);
    flushDirty();
}

void RenderScheduler::sceneEdited() {
    const Project& project = session_.project();
    const nlohmann::json json = projectToJson(project);
    for (int i = 0; i < int(partKeys_.size()) && i < int(project.views.size()); ++i) {
        const View& view = project.views[std::size_t(i)];
        const std::string viewKey = viewKeyOf(view);
        if (viewKey != viewKeys_[std::size_t(i)]) {
            viewKeys_[std::size_t(i)] = viewKey;
            dirtyViews_.insert(i);
        }
        const std::string key = partKeyOf(json, project, view);
        if (key == partKeys_[std::size_t(i)]) continue;
        partKeys_[std::size_t(i)] = key;
        states_[std::size_t(i)] = stateOfKey(key);
        emit stateChanged(i, states_[std::size_t(i)]);
        dirtyViews_.insert(i);
        dirtyParts_.insert(i);
        if (playing_) holdReference(i);
    }
    flushDirty();
    if (!dirtyParts_.empty() && !playing_) debounce_.start();
}

bool RenderScheduler::makeTask(int view, bool reference, int factor, RenderTask& task) {
    const Project& project = session_.project();
    const View& v = project.views[std::size_t(view)];
    task.view = ids_[std::size_t(view)];
    task.reference = reference;
    task.factor = factor;
    // The path tracer as a view, or any technique that sent progressive images, may render for minutes (a reduced
    // stage is short).
    task.slow = !reference && factor == 1 && (progressive_[std::size_t(view)] || v.technique == "reference");
    task.hidden = !reference && !onScreen_[std::size_t(view)];
    task.generation = nextGeneration_++;
    task.state = states_[std::size_t(view)];
    try {
        task.job = std::make_shared<RenderJob>(reference ? makeReferenceJob(project, session_.path().toStdString(), v.name)
                                                         : makeViewJob(project, session_.path().toStdString(), v.name));
        // Every image carries the state of its part (exports pair a view with its reference by it).
        task.job->metadata["partHash"] = stateName(task.state).toStdString();
        if (factor > 1) {
            // A reduced stage: the same render at 1/factor of the resolution in each axis, for its first image.
            Camera& camera = task.job->request.scene.camera;
            camera.width = std::max(1, (camera.width + factor - 1) / factor);
            camera.height = std::max(1, (camera.height + factor - 1) / factor);
            task.job->metadata["resolutionFactor"] = std::to_string(factor);
            // And less of the work that does not shrink with the image, where the technique says so (its label).
            const std::string reduced = task.job->technique->reduceForPreview(task.job->request.params, factor);
            if (!reduced.empty()) task.job->metadata["reducedWork"] = reduced;
        }
        // A technique view that renders on a hardware GPU may run beside the CPU's renders (RenderService).
        if (!reference && task.job->request.params.find("device")) {
            const std::string& device = task.job->request.params.getEnum("device");
            task.gpu = device == "gpu" || (device == "auto" && gpu::hardwareDeviceAvailable());
        }
    } catch (const std::exception& e) {
        emit failed(view, QString::fromStdString(e.what()));
        return false;
    }
    return true;
}

void RenderScheduler::render(int view, bool reference) {
    // A view's new state starts its progressive resolution again (resolution_schedule.h).
    if (reference) return renderStage(view, 0);
    // A view off screen goes straight to its full resolution: nobody would see its reduced images.
    const bool staged = progressiveResolution_ && onScreen_[std::size_t(view)];
    renderStage(view, staged ? schedules_[std::size_t(view)].begin() : 1);
}

void RenderScheduler::renderStage(int view, int factor) {
    const bool reference = factor == 0;
    RenderTask task;
    if (!makeTask(view, reference, std::max(factor, 1), task)) return;
    quint64& generation = (reference ? referenceGeneration_ : generation_)[std::size_t(view)];
    sppShown_.erase(generation);
    generation = task.generation;
    (reference ? referencePending_ : pending_)[std::size_t(view)] = true;
    emit started(view, reference, task.job->request.spp);
    if (!reference) {
        // The full resolution after a reduced image on screen is no longer a first image: in the class of slow
        // renders, so that another view's first image (an edit there) goes first instead of waiting for it, while
        // it still goes before other views' refinements (a progressive view's accumulation) (RenderService).
        if (factor == 1 && progressiveResolution_ && schedules_[std::size_t(view)].shown()) task.slow = true;
        renderedHidden_[std::size_t(view)] = task.hidden;
        trace("view %d: job made (1/%d%s)", view, task.factor, task.hidden ? ", off screen" : "");
        submitted_[std::size_t(view)].start();
        service_->submit(std::move(task));
        return;
    }
    // A finished reference of exactly this part of the scene may be on disk already.
    const QString cached = referenceCachePath(view);
    cachePathOf_[task.generation] = cached;
    if (QFile::exists(cached)) {
        // Read in the background (an EXR of 512 x 512 takes ~10 ms, more while renders run); an unreadable file is
        // removed and the reference rendered after all.
        service_->cancelReference(task.view);
        background_.run([this, task, cached] {
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
                QMetaObject::invokeMethod(
                    this,
                    [this, task] {
                        const int index = indexOfId(task.view);
                        if (index >= 0 && task.generation == referenceGeneration_[std::size_t(index)])
                            service_->submit(task);
                    },
                    Qt::QueuedConnection);
                return;
            }
            QMetaObject::invokeMethod(this, [this, out] { onOutput(out); }, Qt::QueuedConnection);
        });
        return;
    }
    service_->submit(std::move(task));
}

QString RenderScheduler::referenceCacheFolder() {
    return QStandardPaths::writableLocation(QStandardPaths::CacheLocation) + "/references";
}

QString RenderScheduler::referenceCachePath(int view) const {
    // Everything the reference's image depends on: its part of the scene, the reference settings (in the part key),
    // where relative files resolve, and the renderer's version.
    // (The part key is current: reset() and sceneEdited() keep it, synchronously with the session's edits.)
    const std::string key = partKeys_[std::size_t(view)] + "|" +
                            QFileInfo(session_.path()).absolutePath().toStdString() + "|" + tyndallVersion();
    const QByteArray hash = QCryptographicHash::hash(QByteArray::fromStdString(key), QCryptographicHash::Sha1).toHex();
    return referenceCacheFolder() + "/" + QString::fromLatin1(hash) + ".exr";
}

void RenderScheduler::flushDirty() {
    // While the animation plays, a progressive view (the path tracer as a view, whose render may take minutes) is not
    // waited for: play advances only once it has shown an image of its state, and then its render in flight is
    // replaced at once.
    if (animating_) {
        for (auto it = dirtyViews_.begin(); it != dirtyViews_.end();) {
            if (!progressive_[std::size_t(*it)]) {
                ++it;
                continue;
            }
            const int view = *it;
            it = dirtyViews_.erase(it);
            render(view, false);
        }
    }
    qint64 recheck = -1;  // when the oldest render let finish reaches kSupersedeMs
    bool offScreenWait = false;
    for (auto it = dirtyViews_.begin(); it != dirtyViews_.end();) {
        const std::size_t v = std::size_t(*it);
        // Off screen: once the edits pause (not while the animation plays: it waits for every view). Its render of
        // an older state, if one is in flight (started at the last pause), stops: it would take the cores from the
        // views on screen for an image of a state nobody sees.
        if (!onScreen_[v] && !animating_ && !playing_) {
            holdView(int(v));
            offScreenWait = true;
            ++it;
            continue;
        }
        if (pending_[v]) {
            const qint64 ran = submitted_[v].isValid() ? submitted_[v].elapsed() : 0;
            // A stage in flight is judged by the predicted time to its first image (a reduced one's is about the
            // schedule's budget), not by the view's last finished render: replacing it at every step of a drag over a
            // view whose finished image takes seconds (LTSD with shadows, the path tracer's 64 spp) would never let an
            // image through (measured: 1.5 s median from a step to the screen).
            const int stage = progressiveResolution_ ? schedules_[v].current() : 0;
            const double stageSeconds =
                stage > 0 ? schedules_[v].predicted(stage).value_or(lastSeconds_[v]) : lastSeconds_[v];
            const bool slow = stageSeconds * 1e3 >= double(kSupersedeMs) || ran >= kSupersedeMs;
            // A progressive render that has shown its first image only refines (and may be waiting in the queue
            // behind another view's first image), as does a finer stage of an edit whose reduced image is on screen:
            // the new state's first image comes first.
            const bool refining =
                shownGeneration_[v] == generation_[v] || (progressiveResolution_ && schedules_[v].shown());
            if (!slow && !refining) {
                recheck = recheck < 0 ? kSupersedeMs - ran : std::min(recheck, kSupersedeMs - ran);
                ++it;
                continue;
            }
        }
        const int view = *it;
        it = dirtyViews_.erase(it);
        render(view, false);  // replaces the render in flight, if any
    }
    if (recheck >= 0) QTimer::singleShot(int(std::max<qint64>(recheck, 1)), this, [this] { flushDirty(); });
    if (offScreenWait) debounce_.start();
}

bool RenderScheduler::settled() const {
    for (bool p : pending_)
        if (p) return false;
    for (bool p : referencePending_)
        if (p) return false;
    return service_->idle() && dirtyViews_.empty() && dirtyParts_.empty() && !debounce_.isActive();
}

bool RenderScheduler::busy(int view, bool reference) const {
    if (view < 0 || view >= int(pending_.size())) return false;
    if (reference) return referencePending_[std::size_t(view)] || dirtyParts_.count(view);
    return pending_[std::size_t(view)] || dirtyViews_.count(view);
}

bool RenderScheduler::viewsCaughtUp() const {
    for (std::size_t i = 0; i < pending_.size(); ++i) {
        if (dirtyViews_.count(int(i))) return false;
        if (!pending_[i]) continue;
        // A progressive view has caught up once it shows a pass of the current state.
        if (progressive_[i] && shownState_[i] == states_[i]) continue;
        return false;
    }
    return true;
}

void RenderScheduler::onOutput(const RenderOutput& task) {
    // The task carries its view's id; the view may have moved (views added or removed before it) or be gone.
    RenderOutput out = task;
    out.view = indexOfId(task.view);
    trace("%s %d: image received (%d spp)", out.reference ? "reference" : "view", out.view, out.spp);
    if (out.view < 0) return;
    const std::vector<quint64>& generations = out.reference ? referenceGeneration_ : generation_;
    if (out.generation != generations[std::size_t(out.view)]) return;  // stale: a newer render is on its way
    // A render interrupted for another view's first image starts again from zero (RenderService): its progressive
    // images go out only once they have more samples than the one shown.
    if (!out.final && out.image) {
        auto [shown, fresh] = sppShown_.try_emplace(out.generation, out.spp);
        if (!fresh && out.spp <= shown->second) return;
        shown->second = out.spp;
    }
    if (out.final) sppShown_.erase(out.generation);
    const std::size_t v = std::size_t(out.view);
    if (!out.reference && out.image) {
        // The schedule's stage delivered its first image: a reduced one goes out as a preview and the next stage
        // replaces it (or, after an edit meanwhile, the new state's first stage).
        const int next = schedules_[v].delivered(out.factor, out.seconds);
        if (out.factor > 1) {
            emit output(out);
            if (dirtyViews_.erase(out.view))
                render(out.view, false);
            else
                renderStage(out.view, next);
            return;
        }
    }
    if (out.factor > 1) {  // a reduced stage failed: the full resolution says why, or renders
        renderStage(out.view, 1);
        return;
    }
    if (!out.reference && !out.final && out.image) progressive_[v] = true;
    if (!out.reference && out.image) {
        shownState_[v] = out.state;
        shownGeneration_[v] = out.generation;
    }
    if (out.reference && out.error.isEmpty()) {
        // A finished reference goes to the disk cache, written in the pool (an EXR of 512 x 512 takes ~0.2 s),
        // atomically, so that a reader never sees half of it.
        const auto path = cachePathOf_.find(out.generation);
        if (out.final && !out.cached && path != cachePathOf_.end() && out.image) {
            QDir().mkpath(referenceCacheFolder());
            background_.run([image = out.image, file = path->second.toStdString()] {
                try {
                    writeImage(*image, file);
                } catch (const std::exception&) {
                    // A cache that cannot be written costs a render next time, nothing else.
                }
            });
        }
    }
    if (out.reference && out.final) cachePathOf_.erase(out.generation);
    if (out.final) (out.reference ? referencePending_ : pending_)[v] = false;
    if (!out.reference && out.final && out.image) lastSeconds_[v] = out.seconds;
    emit output(out);
    if (!out.reference && out.final && dirtyViews_.count(out.view)) QTimer::singleShot(0, this, [this] { flushDirty(); });
}

}  // namespace tyndall::studio
