// What the mouse and the keys do over the viewport (a QWindow: its events arrive as the Viewport's signals): the
// camera (Alt+drag orbits, the wheel dollies), the display (Ctrl+wheel zooms, a middle drag pans, a drag moves the
// wipe's divider, a double-click centres it, Shift held shows the reference), a right drag draws the metrics region,
// a hover inspects (debounced), and on a particle medium Ctrl+click adds an impulse and Ctrl+Shift+drag moves its
// targets. Keys go to the action table. The studio does the work; this class only reads the gestures.
#pragma once

#include "actions.h"
#include "studio.h"
#include "viewport.h"

#include <QObject>
#include <QPoint>
#include <QTimer>

#include <vector>

namespace tyndall::studio {

class ViewportController final : public QObject {
    Q_OBJECT
public:
    ViewportController(Studio& studio, Viewport& viewport, const ActionTable& actions, QObject* parent);
    // A key pressed or released over the viewport or the window: Shift shows the reference while held; other keys
    // trigger their action.
    void key(int key, Qt::KeyboardModifiers modifiers, bool pressed);
    // For the help overlay.
    static std::vector<Binding> bindings();

private:
    void press(QPointF position, Qt::MouseButtons buttons);
    void move(QPointF position, Qt::MouseButtons buttons);
    void wheel(double steps);

    Studio& studio_;
    const ActionTable& actions_;
    QPointF last_;        // the last position
    QPoint regionStart_;  // a region's first corner (image pixels)
    QTimer probeTimer_;   // the Inspector's debounce
    QPointF probePosition_;
    // Ctrl+Shift+drag of a particle medium's targets: the medium, its offset at the press, the metres per pixel.
    int offsetMedium_ = -1;
    Vec3 offsetStart_{0.0};
    QPointF offsetFrom_;
    Vec3 offsetRight_{0.0}, offsetUp_{0.0};
};

}  // namespace tyndall::studio
