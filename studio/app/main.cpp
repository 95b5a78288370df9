// tyndall-studio [project] [--set path=value ...]: the lookdev and comparison studio. Opens the project (the bundled
// default project when none is given). Needs a window system with Vulkan surfaces (the xcb platform; lavapipe does).
#include "main_window.h"

#include <QApplication>
#include <QMessageBox>
#include <QVulkanInstance>

#include <cstdio>

int main(int argc, char** argv) {
    QApplication app(argc, argv);
    QApplication::setApplicationName("Tyndall Studio");
    QString project = TYNDALL_DEFAULT_PROJECT;
    std::vector<std::string> overrides;
    const QStringList args = QApplication::arguments();
    for (int i = 1; i < args.size(); ++i) {
        if (args[i] == "--set" && i + 1 < args.size())
            overrides.push_back(args[++i].toStdString());
        else if (args[i] == "--help") {
            std::printf("usage: tyndall-studio [project.json] [--set path=value ...]\n");
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
    return app.exec();
}
