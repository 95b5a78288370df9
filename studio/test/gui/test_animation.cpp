#include "gui_test.h"

namespace tyndall::studio::gui {

// The particle simulation driven from the studio (issue 20, item 6), a case of its own (Studio.Gui.Animation,
// `--animation`) on the bundled smoke cloud, small, with one ISV view and the path tracer as a (progressive) view: play
// advances the steps only as the views follow and shows a moving cloud, undo takes the whole play back, a Ctrl+click
// pushes the particles under the cursor, Ctrl+Shift+drag and the Scene dock move the targets, reset goes back to the
// start, and a saved frame is the one on screen (loadProject, and a render of the file equals the studio's image).
class AnimationTest final : public QObject {
    Q_OBJECT
public:
    explicit AnimationTest(QVulkanInstance* vulkan) : vulkan_(vulkan) {}

private:
    const ParticleMedium& smoke() const { return window_->studio().session().project().scene.particleMedia.at(0); }
    int steps() const { return smoke().simulation ? smoke().simulation->steps : 0; }
    // The ISV view's final image of the current state (waits up to 2 minutes for it; null if none came).
    std::shared_ptr<const Image> currentIsv() {
        QElapsedTimer clock;
        clock.start();
        while (clock.elapsed() < 120000) {
            const ViewFrame& f = window_->studio().frames()[0];
            if (f.image && f.imageState == f.state && !f.rendering) return f.image;
            QTest::qWait(20);
        }
        return nullptr;
    }
    QPoint isvCentre() const {
        const QRect r = viewRects(window_->studio().frames(), window_->studio().compositorState(),
                                  window_->viewport()->pixelSize())[0];
        return r.center();
    }
    void shoot(const QString& name) {
        window_->studio().recompose();
        const QImage frame = window_->studio().composedFrame();
        frame.save(QString(TYNDALL_TEST_TMP) + "/animation-" + name + ".png");  // to look at
        QVERIFY2(distinctColours(frame) > 50, qPrintable(name));
    }

private slots:
    void initTestCase() {
        QDir(QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave").removeRecursively();
        QSettings().remove("window");
        QDir().mkpath(TYNDALL_TEST_TMP);
        std::vector<std::string> overrides = kSmall;
        overrides.push_back(
            R"(views=[{"name": "isv", "technique": "isv"}, {"name": "path traced", "technique": "reference"}])");
        window_ = std::make_unique<MainWindow>(vulkan_, overrides);
        window_->show();
        QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
        QVERIFY(window_->openProject(kSmoke, false));
        QVERIFY(!smoke().simulation);
        QVERIFY(window_->findChild<QAction*>("playAnimation")->isEnabled());
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 240000);
    }

    // The default project has no particle medium: the animation's actions are disabled there.
    void actionsNeedAParticleMedium() {
        auto* play = window_->findChild<QAction*>("playAnimation");
        auto* bar = window_->findChild<QToolBar*>("animationToolbar");
        QVERIFY(play && bar);
        QVERIFY(play->isEnabled() && bar->isVisible());
        QVERIFY(window_->openProject(kDefaultProject, false));
        QVERIFY(!play->isEnabled() && !bar->isVisible());
        QVERIFY(!window_->findChild<QAction*>("stepAnimation")->isEnabled());
        QVERIFY(window_->openProject(kSmoke, false));
        QVERIFY(play->isEnabled() && bar->isVisible());
        QVERIFY(window_->shortcutsText().contains("Ctrl+click"));
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 240000);
    }

    // P plays: the steps grow at the wall clock's rate, but only as the views deliver their frames (the ISV view shows
    // several states, each a different picture); P pauses; one undo takes the whole play back.
    void playAdvancesAsTheViewsFollow() {
        // The targets moved to the right: the particles start at rest at their places and drift after them. (At step 0
        // nothing has moved yet: the same picture.)
        const std::shared_ptr<const Image> still = currentIsv();
        QString error;
        QVERIFY2(window_->studio().animation().setOffset(0, Vec3(0.6, 0.0, 0.0), &error), qPrintable(error));
        QCOMPARE(steps(), 0);
        const std::shared_ptr<const Image> start = currentIsv();
        QVERIFY(still && start && samePixels(*still, *start));
        shoot("before-play");
        const int undoBefore = window_->studio().session().undoStack()->count();
        QElapsedTimer clock;
        clock.start();
        QTest::keyClick(window_->viewport(), Qt::Key_P);
        QVERIFY(window_->studio().animation().playing());
        QVERIFY(window_->findChild<QAction*>("playAnimation")->isChecked());
        // Every ISV image of a new state that arrives while playing.
        std::vector<std::shared_ptr<const Image>> images;
        std::vector<int> stepsSeen;
        std::set<quint64> states;
        while (images.size() < 3 && clock.elapsed() < 180000) {
            QTest::qWait(10);
            const ViewFrame& f = window_->studio().frames()[0];
            if (f.image && f.image != start && f.imageState == f.state && !states.count(f.imageState)) {
                states.insert(f.imageState);
                images.push_back(f.image);
                stepsSeen.push_back(steps());
                if (images.size() == 2) shoot("playing");
            }
        }
        QTest::keyClick(window_->viewport(), Qt::Key_P);
        const double seconds = clock.elapsed() * 1e-3;
        QVERIFY(!window_->studio().animation().playing());
        QVERIFY2(images.size() >= 2, qPrintable(QString::number(images.size())));
        const int played = steps();
        QVERIFY(smoke().simulation);
        const double dt = smoke().simulation->timeStep;
        // Steps grew, by no more than the wall time allows.
        QVERIFY2(played > 0 && played <= seconds / dt + 1, qPrintable(QString("%1 in %2 s").arg(played).arg(seconds)));
        QVERIFY(std::is_sorted(stepsSeen.begin(), stepsSeen.end()));
        // The cloud moved: the frames differ, from the start and from each other.
        QVERIFY(!samePixels(*start, *images[0]));
        QVERIFY(!samePixels(*images[0], *images[1]));
        // One undo step for the whole play; undo restores the steps before it.
        QCOMPARE(window_->studio().session().undoStack()->count(), undoBefore + 1);
        window_->studio().session().undoStack()->undo();
        QCOMPARE(steps(), 0);
        const std::shared_ptr<const Image> undone = currentIsv();
        QVERIFY(undone && samePixels(*undone, *start));  // the same frame again (ISV is deterministic)
        window_->studio().session().undoStack()->redo();
        QCOMPARE(steps(), played);
    }

    // A Ctrl+click on the ISV view adds one impulse at the current step, on the camera ray through the pixel inside the
    // cloud, and (paused) steps to the push's farthest: the particles near it are pushed away, those beyond its radius
    // move as without it; a marker on every view shows where it pushed.
    void ctrlClickAddsAnImpulse() {
        QTest::keyClick(window_->viewport(), Qt::Key_1);  // the ISV view alone: a large target
        QString error;
        const std::shared_ptr<const Image> before = currentIsv();
        const int s = steps();
        const std::size_t impulsesBefore = smoke().simulation->impulses.size();
        const std::vector<Particle> rest = smoke().allParticles();
        Vec3 lo(1e300), hi(-1e300);
        for (const Particle& p : rest) {
            lo = glm::min(lo, p.centre - p.scale);
            hi = glm::max(hi, p.centre + p.scale);
        }
        const QPoint at = isvCentre();
        QTest::mouseClick(window_->viewport(), Qt::LeftButton, Qt::ControlModifier, at);
        QTRY_COMPARE(smoke().simulation->impulses.size(), impulsesBefore + 1);
        const ParticleImpulse impulse = smoke().simulation->impulses.back();
        QCOMPARE(impulse.step, s);
        // Paused, the click advances to the push's farthest (0.24 s, 14 steps, with the default spring): visible.
        const int peakSteps = int(std::lround(impulsePeakSeconds(*smoke().simulation) / smoke().simulation->timeStep));
        QVERIFY(peakSteps > 5);
        QCOMPARE(steps(), s + peakSteps);
        QCOMPARE(impulse.radius, window_->studio().animation().impulseRadius());
        QCOMPARE(impulse.speed, window_->studio().animation().impulseSpeed());
        for (int c = 0; c < 3; ++c)
            QVERIFY2(impulse.position[c] > lo[c] && impulse.position[c] < hi[c], qPrintable(QString::number(c)));
        // On the ray through the clicked pixel, and at a particle (the ray meets the cloud there).
        int view;
        QPoint pixel;
        QVERIFY(window_->studio().viewAt(at, view, pixel));
        bool hit = false;
        const std::optional<Vec3> expected = impulsePoint(window_->studio().session().project().scene.camera, rest,
                                                          pixel.x() + 0.5, pixel.y() + 0.5, &hit);
        QVERIFY(expected && hit);
        QVERIFY(glm::length(*expected - impulse.position) < 1e-9);

        // The step with the impulse against the same step without it.
        ParticleSimulation without = *smoke().simulation;
        without.impulses.pop_back();
        const std::vector<Particle> pushed = smoke().allParticles();
        ParticleMedium bare = smoke();
        bare.simulation.reset();
        const std::vector<Particle> unsimulated = bare.allParticles();
        const std::vector<Particle> unpushed = simulateParticles(unsimulated, without);
        QCOMPARE(pushed.size(), unpushed.size());
        int near = 0, far = 0;
        for (std::size_t i = 0; i < pushed.size(); ++i) {
            const double d = glm::length(rest[i].centre - impulse.position);
            if (d < impulse.radius * 0.9) {
                // Moved from where it would be, away from the impulse (the spring is linear: the push's
                // displacement keeps the direction it was given, however the targets drift meanwhile).
                ++near;
                QVERIFY(glm::dot(pushed[i].centre - unpushed[i].centre, rest[i].centre - impulse.position) > 0.0);
            } else if (d >= impulse.radius) {
                ++far;
                QVERIFY(pushed[i].centre == unpushed[i].centre);
            }
        }
        QVERIFY2(near > 10 && far > 10, qPrintable(QString("%1 %2").arg(near).arg(far)));
        const std::shared_ptr<const Image> after = currentIsv();
        QVERIFY(before && after && !samePixels(*after, *before));
        shoot("impulse");
        // A marker where it pushed: on the clicked pixel (the impulse is on its ray), its radius on screen, drawn on
        // the view and nowhere else.
        const std::vector<ImageMarker> markers = window_->studio().compositorState().markers;
        QCOMPARE(markers.size(), std::size_t(1));
        QVERIFY2(std::abs(markers[0].centre.x() - (pixel.x() + 0.5)) < 0.01 &&
                     std::abs(markers[0].centre.y() - (pixel.y() + 0.5)) < 0.01,
                 qPrintable(QString("%1 %2 for %3 %4")
                                .arg(markers[0].centre.x())
                                .arg(markers[0].centre.y())
                                .arg(pixel.x())
                                .arg(pixel.y())));
        QVERIFY(markers[0].radius > 3.0 && markers[0].opacity > 0.5);
        QVERIFY(markers[0].label.contains(QString("step %1").arg(s)));
        {
            const QSize size = window_->viewport()->pixelSize();
            CompositorState unmarked = window_->studio().compositorState();
            unmarked.markers.clear();
            const QImage with = compose(window_->studio().frames(), window_->studio().compositorState(), size);
            const QImage without = compose(window_->studio().frames(), unmarked, size);
            const QRect tile = viewRects(window_->studio().frames(), unmarked, size)[0];
            int inside = 0, outside = 0;
            for (int y = 0; y < with.height(); ++y)
                for (int x = 0; x < with.width(); ++x)
                    if (with.pixel(x, y) != without.pixel(x, y)) ++(tile.contains(x, y) ? inside : outside);
            QVERIFY2(inside > 30 && outside == 0, qPrintable(QString("%1 %2").arg(inside).arg(outside)));
        }
        // It fades with the push and is gone 1.5 s (simulated) after it.
        QVERIFY(window_->studio().animation().step(120, &error));
        QVERIFY(window_->studio().compositorState().markers.empty());
        window_->studio().session().undoStack()->undo();
        QCOMPARE(window_->studio().compositorState().markers.size(), std::size_t(1));
        // One undo step.
        window_->studio().session().undoStack()->undo();
        QCOMPARE(smoke().simulation->impulses.size(), impulsesBefore);
        QCOMPARE(steps(), s);
        window_->studio().session().undoStack()->redo();
    }

    // The region of targets moves: Ctrl+Shift+drag to the right moves it along the camera's right (+x here) by about
    // the distance the cursor covers at the cloud's depth; the Scene dock edits it too.
    void offsetMovesTheTargets() {
        const Vec3 start = smoke().simulation->offset;
        const QPoint from = isvCentre();
        QTest::mousePress(window_->viewport(), Qt::LeftButton, Qt::ControlModifier | Qt::ShiftModifier, from);
        for (int dx = 10; dx <= 40; dx += 10)
            QTest::mouseMove(window_->viewport(), from + QPoint(dx, 0));
        QTest::mouseRelease(window_->viewport(), Qt::LeftButton, Qt::ControlModifier | Qt::ShiftModifier,
                            from + QPoint(40, 0));
        const Vec3 moved = smoke().simulation->offset;
        QVERIFY2(moved.x - start.x > 0.05 && std::abs(moved.y - start.y) < 0.02,
                 qPrintable(QString("%1 %2 %3").arg(moved.x).arg(moved.y).arg(moved.z)));
        window_->studio().session().undoStack()->undo();  // the drag is one edit
        QVERIFY(smoke().simulation->offset == start);

        auto* x = window_->scenePanel()->findChild<QDoubleSpinBox*>("scene:particleMedia[smoke].simulation.offset[0]");
        QVERIFY(x);
        x->setValue(0.3);
        QCOMPARE(smoke().simulation->offset.x, 0.3);
        QTest::keyClick(window_->viewport(), Qt::Key_Period);  // a step, to see the cloud follow its targets
        QVERIFY(currentIsv());
        shoot("offset");
    }

    // A saved frame is the frame on screen: the file loads with its steps and impulses, and a render of the file's
    // ISV view (what `tyndall render file --view isv` does) equals the studio's image.
    void savedFrameIsTheFrameOnScreen() {
        const QString path = QString(TYNDALL_TEST_TMP) + "/animated-smoke.json";
        QString error;
        QVERIFY2(window_->studio().saveProjectAs(path, &error), qPrintable(error));
        const Project loaded = loadProject(techniqueCatalogue(), path.toStdString());
        const ParticleSimulation& saved = *loaded.scene.particleMedia.at(0).simulation;
        const ParticleSimulation& shown = *smoke().simulation;
        QCOMPARE(saved.steps, shown.steps);
        QVERIFY(saved.steps > 0);
        QCOMPARE(saved.impulses.size(), shown.impulses.size());
        QVERIFY(!saved.impulses.empty());
        for (std::size_t i = 0; i < saved.impulses.size(); ++i) {
            QCOMPARE(saved.impulses[i].step, shown.impulses[i].step);
            QVERIFY(saved.impulses[i].position == shown.impulses[i].position);
            QCOMPARE(saved.impulses[i].radius, shown.impulses[i].radius);
        }
        QVERIFY(saved.offset == shown.offset);
        const std::shared_ptr<const Image> onScreen = currentIsv();
        QVERIFY(onScreen);
        RenderJob job = makeViewJob(loaded, path.toStdString(), "isv");
        const RenderResult rendered = runJob(job);
        QVERIFY(samePixels(rendered.image, *onScreen));
    }

    // Reset (Ctrl+R): step 0, no impulses, targets back; undoable.
    void resetGoesBackToTheStart() {
        QVERIFY(steps() > 0 && !smoke().simulation->impulses.empty());
        const int s = steps();
        QTest::keyClick(window_->viewport(), Qt::Key_R, Qt::ControlModifier);
        QCOMPARE(steps(), 0);
        QVERIFY(smoke().simulation->impulses.empty());
        QVERIFY(smoke().simulation->offset == Vec3(0.0));
        QVERIFY(currentIsv());
        shoot("reset");
        window_->studio().session().undoStack()->undo();
        QCOMPARE(steps(), s);
        window_->studio().session().undoStack()->redo();
        QCOMPARE(steps(), 0);
    }

    // isv/motion.json (issue 33, problem 10): the toolbar shows the step and the simulated time; Play advances visibly,
    // at most the pace's steps a frame, each view's image saying which step it shows and the pixels changing from
    // frame to frame; references wait for the pause (they would be out of date at once) and start after it.
    void motionPlaysVisiblyWithItsClock() {
        QVERIFY(window_->openProject(kMotion, false));
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 240000);
        auto* clock = window_->findChild<QLabel*>("animationClock");
        auto* pace = window_->findChild<QComboBox*>("animationPace");
        QVERIFY(clock && pace && clock->isVisible() && pace->isVisible());
        QCOMPARE(clock->text(), QString("step 45 · 0.75 s"));
        QVERIFY2(clock->toolTip().contains("impulse at step 10"), qPrintable(clock->toolTip()));
        QCOMPARE(pace->currentData().toInt(), Animation::kDefaultMaxStepsPerFrame);
        const std::shared_ptr<const Image> start = currentIsv();
        QVERIFY(start && start->metadata.count("animationFrame"));
        QCOMPARE(QString::fromStdString(start->metadata.at("animationFrame")), QString("step 45 (0.75 s)"));

        int referenceStarts = 0;
        const QMetaObject::Connection counting =
            connect(&window_->studio().scheduler(), &RenderScheduler::started, this,
                    [&](int, bool reference, int) { referenceStarts += reference; });
        QTest::keyClick(window_->viewport(), Qt::Key_P);
        QVERIFY(window_->studio().animation().playing());
        QElapsedTimer clockTime;
        clockTime.start();
        std::vector<std::shared_ptr<const Image>> images = {start};
        std::vector<int> stepsShown = {45};
        bool statusSaidPlaying = false, paceShown = false;
        while (images.size() < 6 && clockTime.elapsed() < 120000) {
            QTest::qWait(10);
            statusSaidPlaying |= window_->studio().status().startsWith("Playing");
            paceShown |= clock->text().contains("x real time");
            const ViewFrame& f = window_->studio().frames()[0];
            if (!f.image || f.image == images.back()) continue;
            const QString frame = QString::fromStdString(f.image->metadata.at("animationFrame"));
            const int step = frame.section(' ', 1, 1).toInt();
            // The caption names the frame the tile shows; the clock is at it or ahead (the view lags play).
            QVERIFY2(tileCaption(f, false, 2000, window_->font()).join(" ").contains("step " + QString::number(step)),
                     qPrintable(tileCaption(f, false, 2000, window_->font()).join(" | ")));
            QVERIFY(clock->text().section(' ', 1, 1).toInt() >= step);
            images.push_back(f.image);
            stepsShown.push_back(step);
        }
        QTest::keyClick(window_->viewport(), Qt::Key_P);
        QVERIFY(!window_->studio().animation().playing());
        disconnect(counting);
        QVERIFY2(images.size() == 6, qPrintable(QString::number(images.size())));
        QVERIFY(statusSaidPlaying && paceShown);
        for (std::size_t i = 1; i < images.size(); ++i) {
            // Forward by at most the pace's steps a frame (the cloud still moves here: it settles by step ~250),
            // and the pixels show it.
            QVERIFY2(stepsShown[i] > stepsShown[i - 1] &&
                         stepsShown[i] - stepsShown[i - 1] <= Animation::kDefaultMaxStepsPerFrame,
                     qPrintable(QString("%1 after %2").arg(stepsShown[i]).arg(stepsShown[i - 1])));
            QVERIFY2(!samePixels(*images[i], *images[i - 1]), qPrintable(QString::number(i)));
        }
        QCOMPARE(referenceStarts, 0);
        // After the pause the references render the frame play stopped at, and the view compares against it.
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 240000);
        const ViewFrame& f = window_->studio().frames()[0];
        QVERIFY(f.reference && f.referenceState == f.state && f.imageState == f.state && f.metrics);
        QCOMPARE(QString::fromStdString(f.reference->metadata.at("animationFrame")),
                 clock->text().section(" · ", 0, 0) + " (" + clock->text().section(" · ", 1, 1) + ")");
        QCOMPARE(window_->studio().status(), QString("Ready"));
        shoot("motion-paused");
    }

    void cleanupTestCase() { window_.reset(); }

private:
    const QString kSmoke = TYNDALL_SOURCE_DIR "/projects/isv/smoke.json";
    const QString kMotion = TYNDALL_SOURCE_DIR "/projects/isv/motion.json";
    QVulkanInstance* vulkan_;
    std::unique_ptr<MainWindow> window_;
};

QObject* makeAnimationTest(QVulkanInstance* vulkan) {
    return new AnimationTest(vulkan);
}

}  // namespace tyndall::studio::gui

#include "test_animation.moc"
