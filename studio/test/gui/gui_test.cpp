#include "gui_test.h"

namespace tyndall::studio::gui {

std::unique_ptr<MainWindow>& FlowCase::sharedWindow() {
    static std::unique_ptr<MainWindow> window;
    return window;
}

void FlowCase::startOnTheDefaultProject() {
    if (!window_) {
        // Autosaves left by an earlier run that was killed would ask to be recovered (a modal dialog): start without.
        QDir(QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave").removeRecursively();
        QSettings().remove("window");  // the default layout, whatever an earlier run left
        window_ = std::make_unique<MainWindow>(vulkan_, kSmall);
        window_->show();
        QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
    } else {
        // Another class's cases ran before: the default project again, without its autosave, on the default display.
        window_->studio().compositorState() = CompositorState{};
        window_->studio().setRegion(QRect());
        window_->studio().chooseReferenceView(-1);
    }
    // The flows reopen the default project after editing it, and the autosave timer may have saved those edits in
    // between: with Recovery::Ask a modal "recover?" would then wait forever. The recovery flows (test_projects.cpp)
    // set Ask themselves.
    window_->studio().setRecovery(Studio::Recovery::Never);
    QVERIFY(window_->openProject(kDefaultProject, false));
    QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 240000);
}

QString FlowCase::openCopyOfTheDefaultProject(const QString& folder) {
    const QString dir = QString(TYNDALL_TEST_TMP) + "/" + folder;
    QDir(dir).removeRecursively();
    QDir().mkpath(dir);
    const QString path = dir + "/room.json";
    if (!QFile::copy(kDefaultProject, path)) return {};
    QFile::remove(Studio::autosavePath(path));
    window_->studio().setRecovery(Studio::Recovery::Never);
    return window_->openProject(path, false) ? path : QString();
}

}  // namespace tyndall::studio::gui
