#include "animation.h"

#include "shared/camera.h"
#include "tyndall/framework/shader_params.h"

#include <QStringList>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tyndall::studio {

namespace {

nlohmann::json vec3Json(const Vec3& v) {
    return nlohmann::json::array({v.x, v.y, v.z});
}

// A medium's simulation step (the default one's when it has no simulation yet).
double timeStepOf(const ParticleMedium& medium) {
    return medium.simulation ? medium.simulation->timeStep : ParticleSimulation{}.timeStep;
}

}  // namespace

std::optional<Vec3> impulsePoint(const Camera& camera, const std::vector<Particle>& particles, double px, double py,
                                 bool* hit) {
    if (hit) *hit = false;
    if (particles.empty()) return std::nullopt;
    glm::vec3 o, d;
    shader::cameraRay(toCameraParams(camera), float(px), float(py), o, d);
    const Vec3 origin = camera.position, dir = glm::normalize(Vec3(d));
    // The nearest particle the ray passes within its scale of (its tetrahedron's circumsphere), in front of the camera.
    double nearest = std::numeric_limits<double>::infinity();
    Vec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (const Particle& p : particles) {
        lo = glm::min(lo, p.centre);
        hi = glm::max(hi, p.centre);
        const double t = glm::dot(p.centre - origin, dir);
        if (t <= 0.0 || t >= nearest) continue;
        if (glm::length(origin + t * dir - p.centre) < p.scale) nearest = t;
    }
    if (std::isfinite(nearest)) {
        if (hit) *hit = true;
        return origin + nearest * dir;
    }
    const double t = glm::dot(0.5 * (lo + hi) - origin, dir);
    if (!(t > 0.0)) return std::nullopt;
    return origin + t * dir;
}

Animation::Animation(Session& session, QObject* parent) : QObject(parent), session_(session) {
    timer_.setInterval(kTickMs);
    connect(&timer_, &QTimer::timeout, this, &Animation::tick);
    // Another project stops the animation.
    connect(&session_, &Session::projectReplaced, this, [this] {
        pause();
        emit clockChanged();
    });
    connect(&session_, &Session::sceneChanged, this, &Animation::clockChanged);
}

QString Animation::clockText() const {
    QStringList media;
    const std::vector<ParticleMedium>& all = session_.project().scene.particleMedia;
    int simulated = 0;
    for (const ParticleMedium& m : all)
        simulated += bool(m.simulation);
    for (const ParticleMedium& m : all) {
        if (!m.simulation) continue;
        const QString frame = QString("step %1 · %2 s")
                                  .arg(m.simulation->steps)
                                  .arg(m.simulation->steps * m.simulation->timeStep, 0, 'f', 2);
        media << (simulated > 1 ? QString::fromStdString(m.name) + " " + frame : frame);
    }
    QString text = media.isEmpty() ? QString("step 0 · not simulated yet") : media.join("  ");
    if (playing() && pace_ > 0.0) text += QString("  ·  %1x real time").arg(pace_, 0, 'g', 2);
    return text;
}

QString Animation::impulsesText() const {
    QStringList lines;
    for (const ParticleMedium& m : session_.project().scene.particleMedia) {
        if (!m.simulation) continue;
        for (const ParticleImpulse& impulse : m.simulation->impulses)
            lines << QString("%1: impulse at step %2 (%3 s), radius %4 m, %5 m/s")
                         .arg(QString::fromStdString(m.name))
                         .arg(impulse.step)
                         .arg(impulse.step * m.simulation->timeStep, 0, 'f', 2)
                         .arg(impulse.radius)
                         .arg(impulse.speed);
    }
    return lines.isEmpty() ? QString("No impulses (Ctrl+click a view to push the particles)") : lines.join("\n");
}

bool Animation::available() const {
    return !session_.project().scene.particleMedia.empty();
}

void Animation::play() {
    if (playing() || !available()) return;
    ++plays_;
    carry_.assign(session_.project().scene.particleMedia.size(), 0.0);
    simulatedSeconds_ = wallSeconds_ = pace_ = 0.0;
    sinceAdvance_.start();
    timer_.start();
    emit playingChanged(true);
    emit clockChanged();
}

void Animation::pause() {
    if (!playing()) return;
    timer_.stop();
    emit playingChanged(false);
    emit clockChanged();
}

void Animation::togglePlay() {
    playing() ? pause() : play();
}

void Animation::tick() {
    if (!available()) {
        pause();
        return;
    }
    if (viewsReady_ && !viewsReady_()) return;
    // The simulated time that passed since the last advance (however long the views took), in whole steps of each
    // medium; what is left of a step is carried to the next advance.
    const std::vector<ParticleMedium>& media = session_.project().scene.particleMedia;
    if (carry_.size() != media.size()) carry_.assign(media.size(), 0.0);
    const double elapsed = double(sinceAdvance_.nsecsElapsed()) * 1e-9;
    std::vector<int> steps(media.size(), 0);
    bool any = false;
    for (std::size_t i = 0; i < media.size(); ++i) {
        const double dt = timeStepOf(media[i]);
        const double owed = carry_[i] + elapsed;
        steps[i] = int(std::floor(owed / dt));
        if (maxStepsPerFrame_ > 0) steps[i] = std::min(steps[i], maxStepsPerFrame_);
        any |= steps[i] > 0;
    }
    if (!any) return;
    std::vector<std::size_t> all(media.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    QString error;
    emit advancing(true);
    const bool ok = edit([&](nlohmann::json& sim, std::size_t i) { sim["steps"] = sim.value("steps", 0) + steps[i]; },
                         all, "play", &error, 16 + plays_ % 100000);
    emit advancing(false);
    if (!ok) {
        pause();
        emit refused(error);
        return;
    }
    double advanced = 0.0;
    for (std::size_t i = 0; i < media.size(); ++i) {
        const double dt = timeStepOf(media[i]);
        // What is left of a step carries over; the time a frame's limit of steps dropped does not (slow motion).
        carry_[i] = std::clamp(carry_[i] + elapsed - steps[i] * dt, 0.0, dt);
        advanced = std::max(advanced, steps[i] * dt);
    }
    // The pace over the last few advances (each older one weighs half as much as the next).
    simulatedSeconds_ = 0.5 * simulatedSeconds_ + advanced;
    wallSeconds_ = 0.5 * wallSeconds_ + elapsed;
    pace_ = wallSeconds_ > 0.0 ? simulatedSeconds_ / wallSeconds_ : 0.0;
    sinceAdvance_.start();
    emit clockChanged();
}

bool Animation::edit(const std::function<void(nlohmann::json&, std::size_t)>& change,
                     const std::vector<std::size_t>& media, const QString& text, QString* error, int mergeId) {
    const nlohmann::json project = projectToJson(session_.project());
    std::vector<std::string> overrides;
    for (std::size_t i : media) {
        const nlohmann::json& medium = project.at("particleMedia").at(i);
        nlohmann::json sim = medium.contains("simulation") ? medium["simulation"] : nlohmann::json::object();
        change(sim, i);
        // By index: a medium's name may hold characters that the path syntax uses.
        overrides.push_back("particleMedia[" + std::to_string(i) + "].simulation=" + sim.dump());
    }
    if (overrides.empty()) return true;
    return session_.editScene(overrides, text, error, mergeId);
}

bool Animation::step(int steps, QString* error, int mergeId) {
    std::vector<std::size_t> all(session_.project().scene.particleMedia.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    return edit([steps](nlohmann::json& sim, std::size_t) { sim["steps"] = sim.value("steps", 0) + steps; }, all,
                steps == 1 ? QString("step") : QString("%1 steps").arg(steps), error, mergeId);
}

bool Animation::reset(QString* error) {
    pause();
    std::vector<std::size_t> simulated;
    const std::vector<ParticleMedium>& media = session_.project().scene.particleMedia;
    for (std::size_t i = 0; i < media.size(); ++i)
        if (media[i].simulation) simulated.push_back(i);
    return edit(
        [](nlohmann::json& sim, std::size_t) {
            sim["steps"] = 0;
            sim["impulses"] = nlohmann::json::array();
            sim["offset"] = vec3Json(Vec3(0.0));
        },
        simulated, "reset the animation", error, -1);
}

bool Animation::addImpulse(int medium, const Vec3& position, QString* error) {
    if (medium < 0 || medium >= int(session_.project().scene.particleMedia.size())) return false;
    const double radius = impulseRadius_, speed = impulseSpeed_;
    const ParticleMedium& m = session_.project().scene.particleMedia[std::size_t(medium)];
    const ParticleSimulation simulation = m.simulation ? *m.simulation : ParticleSimulation{};
    const int advance =
        playing() ? 1 : std::max(1, int(std::lround(impulsePeakSeconds(simulation) / simulation.timeStep)));
    return edit(
        [&](nlohmann::json& sim, std::size_t) {
            const int step = sim.value("steps", 0);
            if (!sim.contains("impulses")) sim["impulses"] = nlohmann::json::array();
            sim["impulses"].push_back({{"step", step},
                                       {"position", vec3Json(position)},
                                       {"radius", radius},
                                       {"speed", speed}});
            sim["steps"] = step + advance;
        },
        {std::size_t(medium)}, "impulse", error, -1);
}

bool Animation::setOffset(int medium, const Vec3& offset, QString* error, int mergeId) {
    if (medium < 0 || medium >= int(session_.project().scene.particleMedia.size())) return false;
    return edit([&](nlohmann::json& sim, std::size_t) { sim["offset"] = vec3Json(offset); },
                {std::size_t(medium)}, "move the particles' targets", error, mergeId);
}

}  // namespace tyndall::studio
