// The studio's responsiveness, measured in a real window (run under xvfb-run with QT_QPA_PLATFORM=xcb):
//   xvfb-run -a -s "-screen 0 1600x1000x24" build/studio/bench/tyndall_studio_latency
// - time from a parameter change to the first updated image of the technique view at 512 x 512 (its first progressive
//   pass) and to its final image, per technique (the median of 5 edits, after the project has settled; references at
//   4 spp so that they settle quickly);
// - the GUI thread's longest stall while a view re-renders on every change of a slider dragged for 3 s (every 16 ms),
//   measured as the longest gap between the ticks of a 1 ms timer, and the longest stall while references refine.
#include "main_window.h"

#include <QApplication>
#include <QElapsedTimer>
#include <QFileInfo>
#include <QStandardPaths>
#include <QTest>
#include <QVulkanInstance>

#include <algorithm>
#include <cstdio>
#include <vector>

using namespace tyndall;
using namespace tyndall::studio;

namespace {

const std::vector<std::string> k512 = {"camera.width=512", "camera.height=512", "reference.spp=4"};

// The longest gap between ticks of a 1 ms timer while `work` runs the event loop.
template <typename Work>
double longestStallMs(Work&& work) {
    QElapsedTimer clock;
    clock.start();
    qint64 last = clock.nsecsElapsed(), longest = 0;
    QTimer ticker;
    QObject::connect(&ticker, &QTimer::timeout, [&] {
        const qint64 now = clock.nsecsElapsed();
        longest = std::max(longest, now - last);
        last = now;
    });
    ticker.start(1);
    work();
    ticker.stop();
    return double(longest) * 1e-6;
}

void waitSettled(MainWindow& w, int timeoutMs = 600000) {
    QElapsedTimer t;
    t.start();
    while (!w.settled() && t.elapsed() < timeoutMs)
        QTest::qWait(5);
}

struct Edit {
    const char* project;
    const char* view;
    const char* parameter;
};

}  // namespace

int main(int argc, char** argv) {
    QApplication app(argc, argv);
    QStandardPaths::setTestModeEnabled(true);
    QVulkanInstance vulkan;
    vulkan.setApiVersion(QVersionNumber(1, 2));
    if (!vulkan.create()) {
        std::fprintf(stderr, "no Vulkan instance\n");
        return 1;
    }
    const QString root = TYNDALL_SOURCE_DIR;
    const Edit edits[] = {{"/projects/examples/wvds-box.json", "analytic", "shadows"},
                          {"/projects/examples/wvds-box.json", "mcwvds", "shadows"},
                          {"/projects/default.json", "light shaft", "shadows"},
                          {"/projects/examples/pegoraro-street.json", "closed form", "shadows"}};
    std::printf("medians of 5 edits at 512 x 512\n");
    for (const Edit& e : edits) {
        MainWindow window(&vulkan, k512);
        window.setRecovery(MainWindow::Recovery::Never);
        window.show();
        if (!QTest::qWaitForWindowExposed(&window)) return 1;
        if (!window.openProject(root + e.project, false)) return 1;
        waitSettled(window);
        int view = -1;
        for (int i = 0; i < int(window.session().project().views.size()); ++i)
            if (window.session().project().views[std::size_t(i)].name == e.view) view = i;
        if (view < 0) return 1;
        std::vector<double> first, final;
        bool value = false;
        double stall = 0.0;
        for (int k = 0; k < 5; ++k) {
            const auto before = window.frames()[std::size_t(view)].image;
            QElapsedTimer t;
            t.start();
            double firstMs = 0.0;
            stall = std::max(stall, longestStallMs([&] {
                window.session().setParameter(view, e.parameter, value);
                while (window.frames()[std::size_t(view)].image == before)
                    QTest::qWait(1);
                firstMs = double(t.nsecsElapsed()) * 1e-6;
                while (!window.settled())
                    QTest::qWait(1);
            }));
            first.push_back(firstMs);
            final.push_back(double(t.nsecsElapsed()) * 1e-6);
            value = !value;
        }
        std::sort(first.begin(), first.end());
        std::sort(final.begin(), final.end());
        const View& v = window.session().project().views[std::size_t(view)];
        std::printf("%-24s %-12s %-10s first image %6.0f ms (worst %6.0f), final %6.0f ms, GUI stall %.1f ms\n",
                    QFileInfo(e.project).fileName().toUtf8().constData(), e.view, v.technique.c_str(), first[2],
                    first.back(), final[2], stall);
        std::fflush(stdout);
    }

    // A slider dragged over the WVDS view for 3 s, and the references of the default project refining.
    MainWindow window(&vulkan, k512);
    window.setRecovery(MainWindow::Recovery::Never);
    window.show();
    if (!QTest::qWaitForWindowExposed(&window)) return 1;
    window.openProject(root + "/projects/examples/wvds-box.json", false);
    waitSettled(window);
    const double dragStall = longestStallMs([&] {
        for (int k = 0; k < 180; ++k) {
            window.session().setParameter(0, "pdfScale", 1.0 + 0.002 * (k % 50));
            QTest::qWait(16);
        }
        waitSettled(window);
    });
    std::printf("GUI thread's longest stall during a 3 s drag over the WVDS view: %.1f ms\n", dragStall);
    MainWindow room(&vulkan, {"camera.width=512", "camera.height=512", "reference.spp=16"});
    room.setRecovery(MainWindow::Recovery::Never);
    room.show();
    if (!QTest::qWaitForWindowExposed(&room)) return 1;
    const double refineStall = longestStallMs([&] {
        room.openProject(root + "/projects/default.json", false);
        waitSettled(room);
    });
    std::printf("GUI thread's longest stall while the default project's views and references render: %.1f ms\n",
                refineStall);
    return 0;
}
