// The studio's responsiveness, measured in a real window (run under xvfb-run with QT_QPA_PLATFORM=xcb):
//   xvfb-run -a -s "-screen 0 1600x1000x24" build/studio/bench/tyndall_studio_latency
//       [--stalls | --edit VIEW | --all [--json FILE]]
// - --all: every view of every bundled project (measureAll);
// - time from a parameter change to the first frame on screen that shows the updated technique view at 512 x 512 (a
//   reduced image of its progressive resolution, or its first progressive pass), to its first full-resolution image,
//   and until everything settled, per technique (the median of 6 edits, after the project has settled; references at
//   4 spp so that they settle quickly), with the progressive resolution on and off in turn;
// - the GUI thread's longest stall while a view re-renders on every change of the parameter panel's slider, dragged for
//   3 s (a step every 16 ms),
//   measured as the longest gap between the ticks of a 1 ms timer, and the longest stall while references refine;
//   with each, the gaps' 99th percentile and how many exceeded 20 ms (the longest is one event in a minute: it says
//   little of how the rest went).
#include "main_window.h"
#include "parameter_panel.h"

#include <QApplication>
#include <QDir>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QSaveFile>
#include <QSlider>
#include <QStandardPaths>
#include <QTest>
#include <QUndoStack>
#include <QVulkanInstance>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <map>
#include <thread>

#include <unistd.h>
#include <cstdio>
#include <string>
#include <vector>

using namespace tyndall;
using namespace tyndall::studio;

namespace {

// With TYNDALL_TRACE_EVENTS set, every event dispatch on the GUI thread longer than 15 ms is printed with its receiver,
// its type, and the GUI thread's CPU time during it (wall >> CPU: the thread waited or was preempted).
class TracingApplication : public QApplication {
public:
    using QApplication::QApplication;
    bool notify(QObject* receiver, QEvent* event) override {
        if (!trace_) return QApplication::notify(receiver, event);
        timespec c0, c1;
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
        QElapsedTimer wall;
        wall.start();
        const int type = int(event->type());
        eventStart_.store(wall_.nsecsElapsed());
        const char* name = receiver->metaObject()->className();
        const bool result = QApplication::notify(receiver, event);
        eventStart_.store(-1);
        const double ms = double(wall.nsecsElapsed()) * 1e-6;
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
        if (ms > 1.0) log_.push_back({eventStartOf(wall), double(wall_.nsecsElapsed()) * 1e-6, type, name,
                                      double(c1.tv_sec - c0.tv_sec) * 1e3 + double(c1.tv_nsec - c0.tv_nsec) * 1e-6});
        if (ms > 15.0)
            std::fprintf(stderr, "event %4d to %-28s %6.1f ms wall, %6.1f ms CPU\n", type, name, ms,
                         double(c1.tv_sec - c0.tv_sec) * 1e3 + double(c1.tv_nsec - c0.tv_nsec) * 1e-6);
        return result;
    }
    bool trace_ = qEnvironmentVariableIsSet("TYNDALL_TRACE_EVENTS");
    // A watchdog prints what the GUI thread is blocked in (its system call and kernel wait channel) when one event
    // has run for 30 ms.
    void startWatchdog() {
        if (!trace_) return;
        wall_.start();
        const pid_t gui = gettid();
        std::thread([this, gui] {
            qint64 reported = -2;
            for (;;) {
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
                const qint64 start = eventStart_.load();
                if (start < 0 || start == reported || wall_.nsecsElapsed() - start < 30000000) continue;
                reported = start;
                auto slurp = [&](const char* what) {
                    QFile f(QString("/proc/self/task/%1/%2").arg(gui).arg(what));
                    return f.open(QIODevice::ReadOnly) ? QString::fromLatin1(f.readAll()).simplified() : QString();
                };
                std::fprintf(stderr, "watchdog: GUI blocked: syscall %s | wchan %s | %s\n",
                             qPrintable(slurp("syscall").section(' ', 0, 0)), qPrintable(slurp("wchan")),
                             qPrintable(slurp("stack").left(300)));
            }
        }).detach();
    }
    double eventStartOf(const QElapsedTimer& event) const {
        return double(wall_.nsecsElapsed() - event.nsecsElapsed()) * 1e-6;
    }
    // Prints the events of more than 1 ms that overlap [from, to] (ms on wall_).
    void dump(double from, double to) const {
        for (const Logged& e : log_)
            if (e.end >= from && e.start <= to)
                std::fprintf(stderr, "  %9.1f - %9.1f  event %4d to %-28s CPU %5.1f ms\n", e.start, e.end, e.type,
                             e.name, e.cpu);
    }
    double now() const { return double(wall_.nsecsElapsed()) * 1e-6; }
    struct Logged {
        double start, end;
        int type;
        const char* name;
        double cpu;
    };
    std::vector<Logged> log_;
    QElapsedTimer wall_;
    std::atomic<qint64> eventStart_{-1};
};
TracingApplication* tracer = nullptr;

const std::vector<std::string> k512 = {"camera.width=512", "camera.height=512", "reference.spp=4"};

// Gaps between the ticks of a 1 ms timer while some work ran the event loop.
struct Stalls {
    double longestMs = 0.0;
    double p99Ms = 0.0;  // the 99th percentile of the gaps
    int over20 = 0;      // gaps longer than 20 ms
    double seconds = 0.0;
};
Stalls lastStalls;

// The longest gap between ticks of a 1 ms timer while `work` runs the event loop (lastStalls has the rest).
template <typename Work>
double longestStallMs(Work&& work) {
    QElapsedTimer clock;
    clock.start();
    qint64 last = clock.nsecsElapsed(), longest = 0;
    double worstEnd = 0.0;
    std::vector<double> gaps;
    QTimer ticker;
    QObject::connect(&ticker, &QTimer::timeout, [&] {
        const qint64 now = clock.nsecsElapsed();
        gaps.push_back(double(now - last) * 1e-6);
        if (now - last > longest) {
            longest = now - last;
            if (tracer) worstEnd = tracer->now();
        }
        last = now;
    });
    ticker.start(1);
    work();
    ticker.stop();
    if (tracer && tracer->trace_) {
        std::fprintf(stderr, "longest stall %.1f ms, ending at %.1f; events in it:\n", double(longest) * 1e-6, worstEnd);
        tracer->dump(worstEnd - double(longest) * 1e-6, worstEnd);
    }
    lastStalls = Stalls{};
    lastStalls.longestMs = double(longest) * 1e-6;
    lastStalls.seconds = double(clock.nsecsElapsed()) * 1e-9;
    lastStalls.over20 = int(std::count_if(gaps.begin(), gaps.end(), [](double g) { return g > 20.0; }));
    if (!gaps.empty()) {
        std::sort(gaps.begin(), gaps.end());
        lastStalls.p99Ms = gaps[std::min(gaps.size() - 1, gaps.size() * 99 / 100)];
    }
    return lastStalls.longestMs;
}

void waitSettled(MainWindow& w, int timeoutMs = 600000) {
    QElapsedTimer t;
    t.start();
    while (!w.studio().settled() && t.elapsed() < timeoutMs)
        QTest::qWait(5);
}

struct Edit {
    const char* project;
    const char* view;
    const char* parameter;
    nlohmann::json values[2] = {false, true};  // set in turn
};

double percentile(std::vector<double> x, double p) {
    if (x.empty()) return 0.0;
    std::sort(x.begin(), x.end());
    return x[std::min(x.size() - 1, std::size_t(p * double(x.size())))];
}

// The newest step of a drag that `image` shows: the step whose part state it carries (metadata "partHash"), or -1 (an
// image from before the drag, or none).
int stepShown(const std::shared_ptr<const Image>& image, const std::map<std::string, int>& stepOfState) {
    if (!image) return -1;
    const auto it = image->metadata.find("partHash");
    if (it == image->metadata.end()) return -1;
    const auto step = stepOfState.find(it->second);
    return step == stepOfState.end() ? -1 : step->second;
}

// --all [--json FILE]: every view of every bundled project (default, examples/, ltsd/, isv/), at the project's own
// size with references at 4 spp. Per view, after the project settled, the view is shown alone (the others, off
// screen, wait for the drag to pause: RenderScheduler::setOnScreen) and the camera orbits by 0.1 degree every 16 ms
// for 3 s, the steps of a drag in the viewport, each a new state of the scene. An edit's latency is the time from its
// step to the first frame presented that shows an image of it or of a later step (a reduced image counts: it is
// labelled as one); an edit still unshown 10 s after the drag counts as that long. Then kFullEdits single steps, each
// from the settled view to its full-resolution image; then the camera goes back (undo). The JSON is a list of
// {"project", "view", "technique", "firstImageMs": {"median", "p95"}, "fullResolutionMs": {"median", "p95"}} and one
// {"stallMs": {"longest", "p99"}}: the GUI thread's longest gap between the ticks of a 1 ms timer over every drag and
// edit, and the largest of their 99th percentiles.
int measureAll(QVulkanInstance& vulkan, const QString& root, const std::string& jsonPath) {
    constexpr int kSteps = 180;  // 3 s at one step per 16 ms
    constexpr int kFullEdits = 3;
    const double kYaw = 0.1 * 3.14159265358979 / 180.0;  // per step: 18 degrees over the drag, always one way
    QStringList projects = {root + "/projects/default.json"};
    for (const char* folder : {"/projects/examples", "/projects/ltsd", "/projects/isv"})
        for (const QString& name : QDir(root + folder).entryList({"*.json"}, QDir::Files, QDir::Name))
            projects << root + folder + "/" + name;
    // TYNDALL_LATENCY_PROJECTS: only the projects whose path contains it (a quicker run while looking into one).
    const QString only = qEnvironmentVariable("TYNDALL_LATENCY_PROJECTS");
    nlohmann::json results = nlohmann::json::array();
    double longestStall = 0.0, p99Stall = 0.0;
    for (const QString& project : projects) {
        if (!only.isEmpty() && !project.contains(only)) continue;
        MainWindow window(&vulkan, {"reference.spp=4"});
        window.studio().setRecovery(Studio::Recovery::Never);
        window.show();
        if (!QTest::qWaitForWindowExposed(&window) || !window.openProject(project, false)) {
            std::fprintf(stderr, "cannot open %s\n", project.toUtf8().constData());
            return 1;
        }
        waitSettled(window);
        Studio& studio = window.studio();
        QUndoStack& undo = *studio.session().undoStack();
        for (int view = 0; view < int(studio.session().project().views.size()); ++view) {
            const View v = studio.session().project().views[std::size_t(view)];
            studio.showViewAlone(view);
            waitSettled(window);
            const int undoIndex = undo.index();
            std::map<std::string, int> stepOfState;
            std::vector<double> orbitMs;
            std::vector<double> stepAt(kSteps, 0.0), latency(kSteps, -1.0);
            QElapsedTimer t;
            t.start();
            int presented = window.viewport()->framesPresented(), resolved = 0;
            auto poll = [&] {
                QTest::qWait(1);
                if (window.viewport()->framesPresented() == presented) return;
                presented = window.viewport()->framesPresented();
                const int shown = stepShown(shownImage(studio.frames()[std::size_t(view)]), stepOfState);
                const double now = double(t.nsecsElapsed()) * 1e-6;
                for (; resolved <= shown; ++resolved)
                    latency[std::size_t(resolved)] = now - stepAt[std::size_t(resolved)];
            };
            longestStall = std::max(longestStall, longestStallMs([&] {
                                        for (int k = 0; k < kSteps; ++k) {
                                            stepAt[std::size_t(k)] = double(t.nsecsElapsed()) * 1e-6;
                                            QElapsedTimer o;
                                            o.start();
                                            studio.orbitCamera(kYaw, 0.0);
                                            orbitMs.push_back(double(o.nsecsElapsed()) * 1e-6);
                                            stepOfState[stateName(studio.scheduler().state(view)).toStdString()] = k;
                                            while (double(t.nsecsElapsed()) * 1e-6 < stepAt[std::size_t(k)] + 16.0)
                                                poll();
                                        }
                                        const double end = double(t.nsecsElapsed()) * 1e-6;
                                        while (resolved < kSteps && double(t.nsecsElapsed()) * 1e-6 < end + 10000.0)
                                            poll();
                                    }));
            p99Stall = std::max(p99Stall, lastStalls.p99Ms);
            std::printf("orbit step on the GUI thread: median %.2f ms, p95 %.2f ms, max %.2f\n",
                        percentile(orbitMs, 0.5), percentile(orbitMs, 0.95), percentile(orbitMs, 1.0));
            for (int k = 0; k < kSteps; ++k)
                if (latency[std::size_t(k)] < 0.0)
                    latency[std::size_t(k)] = double(t.nsecsElapsed()) * 1e-6 - stepAt[std::size_t(k)];
            waitSettled(window, 5000);  // a progressive view refines for long: the next edit replaces it
            std::vector<double> full;
            for (int k = 0; k < kFullEdits; ++k) {
                QElapsedTimer e;
                e.start();
                longestStall = std::max(longestStall, longestStallMs([&] {
                                            studio.orbitCamera(4.0 * kYaw, 0.0);
                                            const quint64 state = studio.scheduler().state(view);
                                            auto done = [&] {
                                                const ViewFrame& f = studio.frames()[std::size_t(view)];
                                                return f.image && f.imageState == state;
                                            };
                                            while (!done() && e.elapsed() < 600000)
                                                QTest::qWait(1);
                                            full.push_back(double(e.nsecsElapsed()) * 1e-6);
                                            waitSettled(window, 5000);
                                        }));
                p99Stall = std::max(p99Stall, lastStalls.p99Ms);
            }
            undo.setIndex(undoIndex);  // the camera as it was, for the next view
            waitSettled(window);
            const QString name = QDir(root).relativeFilePath(project);
            nlohmann::json entry = {
                {"project", name.toStdString()},
                {"view", v.name},
                {"technique", v.technique},
                {"firstImageMs", {{"median", percentile(latency, 0.5)}, {"p95", percentile(latency, 0.95)}}},
                {"fullResolutionMs", {{"median", percentile(full, 0.5)}, {"p95", percentile(full, 0.95)}}}};
            std::printf(
                "%-36s %-18s %-10s drag: first image %6.0f ms (p95 %6.0f); full resolution %6.0f ms (p95 "
                "%6.0f)\n",
                name.toUtf8().constData(), v.name.c_str(), v.technique.c_str(), percentile(latency, 0.5),
                percentile(latency, 0.95), percentile(full, 0.5), percentile(full, 0.95));
            std::fflush(stdout);
            results.push_back(std::move(entry));
        }
    }
    results.push_back({{"stallMs", {{"longest", longestStall}, {"p99", p99Stall}}}});
    std::printf("GUI thread: longest stall %.1f ms, 99th percentile %.1f ms\n", longestStall, p99Stall);
    if (!jsonPath.empty()) {
        QSaveFile file(QString::fromStdString(jsonPath));  // all or nothing
        if (!file.open(QIODevice::WriteOnly) || file.write(QByteArray::fromStdString(results.dump(2) + "\n")) < 0 ||
            !file.commit()) {
            std::fprintf(stderr, "cannot write %s\n", jsonPath.c_str());
            return 1;
        }
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    TracingApplication app(argc, argv);
    app.startWatchdog();
    tracer = &app;
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
                          {"/projects/examples/pegoraro-street.json", "closed form", "shadows"},
                          {"/projects/examples/ltsd-room.json", "ltsd", "nodes", {9, 8}},
                          {"/projects/isv/smoke.json", "isv", "fading"},
                          {"/projects/examples/volume-ris-shaft.json", "shaft", "shadows"}};
    // --stalls: only the drag and the refinement (the edits take ~5 minutes); --edit VIEW: only the edit of that view,
    // then stop.
    const std::string option = argc > 1 ? argv[1] : "", only = argc > 2 ? argv[2] : "";
    const bool stallsOnly = option == "--stalls";
    if (!stallsOnly && option != "--all")
        std::printf("medians of 6 edits each at 512 x 512, progressive resolution on and off in turn\n");
    for (const Edit& e : edits) {
        if (stallsOnly || option == "--all") break;
        if (option == "--edit" && only != e.view) continue;
        MainWindow window(&vulkan, k512);
        window.studio().setRecovery(Studio::Recovery::Never);
        window.show();
        if (!QTest::qWaitForWindowExposed(&window)) return 1;
        if (!window.openProject(root + e.project, false)) return 1;
        waitSettled(window);
        int view = -1;
        for (int i = 0; i < int(window.studio().session().project().views.size()); ++i)
            if (window.studio().session().project().views[std::size_t(i)].name == e.view) view = i;
        if (view < 0) return 1;
        // Per mode (0: progressive resolution on, 1: off), alternately: first frame, full resolution, settled.
        std::vector<double> first[2], full[2], final[2];
        bool value = false;
        double stall = 0.0;
        auto shown = [&] { return shownImage(window.studio().frames()[std::size_t(view)]); };
        for (int k = 0; k < 12; ++k) {
            const int mode = k % 2;
            window.studio().scheduler().setProgressiveResolution(mode == 0);
            const auto before = window.studio().frames()[std::size_t(view)].image;
            QElapsedTimer t;
            t.start();
            double firstMs = 0.0, fullMs = 0.0;
            stall = std::max(stall, longestStallMs([&] {
                                 window.studio().session().setParameter(view, e.parameter, e.values[value]);
                                 while (shown() == before)
                                     QTest::qWait(1);
                                 // The image was composed as it arrived; the next frame the viewport presents shows it.
                                 const int presented = window.viewport()->framesPresented();
                                 while (window.viewport()->framesPresented() == presented)
                                     QTest::qWait(1);
                                 firstMs = double(t.nsecsElapsed()) * 1e-6;
                                 while (window.studio().frames()[std::size_t(view)].image == before)
                                     QTest::qWait(1);
                                 fullMs = double(t.nsecsElapsed()) * 1e-6;
                                 while (!window.studio().settled())
                                     QTest::qWait(1);
                             }));
            first[mode].push_back(firstMs);
            full[mode].push_back(fullMs);
            final[mode].push_back(double(t.nsecsElapsed()) * 1e-6);
            value = !value;
        }
        window.studio().scheduler().setProgressiveResolution(true);
        const View& v = window.studio().session().project().views[std::size_t(view)];
        auto median = [](std::vector<double> x) {
            std::sort(x.begin(), x.end());
            return 0.5 * (x[x.size() / 2 - 1] + x[x.size() / 2]);
        };
        for (int mode : {0, 1})
            std::printf("%-24s %-12s %-10s %-16s first frame %6.0f ms, full resolution %6.0f ms, settled %6.0f ms\n",
                        QFileInfo(e.project).fileName().toUtf8().constData(), e.view, v.technique.c_str(),
                        mode == 0 ? "progressive res." : "full res. only", median(first[mode]), median(full[mode]),
                        median(final[mode]));
        std::printf("%-24s %-12s GUI stall %.1f ms\n", "", e.view, stall);
        std::fflush(stdout);
    }

    if (option == "--edit") return 0;
    if (option == "--all") return measureAll(vulkan, root, argc > 3 && only == "--json" ? argv[3] : "");
    // A slider dragged over the WVDS view for 3 s, and the references of the default project refining.
    MainWindow window(&vulkan, k512);
    window.studio().setRecovery(Studio::Recovery::Never);
    window.show();
    if (!QTest::qWaitForWindowExposed(&window)) return 1;
    window.openProject(root + "/projects/examples/wvds-box.json", false);
    waitSettled(window);
    {
        // The viewport's own cost with nothing rendering: 60 frames, each asked for once the last was presented.
        QElapsedTimer t;
        t.start();
        double longest = 0.0;
        for (int k = 0; k < 60; ++k) {
            const int presented = window.viewport()->framesPresented();
            longest = std::max(longest, longestStallMs([&] {
                window.viewport()->requestUpdate();
                while (window.viewport()->framesPresented() == presented)
                    QTest::qWait(1);
            }));
        }
        std::printf("viewport at %d x %d, idle: %.1f ms per frame, longest GUI stall %.1f ms\n",
                    window.viewport()->pixelSize().width(), window.viewport()->pixelSize().height(),
                    double(t.nsecsElapsed()) * 1e-6 / 60.0, longest);
    }
    // The slider of the parameter panel, as a user drags it (view 0, the panel's view).
    auto* spin = window.findChild<QDoubleSpinBox*>("param:pdfScale");
    auto* slider = spin ? spin->parentWidget()->findChild<QSlider*>() : nullptr;
    if (!slider) {
        std::fprintf(stderr, "no pdfScale slider in the parameter panel\n");
        return 1;
    }
    const double dragStall = longestStallMs([&] {
        for (int k = 0; k < 180; ++k) {
            slider->setValue(slider->minimum() + (slider->maximum() - slider->minimum()) * (k % 50) / 100);
            QTest::qWait(16);
        }
        waitSettled(window);
    });
    const Stalls drag = lastStalls;
    std::printf("GUI thread's longest stall during a 3 s drag over the WVDS view: %.1f ms (99th percentile %.1f ms, "
                "%d over 20 ms in %.1f s)\n",
                dragStall, drag.p99Ms, drag.over20, drag.seconds);
    MainWindow room(&vulkan, {"camera.width=512", "camera.height=512", "reference.spp=16"});
    room.studio().setRecovery(Studio::Recovery::Never);
    room.show();
    if (!QTest::qWaitForWindowExposed(&room)) return 1;
    // A new window's first frame builds its display pipeline (on a software device, its shaders are compiled to
    // machine code at the first draw: 25-50 ms here). That is the window's start, not a stall while rendering.
    QElapsedTimer firstFrame;
    firstFrame.start();
    while (room.viewport()->framesPresented() == 0 && firstFrame.elapsed() < 10000)
        QTest::qWait(1);
    const double firstFrameMs = double(firstFrame.nsecsElapsed()) * 1e-6;
    QElapsedTimer opening;
    opening.start();
    room.openProject(root + "/projects/default.json", false);
    // Opening builds the panels; their widgets' posted events (layout, polish) belong to the opening too.
    QCoreApplication::sendPostedEvents();
    const double openMs = double(opening.nsecsElapsed()) * 1e-6;
    // The panels take room from the viewport, so its next frame recreates the swapchain at the new size.
    const int presentedAtOpen = room.viewport()->framesPresented();
    const double resizeStall = longestStallMs([&] {
        QElapsedTimer t;
        t.start();
        while (room.viewport()->framesPresented() == presentedAtOpen && t.elapsed() < 10000)
            QTest::qWait(1);
    });
    const double refineStall = longestStallMs([&] { waitSettled(room); });
    const Stalls refine = lastStalls;
    std::printf("a new window's first frame: %.0f ms; opening the default project (its panels included): %.0f ms, then its "
                "first frame at the viewport's new size: longest GUI stall %.1f ms\n",
                firstFrameMs, openMs, resizeStall);
    std::printf("GUI thread's longest stall while its views and references render: %.1f ms (99th percentile %.1f ms, "
                "%d over 20 ms in %.1f s)\n",
                refineStall, refine.p99Ms, refine.over20, refine.seconds);
    return 0;
}
