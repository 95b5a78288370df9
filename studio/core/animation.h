// The particle simulation driven from the studio (issue #20 item 6, ISV thesis Sec. 3.14): play, pause, step, reset,
// impulses under the mouse and the region of targets moved. Every change is an undoable scene edit of the particle
// media's `simulation` (Session::editScene), so the project on screen is the frame that is saved, and the CLI renders
// the same frame from the saved file.
#pragma once

#include "session.h"

#include "tyndall/core/scene.h"

#include <QElapsedTimer>
#include <QObject>
#include <QTimer>

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
    // click's radius and speed; the medium advances one step with it, so that its push shows at once (an impulse's step
    // must be below `steps`). One undo step.
    bool addImpulse(int medium, const Vec3& position, QString* error);
    // Moves the region of targets of `medium` to `offset` (m); edits with the same non-negative mergeId are one step.
    bool setOffset(int medium, const Vec3& offset, QString* error, int mergeId = -1);

    // What a click's impulse pushes with (the Scene dock edits them): m, > 0, and m/s, >= 0.
    double impulseRadius() const { return impulseRadius_; }
    double impulseSpeed() const { return impulseSpeed_; }
    void setImpulseRadius(double radius) { impulseRadius_ = radius; }
    void setImpulseSpeed(double speed) { impulseSpeed_ = speed; }

    // Simulated time advances at wall-clock rate, in whole steps, at most this often (and only when the views are
    // ready): a fast view sees ~30 frames a second, a slow one fewer and larger advances.
    static constexpr int kTickMs = 33;

signals:
    void playingChanged(bool playing);
    void advancing(bool during);  // around each edit of play (RenderScheduler restarts a progressive view's render)
    void refused(const QString& reason);  // play stopped: an advance was refused (the simulation's limits)

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
    double impulseRadius_ = 0.5, impulseSpeed_ = 1.0;
};

}  // namespace tyndall::studio
