#include "animation.h"

#include "shared/camera.h"
#include "tyndall/framework/shader_params.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tyndall::studio {

namespace {

nlohmann::json vec3Json(const Vec3& v) {
    return nlohmann::json::array({v.x, v.y, v.z});
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
    connect(&session_, &Session::projectReplaced, this, [this] { pause(); });
}

bool Animation::available() const {
    return !session_.project().scene.particleMedia.empty();
}

void Animation::play() {
    if (playing() || !available()) return;
    ++plays_;
    carry_.assign(session_.project().scene.particleMedia.size(), 0.0);
    sinceAdvance_.start();
    timer_.start();
    emit playingChanged(true);
}

void Animation::pause() {
    if (!playing()) return;
    timer_.stop();
    emit playingChanged(false);
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
        const double dt = media[i].simulation ? media[i].simulation->timeStep : ParticleSimulation{}.timeStep;
        const double owed = carry_[i] + elapsed;
        steps[i] = int(std::floor(owed / dt));
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
    for (std::size_t i = 0; i < media.size(); ++i) {
        const double dt = media[i].simulation ? media[i].simulation->timeStep : ParticleSimulation{}.timeStep;
        carry_[i] = std::max(0.0, carry_[i] + elapsed - steps[i] * dt);
    }
    sinceAdvance_.start();
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
    return edit(
        [&](nlohmann::json& sim, std::size_t) {
            const int step = sim.value("steps", 0);
            if (!sim.contains("impulses")) sim["impulses"] = nlohmann::json::array();
            sim["impulses"].push_back({{"step", step},
                                       {"position", vec3Json(position)},
                                       {"radius", radius},
                                       {"speed", speed}});
            sim["steps"] = step + 1;
        },
        {std::size_t(medium)}, "impulse", error, -1);
}

bool Animation::setOffset(int medium, const Vec3& offset, QString* error, int mergeId) {
    if (medium < 0 || medium >= int(session_.project().scene.particleMedia.size())) return false;
    return edit([&](nlohmann::json& sim, std::size_t) { sim["offset"] = vec3Json(offset); },
                {std::size_t(medium)}, "move the particles' targets", error, mergeId);
}

}  // namespace tyndall::studio
