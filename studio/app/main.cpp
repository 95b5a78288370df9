// tyndall-studio [project.json] [image ...] [--project project.json] [--set path=value ...] [--screenshot file.png]:
// the lookdev and comparison studio.
//
// - With a project (or nothing): opens it (the bundled default project when none is given), and each image (EXR, HDR,
//   PNG, ...) as a read-only view compared against the project's reference.
// - With images and no project, an image-only session, as tev opens images: nothing renders, the first image is every
//   other image's reference (Shift+1-9 chooses another), with every metric, difference and export. `--project P`
//   keeps the images beside project P instead.
//
// A project that does not open in an interactive run is reported (a dialog, and the status bar) and the studio stays
// open on the bundled default project, the file in the recent list to open again once fixed. With --screenshot it
// waits until every view and reference has rendered, saves a picture of the screen and quits (for documentation and
// checks). Needs a window system with Vulkan surfaces (the xcb platform; lavapipe does).
//
// With --screenshot the run is non-interactive: it never waits on a dialog. Every problem is printed on stderr and
// ends the run: exit 1 for the environment (no Vulkan, a platform without window surfaces such as offscreen, an
// autosave newer than the project that a person must decide about, nothing rendered within
// TYNDALL_SCREENSHOT_TIMEOUT seconds, default 600), exit 2 for a project or an image that does not open.
#include "image_file.h"
#include "main_window.h"

#include "tyndall/core/resources.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"

#include <QApplication>
#include <QFileInfo>
#include <QMessageBox>
#include <QScreen>
#include <QTimer>
#include <QVulkanInstance>

#include <cstdio>

int main(int argc, char** argv) {
    QApplication app(argc, argv);
    QApplication::setOrganizationName("Tyndall");
    QApplication::setApplicationName("Tyndall Studio");
    QString project;
    std::vector<std::string> overrides;
    QString screenshot;
    QString ocio;  // the OpenColorIO config (else $OCIO, else the shipped one)
    QStringList images;
    const QStringList args = QApplication::arguments();
    for (int i = 1; i < args.size(); ++i) {
        if (args[i] == "--set" && i + 1 < args.size())
            overrides.push_back(args[++i].toStdString());
        else if (args[i] == "--screenshot" && i + 1 < args.size())
            screenshot = args[++i];
        else if (args[i] == "--project" && i + 1 < args.size())
            project = args[++i];
        else if (args[i] == "--ocio" && i + 1 < args.size())
            ocio = args[++i];
        else if (args[i] == "--help") {
            std::printf(
                "usage: tyndall-studio [project.json] [image.exr|.hdr|.png ...] [--project project.json] "
                "[--set path=value ...] [--ocio config.ocio] [--screenshot file.png]\n"
                "Images without a project: an image-only session, the first image the reference.\n");
            return 0;
        } else if (tyndall::studio::isImageFile(args[i]))
            images << args[i];
        else
            project = args[i];
    }
    const bool imagesOnly = project.isEmpty() && !images.isEmpty();
    // The bundled default project, where resourceRoot() finds the data (the source tree, or <prefix>/share/tyndall).
    const QString defaultProject =
        QString::fromStdString((tyndall::resourceRoot() / "projects" / "default.json").string());
    if (project.isEmpty() && !imagesOnly) project = defaultProject;
    const bool interactive = screenshot.isEmpty();
    const auto fail = [&](const QString& message) {
        std::fprintf(stderr, "tyndall-studio: %s\n", qPrintable(message));
        if (interactive) QMessageBox::critical(nullptr, "Tyndall Studio", message);
    };
    const QString platform = QGuiApplication::platformName();
    if (!interactive && (platform == "offscreen" || platform == "minimal")) {
        fail("--screenshot needs a window system with Vulkan surfaces (xcb, e.g. under xvfb-run); the '" + platform +
             "' platform has none");
        return 1;
    }
    QVulkanInstance vulkan;
    vulkan.setApiVersion(QVersionNumber(1, 2));
    if (!vulkan.create()) {
        fail("Vulkan is not available: " + QString::number(vulkan.errorCode()));
        return 1;
    }
    if (!interactive && !imagesOnly) {
        try {
            (void)tyndall::loadProject(tyndall::techniqueCatalogue(), project.toStdString(), overrides);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "tyndall-studio: error: %s\n", e.what());
            return 2;
        }
    }
    tyndall::studio::MainWindow window(&vulkan, overrides, ocio);
    if (!interactive && !imagesOnly) {
        // Recovering unsaved changes is a person's decision: report the autosave and leave it for them.
        const QFileInfo autosave(tyndall::studio::Studio::autosavePath(project)), file(project);
        if (autosave.exists() && autosave.lastModified() >= file.lastModified()) {
            fail("an autosave of " + project + " is newer than the file (" + autosave.filePath() +
                 "); open the project interactively to recover or discard it");
            return 1;
        }
        window.studio().setRecovery(tyndall::studio::Studio::Recovery::Never);
    }
    window.show();
    if (imagesOnly) {
        QString error;
        if (!window.studio().openImageSession(images, &error)) {
            fail(error);
            if (!interactive) return 2;
        }
    } else if (!interactive) {
        if (!window.openProject(project, false)) {
            std::fprintf(stderr, "tyndall-studio: cannot open %s\n", qPrintable(project));
            return 2;
        }
    } else {
        window.openAtStart(project, defaultProject);  // a file that does not open: the default one, said so
    }
    if (!imagesOnly)
        for (const QString& image : images) {
            QString error;
            if (window.studio().openImageView(image, &error) >= 0) continue;
            fail(error);
            if (!interactive) return 2;
        }
    QTimer poll;
    QTimer deadline;
    if (!screenshot.isEmpty()) {
        bool ok = false;
        const int timeout = qEnvironmentVariableIntValue("TYNDALL_SCREENSHOT_TIMEOUT", &ok);
        deadline.setSingleShot(true);
        QObject::connect(&deadline, &QTimer::timeout, [&] {
            std::fprintf(stderr, "tyndall-studio: not every view rendered within %d s; no screenshot written\n",
                         ok && timeout > 0 ? timeout : 600);
            QApplication::exit(1);
        });
        deadline.start((ok && timeout > 0 ? timeout : 600) * 1000);
        QObject::connect(&poll, &QTimer::timeout, [&] {
            if (!window.studio().settled()) return;
            poll.stop();
            deadline.stop();
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
