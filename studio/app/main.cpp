// tyndall-studio [project] [--set path=value ...] [--screenshot file.png]: the lookdev and comparison studio. Opens
// the project (the bundled default project when none is given). With --screenshot it waits until every view and
// reference has rendered, saves a picture of the screen and quits (for documentation and checks). Needs a window
// system with Vulkan surfaces (the xcb platform; lavapipe does).
#include "main_window.h"

#include <QApplication>
#include <QMessageBox>
#include <QScreen>
#include <QTimer>
#include <QVulkanInstance>

#include <cstdio>

int main(int argc, char** argv) {
    QApplication app(argc, argv);
    QApplication::setOrganizationName("Tyndall");
    QApplication::setApplicationName("Tyndall Studio");
    QString project = TYNDALL_DEFAULT_PROJECT;
    std::vector<std::string> overrides;
    QString screenshot;
    const QStringList args = QApplication::arguments();
    for (int i = 1; i < args.size(); ++i) {
        if (args[i] == "--set" && i + 1 < args.size())
            overrides.push_back(args[++i].toStdString());
        else if (args[i] == "--screenshot" && i + 1 < args.size())
            screenshot = args[++i];
        else if (args[i] == "--help") {
            std::printf("usage: tyndall-studio [project.json] [--set path=value ...] [--screenshot file.png]\n");
            return 0;
        } else
            project = args[i];
    }
    QVulkanInstance vulkan;
    vulkan.setApiVersion(QVersionNumber(1, 2));
    if (!vulkan.create()) {
        QMessageBox::critical(nullptr, "Tyndall Studio", "Vulkan is not available: " +
                                                              QString::number(vulkan.errorCode()));
        return 1;
    }
    tyndall::studio::MainWindow window(&vulkan, overrides);
    window.show();
    if (!window.openProject(project)) return 2;
    QTimer poll;
    if (!screenshot.isEmpty()) {
        QObject::connect(&poll, &QTimer::timeout, [&] {
            if (!window.settled()) return;
            poll.stop();
            // A moment for the last frame to be presented, then the whole screen (the Vulkan viewport included).
            QTimer::singleShot(500, [&] {
                const bool ok = window.screen()->grabWindow(0).save(screenshot);
                std::printf("%s %s\n", ok ? "wrote" : "could not write", qPrintable(screenshot));
                QApplication::exit(ok ? 0 : 1);
            });
        });
        poll.start(200);
    }
    return app.exec();
}
