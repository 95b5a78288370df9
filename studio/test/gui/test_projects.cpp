// Project files: a broken project refused, crash recovery, failed autosaves, no prompt after a discard or Save As,
// snapshots saved beside the project, one line changed by an edit, another project started clean.
#include "gui_test.h"

namespace tyndall::studio::gui {

class ProjectsTest final : public FlowCase {
    Q_OBJECT
public:
    using FlowCase::FlowCase;

private slots:
    void initTestCase() { startOnTheDefaultProject(); }

    // A broken project is refused with a dialog that names the file and the problem; the current project stays.
    void refusesABrokenProject() {
        const QString path = QString(TYNDALL_TEST_TMP) + "/broken.json";
        QDir().mkpath(TYNDALL_TEST_TMP);
        QFile file(path);
        QVERIFY(file.open(QIODevice::WriteOnly));
        file.write("{\"tyndall\": 1, \"camera\": {\"fovY\": 400}}");
        file.close();
        QString dialogText;
        acceptMessageBoxSoon(&dialogText);
        QVERIFY(!window_->openProject(path, true));
        QVERIFY2(dialogText.contains("broken.json") && dialogText.contains("fovY"), qPrintable(dialogText));
        QCOMPARE(window_->studio().session().path(), kDefaultProject);
        QCOMPARE(int(window_->studio().frames().size()), 4);
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
        QVERIFY(window_->studio().frames()[0].image);
    }

    // A project named on the command line that does not open (truncated) is reported, and the studio stays open on
    // the default project with the file in the recent list (issue 33: it showed the message over an empty window
    // titled "Tyndall -  - Tyndall Studio" and exited with 2).
    void aBadProjectOnTheCommandLineKeepsTheStudioOpen() {
        const QString path = QString(TYNDALL_TEST_TMP) + "/truncated.json";
        QFile file(path);
        QVERIFY(file.open(QIODevice::WriteOnly));
        file.write("{\"tyndall\": 1, \"camera\": {\"fovY\": 4");
        file.close();
        MainWindow fresh(vulkan_, kSmall);
        fresh.studio().setRecovery(Studio::Recovery::Never);
        fresh.show();
        QVERIFY(QTest::qWaitForWindowExposed(&fresh));
        QString dialogText;
        acceptMessageBoxSoon(&dialogText);
        QVERIFY(!fresh.openAtStart(path, kDefaultProject));
        QVERIFY2(dialogText.contains("truncated.json"), qPrintable(dialogText));
        QVERIFY(fresh.isVisible());
        QCOMPARE(fresh.studio().session().path(), kDefaultProject);
        QVERIFY2(fresh.windowTitle().startsWith(QString::fromStdString(fresh.studio().session().project().name)),
                 qPrintable(fresh.windowTitle()));
        QVERIFY2(fresh.statusBar()->currentMessage().contains("truncated.json"),
                 qPrintable(fresh.statusBar()->currentMessage()));
        QVERIFY(fresh.studio().recentProjects().contains(QFileInfo(path).absoluteFilePath()) ||
                fresh.studio().recentProjects().contains(path));
        QTRY_VERIFY_WITH_TIMEOUT(fresh.studio().settled(), 120000);
    }

    // Images and no project: an image-only session, as in tev (issue 33: the default project rendered first and its
    // 480 x 360 reference made "sizes differ"). Nothing renders; the first image is the reference of the others, with
    // metrics, differences and export; Shift+2 makes the second one the reference. The screen is saved as a
    // screenshot of the session (image-session.png).
    void opensAnImageOnlySession() {
        const QString dir = QString(TYNDALL_TEST_TMP) + "/image-session";
        QDir(dir).removeRecursively();
        QDir().mkpath(dir);
        Image a = Image::rgb(64, 48), b = Image::rgb(64, 48);
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 64; ++x)
                for (int c = 0; c < 3; ++c) {
                    a.at(x, y, c) = 0.2f + 0.6f * float(x) / 64.0f;
                    b.at(x, y, c) = a.at(x, y, c) * (1.0f + 0.2f * float(y) / 48.0f);
                }
        writeImage(a, (dir + "/a.exr").toStdString());
        writeImage(b, (dir + "/b.exr").toStdString());
        MainWindow fresh(vulkan_, kSmall);
        fresh.show();
        QVERIFY(QTest::qWaitForWindowExposed(&fresh));
        Studio& studio = fresh.studio();
        QElapsedTimer clock;
        clock.start();
        QString error;
        QVERIFY2(studio.openImageSession({dir + "/a.exr", dir + "/b.exr"}, &error), qPrintable(error));
        QVERIFY(studio.imageSession());
        QCOMPARE(studio.comparison().size(), 2);
        QCOMPARE(studio.referenceView(), 0);
        QTRY_VERIFY_WITH_TIMEOUT(studio.frames()[1].metrics.has_value(), 10000);
        qInfo("image-only session: metrics after %lld ms", clock.elapsed());
        // HDR-FLIP follows the metrics in the background: the studio is settled once it has arrived.
        QTRY_VERIFY_WITH_TIMEOUT(studio.settled(), 10000);
        QVERIFY(studio.frames()[1].flip.has_value());
        QVERIFY(studio.frames()[1].metrics->relMSE > 1e-4);
        QCOMPARE(fresh.windowTitle(), QString("a.exr, b.exr - Tyndall Studio"));
        // The tiles' captions: the reference says so; the other its numbers.
        const QStringList caption0 = tileCaption(studio.frames()[0], false, 600, fresh.font());
        QVERIFY2(caption0.join(" ").contains("reference"), qPrintable(caption0.join(" ")));
        studio.cycleDifference();
        const QImage shot = studio.composedFrame();
        QVERIFY(distinctColours(shot) > 10);
        QVERIFY(shot.save(QString(TYNDALL_TEST_TMP) + "/image-session.png"));
        studio.cycleDifference();
        studio.cycleDifference();
        studio.cycleDifference();
        // Export: both images, b against a, with its metrics.
        QVERIFY2(studio.exportComparison(dir + "/export", &error), qPrintable(error));
        QFile json(dir + "/export/metrics.json");
        QVERIFY(json.open(QIODevice::ReadOnly));
        const nlohmann::json metrics = nlohmann::json::parse(json.readAll().toStdString());
        QCOMPARE(metrics[1]["against"], nlohmann::json("a.exr"));
        QVERIFY(metrics[1].contains("relMSE"));
        QVERIFY(QFile::exists(dir + "/export/b.exr.exr") || QFile::exists(dir + "/export/b.exr"));
        // Shift+2: the second image is the reference; the first has numbers now.
        studio.chooseReferenceView(1);
        QTRY_VERIFY_WITH_TIMEOUT(studio.frames()[0].metrics.has_value(), 10000);
        QVERIFY(!studio.frames()[1].metrics.has_value());
        studio.waitForBackgroundWork();
    }

    // Unsaved changes are autosaved; a studio that opens the project afterwards (after a crash) recovers them as one
    // undoable edit on top of the file, and the project is listed under the recent ones.
    void recoversUnsavedChangesAfterACrash() {
        const QString path = openCopyOfTheDefaultProject("recover");
        QVERIFY(!path.isEmpty());
        QCOMPARE(window_->studio().recentProjects().value(0), QFileInfo(path).absoluteFilePath());
        window_->studio().session().setParameter(1, "raySamples", std::int64_t(3));
        QVERIFY(window_->studio().autosaveNow());
        window_->studio().waitForAutosaves();  // written by the autosave thread
        QVERIFY(QFile::exists(Studio::autosavePath(path)));

        // The first studio "crashes" (it is left as it is); a second one opens the same project.
        MainWindow second(vulkan_, kSmall);
        second.studio().setRecovery(Studio::Recovery::Always);
        QVERIFY(second.openProject(path, false));
        QVERIFY(second.studio().session().modified());
        QVERIFY(second.studio().session().project().views[1].parameters["raySamples"] == nlohmann::json(3));
        second.studio().session().undoStack()->undo();
        QVERIFY(!second.studio().session().project().views[1].parameters.contains("raySamples"));
        QVERIFY(!second.studio().session().modified());
        second.studio().waitForAutosaves();
        QVERIFY(!QFile::exists(Studio::autosavePath(path)));  // back at the file: nothing left to recover
        QTRY_VERIFY_WITH_TIMEOUT(second.studio().settled(), 120000);
    }

    // An autosave that cannot be written says so in the status bar (its path is taken by a folder, which fails even
    // for root), and the session keeps its changes.
    void reportsAFailedAutosave() {
        const QString path = openCopyOfTheDefaultProject("autosave-fails");
        QVERIFY(!path.isEmpty());
        const QString blocked = Studio::autosavePath(path);
        QFile::remove(blocked);
        QVERIFY(QDir().mkpath(blocked + "/taken"));
        window_->studio().session().setParameter(1, "raySamples", std::int64_t(5));
        QVERIFY(window_->studio().autosaveNow());
        window_->studio().waitForAutosaves();
        QTRY_VERIFY_WITH_TIMEOUT(window_->statusBar()->currentMessage().startsWith("Autosave failed"), 5000);
        QVERIFY2(window_->statusBar()->currentMessage().contains(blocked),
                 qPrintable(window_->statusBar()->currentMessage()));
        QVERIFY(window_->studio().session().modified());
        QDir(blocked).removeRecursively();
        window_->studio().session().undoStack()->undo();
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
    }

    // Reopening a file after Discard (on Open) or after Save As asks to recover nothing: the discarded changes and
    // the changes saved elsewhere are not "unsaved changes" of that file. Save As lists the new file as recent.
    void noRecoveryPromptAfterDiscardOrSaveAs() {
        const QString dir = QString(TYNDALL_TEST_TMP) + "/discard";
        QDir(dir).removeRecursively();
        QDir().mkpath(dir);
        const QString path = dir + "/room.json", other = dir + "/room-as.json";
        QVERIFY(QFile::copy(kDefaultProject, path));
        window_->studio().setRecovery(Studio::Recovery::Ask);
        QStringList prompts;
        QTimer watcher;  // answers every dialog: Discard to "save first?", No to "recover?", and notes the latter
        connect(&watcher, &QTimer::timeout, [&] {
            for (QWidget* w : QApplication::topLevelWidgets())
                if (auto* box = qobject_cast<QMessageBox*>(w); box && box->isVisible()) {
                    if (box->button(QMessageBox::Discard)) {
                        box->button(QMessageBox::Discard)->click();
                    } else {
                        prompts << box->text();
                        box->button(QMessageBox::No) ? box->button(QMessageBox::No)->click() : box->reject();
                    }
                }
        });
        watcher.start(50);
        QVERIFY(window_->openProject(path, false));
        window_->studio().session().setParameter(1, "raySamples", std::int64_t(7));
        QVERIFY(window_->studio().autosaveNow());
        window_->studio().waitForAutosaves();
        QVERIFY(window_->confirmDiscard());         // "Discard"
        QVERIFY(!window_->studio().autosaveNow());  // nothing is autosaved while the file dialog would be open
        QVERIFY(window_->openProject(path, false));
        QVERIFY2(prompts.isEmpty(), qPrintable(prompts.join("; ")));
        QVERIFY(!window_->studio().session().modified());

        window_->studio().session().setParameter(1, "raySamples", std::int64_t(9));
        QVERIFY(window_->studio().autosaveNow());
        window_->studio().waitForAutosaves();
        QString error;
        QVERIFY2(window_->studio().saveProjectAs(other, &error), qPrintable(error));
        QCOMPARE(window_->studio().recentProjects().value(0), QFileInfo(other).absoluteFilePath());
        QVERIFY(window_->openProject(path, false));
        QVERIFY2(prompts.isEmpty(), qPrintable(prompts.join("; ")));
        QVERIFY(!window_->studio().session().project().views[1].parameters.contains("raySamples"));
        watcher.stop();
        window_->studio().setRecovery(Studio::Recovery::Never);
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
    }

    // Snapshots belong to the project: saving writes them beside it ("<project>.snapshots/"), and a studio that opens
    // the project gets them back, images, parameters and views, ready to compare against. A broken snapshot index
    // says why and the project opens without them.
    void savesSnapshotsWithTheProject() {
        const QString dir = QString(TYNDALL_TEST_TMP) + "/snapshots";
        QDir(dir).removeRecursively();
        QDir().mkpath(dir);
        const QString path = dir + "/room.json";
        QVERIFY(QFile::copy(kDefaultProject, path));
        QFile::setPermissions(path, QFile::ReadOwner | QFile::WriteOwner);
        window_->studio().setRecovery(Studio::Recovery::Never);
        QVERIFY(window_->openProject(path, false));
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
        window_->studio().selectView(1);
        QCOMPARE(window_->studio().takeSnapshot(), 0);
        window_->studio().session().setParameter(1, "raySamples", std::int64_t(3));
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
        QCOMPARE(window_->studio().takeSnapshot(), 1);
        QString error;
        QVERIFY2(window_->studio().saveProject(&error), qPrintable(error));
        const QString folder = SnapshotStore::folderOf(path);
        QCOMPARE(folder, dir + "/room.snapshots");
        QVERIFY(QFile::exists(folder + "/snapshots.json"));

        MainWindow second(vulkan_, kSmall);
        second.studio().setRecovery(Studio::Recovery::Never);
        QVERIFY(second.openProject(path, false));
        QCOMPARE(second.studio().snapshots().size(), std::size_t(2));
        for (std::size_t i = 0; i < 2; ++i) {
            const Snapshot &saved = window_->studio().snapshots()[i], &loaded = second.studio().snapshots()[i];
            QCOMPARE(loaded.name, saved.name);
            QCOMPARE(loaded.view, 1);
            QVERIFY(loaded.parameters == saved.parameters);
            QCOMPARE(loaded.exposure, saved.exposure);
            QVERIFY(samePixels(*loaded.image, *saved.image));
        }
        QVERIFY(second.studio().snapshots()[1].parameters["raySamples"] == nlohmann::json(3));
        // Snapshots follow their view when the views change, and are not lost: a view added, one removed before it,
        // a rename of it; a snapshot whose view is removed goes with it.
        const auto indexOf = [&](const std::string& name) {
            const std::vector<View>& views = second.studio().session().project().views;
            for (std::size_t v = 0; v < views.size(); ++v)
                if (views[v].name == name) return int(v);
            return -1;
        };
        QVERIFY(second.studio().session().duplicateView(0, &error));
        QCOMPARE(second.studio().snapshots().size(), std::size_t(2));
        QCOMPARE(second.studio().snapshots()[0].view, indexOf("light shaft"));
        QVERIFY(second.studio().session().removeView(0, &error));  // "everything", before it
        QCOMPARE(second.studio().snapshots().size(), std::size_t(2));
        QCOMPARE(second.studio().snapshots()[0].view, indexOf("light shaft"));
        const int shaft = indexOf("light shaft");
        QVERIFY(second.studio().session().renameView(shaft, "shaft", &error));
        QCOMPARE(second.studio().snapshots().size(), std::size_t(2));
        QCOMPARE(second.studio().snapshots()[1].view, shaft);
        QVERIFY(second.studio().session().removeView(shaft, &error));  // kept, without a view, until it comes back
        QCOMPARE(second.studio().snapshots().size(), std::size_t(2));
        QCOMPARE(second.studio().snapshots()[0].view, -1);
        for (int k = 0; k < 4; ++k)
            second.studio().session().undoStack()->undo();
        QCOMPARE(second.studio().session().project().views[1].name, std::string("light shaft"));
        QCOMPARE(second.studio().snapshots().size(), std::size_t(2));
        QCOMPARE(second.studio().snapshots()[0].view, 1);
        QCOMPARE(second.studio().snapshots()[1].view, 1);
        second.studio().compareWithSnapshot(0);
        QVERIFY(second.studio().frames()[1].snapshot == second.studio().snapshots()[0].image);
        QTRY_VERIFY_WITH_TIMEOUT(second.studio().settled(), 120000);

        {
            QFile index(folder + "/snapshots.json");
            QVERIFY(index.open(QIODevice::WriteOnly | QIODevice::Truncate));
            index.write("{\"tyndallSnapshots\": 1, \"snapshots\": [{\"name\": 3}]}");
        }
        MainWindow third(vulkan_, kSmall);
        third.studio().setRecovery(Studio::Recovery::Never);
        QVERIFY(third.openProject(path, false));
        QVERIFY(third.studio().snapshots().empty());
        const QString message = third.statusBar()->currentMessage();
        QVERIFY2(message.contains("snapshots.json") && message.contains("snapshots[0]"), qPrintable(message));
        QTRY_VERIFY_WITH_TIMEOUT(third.studio().settled(), 120000);
        window_->studio().session().undoStack()->undo();
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
    }

    // Saving keeps the file as the user wrote it where nothing changed (issue 19, item 10): an edit of one view's
    // exposure is one changed line of the file, and the next edit one more line, saved against the file as saved.
    // The window's --set overrides (kSmall) are edits of the file too: the first save writes them on their lines.
    void savingAnEditChangesOneLineOfTheFile() {
        const QString path = openCopyOfTheDefaultProject("text-save");
        QVERIFY(!path.isEmpty());
        const auto lines = [&] {
            QFile file(path);
            return file.open(QIODevice::ReadOnly) ? file.readAll().split('\n') : QList<QByteArray>();
        };
        const auto changed = [](const QList<QByteArray>& before, const QList<QByteArray>& after) {
            QList<QByteArray> differing;
            for (qsizetype i = 0; i < std::min(before.size(), after.size()); ++i)
                if (before[i] != after[i]) differing << after[i];
            return before.size() == after.size() ? differing : QList<QByteArray>{"(line count changed)"};
        };
        const QList<QByteArray> original = lines();
        QString error;
        window_->studio().session().setExposure(0, 1.5);
        QVERIFY2(window_->studio().session().save(&error), qPrintable(error));
        const QList<QByteArray> first = lines();
        QCOMPARE(
            changed(original, first),
            (QList<QByteArray>{
                R"(    "width": 96,)", R"(    "height": 72)",
                R"(    {"name": "everything", "technique": "reference", "parameters": {"distanceSampling": "mis"}, "exposure": 1.5},)",
                R"(  "reference": {"mode": "single", "maxDepth": 16, "spp": 8, "seed": 1})"}));
        window_->studio().session().setExposure(3, -0.5);  // "glow" gives no exposure: it is added on its line
        QVERIFY2(window_->studio().session().save(&error), qPrintable(error));
        QCOMPARE(
            changed(first, lines()),
            QList<QByteArray>{
                R"(    {"name": "glow", "technique": "reference", "parameters": {"distanceSampling": "distance"}, "lights": ["lamp"], "media": ["fog"], "exposure": -0.5})"});
        QVERIFY(!window_->studio().session().modified());
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
    }

    // Opening another project leaves nothing of the previous one: the inspector, the pdf plot, the snapshot Compare
    // button.
    void startsAnotherProjectClean() {
        QVERIFY(window_->openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
        window_->studio().setLayoutMode(Layout::Grid);
        window_->studio().recompose();
        const QRect r = viewRects(window_->studio().frames(), window_->studio().compositorState(),
                                  window_->viewport()->pixelSize())[1];
        window_->studio().inspect(QPointF(r.x() + r.width() * 0.5, r.y() + r.height() * 0.6));
        QVERIFY(window_->inspectorText().contains("pixel"));
        QTRY_VERIFY_WITH_TIMEOUT(window_->pdfPlot()->plot()->graphCount() > 0, 60000);
        window_->studio().selectView(1);
        QCOMPARE(window_->studio().takeSnapshot(), 0);
        auto* compare = window_->findChild<QPushButton*>("compareSnapshot");
        QVERIFY(compare);
        compare->setChecked(true);
        QVERIFY(window_->studio().frames()[1].snapshot);
        // A probe still running when the project changes is not shown over the new one.
        window_->studio().inspect(QPointF(r.x() + r.width() * 0.5, r.y() + r.height() * 0.6));
        QVERIFY(window_->openProject(TYNDALL_SOURCE_DIR "/projects/examples/reference-smoke.json", false));
        window_->studio().waitForBackgroundWork();
        QCoreApplication::processEvents();
        QCOMPARE(int(window_->studio().frames().size()), 1);
        QVERIFY(!window_->inspectorText().contains("pixel"));
        QCOMPARE(window_->pdfPlot()->plot()->graphCount(), 0);
        QVERIFY(!compare->isChecked());
        QVERIFY(window_->studio().snapshots().empty());
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
    }
};

QObject* makeProjectsTest(QVulkanInstance* vulkan) {
    return new ProjectsTest(vulkan);
}

}  // namespace tyndall::studio::gui

#include "test_projects.moc"
