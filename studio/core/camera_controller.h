// Camera navigation in the studio: orbit about the target, dolly along the view direction and framing the scene's
// meshes. Each move is an undoable scene edit of the session (a drag's moves merge into one undo step) validated like
// a loaded file; a refused move leaves the camera as it was and says why.
#pragma once

#include "session.h"

#include <QString>

namespace tyndall::studio {

class CameraController {
public:
    explicit CameraController(Session& session) : session_(session) {}

    // Yaw about the camera's up hint and pitch about its right axis (radians), kept 11 degrees from the poles.
    bool orbit(double yaw, double pitch, QString* error);
    // Moves the camera towards (factor < 1) or away from its target: the distance times `factor`.
    bool dolly(double factor, QString* error);
    // Aims at the centre of the meshes' bounds from the current direction, at the distance where their bounding
    // sphere fills the vertical field of view. False without a mesh (error stays empty: nothing to frame).
    bool frameScene(QString* error);

private:
    Session& session_;
};

}  // namespace tyndall::studio
