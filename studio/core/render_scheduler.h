// What renders when: the studio's render orchestration between the session's project and the comparison model.
//
// Each view's render depends on its part of the scene (the camera, the surfaces, its lights and media, the reference
// settings): the part key, hashed into the part's state. A view's own edit of its parameters re-renders the view
// alone (its exposure is the display's: the compositor, the metrics and the exports apply it, nothing renders), at once
// when it is not rendering and otherwise when its render in flight is done, so that a drag shows a new image at the
// rate the technique renders and the last state always renders; a render in flight that would hold the new state back
// for long (it has run kSupersedeMs, or the view's last render took longer), or that has shown its first image and only
// refines, is cancelled instead. An edit of a part re-renders the views of that part and, once the edits pause (a
// debounce), their references. Finished references are cached on disk by the hash of what they render, so that
// reopening a project does not start from zero. Every task carries a generation; outputs of older generations are
// dropped here, and what passes goes out through `output` in order.
#pragma once

#include "background.h"
#include "render_service.h"
#include "resolution_schedule.h"
#include "session.h"

#include <QElapsedTimer>
#include <QObject>
#include <QTimer>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace tyndall::studio {

// A part's state as its images carry it (the metadata "partHash"): 16 hexadecimal digits.
QString stateName(quint64 state);

class RenderScheduler : public QObject {
    Q_OBJECT
public:
    RenderScheduler(Session& session, Background& background, QObject* parent = nullptr);
    ~RenderScheduler() override;

    // The project's views as they are now: cancels and forgets every render (the parts' states are known after it).
    void reset();
    // Renders every view, then every reference.
    void renderAll();
    // The views' list changed (added, removed, renamed, another technique): followViews() or reset() is needed.
    bool viewsChanged() const;
    // Follows an authoring of the views (add, duplicate, rename, remove, or its undo): a view whose technique, part
    // and parameters did not change keeps its renders, in flight or done, under its new index (by its name first, then
    // as the one renamed); the others need renderView(). Returns, per view, the index it had before (-1: new), for the
    // comparison model to keep its images.
    std::vector<int> followViews();
    void renderView(int view);  // the view and its reference
    // An edit of view `view`'s parameters or exposure (which renders nothing).
    void viewEdited(int view);
    // An edit of the scene: the views whose part changed (stateChanged) render again, and their references once the
    // edits pause; views whose parameters changed (a whole project replaced: recovery, or its undo) render alone.
    void sceneEdited();
    void cancelAll();

    quint64 state(int view) const;  // of the view's part: images of one state compare (never 0)
    // While the animation plays, a progressive view's render in flight is replaced at once by the next frame's.
    void setAnimating(bool animating) { animating_ = animating; }
    // While the animation plays, references wait (each would be out of date at the next frame, and would take the
    // cores from the views): those of changed parts are cancelled, and they all start once play pauses.
    void setPlaying(bool playing);
    // Reduced stages after an edit (resolution_schedule.h); off, every render is at full resolution (the latency
    // bench compares both).
    void setProgressiveResolution(bool on) { progressiveResolution_ = on; }
    bool playing() const { return playing_; }
    // Which views are on screen (the layout's; every one by default). A view off screen is not dragged at: after an
    // edit it renders once the edits pause (the references' debounce) and every view on screen shows a full image of
    // its state, at full resolution, in RenderService's refinement class (the next edit stops that render); a view
    // that comes on screen with its state still unshown starts its progressive resolution at once.
    void setOnScreen(const std::vector<bool>& onScreen);
    // Every view shows (or is done with) the current state: the animation may advance.
    bool viewsCaughtUp() const;
    // Nothing is queued, running or waiting for its debounce.
    bool settled() const;
    // A render of the view's image (or of its reference) is queued, running or waiting for an edit's debounce.
    bool busy(int view, bool reference) const;

    static QString referenceCacheFolder();
    QString referenceCachePath(int view) const;
    RenderService& service() { return *service_; }

signals:
    // A render was submitted (targetSpp: what it renders to; a reference's) or could not be made (the job's error).
    void started(int view, bool reference, int targetSpp);
    void failed(int view, const QString& error);
    void stopped(int view, bool reference);  // a render was cancelled and nothing replaces it yet
    // An image (progressive or final) or a failure of the current generation.
    void output(const tyndall::studio::RenderOutput& out);
    void stateChanged(int view, quint64 state);

private:
    void render(int view, bool reference);
    // A view's render at 1/factor of its resolution (1: full), a stage of its schedule.
    void renderStage(int view, int factor);
    // The task of a render, its job made; false (with `failed` emitted) when the job cannot be made.
    bool makeTask(int view, bool reference, int factor, RenderTask& task);
    void holdView(int view);       // cancels the view's render in flight until the edits pause (off screen)
    void holdReference(int view);  // cancels the view's reference render until the play pauses
    // Every view on screen shows a full-resolution image of its state (a progressive one may go on refining).
    bool onScreenCaughtUp() const;
    int indexOfId(int id) const;  // the view a task's id stands for now; -1 when it was removed
    void flushDirty();
    void onOutput(const RenderOutput& out);
    std::string viewsKey() const;

    Session& session_;
    Background& background_;
    RenderService* service_ = nullptr;
    std::string viewsKey_;                 // the views' names and techniques when restart() ran
    std::vector<std::string> partKeys_;    // per view
    std::vector<std::string> viewKeys_;    // each view's parameters
    std::vector<quint64> states_;
    // Each view's id: what its tasks carry as RenderTask::view, so that a render in flight follows its view when
    // views are added or removed before it (followViews).
    std::vector<int> ids_;
    int nextId_ = 0;
    std::vector<std::string> techniques_, names_;  // per view, as of reset() or followViews()
    std::vector<quint64> generation_, referenceGeneration_;
    std::vector<bool> pending_;            // a technique render of the view is queued or running
    std::vector<bool> referencePending_;   // so is a reference render
    std::vector<bool> progressive_;        // the view's technique sent a progressive image (it may render for long)
    std::vector<bool> onScreen_;           // setOnScreen()
    std::vector<bool> renderedHidden_;     // the view's render in flight was made while it was off screen
    std::vector<quint64> shownState_;      // the state of the view's latest image
    std::vector<quint64> shownGeneration_;  // the render that sent it (the one in flight: it only refines now)
    std::vector<QElapsedTimer> submitted_;  // when the view's render in flight was submitted
    std::vector<double> lastSeconds_;       // how long the view's last finished render took (-1: none yet)
    std::vector<ResolutionSchedule> schedules_;  // each view's progressive resolution (resolution_schedule.h)
    std::set<int> dirtyViews_;             // edited views waiting for their render in flight to finish
    std::set<int> dirtyParts_;             // views whose references restart after the debounce
    std::map<quint64, QString> cachePathOf_;  // reference renders in flight: where their result is cached
    std::map<quint64, int> sppShown_;         // renders in flight (by generation): the spp of their last image
    QTimer debounce_;
    quint64 nextGeneration_ = 1;
    bool animating_ = false;
    bool playing_ = false;
    bool progressiveResolution_ = true;
};

}  // namespace tyndall::studio
