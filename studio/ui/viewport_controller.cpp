#include "viewport_controller.h"

#include <QGuiApplication>

#include <cmath>

namespace tyndall::studio {

ViewportController::ViewportController(Studio& studio, Viewport& viewport, const ActionTable& actions, QObject* parent)
    : QObject(parent), studio_(studio), actions_(actions) {
    probeTimer_.setSingleShot(true);
    probeTimer_.setInterval(60);
    connect(&probeTimer_, &QTimer::timeout, this, [this] { studio_.inspect(probePosition_); });
    connect(&viewport, &Viewport::resized, &studio_, [this](QSize) { studio_.recompose(); });
    connect(&viewport, &Viewport::keyPressed, this, [this](int k, Qt::KeyboardModifiers m) { key(k, m, true); });
    connect(&viewport, &Viewport::keyReleased, this, [this](int k, Qt::KeyboardModifiers m) { key(k, m, false); });
    connect(&viewport, &Viewport::mousePressed, this, &ViewportController::press);
    connect(&viewport, &Viewport::mouseMoved, this, &ViewportController::move);
    connect(&viewport, &Viewport::mouseDoubleClicked, &studio_, [this](QPointF) { studio_.centreSplit(); });
    connect(&viewport, &Viewport::wheelTurned, this, &ViewportController::wheel);
}

std::vector<Binding> ViewportController::bindings() {
    return {
        {"Shift (held)", "Show the reference (single layout)"},
        {"Alt+drag", "Orbit the camera"},
        {"Wheel", "Dolly the camera"},
        {"Ctrl+wheel", "Zoom every view"},
        {"Middle drag", "Pan every view"},
        {"Right drag", "Draw a region: metrics over it"},
        {"Drag / double-click", "Move the wipe's divider / centre it"},
        {"Ctrl+click", "Particle medium: an impulse under the cursor (at the current step; the medium steps once)"},
        {"Ctrl+Shift+drag", "Particle medium: move its region of targets (simulation offset)"},
    };
}

void ViewportController::key(int key, Qt::KeyboardModifiers modifiers, bool pressed) {
    if (key == Qt::Key_Shift) {
        studio_.showReference(pressed);
        return;
    }
    if (pressed) actions_.trigger(key, modifiers);
}

void ViewportController::wheel(double steps) {
    if (QGuiApplication::keyboardModifiers() & Qt::ControlModifier)
        studio_.zoomBy(steps);  // every view zooms together
    else
        studio_.dollyCamera(std::pow(0.9, steps));
}

void ViewportController::press(QPointF position, Qt::MouseButtons buttons) {
    last_ = position;
    offsetMedium_ = -1;
    const Qt::KeyboardModifiers modifiers = QGuiApplication::keyboardModifiers();
    if (modifiers & Qt::AltModifier) return;  // camera navigation
    if ((modifiers & Qt::ControlModifier) && (buttons & Qt::LeftButton)) {
        int medium;
        Vec3 point;
        if (!studio_.particlePointAt(position, medium, point)) return;
        if (modifiers & Qt::ShiftModifier) {  // moving the region of targets: in the image plane at that depth
            if (!studio_.imagePlaneAxes(position, point, offsetRight_, offsetUp_)) return;
            const auto& sim = studio_.session().project().scene.particleMedia[std::size_t(medium)].simulation;
            offsetMedium_ = medium;
            offsetStart_ = sim ? sim->offset : Vec3(0.0);
            offsetFrom_ = position;
            return;
        }
        QString error;
        if (!studio_.addImpulseAt(position, &error) && !error.isEmpty()) studio_.say(error);
        return;
    }
    if (buttons & Qt::LeftButton) studio_.setSplitAt(position);
    int view;
    QPoint pixel;
    if ((buttons & Qt::RightButton) && studio_.viewAt(position, view, pixel)) regionStart_ = pixel;
}

void ViewportController::move(QPointF position, Qt::MouseButtons buttons) {
    const QPointF delta = position - last_;
    last_ = position;
    if ((QGuiApplication::keyboardModifiers() & Qt::AltModifier) && (buttons & Qt::LeftButton)) {
        studio_.orbitCamera(-delta.x() * 0.01, -delta.y() * 0.01);
        return;
    }
    if (offsetMedium_ >= 0 && (buttons & Qt::LeftButton)) {
        const QPointF moved = position - offsetFrom_;
        const Vec3 offset = offsetStart_ + moved.x() * offsetRight_ - moved.y() * offsetUp_;
        QString error;
        if (!studio_.animation().setOffset(offsetMedium_, offset, &error, 3)) studio_.say(error, 5000);
        return;
    }
    if (buttons & Qt::MiddleButton) {  // pan every view together
        studio_.panBy(delta);
        return;
    }
    if (buttons & Qt::LeftButton) studio_.setSplitAt(position);
    int view;
    QPoint pixel;
    if ((buttons & Qt::RightButton) && studio_.viewAt(position, view, pixel))
        studio_.setRegion(QRect(regionStart_, pixel).normalized());
    probePosition_ = position;
    if (!probeTimer_.isActive()) probeTimer_.start();
}

}  // namespace tyndall::studio
