// The studio's background pool: metrics, reference cache reads and writes, exports. Not Qt's global pool: Qt's raster
// engine splits large fills over the global pool and waits for them, so a widget's paint would wait behind a 100 ms
// metrics job. Jobs run below the GUI and no higher than the renders, which an edit is waiting for (at nice 5, the
// metrics of each progressive image took the CPU from the next pass).
#pragma once

#include <QObject>
#include <QThreadPool>

#include <functional>

namespace tyndall::studio {

class Background : public QObject {
public:
    explicit Background(QObject* parent = nullptr);
    ~Background() override;
    void run(std::function<void()> work);
    void waitForDone();

private:
    QThreadPool* pool_ = nullptr;
};

}  // namespace tyndall::studio
