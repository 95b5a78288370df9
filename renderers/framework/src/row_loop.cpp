#include "tyndall/framework/row_loop.h"

#include "tyndall/core/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace tyndall {

void RowLoop::forEachChunk(const std::function<void(int begin, int end)>& chunk) {
    tbb::task_arena arena(threads_ > 0 ? threads_ : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, rows_, grain_), [&](const tbb::blocked_range<int>& r) {
            if (!cancelled()) chunk(r.begin(), r.end());
        });
    });
    if (cancel_ && cancel_->load()) throw Cancelled();
}

void RowLoop::rowDone() {
    const int done = done_.fetch_add(1) + 1;
    if (progress_ && done % 16 == 0) (*progress_)(from_ + (to_ - from_) * double(done) / rows_);
}

}  // namespace tyndall
