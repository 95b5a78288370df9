// Composes the viewport's frames (compositor.h) in a thread of its own, so that the GUI thread only hands over what to
// show: a frame of six 512 x 512 views at 1600 x 1000 takes 10-30 ms to compose here, longer than the GUI may stall.
// Requests replace the one waiting (a drag composes at the rate the thread keeps up with, and the last state is always
// composed); every finished frame newer than the one shown, and different from it, goes to `composed` on the GUI
// thread.
#pragma once

#include "compositor.h"

#include <QImage>
#include <QObject>

#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace tyndall::studio {

class Composer : public QObject {
    Q_OBJECT
public:
    explicit Composer(QObject* parent = nullptr);
    ~Composer() override;

    // Composes `frames` under `state` at `size` (the images are shared, not copied).
    void request(std::vector<ViewFrame> frames, CompositorState state, QSize size);
    // Blocks until the latest request is composed and returns its frame (for exports and tests, which need the frame
    // of the current state).
    QImage wait();

signals:
    void composed(const QImage& frame);

private:
    struct Request {
        std::vector<ViewFrame> frames;
        CompositorState state;
        QSize size;
        quint64 serial = 0;
    };
    void run();

    std::mutex mutex_;
    std::condition_variable wake_, done_;
    std::optional<Request> pending_;
    quint64 requested_ = 0, finished_ = 0, shown_ = 0;
    QImage latest_;
    bool quit_ = false;
    std::thread thread_;
};

}  // namespace tyndall::studio
