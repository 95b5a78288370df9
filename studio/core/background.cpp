#include "background.h"

#include "render_service.h"

namespace tyndall::studio {

Background::Background(QObject* parent) : QObject(parent) {
    pool_ = new QThreadPool(this);
    pool_->setMaxThreadCount(2);
}

Background::~Background() { pool_->waitForDone(); }

void Background::run(std::function<void()> work) {
    pool_->start([work = std::move(work)] {
        lowerCurrentThreadPriority(10);  // the pool's threads keep the value
        work();
    });
}

void Background::waitForDone() { pool_->waitForDone(); }

}  // namespace tyndall::studio
