// The CPU row loop of every technique (model: pbrt-v4's ParallelFor over rows): the rows of an image in parallel on
// the render's threads, with cancellation and progress, written once.
#pragma once

#include "tyndall/framework/technique.h"

#include <atomic>
#include <functional>

namespace tyndall {

// Runs row(y) for every y in [0, rows) on `threads` workers (0: every core) in a task arena of its own. Before each row
// it checks the cancel flag: once that is set no new row starts, and run() throws Cancelled after the workers have
// stopped. With callbacks, progress is reported every 16 rows, mapped onto [from, to].
//
// A technique whose shared-header accessors read a scene bound to the thread names its binding as `Bind`: one is
// constructed from run()'s further arguments on the worker for each chunk of rows, e.g.
//     RowLoop(height, request.threads, callbacks).run<ltsd::SceneScope>([&](int y) { ... }, scene);
class RowLoop {
public:
    RowLoop(int rows, int threads, const RenderCallbacks& callbacks, double from = 0.0, double to = 1.0)
        : rows_(rows),
          threads_(threads),
          cancel_(callbacks.cancel),
          progress_(callbacks.progress ? &callbacks.progress : nullptr),
          from_(from),
          to_(to) {}
    // Without progress: cancellation only.
    RowLoop(int rows, int threads, const std::atomic<bool>* cancel) : rows_(rows), threads_(threads), cancel_(cancel) {}

    // Rows per chunk at least (the default, 1, balances rows of very different cost).
    RowLoop& grain(int rows) {
        grain_ = rows;
        return *this;
    }

    struct NoBinding {
        template <typename... Args>
        explicit NoBinding(const Args&...) {}
    };

    template <typename Bind = NoBinding, typename Row, typename... Args>
    void run(Row&& row, const Args&... bindArgs) {
        forEachChunk([&](int begin, int end) {
            [[maybe_unused]] const Bind binding(bindArgs...);
            for (int y = begin; y < end; ++y) {
                if (cancelled()) return;
                row(y);
                rowDone();
            }
        });
    }

    // For a body that keeps state per chunk of rows: chunk(begin, end) over [0, rows) in parallel, each chunk started
    // only while not cancelled, then Cancelled thrown when cancelled. No progress is reported.
    void forEachChunk(const std::function<void(int begin, int end)>& chunk);

private:
    bool cancelled() const { return cancel_ && cancel_->load(std::memory_order_relaxed); }
    void rowDone();

    int rows_, threads_, grain_ = 1;
    const std::atomic<bool>* cancel_ = nullptr;
    const std::function<void(double)>* progress_ = nullptr;
    double from_ = 0.0, to_ = 1.0;
    std::atomic<int> done_{0};
};

}  // namespace tyndall
