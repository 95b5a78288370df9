// The central viewport: a QVulkanWindow (embedded with QWidget::createWindowContainer) that only displays frames the
// GUI thread composed (compositor.h). Its device is the window's own: techniques render on the renderer library's
// gpu::Context, never here, so a long dispatch can never freeze the display (GPU framework issue). Key and mouse
// events reach the QWindow, not the widget tree, so it forwards them as signals.
#pragma once

#include <QElapsedTimer>
#include <QImage>
#include <QTimer>
#include <QVulkanWindow>

namespace tyndall::studio {

class Viewport : public QVulkanWindow {
    Q_OBJECT
public:
    Viewport();

    QVulkanWindowRenderer* createRenderer() override;

    // Shown from the next frame on; best at pixelSize(), else drawn at the top left.
    void setFrame(const QImage& frame);
    const QImage& frame() const { return frame_; }
    QSize pixelSize() const;
    // A failure to create the Vulkan resources, shown instead of the frame ("" when there is none).
    const QString& failure() const { return failure_; }
    void setFailure(const QString& failure) { failure_ = failure; }
    int framesPresented() const { return presented_; }
    void countPresented();

signals:
    void resized(QSize pixels);
    void keyPressed(int key, Qt::KeyboardModifiers modifiers);
    void keyReleased(int key, Qt::KeyboardModifiers modifiers);
    void mousePressed(QPointF position, Qt::MouseButtons buttons);
    void mouseMoved(QPointF position, Qt::MouseButtons buttons);
    void mouseDoubleClicked(QPointF position);
    void wheelTurned(double steps);  // + away from the user (dolly in)

protected:
    bool event(QEvent* event) override;
    void resizeEvent(QResizeEvent* event) override;
    void keyPressEvent(QKeyEvent* event) override;
    void keyReleaseEvent(QKeyEvent* event) override;
    void mousePressEvent(QMouseEvent* event) override;
    void mouseMoveEvent(QMouseEvent* event) override;
    void mouseDoubleClickEvent(QMouseEvent* event) override;
    void wheelEvent(QWheelEvent* event) override;

private:
    QImage frame_;
    QString failure_;
    int presented_ = 0;
    static constexpr qint64 kMinFrameIntervalMs = 12;
    QElapsedTimer sinceLastFrame_;
    QTimer frameTimer_;
};

}  // namespace tyndall::studio
