// What renders when: references cached on disk, fast views before slow ones, a GPU view beside the CPU ones.
#include "gui_test.h"

namespace tyndall::studio::gui {

class RenderingTest final : public FlowCase {
    Q_OBJECT
public:
    using FlowCase::FlowCase;

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
        RenderTask slow;
        slow.view = 0;  // "everything", the path tracer
        slow.slow = true;
        slow.generation = 1;
        slow.job =
            std::make_shared<RenderJob>(makeViewJob(project, kDefaultProject.toStdString(), "everything", slowOptions));
        RenderTask fast;
        fast.view = 1;  // "light shaft", WVDS
        fast.generation = 2;
        fast.job = std::make_shared<RenderJob>(makeViewJob(project, kDefaultProject.toStdString(), "light shaft"));
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
        RenderTask slow;
        slow.view = 0;
        slow.slow = true;
        slow.generation = 1;
        slow.job =
            std::make_shared<RenderJob>(makeViewJob(project, kDefaultProject.toStdString(), "everything", slowOptions));
        RenderTask fast;
        fast.view = 1;
        fast.gpu = true;
        fast.generation = 2;
        fast.job = std::make_shared<RenderJob>(makeViewJob(project, kDefaultProject.toStdString(), "light shaft"));
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
