// The studio's GUI tests, split by feature (one file and one QTest class each), run in a real window under Xvfb
// (QVulkanWindow needs the xcb platform; the offscreen platform cannot create Vulkan surfaces). The flow cases share
// one window and start on the default project; the LTSD plots and the animation make their own.
#pragma once

#include "main_window.h"
#include "parameter_panel.h"
#include "scene_panel.h"

#include "tyndall/core/phase_eval.h"
#include "tyndall/image/colour_map.h"
#include "tyndall/image/flip.h"
#include "tyndall/image/image_io.h"
#include "tyndall/image/metrics.h"
#include "tyndall/tables/ltsd_table.h"
#include "tyndall/techniques/registry.h"

#include <qcustomplot.h>
#include <QAbstractSlider>
#include <QAbstractSpinBox>
#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDialog>
#include <QDir>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QLabel>
#include <QListWidget>
#include <QMenu>
#include <QMenuBar>
#include <QMessageBox>
#include <QMimeData>
#include <QPointer>
#include <QProgressDialog>
#include <QPushButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QSignalSpy>
#include <QSpinBox>
#include <QStandardPaths>
#include <QStatusBar>
#include <QTabWidget>
#include <QTableWidget>
#include <QTest>
#include <QThreadPool>
#include <QTimer>
#include <QToolBar>
#include <QUndoStack>
#include <QUrl>
#include <QVulkanInstance>
#include <QWheelEvent>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numbers>
#include <set>

namespace tyndall::studio::gui {

const QString kDefaultProject = TYNDALL_SOURCE_DIR "/projects/default.json";

// Small renders so that the suite stays short: the project's camera and its reference at a few spp.
inline const std::vector<std::string> kSmall = {"camera.width=96", "camera.height=72", "reference.spp=8"};

// Writes `project` as TYNDALL_TEST_TMP/<name> and returns its path ("" when it cannot be written).
inline QString writeTestProject(const nlohmann::json& project, const QString& name) {
    if (!QDir().mkpath(TYNDALL_TEST_TMP)) return {};
    const QString path = QString(TYNDALL_TEST_TMP) + "/" + name;
    QFile file(path);
    if (!file.open(QIODevice::WriteOnly | QIODevice::Truncate)) return {};
    file.write(QByteArray::fromStdString(project.dump(2)));
    return path;
}

inline double sum(const Image& image) {
    double s = 0.0;
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            for (int c = 0; c < 3; ++c)
                s += image.at(x, y, c);
    return s;
}

inline bool samePixels(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height()) return false;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            for (int c = 0; c < 3; ++c)
                if (a.at(x, y, c) != b.at(x, y, c)) return false;
    return true;
}

// How many distinct colours a frame has: a frame of one colour shows nothing.
inline int distinctColours(const QImage& image) {
    QSet<QRgb> colours;
    for (int y = 0; y < image.height(); y += 3)
        for (int x = 0; x < image.width(); x += 3)
            colours.insert(image.pixel(x, y));
    return int(colours.size());
}

// Accepts the message box that shows within `ms` (a modal one blocks the test's call), its text into `text`.
inline void acceptMessageBoxSoon(QString* text, int ms = 500) {
    QTimer::singleShot(ms, [text] {
        for (QWidget* w : QApplication::topLevelWidgets())
            if (auto* box = qobject_cast<QMessageBox*>(w); box && box->isVisible()) {
                *text = box->text();
                box->accept();
            }
    });
}

// A class of flow cases: its initTestCase puts the shared window on the default project, settled, with the default
// display; the cases go on from there in their order.
class FlowCase : public QObject {
    Q_OBJECT
public:
    explicit FlowCase(QVulkanInstance* vulkan) : vulkan_(vulkan) {}
    // The window every flow case of a run shares (made by the first class, closed at the end of the run).
    static std::unique_ptr<MainWindow>& sharedWindow();

protected:
    // Made at the first class; later ones open the default project again (its references come from the disk cache).
    void startOnTheDefaultProject();
    // Opens a fresh copy of the default project in TYNDALL_TEST_TMP/<folder> (no autosave of it to recover): its
    // path, or empty when it could not.
    QString openCopyOfTheDefaultProject(const QString& folder);

    QVulkanInstance* vulkan_;
    std::unique_ptr<MainWindow>& window_ = sharedWindow();
};

}  // namespace tyndall::studio::gui
