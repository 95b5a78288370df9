#include "render_service.h"

#include "trace.h"

#include "tyndall/error.h"

#include <QMetaObject>

#include <algorithm>
#include <cerrno>
#include <chrono>

#ifdef __linux__
#include <sys/resource.h>
#include <unistd.h>
#endif

namespace tyndall::studio {

void lowerCurrentThreadPriority(int nice) {
#ifdef __linux__
    // On Linux the nice value belongs to the thread (the task), not to the process.
    const id_t self = id_t(gettid());
    errno = 0;
    const int current = getpriority(PRIO_PROCESS, self);
    if (errno == 0 && current < nice) setpriority(PRIO_PROCESS, self, nice);
#else
    (void)nice;
#endif
}

RenderService::RenderService(QObject* parent) : QObject(parent) {
    thread_ = std::thread([this] { run(); });
}

RenderService::~RenderService() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
        queue_.clear();
        cancel_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

void RenderService::submit(RenderTask task) {
    {
        std::lock_guard lock(mutex_);
        for (auto it = queue_.begin(); it != queue_.end();)
            it = (it->view == task.view && it->reference == task.reference) ? queue_.erase(it) : it + 1;
        if (running_ && runningView_ == task.view && runningReference_ == task.reference) cancel_ = true;
        // An edit comes first: a running task of a later class steps aside and starts again afterwards.
        const int running = runningReference_ ? 2 : runningSlow_ ? 1 : 0;
        if (running_ && !cancel_ && classOf(task) < running) {
            cancel_ = true;
            requeueRunning_ = true;
        }
        enqueue(std::move(task));
    }
    wake_.notify_all();
    emit idleChanged(false);
}

int RenderService::classOf(const RenderTask& task) {
    return task.reference ? 2 : task.slow ? 1 : 0;
}

void RenderService::enqueue(RenderTask task) {
    // Before the first task of its class or a later one: newest first within the class.
    const int c = classOf(task);
    auto at = std::find_if(queue_.begin(), queue_.end(), [c](const RenderTask& t) { return classOf(t) >= c; });
    queue_.insert(at, std::move(task));
}

void RenderService::cancelAll() {
    {
        std::lock_guard lock(mutex_);
        queue_.clear();
        if (running_) cancel_ = true;
        requeueRunning_ = false;
    }
}

void RenderService::cancelReference(int view) {
    std::lock_guard lock(mutex_);
    for (auto it = queue_.begin(); it != queue_.end();)
        it = (it->view == view && it->reference) ? queue_.erase(it) : it + 1;
    if (running_ && runningReference_ && runningView_ == view) {
        cancel_ = true;
        requeueRunning_ = false;
    }
}

bool RenderService::idle() const {
    std::lock_guard lock(mutex_);
    return !running_ && queue_.empty();
}

void RenderService::post(RenderOutput out) {
    QMetaObject::invokeMethod(this, [this, out = std::move(out)] { emit output(out); }, Qt::QueuedConnection);
}

void RenderService::run() {
    using Clock = std::chrono::steady_clock;
    // Renders run below the GUI: an edit's frame is drawn and the window keeps answering while they compute. The
    // renders themselves wait for nothing but the CPU, so their latency hardly changes (the GUI needs little of it).
    lowerCurrentThreadPriority(10);
    for (;;) {
        std::shared_ptr<RenderTask> task;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return quit_ || !queue_.empty(); });
            if (quit_) return;
            // The queue is in order: fast views, slow views, references.
            task = std::make_shared<RenderTask>(std::move(queue_.front()));
            queue_.pop_front();
            running_ = true;
            runningView_ = task->view;
            runningReference_ = task->reference;
            runningSlow_ = task->slow;
            runningTask_ = task;
            cancel_ = false;
            requeueRunning_ = false;
        }
        RenderOutput out;
        out.view = task->view;
        out.reference = task->reference;
        out.generation = task->generation;
        out.state = task->state;
        out.targetSpp = task->job->request.spp;
        const auto started = Clock::now();
        trace("%s %d: worker starts", task->reference ? "reference" : "view", task->view);
        auto lastPost = started - std::chrono::hours(1);  // the first progressive image goes out at once
        RenderCallbacks callbacks;
        callbacks.cancel = &cancel_;
        callbacks.intermediate = [&](const Image& image, int spp) {
            // Progressive images at most every 200 ms: the GUI composes each one.
            if (Clock::now() - lastPost < std::chrono::milliseconds(200)) return;
            lastPost = Clock::now();
            RenderOutput partial = out;
            auto copy = std::make_shared<Image>(image);
            // Progressive images carry the job's metadata too (the view, partHash, what it leaves out), as the final one
            // does.
            for (const auto& [key, value] : task->job->metadata) copy->metadata.emplace(key, value);
            partial.image = std::move(copy);
            partial.spp = spp;
            partial.seconds = std::chrono::duration<double>(Clock::now() - started).count();
            trace("%s %d: image posted (%d spp)", task->reference ? "reference" : "view", task->view, spp);
            post(std::move(partial));
        };
        bool cancelled = false;
        try {
            RenderResult result = runJob(*task->job, callbacks);
            out.image = std::make_shared<Image>(std::move(result.image));
            out.spp = result.spp;
            out.seconds = result.seconds;
            out.final = true;
        } catch (const Cancelled&) {
            cancelled = true;
        } catch (const std::exception& e) {
            out.error = QString::fromStdString(e.what());
            out.final = true;
        }
        bool nowIdle = false;
        {
            std::lock_guard lock(mutex_);
            running_ = false;
            runningTask_.reset();
            if (cancelled && requeueRunning_ && !quit_) {
                // The interrupted task starts again once the edit's renders are done (oldest of its class: after the
                // tasks queued meanwhile, which are newer).
                bool replaced = false;
                for (const RenderTask& t : queue_)
                    replaced |= t.view == task->view && t.reference == task->reference;
                if (!replaced) {
                    const int c = classOf(*task);
                    auto at = std::find_if(queue_.begin(), queue_.end(),
                                           [c](const RenderTask& t) { return classOf(t) > c; });
                    queue_.insert(at, *task);
                }
            }
            nowIdle = queue_.empty();
        }
        if (!cancelled) post(std::move(out));
        if (nowIdle)
            QMetaObject::invokeMethod(this, [this] { emit idleChanged(idle()); }, Qt::QueuedConnection);
    }
}

}  // namespace tyndall::studio
