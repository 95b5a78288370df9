// What renders when: references cached on disk, fast views before slow ones, a GPU view beside the CPU ones.
#include "gui_test.h"

namespace tyndall::studio::gui {

class RenderingTest final : public FlowCase {
    Q_OBJECT
public:
    using FlowCase::FlowCase;

private:
    // A render task of the default project's view `name` (index `view`), as the scheduler would submit it.
    static RenderTask viewTask(const Project& project, int view, const std::string& name, bool slow, quint64 generation,
                               const JobOptions& options = {}) {
        RenderTask task;
        task.view = view;
        task.slow = slow;
        task.generation = generation;
        task.job = std::make_shared<RenderJob>(makeViewJob(project, kDefaultProject.toStdString(), name, options));
        return task;
    }

private slots:
    void initTestCase() { startOnTheDefaultProject(); }

    // Finished references are cached on disk: a studio that opens the same project gets them without rendering.
    void cachesFinishedReferencesOnDisk() {
        for (const ViewFrame& f : window_->studio().frames())
            QVERIFY(!f.referenceCached);            // the first studio rendered them (the cache was empty)
        window_->studio().waitForBackgroundWork();  // the cache files are written in a thread pool
        MainWindow second(vulkan_, kSmall);
        second.studio().setRecovery(Studio::Recovery::Never);
        QVERIFY(second.openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(second.studio().settled(), 120000);
        for (std::size_t i = 0; i < second.studio().frames().size(); ++i) {
            const ViewFrame& f = second.studio().frames()[i];
            QVERIFY2(f.referenceCached, qPrintable(f.name));
            QVERIFY(samePixels(*f.reference, *window_->studio().frames()[i].reference));
        }
    }

    // Scheduling: a fast technique's render does not wait behind a slow, progressive one (the path tracer as a view):
    // the slow render steps aside, the fast one finishes first, and the slow one starts again and finishes.
    void fastViewsGoBeforeSlowOnes() {
        const Project project = loadProject(techniqueCatalogue(), kDefaultProject.toStdString(), kSmall);
        JobOptions slowOptions;
        slowOptions.spp = 4096;  // minutes at full speed: it must be interrupted to let the fast view through
        RenderService service;
        std::vector<int> finals;
        int slowImages = 0;
        connect(&service, &RenderService::output, [&](const RenderOutput& out) {
            if (out.view == 0 && !out.final && out.image) ++slowImages;
            if (out.final) finals.push_back(out.error.isEmpty() ? out.view : -1 - out.view);
        });
        const RenderTask slow = viewTask(project, 0, "everything", true, 1, slowOptions);  // the path tracer
        const RenderTask fast = viewTask(project, 1, "light shaft", false, 2);             // WVDS
        service.submit(slow);
        QTRY_VERIFY_WITH_TIMEOUT(slowImages > 0, 60000);  // the slow render is running
        service.submit(fast);
        QTRY_VERIFY_WITH_TIMEOUT(!finals.empty(), 60000);
        QCOMPARE(finals.front(), 1);
        // The slow one went back to the queue: it runs again (from zero) once the fast one is done.
        const int before = slowImages;
        QTRY_VERIFY_WITH_TIMEOUT(slowImages > before, 60000);
        QVERIFY(!service.idle());
        service.cancelAll();
        QTRY_VERIFY_WITH_TIMEOUT(service.idle(), 60000);
    }

    // Two slow views (the path tracer, and WVDS once it has sent progressive images): the second's first image does
    // not wait for the first's accumulation. The running one steps aside (its first image out) and starts again once
    // the waiting view has rendered (issue 31: WVDS waited 16 s behind the path tracer's 64 spp).
    void aSlowViewsFirstImageDoesNotWaitForAnothersAccumulation() {
        const Project project = loadProject(techniqueCatalogue(), kDefaultProject.toStdString(), kSmall);
        JobOptions longOptions;
        longOptions.spp = 4096;  // minutes: the second view's image can only come first if this one steps aside
        RenderService service;
        std::vector<RenderOutput> outputs;
        connect(&service, &RenderService::output, [&](const RenderOutput& out) { outputs.push_back(out); });
        const RenderTask first = viewTask(project, 0, "everything", true, 1, longOptions);  // the path tracer
        // WVDS, slow as the scheduler marks it once it sent a progressive image.
        const RenderTask second = viewTask(project, 1, "light shaft", true, 2);
        service.submit(first);
        QTest::qWait(100);  // the worker has taken it
        service.submit(second);
        auto finalOf = [&](int view) {
            return std::find_if(outputs.begin(), outputs.end(),
                                [view](const RenderOutput& o) { return o.view == view && o.final; });
        };
        QTRY_VERIFY_WITH_TIMEOUT(finalOf(1) != outputs.end(), 60000);
        QVERIFY(finalOf(1)->error.isEmpty() && finalOf(1)->image);
        // The path tracer had shown at most its first image before then, and goes on afterwards.
        const std::size_t at = std::size_t(finalOf(1) - outputs.begin());
        int before = 0;
        for (std::size_t i = 0; i < at; ++i)
            before += outputs[i].view == 0;
        QVERIFY2(before <= 1, qPrintable(QString::number(before)));
        QTRY_VERIFY_WITH_TIMEOUT(std::any_of(outputs.begin() + std::ptrdiff_t(at), outputs.end(),
                                             [](const RenderOutput& o) { return o.view == 0 && o.image; }),
                                 60000);
        service.cancelAll();
        QTRY_VERIFY_WITH_TIMEOUT(service.idle(), 60000);
    }

    // The sun edit of the issue, on the default project, in the studio: after it, the two views it affects (the path
    // tracer "everything" and WVDS "light shaft") each show their first image before any view shows a refinement
    // (a second image of the new state), while the path tracer's render of the edit before is still running.
    void everyAffectedViewsFirstImageComesBeforeAnyRefinement() {
        Studio& studio = window_->studio();
        QTRY_VERIFY_WITH_TIMEOUT(studio.settled(), 120000);
        struct Seen {
            int view, spp, factor;
            bool final;
            quint64 state;
        };
        std::vector<Seen> seen;
        const QMetaObject::Connection watching =
            connect(&studio.scheduler(), &RenderScheduler::output, this, [&](const RenderOutput& out) {
                if (!out.reference && out.image) seen.push_back({out.view, out.spp, out.factor, out.final, out.state});
            });
        QString error;
        QVERIFY2(studio.session().editScene({"lights[sun].direction=[0.3, -0.42, 1.0]"}, "sun", &error),
                 qPrintable(error));
        // The path tracer's render of this state is running (it has shown an image) when the next edit comes.
        QTRY_VERIFY_WITH_TIMEOUT(
            std::any_of(seen.begin(), seen.end(),
                        [&](const Seen& s) { return s.view == 0 && s.state == studio.frames()[0].state; }),
            60000);
        const std::size_t start = seen.size();
        QVERIFY2(studio.session().editScene({"lights[sun].direction=[0.32, -0.42, 1.0]"}, "sun", &error),
                 qPrintable(error));
        const quint64 everything = studio.frames()[0].state, shaft = studio.frames()[1].state;
        QTRY_VERIFY_WITH_TIMEOUT(studio.settled(), 240000);
        disconnect(watching);
        // Per view of the new state: its first image (of any resolution: a reduced one counts) and its refinements
        // (the full-resolution images after its first full-resolution one: more samples).
        std::map<int, int> images, fullImages;
        std::optional<std::size_t> lastFirst, firstRefinement;
        for (std::size_t i = start; i < seen.size(); ++i) {
            const Seen& s = seen[i];
            if (s.state != (s.view == 0 ? everything : s.view == 1 ? shaft : 0)) continue;
            if (images[s.view]++ == 0) lastFirst = i;
            if (s.factor == 1 && fullImages[s.view]++ > 0 && !firstRefinement) firstRefinement = i;
        }
        QVERIFY(images[0] >= 1 && images[1] >= 1);
        QVERIFY2(fullImages[0] + fullImages[1] > 2, "no refinement at all: the check would be empty");
        QVERIFY2(
            !firstRefinement || *lastFirst < *firstRefinement,
            qPrintable(
                QString("the last first image came at %1, a refinement at %2").arg(*lastFirst).arg(*firstRefinement)));
        studio.session().undoStack()->undo();
        studio.session().undoStack()->undo();
        QTRY_VERIFY_WITH_TIMEOUT(studio.settled(), 240000);
    }

    // With a GPU worker (on a machine with a hardware GPU; forced on here, where lavapipe shares the CPU's cores), a
    // GPU view's render runs beside a CPU one instead of interrupting it: the path tracer's progressive render goes on
    // (its spp never starts again) while the WVDS view, on the GPU, finishes.
    void aGpuViewRendersBesideTheCpu() {
        Project project = loadProject(techniqueCatalogue(), kDefaultProject.toStdString(), kSmall);
        project.views[1].parameters["device"] = "gpu";
        JobOptions slowOptions;
        slowOptions.spp = 4096;
        RenderService service(nullptr, RenderService::GpuWorker::On);
        QVERIFY(service.hasGpuWorker());
        int slowImages = 0, lastSpp = 0, fastFinals = 0;
        bool restarted = false;
        connect(&service, &RenderService::output, [&](const RenderOutput& out) {
            if (out.view == 0 && out.image) {
                restarted |= out.spp < lastSpp;
                lastSpp = out.spp;
                ++slowImages;
            }
            if (out.view == 1 && out.final) fastFinals += out.error.isEmpty() ? 1 : 100;
        });
        const RenderTask slow = viewTask(project, 0, "everything", true, 1, slowOptions);
        RenderTask fast = viewTask(project, 1, "light shaft", false, 2);
        fast.gpu = true;
        service.submit(slow);
        // Past its first pass, so that a restart would show as an image of fewer samples.
        QTRY_VERIFY_WITH_TIMEOUT(lastSpp > 1, 60000);
        service.submit(fast);
        QTRY_VERIFY_WITH_TIMEOUT(fastFinals > 0, 60000);
        QCOMPARE(fastFinals, 1);
        const int before = slowImages;
        QTRY_VERIFY_WITH_TIMEOUT(slowImages > before, 60000);
        QVERIFY2(!restarted, "the CPU's render was interrupted");
        service.cancelAll();
        QTRY_VERIFY_WITH_TIMEOUT(service.idle(), 60000);
    }
};

QObject* makeRenderingTest(QVulkanInstance* vulkan) {
    return new RenderingTest(vulkan);
}

}  // namespace tyndall::studio::gui

#include "test_rendering.moc"
