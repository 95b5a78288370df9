// The particle simulation driven from the studio (issue #20 item 6, ISV thesis Sec. 3.14): play, pause, step, reset,
// impulses under the mouse and the region of targets moved. Every change is an undoable scene edit of the particle
// media's `simulation` (Session::editScene), so the project on screen is the frame that is saved, and the CLI renders
// the same frame from the saved file.
#pragma once

#include "session.h"

#include "tyndall/core/scene.h"

#include <QElapsedTimer>
#include <QObject>
#include <QString>
#include <QTimer>

#include <algorithm>
#include <functional>
#include <optional>
#include <vector>

namespace tyndall::studio {

// Where an impulse clicked at image point (px, py) of `camera` (pixels, top-left origin, as in shaders/shared/camera.h)
// goes: on the camera ray through it, at the distance of the nearest (along the ray) of `particles` whose centre the ray
// passes within that particle's scale of; when it passes near none, at the distance of the particles' bounding-box
// centre (the cloud's middle). `hit` says which. Empty without particles or for a centre behind the camera.
std::optional<Vec3> impulsePoint(const Camera& camera, const std::vector<Particle>& particles, double px, double py,
                                 bool* hit = nullptr);

class Animation : public QObject {
    Q_OBJECT
public:
    explicit Animation(Session& session, QObject* parent = nullptr);

    // Whether the views have caught up with the last advance; play advances only then (RenderScheduler::viewsCaughtUp:
    // every fast view has delivered an image of the current state, a progressive one its first pass).
    void setViewsReady(std::function<bool()> ready) { viewsReady_ = std::move(ready); }

    bool available() const;  // the project has a particle medium
    bool playing() const { return timer_.isActive(); }
    void play();
    void pause();
    void togglePlay();
    // Advances every particle medium by `steps` (creating its simulation with the defaults when it has none): one undo
    // step, or, with a non-negative mergeId, merged with the edits of the same id before it (one play).
    bool step(int steps, QString* error, int mergeId = -1);
    // Steps 0, no impulses, offset 0 in every particle medium with a simulation (its other settings stay); pauses.
    bool reset(QString* error);
    // An impulse in particle medium `medium` (index into particleMedia) at `position`, at the current step, with the
    // click's radius and speed. While playing, the medium advances one step with it (an impulse's step must be below
    // `steps`) and play shows the push; paused, it advances to the push's farthest (impulsePeakSeconds), so that the
    // click shows what it did. One undo step.
    bool addImpulse(int medium, const Vec3& position, QString* error);
    // Moves the region of targets of `medium` to `offset` (m); edits with the same non-negative mergeId are one step.
    bool setOffset(int medium, const Vec3& offset, QString* error, int mergeId = -1);

    // What a click's impulse pushes with (the Scene dock edits them): m, > 0, and m/s, >= 0.
    double impulseRadius() const { return impulseRadius_; }
    double impulseSpeed() const { return impulseSpeed_; }
    void setImpulseRadius(double radius) { impulseRadius_ = radius; }
    void setImpulseSpeed(double speed) { impulseSpeed_ = speed; }

    // The pace of play. Simulated time advances at wall-clock rate, in whole steps, at most every kTickMs and only once
    // the views have shown the last advance; with a limit of steps per frame (> 0), a frame advances by at most that
    // many steps and the time beyond is dropped: slow views play in slow motion, every step of the motion shown
    // (Blender's "play every frame"), fast ones in real time. 0: real time, slow views skipping steps.
    int maxStepsPerFrame() const { return maxStepsPerFrame_; }
    void setMaxStepsPerFrame(int steps) { maxStepsPerFrame_ = std::max(0, steps); }
    static constexpr int kDefaultMaxStepsPerFrame = 4;
    static constexpr int kTickMs = 33;

    // What the toolbar shows: the frame ("step 45 · 0.75 s", each simulated medium by name when there are several,
    // "not simulated" for none) and, while playing, the pace against real time ("0.12x real time").
    QString clockText() const;
    // The impulses (step, time) of every simulated medium, for the clock's tooltip.
    QString impulsesText() const;
    // Simulated seconds per wall-clock second over the last few advances of this play (0 before two advances).
    double pace() const { return pace_; }

signals:
    void playingChanged(bool playing);
    void advancing(bool during);  // around each edit of play (RenderScheduler restarts a progressive view's render)
    void refused(const QString& reason);  // play stopped: an advance was refused (the simulation's limits)
    void clockChanged();                  // clockText() changed: a step, a play, a pause

private:
    void tick();
    // One scene edit of the `simulation` (JSON, {} when the medium has none) of each of `media`.
    bool edit(const std::function<void(nlohmann::json& simulation, std::size_t medium)>& change,
              const std::vector<std::size_t>& media, const QString& text, QString* error, int mergeId);

    Session& session_;
    std::function<bool()> viewsReady_;
    QTimer timer_;
    QElapsedTimer sinceAdvance_;
    std::vector<double> carry_;  // per medium: simulated seconds owed, less than a step
    int plays_ = 0;              // each play is one undo step: its merge id
    int maxStepsPerFrame_ = kDefaultMaxStepsPerFrame;
    // The pace: simulated and wall-clock seconds of this play's advances, decayed so that it follows the views.
    double simulatedSeconds_ = 0.0, wallSeconds_ = 0.0, pace_ = 0.0;
    QElapsedTimer sincePlay_;
    double impulseRadius_ = 0.5, impulseSpeed_ = 1.0;
};

}  // namespace tyndall::studio
