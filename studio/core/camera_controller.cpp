#include "camera_controller.h"

#include "tyndall/core/geometry.h"

#include <QFileInfo>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <string>

namespace tyndall::studio {

namespace {

// The --set form of a vector (the session's edits take override strings, validated like a file).
std::string vec(const Vec3& v) {
    return "[" + std::to_string(v.x) + "," + std::to_string(v.y) + "," + std::to_string(v.z) + "]";
}

// Merge ids of the session's scene edits: the steps of one drag are one undo step.
constexpr int kOrbitMerge = 1, kDollyMerge = 2;

}  // namespace

bool CameraController::orbit(double yaw, double pitch, QString* error) {
    const Camera& cam = session_.project().scene.camera;
    const Vec3 up = glm::normalize(cam.up);
    Vec3 offset = cam.position - cam.target;
    if (!(glm::length(offset) > 0.0)) return true;
    offset = glm::dmat3(glm::rotate(glm::dmat4(1.0), yaw, up)) * offset;
    const Vec3 right = glm::normalize(glm::cross(-offset, up));
    const Vec3 pitched = glm::dmat3(glm::rotate(glm::dmat4(1.0), pitch, right)) * offset;
    if (std::abs(glm::dot(glm::normalize(pitched), up)) < 0.98) offset = pitched;
    return session_.editScene({"camera.position=" + vec(cam.target + offset)}, "orbit", error, kOrbitMerge);
}

bool CameraController::dolly(double factor, QString* error) {
    const Camera& cam = session_.project().scene.camera;
    return session_.editScene({"camera.position=" + vec(cam.target + (cam.position - cam.target) * factor)}, "dolly",
                              error, kDollyMerge);
}

bool CameraController::frameScene(QString* error) {
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
            // A mesh that does not load is left out of the bounds; the render says why it failed.
        }
    }
    if (!(lo.x <= hi.x)) return false;
    const Camera& cam = project.scene.camera;
    const Vec3 centre = 0.5 * (lo + hi);
    const double radius = 0.5 * glm::length(hi - lo);
    const Vec3 p = centre + glm::normalize(cam.position - cam.target) * (radius / std::sin(glm::radians(cam.fovY) * 0.5));
    return session_.editScene({"camera.position=" + vec(p), "camera.target=" + vec(centre)}, "frame the scene", error);
}

}  // namespace tyndall::studio
