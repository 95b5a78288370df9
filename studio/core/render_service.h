// Renders views and references off the GUI thread, in four classes: the first image of fast technique views (the
// analytic and GPU techniques, ~0.1-1 s, and the reduced stages of every view), then the first image of slow ones
// (progressive: the path tracer as a view, which may render for minutes) and the full resolution of a view whose
// reduced image is on screen, then the refinement of views that have shown their first image and the renders of
// views off screen, then references; newest first within a class. A new task for a view (or its reference) replaces
// the queued one and cancels the running one, so stale results are dropped rather than shown. A task of an earlier
// class interrupts a running one of a later class on the worker it needs (a first image a refinement or a reference,
// and so on), which goes back to the queue and starts again afterwards: the cores serve the edit first, and every
// affected view shows its first image before any view refines (issue 31: a WVDS view waited 16 s behind the path
// tracer's 64 spp). A progressive render that posts its first image while another view's first image waits steps
// aside at once. Outputs (progressive images and the final one) arrive on the GUI thread through `output`.
//
// Workers: one for everything, and, when the machine has a hardware GPU (gpu::hardwareDeviceAvailable), a second that
// runs only the tasks that render on it (RenderTask::gpu), concurrently with the CPU's: a GPU view's edit then neither
// waits for nor interrupts a reference. Here the only device is lavapipe, which renders on the same two cores as the
// CPU, so a second worker would only halve the speed of both: it is off (the tests turn it on to check it).
#pragma once

#include "tyndall/techniques/render.h"

#include <QObject>
#include <QString>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace tyndall::studio {

// Background work yields the CPU to the GUI thread (two cores here carry the GUI, lavapipe and the renders): raises
// the calling thread's nice value to `nice` (Linux; a no-op elsewhere). Threads it starts later inherit it, so the
// worker's TBB threads and the lavapipe threads of the renderer library's gpu::Context, which the worker creates, run
// at the same lower priority. The display device's threads, which the GUI thread creates, keep the normal one.
void lowerCurrentThreadPriority(int nice);

struct RenderTask {
    int view = 0;
    bool reference = false;
    // A technique view that renders progressively for long, or a full resolution after a reduced image (its class
    // above).
    bool slow = false;
    bool shown = false;      // its first image went out: it was interrupted while refining (the refinement class)
    bool hidden = false;     // its view is off screen: in the refinement class too
    int factor = 1;          // a reduced stage of the view's progressive resolution: 1/factor of it in each axis
    bool gpu = false;        // it renders on a hardware GPU: the GPU worker may take it
    quint64 generation = 0;  // increases with every edit; outputs of older generations are stale
    quint64 state = 0;       // the state of the view's part of the scene it renders (images of one state compare)
    std::shared_ptr<RenderJob> job;
};

struct RenderOutput {
    int view = 0;
    bool reference = false;
    quint64 generation = 0;
    quint64 state = 0;                   // the task's
    std::shared_ptr<const Image> image;  // null when the render failed
    int spp = 0;
    int targetSpp = 0;                   // what the render goes to (0: the technique's default)
    double seconds = 0.0;
    bool final = false;
    bool cached = false;  // a reference read from the disk cache, not rendered
    int factor = 1;       // the task's: > 1 for a reduced image (a preview, never compared)
    QString error;
};

class RenderService : public QObject {
    Q_OBJECT
public:
    // gpuWorker: the second worker for GPU tasks (by default when a hardware GPU is available).
    enum class GpuWorker { Auto, On, Off };
    explicit RenderService(QObject* parent = nullptr, GpuWorker gpuWorker = GpuWorker::Auto);
    ~RenderService() override;

    void submit(RenderTask task);
    void cancelAll();
    // Drops a queued reference of `view` and cancels it if it is running (a cached one replaces it).
    void cancelReference(int view);
    // Drops the queued tasks of `view` (its image's and its reference's) and cancels the running ones (it is gone).
    void cancelView(int view);
    bool idle() const;
    bool hasGpuWorker() const { return workers_.size() > 1; }

signals:
    void output(const tyndall::studio::RenderOutput& out);
    void idleChanged(bool idle);

private:
    struct Worker {
        bool gpuOnly = false;  // takes only tasks with `gpu`
        bool running = false;
        std::shared_ptr<RenderTask> task;
        std::atomic<bool> cancel{false};
        bool requeue = false;  // the running task was interrupted for an earlier class: it goes back to the queue
        std::thread thread;
    };
    void run(Worker& worker);
    void post(RenderOutput out);
    // 0 a fast view's first image, 1 a slow view's, 2 a view's refinement, 3 a reference.
    static int classOf(const RenderTask& task);
    bool firstImageWaits(const Worker& worker) const;  // a queued task this worker takes is of class 0 or 1
    void enqueue(RenderTask task, bool oldest);  // at its class's place (mutex_ held)
    bool takes(const Worker& worker, const RenderTask& task) const;
    bool anyRunning() const;  // mutex_ held

    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<RenderTask> queue_;
    bool quit_ = false;
    std::vector<std::unique_ptr<Worker>> workers_;
};

}  // namespace tyndall::studio
