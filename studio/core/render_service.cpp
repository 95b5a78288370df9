#include "render_service.h"

#include "trace.h"

#include "tyndall/core/error.h"
#include "tyndall/gpu/context.h"

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

RenderService::RenderService(QObject* parent, GpuWorker gpuWorker) : QObject(parent) {
    bool second = gpuWorker == GpuWorker::On;
    if (gpuWorker == GpuWorker::Auto) {
        try {
            second = gpu::hardwareDeviceAvailable();
        } catch (const std::exception&) {
            second = false;
        }
    }
    workers_.push_back(std::make_unique<Worker>());
    if (second) {
        workers_.push_back(std::make_unique<Worker>());
        workers_.back()->gpuOnly = true;
    }
    for (auto& worker : workers_)
        worker->thread = std::thread([this, w = worker.get()] { run(*w); });
}

RenderService::~RenderService() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
        queue_.clear();
        for (auto& worker : workers_) worker->cancel = true;
    }
    wake_.notify_all();
    for (auto& worker : workers_) worker->thread.join();
}

bool RenderService::takes(const Worker& worker, const RenderTask& task) const {
    // With a GPU worker, the GPU's tasks are its own and the other worker keeps the CPU's.
    if (worker.gpuOnly) return task.gpu;
    return workers_.size() == 1 || !task.gpu;
}

bool RenderService::anyRunning() const {
    for (const auto& worker : workers_)
        if (worker->running) return true;
    return false;
}

void RenderService::submit(RenderTask task) {
    {
        std::lock_guard lock(mutex_);
        for (auto it = queue_.begin(); it != queue_.end();)
            it = (it->view == task.view && it->reference == task.reference) ? queue_.erase(it) : it + 1;
        for (auto& worker : workers_) {
            if (!worker->running) continue;
            const RenderTask& running = *worker->task;
            if (running.view == task.view && running.reference == task.reference) {
                worker->cancel = true;
                worker->requeue = false;
            }
        }
        // An edit comes first: a running task of a later class on the worker this task needs steps aside and starts
        // again afterwards. (Another worker's task goes on: it does not stand in the way.)
        for (auto& worker : workers_) {
            if (!worker->running || worker->cancel || !takes(*worker, task)) continue;
            if (classOf(task) < classOf(*worker->task)) {
                worker->cancel = true;
                worker->requeue = true;
            }
        }
        enqueue(std::move(task), false);
    }
    wake_.notify_all();
    emit idleChanged(false);
}

int RenderService::classOf(const RenderTask& task) {
    return task.reference ? 3 : (task.shown || task.hidden) ? 2 : task.slow ? 1 : 0;
}

bool RenderService::firstImageWaits(const Worker& worker) const {
    return std::any_of(queue_.begin(), queue_.end(),
                       [&](const RenderTask& t) { return classOf(t) < 2 && takes(worker, t); });
}

void RenderService::enqueue(RenderTask task, bool oldest) {
    // Newest first within a class: before the first task of its class (or of a later one); an interrupted task, the
    // oldest of its class, after the tasks of its class queued meanwhile.
    const int c = classOf(task);
    auto at = std::find_if(queue_.begin(), queue_.end(),
                           [c, oldest](const RenderTask& t) { return oldest ? classOf(t) > c : classOf(t) >= c; });
    queue_.insert(at, std::move(task));
}

void RenderService::cancelAll() {
    std::lock_guard lock(mutex_);
    queue_.clear();
    for (auto& worker : workers_) {
        if (worker->running) worker->cancel = true;
        worker->requeue = false;
    }
}

void RenderService::cancelReference(int view) {
    std::lock_guard lock(mutex_);
    for (auto it = queue_.begin(); it != queue_.end();)
        it = (it->view == view && it->reference) ? queue_.erase(it) : it + 1;
    for (auto& worker : workers_)
        if (worker->running && worker->task->reference && worker->task->view == view) {
            worker->cancel = true;
            worker->requeue = false;
        }
}

void RenderService::cancelView(int view) {
    std::lock_guard lock(mutex_);
    for (auto it = queue_.begin(); it != queue_.end();)
        it = it->view == view ? queue_.erase(it) : it + 1;
    for (auto& worker : workers_)
        if (worker->running && worker->task->view == view) {
            worker->cancel = true;
            worker->requeue = false;
        }
}

bool RenderService::idle() const {
    std::lock_guard lock(mutex_);
    return !anyRunning() && queue_.empty();
}

void RenderService::post(RenderOutput out) {
    QMetaObject::invokeMethod(this, [this, out = std::move(out)] { emit output(out); }, Qt::QueuedConnection);
}

void RenderService::run(Worker& worker) {
    using Clock = std::chrono::steady_clock;
    // Renders run below the GUI: an edit's frame is drawn and the window keeps answering while they compute. The
    // renders themselves wait for nothing but the CPU, so their latency hardly changes (the GUI needs little of it).
    lowerCurrentThreadPriority(10);
    for (;;) {
        std::shared_ptr<RenderTask> task;
        {
            std::unique_lock lock(mutex_);
            // The queue is in order of class (first images, refinements, references); the first this worker takes.
            auto next = queue_.end();
            wake_.wait(lock, [&] {
                if (quit_) return true;
                next = std::find_if(queue_.begin(), queue_.end(), [&](const RenderTask& t) { return takes(worker, t); });
                return next != queue_.end();
            });
            if (quit_) return;
            task = std::make_shared<RenderTask>(std::move(*next));
            queue_.erase(next);
            worker.running = true;
            worker.task = task;
            worker.cancel = false;
            worker.requeue = false;
        }
        RenderOutput out;
        out.view = task->view;
        out.reference = task->reference;
        out.generation = task->generation;
        out.state = task->state;
        out.targetSpp = task->job->request.spp;
        out.factor = task->factor;
        const auto started = Clock::now();
        trace("%s %d: worker starts", task->reference ? "reference" : "view", task->view);
        auto lastPost = started - std::chrono::hours(1);  // the first progressive image goes out at once
        RenderCallbacks callbacks;
        callbacks.cancel = &worker.cancel;
        callbacks.intermediate = [&](const Image& image, int spp) {
            // Progressive images at most every 200 ms: the GUI composes each one.
            if (Clock::now() - lastPost < std::chrono::milliseconds(200)) return;
            lastPost = Clock::now();
            RenderOutput partial = out;
            auto copy = std::make_shared<Image>(image);
            // Progressive images carry the job's metadata too (the view, partHash, what it leaves out, its exposure),
            // as the final one does.
            for (const auto& [key, value] : task->job->metadata) copy->metadata.emplace(key, value);
            copy->metadata["exposure"] = std::to_string(task->job->exposure);
            partial.image = std::move(copy);
            partial.spp = spp;
            partial.seconds = std::chrono::duration<double>(Clock::now() - started).count();
            trace("%s %d: image posted (%d spp)", task->reference ? "reference" : "view", task->view, spp);
            post(std::move(partial));
            if (task->reference || task->shown || task->factor > 1) return;
            // Its first image is out: from here on it refines, after every other view's first image.
            std::lock_guard lock(mutex_);
            task->shown = true;
            if (!worker.cancel && firstImageWaits(worker)) {
                worker.cancel = true;
                worker.requeue = true;
            }
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
            worker.running = false;
            worker.task.reset();
            if (cancelled && worker.requeue && !quit_) {
                // The interrupted task starts again once the edit's renders are done, unless a newer one replaced it.
                bool replaced = false;
                for (const RenderTask& t : queue_)
                    replaced |= t.view == task->view && t.reference == task->reference;
                if (!replaced) enqueue(*task, true);
            }
            nowIdle = queue_.empty() && !anyRunning();
        }
        if (!cancelled) post(std::move(out));
        if (nowIdle)
            QMetaObject::invokeMethod(this, [this] { emit idleChanged(idle()); }, Qt::QueuedConnection);
        wake_.notify_all();  // a requeued task may be the other worker's
    }
}

}  // namespace tyndall::studio
