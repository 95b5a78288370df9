#include "composer.h"

#include "trace.h"

#include <QMetaObject>

namespace tyndall::studio {

Composer::Composer(QObject* parent) : QObject(parent) {
    thread_ = std::thread([this] { run(); });
}

Composer::~Composer() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

void Composer::request(std::vector<ViewFrame> frames, CompositorState state, QSize size) {
    {
        std::lock_guard lock(mutex_);
        pending_ = Request{std::move(frames), state, size, ++requested_};
    }
    wake_.notify_all();
}

QImage Composer::wait() {
    std::unique_lock lock(mutex_);
    done_.wait(lock, [&] { return finished_ == requested_; });
    return latest_;
}

void Composer::run() {
    for (;;) {
        Request r;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return quit_ || pending_; });
            if (quit_) return;
            r = std::move(*pending_);
            pending_.reset();
        }
        QImage frame = compose(r.frames, r.state, r.size);
        r.frames.clear();  // the images go back to their owners here, not on the GUI thread's time
        trace("composed frame %llu", static_cast<unsigned long long>(r.serial));
        bool same;
        {
            std::lock_guard lock(mutex_);
            // Many changes do not change the picture (a new parameter value, before its render arrives): a frame
            // equal to the last one is not shown again, since presenting costs the GUI thread several ms here.
            same = frame == latest_;
            if (!same) latest_ = frame;
            finished_ = r.serial;
        }
        done_.notify_all();
        if (same) continue;
        QMetaObject::invokeMethod(
            this,
            [this, frame = std::move(frame), serial = r.serial] {
                if (serial <= shown_) return;  // a newer frame was shown already
                shown_ = serial;
                emit composed(frame);
            },
            Qt::QueuedConnection);
    }
}

}  // namespace tyndall::studio
