// The studio's GUI flows in a real window under Xvfb, checked on what the frames show: start on the default project,
// switch layouts, change a parameter and see that view change and the others not, undo it, wipe, export a comparison
// and check the files, and refuse a broken project with a dialog while keeping the current one.
#include "main_window.h"

#include "tyndall/core/phase_eval.h"
#include "tyndall/image/colour_map.h"
#include "tyndall/image/image_io.h"
#include "tyndall/tables/ltsd_table.h"
#include "tyndall/techniques/registry.h"

#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <qcustomplot.h>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QStandardPaths>
#include <QMessageBox>
#include <QElapsedTimer>
#include <QLabel>
#include <QPointer>
#include <QPushButton>
#include <QDialog>
#include <QProgressDialog>
#include <QSignalSpy>
#include <QDockWidget>
#include <QSettings>
#include <QListWidget>
#include <QMenuBar>
#include <QAction>
#include <QUndoStack>
#include <QTableWidget>
#include <QStatusBar>
#include <QTabWidget>
#include <QMimeData>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QUrl>
#include <QTest>
#include <QThreadPool>
#include <QTimer>
#include <QToolBar>
#include <QVulkanInstance>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <set>

using namespace tyndall;
using namespace tyndall::studio;

namespace {

const QString kDefaultProject = TYNDALL_SOURCE_DIR "/projects/default.json";

// Small renders so that the suite stays short: the project's camera and its reference at a few spp.
const std::vector<std::string> kSmall = {"camera.width=96", "camera.height=72", "reference.spp=8"};

double sum(const Image& image) {
    double s = 0.0;
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            for (int c = 0; c < 3; ++c)
                s += image.at(x, y, c);
    return s;
}

bool samePixels(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height()) return false;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            for (int c = 0; c < 3; ++c)
                if (a.at(x, y, c) != b.at(x, y, c)) return false;
    return true;
}

// How many distinct colours a frame has: a frame of one colour shows nothing.
int distinctColours(const QImage& image) {
    QSet<QRgb> colours;
    for (int y = 0; y < image.height(); y += 3)
        for (int x = 0; x < image.width(); x += 3)
            colours.insert(image.pixel(x, y));
    return int(colours.size());
}

}  // namespace

class StudioTest : public QObject {
    Q_OBJECT
public:
    explicit StudioTest(QVulkanInstance* vulkan) : vulkan_(vulkan) {}

private slots:
    void initTestCase() {
        // Autosaves left by an earlier run that was killed would ask to be recovered (a modal dialog): start without.
        QDir(QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave").removeRecursively();
        QSettings().remove("window");  // the default layout, whatever an earlier run left
        window_ = std::make_unique<MainWindow>(vulkan_, kSmall);
        window_->show();
        QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
        QVERIFY(window_->openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 240000);
    }

    // Every view rendered with its reference; the viewport presented the composed frame, and a screenshot of it shows
    // the same picture (Qt 6.4's grab of a BGRA swapchain swaps red and blue: either order is accepted).
    void startsOnTheDefaultProject() {
        const auto& frames = window_->frames();
        QCOMPARE(int(frames.size()), 4);
        for (const ViewFrame& f : frames) {
            QVERIFY2(f.image, qPrintable(f.name + ": " + f.error));
            QVERIFY2(f.reference, qPrintable(f.name));
            QVERIFY(sum(*f.image) > 0.0);
            QVERIFY(f.metrics.has_value());
        }
        QCOMPARE(frames[1].technique, QString("WVDS box"));
        QVERIFY(window_->windowTitle().contains("Foggy room"));
        // The metrics dock: a row per view, named after it, with the numbers of its metrics.
        auto* table = window_->findChild<QTableWidget*>("metrics");
        QVERIFY(table);
        QTRY_COMPARE(table->rowCount(), int(frames.size()));
        for (int row = 0; row < table->rowCount(); ++row) {
            QCOMPARE(table->verticalHeaderItem(row)->text(), frames[std::size_t(row)].name);
            QCOMPARE(table->item(row, 0)->text(), QString::number(frames[std::size_t(row)].metrics->relMSE, 'g', 3));
            QCOMPARE(table->item(row, 1)->text(), QString::number(frames[std::size_t(row)].metrics->psnr, 'g', 4));
        }
        QTRY_VERIFY(window_->viewport()->framesPresented() > 0);
        window_->recompose();
        QVERIFY(distinctColours(window_->composedFrame()) > 50);

        QTRY_VERIFY(window_->viewport()->framesPresented() > 1);
        const QImage shot = window_->viewport()->grab();
        const QImage composed = window_->composedFrame();
        QVERIFY(!shot.isNull());
        QCOMPARE(shot.size(), composed.size());
        int matches = 0, samples = 0;
        for (int y = 5; y < shot.height(); y += 17)
            for (int x = 5; x < shot.width(); x += 17) {
                const QColor s = shot.pixelColor(x, y), c = composed.pixelColor(x, y);
                const bool straight = std::abs(s.red() - c.red()) <= 2 && std::abs(s.blue() - c.blue()) <= 2;
                const bool swapped = std::abs(s.red() - c.blue()) <= 2 && std::abs(s.blue() - c.red()) <= 2;
                matches += (straight || swapped) && std::abs(s.green() - c.green()) <= 2;
                ++samples;
            }
        QVERIFY2(matches >= samples * 95 / 100, qPrintable(QString("%1 of %2").arg(matches).arg(samples)));
    }

    // Finished references are cached on disk: a studio that opens the same project gets them without rendering.
    void cachesFinishedReferencesOnDisk() {
        for (const ViewFrame& f : window_->frames())
            QVERIFY(!f.referenceCached);  // the first studio rendered them (the cache was empty)
        window_->waitForBackgroundWork();  // the cache files are written in a thread pool
        MainWindow second(vulkan_, kSmall);
        second.setRecovery(MainWindow::Recovery::Never);
        QVERIFY(second.openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(second.settled(), 120000);
        for (std::size_t i = 0; i < second.frames().size(); ++i) {
            const ViewFrame& f = second.frames()[i];
            QVERIFY2(f.referenceCached, qPrintable(f.name));
            QVERIFY(samePixels(*f.reference, *window_->frames()[i].reference));
        }
    }

    // The tonemap operator (toolbar combo, M cycles) changes every view's display: what the viewport shows at a pixel
    // is tonemapRgb() of the view's image there, for each operator, and false colour adds its colour bar.
    void tonemapsTheViewport() {
        window_->setLayoutMode(Layout::Single);
        window_->selectView(0);
        auto* combo = window_->findChild<QComboBox*>("tonemap");
        QVERIFY(combo);
        QCOMPARE(combo->count(), int(tonemapNames().size()));
        const ViewFrame& f = window_->frames()[0];
        const std::vector<QRect> rects = viewRects(window_->frames(), window_->compositorState(),
                                                   window_->composedFrame().size());
        const QPoint at = rects[0].center();
        int view = -1;
        QPoint pixel;
        QVERIFY(window_->viewAt(at, view, pixel));
        QCOMPARE(view, 0);
        std::vector<QImage> frames;
        for (int op = 0; op < combo->count(); ++op) {
            combo->setCurrentIndex(op);
            QCOMPARE(int(window_->compositorState().tonemap), op);
            const QImage frame = window_->composedFrame();
            const QColor shown = frame.pixelColor(at);
            // The nearest-neighbour scaling may land on a neighbour of the pixel viewAt() names.
            bool found = false;
            for (int dy = -1; dy <= 1 && !found; ++dy)
                for (int dx = -1; dx <= 1 && !found; ++dx) {
                    const int x = std::clamp(pixel.x() + dx, 0, f.image->width() - 1);
                    const int y = std::clamp(pixel.y() + dy, 0, f.image->height() - 1);
                    const auto d = tonemapRgb(f.image->at(x, y, 0), f.image->at(x, y, 1), f.image->at(x, y, 2),
                                              f.exposure + window_->compositorState().exposureOffset, Tonemap(op));
                    found = std::abs(shown.red() - int(std::lround(d[0] * 255.0f))) <= 1 &&
                            std::abs(shown.green() - int(std::lround(d[1] * 255.0f))) <= 1 &&
                            std::abs(shown.blue() - int(std::lround(d[2] * 255.0f))) <= 1;
                }
            QVERIFY2(found, qPrintable(QString("operator %1 shows %2").arg(op).arg(shown.name())));
            frames.push_back(frame);
        }
        for (std::size_t i = 0; i < frames.size(); ++i)
            for (std::size_t j = i + 1; j < frames.size(); ++j) QVERIFY(frames[i] != frames[j]);
        // False colour draws the viridis bar at the bottom right: its left end is viridis(0), dark purple.
        const QImage falseColour = frames.back();
        const int barWidth = std::min(256, falseColour.width() / 3);
        const QColor left = falseColour.pixelColor(falseColour.width() - barWidth - 12 + 1, falseColour.height() - 25);
        QVERIFY2(left.red() > 50 && left.red() < 90 && left.green() < 20 && left.blue() > 60, qPrintable(left.name()));
        // M (an application-wide shortcut, here typed in the viewport) cycles from false colour back to sRGB, and the
        // combo follows.
        QTest::keyClick(window_->viewport(), Qt::Key_M);
        QCOMPARE(window_->compositorState().tonemap, Tonemap::Srgb);
        QCOMPARE(combo->currentIndex(), 0);
        QCOMPARE(window_->composedFrame(), frames.front());
        window_->setLayoutMode(Layout::Grid);
    }

    // Grid shows every view; single shows one (keys 1-9 select it, from the viewport), holding Shift shows its
    // reference.
    void switchesLayouts() {
        window_->setLayoutMode(Layout::Grid);
        const QImage grid = window_->composedFrame();
        QTest::keyClick(window_->viewport(), Qt::Key_2);
        QCOMPARE(window_->compositorState().current, 1);
        QCOMPARE(window_->compositorState().layout, Layout::Single);
        const QImage single = window_->composedFrame();
        QVERIFY(single != grid);
        QTest::keyPress(window_->viewport(), Qt::Key_Shift);
        QVERIFY(window_->compositorState().showReference);
        const QImage reference = window_->composedFrame();
        QTest::keyRelease(window_->viewport(), Qt::Key_Shift);
        QVERIFY(!window_->compositorState().showReference);
        QVERIFY(reference != single);

        // Shift+2 makes view 2 every other view's reference (its label and metrics follow); Shift+2 again undoes it.
        QTest::keyClick(window_->viewport(), Qt::Key_2, Qt::ShiftModifier);
        QCOMPARE(window_->referenceView(), 1);
        QVERIFY(window_->frames()[0].alternate == window_->frames()[1].image);
        QVERIFY(!window_->frames()[1].alternate);
        QTRY_VERIFY(window_->settled());
        QVERIFY(window_->frames()[0].metrics && window_->frames()[0].metrics->relMSE > 0.0);
        QTest::keyClick(window_->viewport(), Qt::Key_2, Qt::ShiftModifier);
        QCOMPARE(window_->referenceView(), -1);
        QVERIFY(!window_->frames()[0].alternate);
        QTRY_VERIFY(window_->settled());

        // Zoom shows the same part of every view: the frame changes, and the cursor maps to pixels of that part.
        window_->setLayoutMode(Layout::Grid);
        const QImage unzoomed = window_->composedFrame();
        const QRect r = viewRects(window_->frames(), window_->compositorState(), window_->viewport()->pixelSize())[0];
        int view = -1;
        QPoint pixel;
        QVERIFY(window_->viewAt(QPointF(r.x() + 1, r.y() + 1), view, pixel));
        QCOMPARE(pixel, QPoint(0, 0));
        window_->compositorState().zoom = 4.0;
        window_->recompose();
        QVERIFY(window_->composedFrame() != unzoomed);
        QVERIFY(window_->viewAt(QPointF(r.x() + 1, r.y() + 1), view, pixel));
        QCOMPARE(view, 0);
        QCOMPARE(pixel, QPoint(36, 27));  // the centre quarter of 96 x 72 starts at (36, 27)
        QTest::keyClick(window_->viewport(), Qt::Key_Z);
        QCOMPARE(window_->compositorState().zoom, 1.0);
        QCOMPARE(window_->composedFrame(), unzoomed);
    }

    // Turning off the light shaft's shadows re-renders that view only; undo brings the same image back.
    void aParameterChangesItsViewOnlyAndUndoes() {
        window_->selectView(1);
        const auto before = window_->frames();
        auto* shadows = window_->findChild<QCheckBox*>("param:shadows");
        QVERIFY(shadows);
        QVERIFY(shadows->isChecked());
        shadows->setChecked(false);
        QVERIFY(window_->session().modified());
        QVERIFY(window_->isWindowModified());
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        const auto after = window_->frames();
        QVERIFY(after[1].image != before[1].image);
        QVERIFY(sum(*after[1].image) > sum(*before[1].image));  // unshadowed: more light
        for (int i : {0, 2, 3})
            QVERIFY(after[std::size_t(i)].image == before[std::size_t(i)].image);
        QVERIFY(window_->session().project().views[1].parameters["shadows"] == nlohmann::json(false));

        window_->session().undoStack()->undo();
        QVERIFY(!window_->session().modified());
        auto* restored = window_->findChild<QCheckBox*>("param:shadows");
        QVERIFY(restored && restored->isChecked());
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QVERIFY(samePixels(*window_->frames()[1].image, *before[1].image));
    }

    // Editing a view's exposure in the Parameters dock (Up key, arrow, typing) and stepping a parameter's spin box
    // change the project while the very same spin box stays: the panel was rebuilt from the edit's own signal, which
    // deleted the spin box inside its stepBy (a segfault in QWidget::style()). Undo moves the same widgets back. A
    // value the scene panel refuses puts its field back in place, too.
    void editsExposureAndParametersInPlace() {
        window_->selectView(1);
        const int undoIndex = window_->session().undoStack()->index();
        QPointer<QDoubleSpinBox> exposure = window_->findChild<QDoubleSpinBox*>("exposure");
        QVERIFY(exposure);
        const double before = window_->session().project().views[1].exposure;
        exposure->setFocus();
        QTest::keyClick(exposure, Qt::Key_Up);
        QCoreApplication::processEvents();
        QVERIFY(exposure);
        QCOMPARE(window_->session().project().views[1].exposure, before + 0.5);
        exposure->stepBy(1);
        QCoreApplication::processEvents();
        QVERIFY(exposure);
        QCOMPARE(window_->session().project().views[1].exposure, before + 1.0);
        QCOMPARE(window_->findChild<QDoubleSpinBox*>("exposure"), exposure.data());

        QDoubleSpinBox* parameter = nullptr;
        for (QDoubleSpinBox* spin : window_->findChildren<QDoubleSpinBox*>())
            if (spin->objectName().startsWith("param:") && spin->value() < spin->maximum()) parameter = spin;
        QVERIFY(parameter);
        const QString name = parameter->objectName().mid(6);
        QPointer<QDoubleSpinBox> kept(parameter);
        parameter->stepBy(1);
        QCoreApplication::processEvents();
        QVERIFY(kept);
        QVERIFY(window_->session().project().views[1].parameters.contains(name.toStdString()));

        window_->session().undoStack()->setIndex(undoIndex);
        QCoreApplication::processEvents();
        QVERIFY(exposure && kept);
        QCOMPARE(exposure->value(), before);
        QCOMPARE(window_->session().project().views[1].exposure, before);
        QVERIFY(!window_->session().project().views[1].parameters.contains(name.toStdString()));

        QPointer<QDoubleSpinBox> fov = window_->findChild<QDoubleSpinBox*>("scene:camera.fovY");
        QVERIFY(fov);
        fov->setValue(179.98);
        fov->stepBy(1);  // 180.03: refused
        QCoreApplication::processEvents();
        QVERIFY(fov);
        QCOMPARE(fov->value(), 179.98);
        QVERIFY(window_->scenePanel()->lastError().contains("fovY"));
        window_->session().undoStack()->setIndex(undoIndex);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // The wipe shows the view left of the divider and its reference right of it; T swaps them; the difference mode
    // draws its colour bar.
    void wipesAndShowsDifferences() {
        window_->selectView(1);
        window_->setLayoutMode(Layout::Single);
        const QImage technique = window_->composedFrame();
        window_->compositorState().showReference = true;
        window_->recompose();
        const QImage reference = window_->composedFrame();
        window_->compositorState().showReference = false;

        window_->setLayoutMode(Layout::Split);
        window_->compositorState().split = 0.5;
        window_->recompose();
        const QImage split = window_->composedFrame();
        const QRect r = viewRects(window_->frames(), window_->compositorState(), split.size())[1];
        QVERIFY(!r.isEmpty());
        const int y = r.center().y();
        const int leftX = r.x() + r.width() / 4, rightX = r.x() + 3 * r.width() / 4;
        QCOMPARE(split.pixel(leftX, y), technique.pixel(leftX, y));
        QCOMPARE(split.pixel(rightX, y), reference.pixel(rightX, y));
        QTest::keyClick(window_->viewport(), Qt::Key_T);
        QVERIFY(window_->compositorState().swapped);
        QCOMPARE(window_->composedFrame().pixel(leftX, y), reference.pixel(leftX, y));
        window_->compositorState().swapped = false;

        window_->setLayoutMode(Layout::Single);
        window_->compositorState().diff = DiffMode::Signed;
        window_->recompose();
        const QImage diff = window_->composedFrame();
        QVERIFY(diff != technique);
        window_->compositorState().diff = DiffMode::Off;
        window_->setLayoutMode(Layout::Grid);
    }

    // A snapshot keeps a view's image and parameters: change the estimator, compare the live view against the
    // snapshot, restore it (one undoable edit) and get the snapshot's very image back.
    void takesComparesAndRestoresASnapshot() {
        window_->selectView(1);
        QCOMPARE(window_->takeSnapshot(), 0);
        const auto shot = window_->snapshots()[0];
        QVERIFY(shot.image == window_->frames()[1].image);
        auto* estimator = window_->findChild<QComboBox*>("param:estimator");
        QVERIFY(estimator);
        estimator->setCurrentText("rm");
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QVERIFY(!samePixels(*window_->frames()[1].image, *shot.image));

        window_->compareWithSnapshot(0);
        const ViewFrame& compared = window_->frames()[1];
        QVERIFY(compared.snapshot == shot.image);
        QTRY_VERIFY(compared.metrics && compared.metrics->relMSE > 0.0);  // computed off the GUI thread
        window_->setLayoutMode(Layout::Single);
        window_->compositorState().showReference = true;
        window_->recompose();
        const QImage snapshotShown = window_->composedFrame();
        window_->compositorState().showReference = false;
        window_->setLayoutMode(Layout::Grid);

        const int undoBefore = window_->session().undoStack()->count();
        window_->restoreSnapshot(0);
        QCOMPARE(window_->session().undoStack()->count(), undoBefore + 1);
        QVERIFY(window_->session().project().views[1].parameters == shot.parameters);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QVERIFY(samePixels(*window_->frames()[1].image, *shot.image));
        QTRY_VERIFY(window_->frames()[1].metrics && window_->frames()[1].metrics->relMSE == 0.0);
        window_->compareWithSnapshot(-1);
        QVERIFY(!window_->frames()[1].snapshot);
        QVERIFY(snapshotShown != window_->composedFrame());
    }

    // The cursor over the WVDS view fills the inspector with every view's value there and the PDF plot with the
    // probe's histograms and pdfs; the convergence plot has each view's error over spp; a region gets its metrics.
    void inspectsPlotsAndMeasuresARegion() {
        window_->setLayoutMode(Layout::Grid);
        window_->recompose();
        const QRect r = viewRects(window_->frames(), window_->compositorState(), window_->viewport()->pixelSize())[1];
        QVERIFY(!r.isEmpty());
        const int graphsBefore = window_->pdfPlot()->plot()->graphCount();
        window_->inspect(QPointF(r.x() + r.width() * 0.5, r.y() + r.height() * 0.6));
        // The values at once; the probe (a WVDS scene preparation, a BVH build) in the background: inspect() returned
        // without it, and its plot comes through the event loop.
        QVERIFY2(window_->inspectorText().contains("pixel"), qPrintable(window_->inspectorText()));
        QVERIFY(window_->inspectorText().contains("light shaft"));
        QCOMPARE(window_->pdfPlot()->plot()->graphCount(), graphsBefore);
        // Nothing of it is clipped: every column (the reference's last) is there, scrolled to if the dock is narrow.
        window_->findChild<QDockWidget*>("inspectorDock")->raise();
        QCoreApplication::processEvents();
        auto* inspector = window_->findChild<QLabel*>("inspector");
        QVERIFY2(inspector->width() >= inspector->sizeHint().width(),
                 qPrintable(QString("%1 px shown of %2").arg(inspector->width()).arg(inspector->sizeHint().width())));
        window_->findChild<QDockWidget*>("metricsDock")->raise();
        QTRY_COMPARE_WITH_TIMEOUT(window_->pdfPlot()->plot()->graphCount(), 6, 60000);
        QVERIFY(window_->pdfPlot()->plot()->graph(0)->dataCount() == 256);
        int withPoints = 0;
        for (int g = 0; g < window_->convergencePlot()->plot()->graphCount(); ++g) {
            QCPGraph* graph = window_->convergencePlot()->plot()->graph(g);
            withPoints += graph->dataCount() > 0;
            // One point (and one kept image) per bucket of spp, four per octave, however many images the view made.
            std::set<int> buckets;
            for (auto it = graph->data()->constBegin(); it != graph->data()->constEnd(); ++it)
                buckets.insert(MainWindow::convergenceBucket(int(std::lround(it->key))));
            QCOMPARE(int(buckets.size()), graph->dataCount());
        }
        QVERIFY(withPoints >= 3);

        window_->setRegion(QRect(20, 20, 40, 30));
        QTRY_VERIFY(window_->settled());
        for (const ViewFrame& f : window_->frames())
            QVERIFY2(f.regionMetrics.has_value(), qPrintable(f.name));
        // The relMSE of each point is computed in the background pool: a view's last point (its final image) is the
        // relMSE its metrics report against the same reference.
        int checked = 0;
        for (std::size_t i = 0; i < window_->frames().size(); ++i) {
            const ViewFrame& f = window_->frames()[i];
            QCPGraph* graph = window_->convergencePlot()->plot()->graph(int(i));
            if (!graph || graph->dataCount() == 0 || !f.metrics || f.snapshot) continue;
            const double last = (graph->data()->constEnd() - 1)->value;
            QVERIFY2(std::abs(last - f.metrics->relMSE) <= 1e-6 * f.metrics->relMSE,
                     qPrintable(QString("%1: plotted %2, metrics %3").arg(f.name).arg(last).arg(f.metrics->relMSE)));
            ++checked;
        }
        QVERIFY(checked >= 3);
    }

    // A progressive view sends an image per pass; the plot keeps the newest of each bucket of spp (four per octave),
    // so that a view's kept images grow with log(spp), and a new render starts the list again.
    void keepsFourConvergencePointsPerOctave() {
        struct Point {
            int spp = 0;
        };
        std::vector<Point> points;
        for (int spp = 1; spp <= 1024; ++spp)
            addConvergencePoint(points, Point{spp});
        QCOMPARE(int(points.size()), 36);  // the buckets of 1 .. 1024 spp: 0, 4, 6, then 8 .. 40
        QCOMPARE(points.back().spp, 1024);
        std::set<int> buckets;
        for (std::size_t k = 0; k < points.size(); ++k) {
            buckets.insert(MainWindow::convergenceBucket(points[k].spp));
            if (k > 0) QVERIFY(points[k].spp > points[k - 1].spp);
        }
        QCOMPARE(buckets.size(), points.size());
        QCOMPARE(points[0].spp, 1);
        addConvergencePoint(points, Point{1});  // a new render
        QCOMPARE(int(points.size()), 1);
    }

    // A light's intensity from the scene panel re-renders the views whose part holds that light (and their references)
    // and no other; an invalid value is refused with its reason; orbiting the camera re-renders every view; undo
    // brings both back.
    void editsTheSceneAndNavigatesTheCamera() {
        const auto before = window_->frames();
        const int undoIndex = window_->session().undoStack()->index();
        auto* intensity = window_->findChild<QDoubleSpinBox*>("scene:lights[lamp].intensity[0]");
        QVERIFY(intensity);
        intensity->setValue(intensity->value() * 3.0);
        QVERIFY(window_->session().modified());
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        const auto after = window_->frames();
        for (int i : {0, 3}) {  // everything, glow: the lamp is in their part
            QVERIFY2(after[std::size_t(i)].image != before[std::size_t(i)].image, qPrintable(after[std::size_t(i)].name));
            QVERIFY(after[std::size_t(i)].reference != before[std::size_t(i)].reference);
        }
        for (int i : {1, 2}) {  // light shaft, area light: it is not
            QVERIFY2(after[std::size_t(i)].image == before[std::size_t(i)].image, qPrintable(after[std::size_t(i)].name));
            QVERIFY(after[std::size_t(i)].reference == before[std::size_t(i)].reference);
        }
        QVERIFY(sum(*after[3].image) > sum(*before[3].image));

        auto* fov = window_->findChild<QDoubleSpinBox*>("scene:camera.fovY");
        QVERIFY(fov);
        const double fovBefore = window_->session().project().scene.camera.fovY;
        fov->setValue(400.0);  // outside (0, 180)
        QVERIFY2(window_->scenePanel()->lastError().contains("fovY"), qPrintable(window_->scenePanel()->lastError()));
        QCOMPARE(window_->session().project().scene.camera.fovY, fovBefore);

        const Vec3 position = window_->session().project().scene.camera.position;
        window_->orbitCamera(0.2, 0.0);
        window_->orbitCamera(0.1, 0.05);
        QVERIFY(glm::length(window_->session().project().scene.camera.position - position) > 0.1);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        for (std::size_t i = 0; i < 4; ++i)
            QVERIFY(window_->frames()[i].image != after[i].image);
        window_->session().undoStack()->undo();  // both orbit steps are one edit
        QVERIFY(glm::length(window_->session().project().scene.camera.position - position) < 1e-9);
        window_->session().undoStack()->undo();
        QCOMPARE(window_->session().undoStack()->index(), undoIndex);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QVERIFY(samePixels(*window_->frames()[3].image, *before[3].image));
    }

    // Captions fit their tiles: in the default window's grid every view's metrics line shows its relMSE and PSNR whole
    // (the compact form drops the long names), and a wide tile gets the full caption with the technique's name.
    void captionsKeepTheirNumbersInNarrowTiles() {
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        window_->setLayoutMode(Layout::Grid);
        const std::vector<ViewFrame>& frames = window_->frames();
        const std::vector<QRect> rects = viewRects(frames, window_->compositorState(), window_->viewport()->pixelSize());
        const QString ellipsis(QChar(0x2026));
        for (std::size_t i = 0; i < frames.size(); ++i) {
            const ViewFrame& f = frames[i];
            QVERIFY(f.metrics);
            const QStringList caption = tileCaption(f, false, rects[i].width(), window_->font());
            QCOMPARE(caption.size(), 2);
            const QString relMSE = QString::number(f.metrics->relMSE, 'g', 3), psnr = QString::number(f.metrics->psnr, 'g', 3);
            QVERIFY2(caption[1].contains(relMSE) && caption[1].contains(psnr + " dB") && !caption[1].contains(ellipsis),
                     qPrintable(QString("%1 px: %2").arg(rects[i].width()).arg(caption[1])));
            QVERIFY2(caption[0].startsWith(f.name) && !caption[0].contains(ellipsis), qPrintable(caption[0]));
            const QStringList wide = tileCaption(f, false, 2000, window_->font());
            QVERIFY(wide[0].contains(f.technique));
            QVERIFY(wide[1].contains("PSNR"));
        }
    }

    // The Scene dock edits materials and phase functions: a material's type (its rows follow: albedo for diffuse, f0
    // and roughness for ggx) and a medium's phase type (g shown only for the types that use it). Each is one undoable
    // edit that re-renders the views it affects; a refused value says why.
    void editsMaterialsAndPhaseFunctionsInTheSceneDock() {
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        const auto before = window_->frames();
        const int undoIndex = window_->session().undoStack()->index();
        auto* brass = window_->findChild<QComboBox*>("scene:materials[brass].type");
        QVERIFY(brass);
        QCOMPARE(brass->currentText(), QString("ggx"));
        QVERIFY(window_->findChild<QWidget*>("scene:materials[brass].f0"));
        QVERIFY(!window_->findChild<QWidget*>("scene:materials[brass].albedo"));
        brass->setCurrentText("diffuse");
        emit brass->activated(brass->currentIndex());
        const auto material = [&](const std::string& name) {
            for (const Material& m : window_->session().project().scene.materials)
                if (m.name == name) return m;
            return Material{};
        };
        QCOMPARE(int(material("brass").kind), int(Material::Kind::Diffuse));
        QCOMPARE(window_->session().undoStack()->index(), undoIndex + 1);
        // The rows follow the type (rebuilt from the event loop).
        QTRY_VERIFY(window_->findChild<QWidget*>("scene:materials[brass].albedo"));
        QVERIFY(!window_->findChild<QWidget*>("scene:materials[brass].f0"));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QVERIFY(window_->frames()[0].image != before[0].image);  // the sphere is in every view's surfaces

        auto* phase = window_->findChild<QComboBox*>("scene:media[fog].phase.type");
        QVERIFY(phase);
        QCOMPARE(phase->currentText(), QString("hg"));
        QVERIFY(window_->findChild<QWidget*>("scene:media[fog].phase.g"));
        phase->setCurrentText("rayleigh");
        emit phase->activated(phase->currentIndex());
        QCOMPARE(window_->session().project().scene.media[0].phase.kind, PhaseKind::Rayleigh);
        QTRY_VERIFY(!window_->findChild<QWidget*>("scene:media[fog].phase.g"));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);

        window_->session().undoStack()->undo();
        QCOMPARE(window_->session().project().scene.media[0].phase.kind, PhaseKind::HenyeyGreenstein);
        window_->session().undoStack()->undo();
        QCOMPARE(int(material("brass").kind), int(Material::Kind::GGX));
        QCOMPARE(window_->session().undoStack()->index(), undoIndex);
        QTRY_VERIFY(window_->findChild<QWidget*>("scene:materials[brass].f0"));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QVERIFY(samePixels(*window_->frames()[0].image, *before[0].image));
    }

    // Staleness: after an edit of the lamp, the views whose part holds it (everything, glow) render again, their images
    // first and their references after the debounce. Meanwhile every comparison is made of an image and a reference
    // of one state (the images carry it as partHash): the metrics are those of that pair, marked stale, the status bar
    // is not "Ready", and an export writes that pair (both files with one partHash) marked stale. Once the references
    // arrive the comparisons are current again. (Before, the new image was compared with the old reference: a bias
    // of +117 % on a view right after an edit.)
    void comparesOnlyImagesOfOneState() {
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        const auto before = window_->frames();
        const int undoIndex = window_->session().undoStack()->index();
        auto* intensity = window_->findChild<QDoubleSpinBox*>("scene:lights[lamp].intensity[0]");
        QVERIFY(intensity);
        intensity->setValue(intensity->value() * 2.0);
        auto hashOf = [](const std::shared_ptr<const Image>& image) {
            return image && image->metadata.count("partHash") ? image->metadata.at("partHash") : std::string("none");
        };
        auto* status = window_->findChild<QLabel*>("renderStatus");
        QVERIFY(status);
        bool sawStale = false, exported = false;
        QElapsedTimer clock;
        clock.start();
        while (!window_->settled() && clock.elapsed() < 120000) {
            QTest::qWait(5);
            for (int i : {0, 3}) {
                const ViewFrame& f = window_->frames()[std::size_t(i)];
                const ComparisonPair pair = comparisonPair(f);
                if (pair.image) QCOMPARE(hashOf(pair.image), hashOf(pair.against));
                if (f.metrics && pair.image) {
                    const Metrics m = computeMetrics(*pair.image, *pair.against, f.exposure);
                    QVERIFY2(std::abs(m.relMSE - f.metrics->relMSE) <= 1e-9 * std::max(1e-12, m.relMSE),
                             qPrintable(f.name));
                }
                if (!(f.image && f.reference && f.imageState != f.referenceState)) continue;
                sawStale = true;
                QVERIFY(pair.stale && pair.image != f.image);
                QVERIFY(status->text() != "Ready");
                if (exported || !f.metrics) continue;
                QVERIFY(f.metricsStale);
                exported = true;
                const QString folder = QString(TYNDALL_TEST_TMP) + "/export-stale";
                QDir(folder).removeRecursively();
                QString error;
                QVERIFY2(window_->exportComparison(folder, &error), qPrintable(error));
                const QString stem = folder + "/" + f.name;
                const Image image = readImage((stem + ".exr").toStdString());
                const Image reference = readImage((stem + "-reference.exr").toStdString());
                QCOMPARE(image.metadata.at("partHash"), reference.metadata.at("partHash"));
                QFile json(folder + "/metrics.json");
                QVERIFY(json.open(QIODevice::ReadOnly));
                const nlohmann::json metrics = nlohmann::json::parse(json.readAll().toStdString());
                QVERIFY(metrics[std::size_t(i)]["stale"] == nlohmann::json(true));
                QVERIFY(window_->exportNotes().join(" ").contains(f.name));
            }
        }
        QVERIFY(window_->settled());
        QVERIFY(sawStale);
        QVERIFY(exported);
        for (const ViewFrame& f : window_->frames()) {
            QCOMPARE(f.imageState, f.referenceState);
            QVERIFY(!comparisonPair(f).stale && comparisonPair(f).image == f.image);
            QVERIFY(!f.metricsStale);
        }
        QVERIFY(window_->frames()[0].state != before[0].state);
        QVERIFY(window_->frames()[1].state == before[1].state);  // the lamp is not in the light shaft's part
        QCOMPARE(status->text(), QString("Ready"));
        window_->session().undoStack()->setIndex(undoIndex);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // The comparison export writes every view, reference and difference, the viewport and the metrics.
    void exportsAComparison() {
        const QString folder = QString(TYNDALL_TEST_TMP) + "/export";
        QDir(folder).removeRecursively();
        QString error;
        QVERIFY2(window_->exportComparison(folder, &error), qPrintable(error));
        for (const ViewFrame& f : window_->frames())
            for (const char* suffix : {".exr", ".png", "-reference.exr", "-reference.png", "-diff.png"})
                QVERIFY2(QFile::exists(folder + "/" + f.name + suffix), qPrintable(f.name + suffix));
        QFile json(folder + "/metrics.json");
        QVERIFY(json.open(QIODevice::ReadOnly));
        const nlohmann::json metrics = nlohmann::json::parse(json.readAll().toStdString());
        QCOMPARE(int(metrics.size()), 4);
        QVERIFY(metrics[1].contains("relMSE"));
        const QImage viewport(folder + "/viewport.png");
        QCOMPARE(viewport.size(), window_->composedFrame().size());
        QVERIFY(QFile::exists(folder + "/metrics.csv"));
        for (const char* plot : {"/plot-convergence.png", "/plot-convergence.svg", "/plot-pdf.png", "/plot-pdf.svg"})
            QVERIFY2(QFile(folder + plot).size() > 1000, plot);
        QFile svg(folder + "/plot-pdf.svg");
        QVERIFY(svg.open(QIODevice::ReadOnly));
        QVERIFY(svg.readAll().contains("<svg"));
        QVERIFY(QImage(folder + "/light shaft-region.png").size() == QSize(40, 30));
        window_->setRegion(QRect());
    }

    // A broken project is refused with a dialog that names the file and the problem; the current project stays.
    void refusesABrokenProject() {
        const QString path = QString(TYNDALL_TEST_TMP) + "/broken.json";
        QDir().mkpath(TYNDALL_TEST_TMP);
        QFile file(path);
        QVERIFY(file.open(QIODevice::WriteOnly));
        file.write("{\"tyndall\": 1, \"camera\": {\"fovY\": 400}}");
        file.close();
        QString dialogText;
        QTimer::singleShot(500, [&] {
            for (QWidget* w : QApplication::topLevelWidgets())
                if (auto* box = qobject_cast<QMessageBox*>(w); box && box->isVisible()) {
                    dialogText = box->text();
                    box->accept();
                }
        });
        QVERIFY(!window_->openProject(path, true));
        QVERIFY2(dialogText.contains("broken.json") && dialogText.contains("fovY"), qPrintable(dialogText));
        QCOMPARE(window_->session().path(), kDefaultProject);
        QCOMPARE(int(window_->frames().size()), 4);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QVERIFY(window_->frames()[0].image);
    }

    // Unsaved changes are autosaved; a studio that opens the project afterwards (after a crash) recovers them as one
    // undoable edit on top of the file, and the project is listed under the recent ones.
    void recoversUnsavedChangesAfterACrash() {
        const QString path = openCopyOfTheDefaultProject("recover");
        QVERIFY(!path.isEmpty());
        QCOMPARE(window_->recentProjects().value(0), QFileInfo(path).absoluteFilePath());
        window_->session().setParameter(1, "raySamples", std::int64_t(3));
        QVERIFY(window_->autosaveNow());
        window_->waitForAutosaves();  // written by the autosave thread
        QVERIFY(QFile::exists(MainWindow::autosavePath(path)));

        // The first studio "crashes" (it is left as it is); a second one opens the same project.
        MainWindow second(vulkan_, kSmall);
        second.setRecovery(MainWindow::Recovery::Always);
        QVERIFY(second.openProject(path, false));
        QVERIFY(second.session().modified());
        QVERIFY(second.session().project().views[1].parameters["raySamples"] == nlohmann::json(3));
        second.session().undoStack()->undo();
        QVERIFY(!second.session().project().views[1].parameters.contains("raySamples"));
        QVERIFY(!second.session().modified());
        second.waitForAutosaves();
        QVERIFY(!QFile::exists(MainWindow::autosavePath(path)));  // back at the file: nothing left to recover
        QTRY_VERIFY_WITH_TIMEOUT(second.settled(), 120000);
    }

    // An autosave that cannot be written says so in the status bar (its path is taken by a folder, which fails even
    // for root), and the session keeps its changes.
    void reportsAFailedAutosave() {
        const QString path = openCopyOfTheDefaultProject("autosave-fails");
        QVERIFY(!path.isEmpty());
        const QString blocked = MainWindow::autosavePath(path);
        QFile::remove(blocked);
        QVERIFY(QDir().mkpath(blocked + "/taken"));
        window_->session().setParameter(1, "raySamples", std::int64_t(5));
        QVERIFY(window_->autosaveNow());
        window_->waitForAutosaves();
        QTRY_VERIFY_WITH_TIMEOUT(window_->statusBar()->currentMessage().startsWith("Autosave failed"), 5000);
        QVERIFY2(window_->statusBar()->currentMessage().contains(blocked), qPrintable(window_->statusBar()->currentMessage()));
        QVERIFY(window_->session().modified());
        QDir(blocked).removeRecursively();
        window_->session().undoStack()->undo();
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // Reopening a file after Discard (on Open) or after Save As asks to recover nothing: the discarded changes and
    // the changes saved elsewhere are not "unsaved changes" of that file. Save As lists the new file as recent.
    void noRecoveryPromptAfterDiscardOrSaveAs() {
        const QString dir = QString(TYNDALL_TEST_TMP) + "/discard";
        QDir(dir).removeRecursively();
        QDir().mkpath(dir);
        const QString path = dir + "/room.json", other = dir + "/room-as.json";
        QVERIFY(QFile::copy(kDefaultProject, path));
        window_->setRecovery(MainWindow::Recovery::Ask);
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
        window_->session().setParameter(1, "raySamples", std::int64_t(7));
        QVERIFY(window_->autosaveNow());
        window_->waitForAutosaves();
        QVERIFY(window_->confirmDiscard());  // "Discard"
        QVERIFY(!window_->autosaveNow());    // nothing is autosaved while the file dialog would be open
        QVERIFY(window_->openProject(path, false));
        QVERIFY2(prompts.isEmpty(), qPrintable(prompts.join("; ")));
        QVERIFY(!window_->session().modified());

        window_->session().setParameter(1, "raySamples", std::int64_t(9));
        QVERIFY(window_->autosaveNow());
        window_->waitForAutosaves();
        QString error;
        QVERIFY2(window_->saveProjectAs(other, &error), qPrintable(error));
        QCOMPARE(window_->recentProjects().value(0), QFileInfo(other).absoluteFilePath());
        QVERIFY(window_->openProject(path, false));
        QVERIFY2(prompts.isEmpty(), qPrintable(prompts.join("; ")));
        QVERIFY(!window_->session().project().views[1].parameters.contains("raySamples"));
        watcher.stop();
        window_->setRecovery(MainWindow::Recovery::Never);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
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
        window_->setRecovery(MainWindow::Recovery::Never);
        QVERIFY(window_->openProject(path, false));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        window_->selectView(1);
        QCOMPARE(window_->takeSnapshot(), 0);
        window_->session().setParameter(1, "raySamples", std::int64_t(3));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QCOMPARE(window_->takeSnapshot(), 1);
        QString error;
        QVERIFY2(window_->saveProject(&error), qPrintable(error));
        const QString folder = SnapshotStore::folderOf(path);
        QCOMPARE(folder, dir + "/room.snapshots");
        QVERIFY(QFile::exists(folder + "/snapshots.json"));

        MainWindow second(vulkan_, kSmall);
        second.setRecovery(MainWindow::Recovery::Never);
        QVERIFY(second.openProject(path, false));
        QCOMPARE(second.snapshots().size(), std::size_t(2));
        for (std::size_t i = 0; i < 2; ++i) {
            const Snapshot &saved = window_->snapshots()[i], &loaded = second.snapshots()[i];
            QCOMPARE(loaded.name, saved.name);
            QCOMPARE(loaded.view, 1);
            QVERIFY(loaded.parameters == saved.parameters);
            QCOMPARE(loaded.exposure, saved.exposure);
            QVERIFY(samePixels(*loaded.image, *saved.image));
        }
        QVERIFY(second.snapshots()[1].parameters["raySamples"] == nlohmann::json(3));
        // Snapshots follow their view when the views change, and are not lost: a view added, one removed before it,
        // a rename of it; a snapshot whose view is removed goes with it.
        const auto indexOf = [&](const std::string& name) {
            const std::vector<View>& views = second.session().project().views;
            for (std::size_t v = 0; v < views.size(); ++v)
                if (views[v].name == name) return int(v);
            return -1;
        };
        QVERIFY(second.session().duplicateView(0, &error));
        QCOMPARE(second.snapshots().size(), std::size_t(2));
        QCOMPARE(second.snapshots()[0].view, indexOf("light shaft"));
        QVERIFY(second.session().removeView(0, &error));  // "everything", before it
        QCOMPARE(second.snapshots().size(), std::size_t(2));
        QCOMPARE(second.snapshots()[0].view, indexOf("light shaft"));
        const int shaft = indexOf("light shaft");
        QVERIFY(second.session().renameView(shaft, "shaft", &error));
        QCOMPARE(second.snapshots().size(), std::size_t(2));
        QCOMPARE(second.snapshots()[1].view, shaft);
        QVERIFY(second.session().removeView(shaft, &error));  // kept, without a view, until it comes back
        QCOMPARE(second.snapshots().size(), std::size_t(2));
        QCOMPARE(second.snapshots()[0].view, -1);
        for (int k = 0; k < 4; ++k) second.session().undoStack()->undo();
        QCOMPARE(second.session().project().views[1].name, std::string("light shaft"));
        QCOMPARE(second.snapshots().size(), std::size_t(2));
        QCOMPARE(second.snapshots()[0].view, 1);
        QCOMPARE(second.snapshots()[1].view, 1);
        second.compareWithSnapshot(0);
        QVERIFY(second.frames()[1].snapshot == second.snapshots()[0].image);
        QTRY_VERIFY_WITH_TIMEOUT(second.settled(), 120000);

        {
            QFile index(folder + "/snapshots.json");
            QVERIFY(index.open(QIODevice::WriteOnly | QIODevice::Truncate));
            index.write("{\"tyndallSnapshots\": 1, \"snapshots\": [{\"name\": 3}]}");
        }
        MainWindow third(vulkan_, kSmall);
        third.setRecovery(MainWindow::Recovery::Never);
        QVERIFY(third.openProject(path, false));
        QVERIFY(third.snapshots().empty());
        const QString message = third.statusBar()->currentMessage();
        QVERIFY2(message.contains("snapshots.json") && message.contains("snapshots[0]"), qPrintable(message));
        QTRY_VERIFY_WITH_TIMEOUT(third.settled(), 120000);
        window_->session().undoStack()->undo();
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
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
        slow.job = std::make_shared<RenderJob>(makeViewJob(project, kDefaultProject.toStdString(), "everything", slowOptions));
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
        slow.job = std::make_shared<RenderJob>(makeViewJob(project, kDefaultProject.toStdString(), "everything", slowOptions));
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

    // Images from other programs are views (tev-like): an EXR of view 0's reference, opened as a file, compares with
    // that reference at relMSE 0 and with another view's reference at once when chosen; it can be every view's
    // comparand (Shift+N); a PNG is decoded from display values; dropped files open; Remove closes an image; images
    // stay through a scene edit; a file that is missing or not an image says why.
    void opensImagesAsViews() {
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        const QString dir = QString(TYNDALL_TEST_TMP) + "/images";
        QDir(dir).removeRecursively();
        QDir().mkpath(dir);
        const int n = int(window_->frames().size());
        const std::shared_ptr<const Image> reference = window_->frames()[0].reference, shaft = window_->frames()[1].image;
        QVERIFY(reference && shaft);
        writeImage(*reference, (dir + "/room.exr").toStdString());
        writeImage(*shaft, (dir + "/shaft.png").toStdString());
        QString error;
        QCOMPARE(window_->openImageView(dir + "/room.exr", &error), n);
        QCOMPARE(int(window_->frames().size()), n + 1);
        QCOMPARE(window_->compositorState().current, n);  // the new view is selected
        {
            const ViewFrame& f = window_->frames()[std::size_t(n)];
            QVERIFY(f.file);
            QCOMPARE(f.name, QString("room.exr"));
            QVERIFY(f.reference == reference);
            QVERIFY(samePixels(*f.image, *reference));
        }
        QTRY_VERIFY(window_->frames()[std::size_t(n)].metrics);
        QCOMPARE(window_->frames()[std::size_t(n)].metrics->relMSE, 0.0);
        auto* against = window_->findChild<QComboBox*>("imageAgainst");
        QVERIFY(against && against->isVisibleTo(window_.get()));
        QCOMPARE(against->count(), n);
        against->setCurrentIndex(1);
        emit against->activated(1);  // the light shaft's part: the room's image is far from it
        QVERIFY(window_->frames()[std::size_t(n)].reference == window_->frames()[1].reference);
        QTRY_VERIFY(window_->frames()[std::size_t(n)].metrics && window_->frames()[std::size_t(n)].metrics->relMSE > 0.01);

        // The image as every view's comparand.
        window_->chooseReferenceView(n);
        QVERIFY(window_->frames()[0].alternate == window_->frames()[std::size_t(n)].image);
        QTRY_VERIFY(window_->frames()[0].metrics);
        window_->chooseReferenceView(-1);

        // A PNG holds display values: decoded with the sRGB curve, to within 8 bits of the clipped original.
        const int png = window_->openImageView(dir + "/shaft.png", &error);
        QCOMPARE(png, n + 1);
        const ViewFrame& p = window_->frames()[std::size_t(png)];
        QVERIFY2(p.technique.contains("sRGB decoded"), qPrintable(p.technique));
        double worst = 0.0;
        for (int y = 0; y < shaft->height(); ++y)
            for (int x = 0; x < shaft->width(); ++x)
                for (int c = 0; c < 3; ++c) {
                    const double original = std::min(1.0, double(shaft->at(x, y, c)));
                    if (original < 0.05) continue;  // 8 bits near black are coarse in linear terms
                    worst = std::max(worst, std::abs(p.image->at(x, y, c) - original) / original);
                }
        QVERIFY2(worst < 0.03, qPrintable(QString::number(worst)));

        // Dropped on the window.
        QMimeData mime;
        mime.setUrls({QUrl::fromLocalFile(dir + "/room.exr")});
        QDragEnterEvent enter(QPoint(20, 20), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
        QApplication::sendEvent(window_.get(), &enter);
        QVERIFY(enter.isAccepted());
        QDropEvent drop(QPointF(20, 20), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
        QApplication::sendEvent(window_.get(), &drop);
        QCOMPARE(int(window_->frames().size()), n + 3);

        // The grid shows every view, the images too.
        window_->setLayoutMode(Layout::Grid);
        const std::vector<QRect> rects = viewRects(window_->frames(), window_->compositorState(), QSize(900, 600));
        QCOMPARE(int(rects.size()), n + 3);
        QVERIFY(!rects.back().isEmpty());

        // Images stay through a scene edit, and Remove closes one.
        QVERIFY(window_->session().editScene({"camera.fovY=51"}, "fov", &error));
        QCOMPARE(int(window_->frames().size()), n + 3);
        window_->selectView(n + 2);
        QPushButton* remove = nullptr;
        for (QPushButton* b : window_->findChildren<QPushButton*>())
            if (b->text() == "Remove") remove = b;
        QVERIFY(remove);
        remove->click();
        QCOMPARE(int(window_->frames().size()), n + 2);

        QCOMPARE(window_->openImageView(dir + "/missing.exr", &error), -1);
        QVERIFY2(error.contains("missing.exr"), qPrintable(error));
        QCOMPARE(window_->openImageView(kDefaultProject, &error), -1);
        QVERIFY2(error.contains("not an image"), qPrintable(error));

        // An image of another size cannot be compared: the tile and the metrics dock say why instead of "waiting".
        const int small = window_->openImageView(TYNDALL_SOURCE_DIR "/tests/data/images/glow-16x12.exr", &error);
        QVERIFY2(small == n + 2, qPrintable(error));
        // (Once the reference of the edited camera is in: the file stands for the current state.)
        QTRY_COMPARE_WITH_TIMEOUT(incomparable(window_->frames()[std::size_t(small)]),
                                  QString("sizes differ: 16 x 12 against 96 x 72"), 120000);
        auto* table = window_->findChild<QTableWidget*>("metrics");
        QTRY_COMPARE(table->item(small, 0)->text(), QString("sizes differ"));
        QCOMPARE(table->item(small, 0)->toolTip(), QString("sizes differ: 16 x 12 against 96 x 72"));
        remove->click();

        window_->session().undoStack()->undo();
        for (int view = n + 1; view >= n; --view) {
            window_->selectView(view);
            remove->click();
        }
        QCOMPARE(int(window_->frames().size()), n);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
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
        window_->session().setExposure(0, 1.5);
        QVERIFY2(window_->session().save(&error), qPrintable(error));
        const QList<QByteArray> first = lines();
        QCOMPARE(changed(original, first),
                 (QList<QByteArray>{R"(    "width": 96,)", R"(    "height": 72)",
                                    R"(    {"name": "everything", "technique": "reference", "parameters": {"distanceSampling": "mis"}, "exposure": 1.5},)",
                                    R"(  "reference": {"mode": "single", "maxDepth": 16, "spp": 8, "seed": 1})"}));
        window_->session().setExposure(3, -0.5);  // "glow" gives no exposure: it is added on its line
        QVERIFY2(window_->session().save(&error), qPrintable(error));
        QCOMPARE(changed(first, lines()),
                 QList<QByteArray>{
                     R"(    {"name": "glow", "technique": "reference", "parameters": {"distanceSampling": "distance"}, "lights": ["lamp"], "media": ["fog"], "exposure": -0.5})"});
        QVERIFY(!window_->session().modified());
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // Ctrl+Y redoes (as well as Ctrl+Shift+Z), and two choices of an enumeration are two undo steps: undo goes back
    // to the first choice, not to the value before both.
    void redoesWithCtrlYAndKeepsChoicesApart() {
        QVERIFY(window_->openProject(kDefaultProject, false));
        window_->selectView(1);
        auto* estimator = window_->findChild<QComboBox*>("param:estimator");
        QVERIFY(estimator);
        const QString first = estimator->currentText();
        QStringList others;
        for (int i = 0; i < estimator->count(); ++i)
            if (estimator->itemText(i) != first) others << estimator->itemText(i);
        QVERIFY(others.size() >= 2);
        estimator->setCurrentText(others[0]);
        estimator->setCurrentText(others[1]);
        QUndoStack* undo = window_->session().undoStack();
        QCOMPARE(undo->count(), 2);
        undo->undo();
        QCOMPARE(window_->session().project().views[1].parameters["estimator"], nlohmann::json(others[0].toStdString()));
        QCOMPARE(estimator->currentText(), others[0]);
        window_->activateWindow();
        QVERIFY(QTest::qWaitForWindowActive(window_.get()));
        QTest::keyClick(window_.get(), Qt::Key_Y, Qt::ControlModifier);
        QCOMPARE(undo->index(), 2);
        QCOMPARE(window_->session().project().views[1].parameters["estimator"], nlohmann::json(others[1].toStdString()));
        undo->setIndex(0);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // Opening another project leaves nothing of the previous one: the inspector, the pdf plot, the snapshot Compare
    // button.
    void startsAnotherProjectClean() {
        QVERIFY(window_->openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        window_->setLayoutMode(Layout::Grid);
        window_->recompose();
        const QRect r = viewRects(window_->frames(), window_->compositorState(), window_->viewport()->pixelSize())[1];
        window_->inspect(QPointF(r.x() + r.width() * 0.5, r.y() + r.height() * 0.6));
        QVERIFY(window_->inspectorText().contains("pixel"));
        QTRY_VERIFY_WITH_TIMEOUT(window_->pdfPlot()->plot()->graphCount() > 0, 60000);
        window_->selectView(1);
        QCOMPARE(window_->takeSnapshot(), 0);
        auto* compare = window_->findChild<QPushButton*>("compareSnapshot");
        QVERIFY(compare);
        compare->setChecked(true);
        QVERIFY(window_->frames()[1].snapshot);
        // A probe still running when the project changes is not shown over the new one.
        window_->inspect(QPointF(r.x() + r.width() * 0.5, r.y() + r.height() * 0.6));
        QVERIFY(window_->openProject(TYNDALL_SOURCE_DIR "/projects/examples/reference-smoke.json", false));
        window_->waitForBackgroundWork();
        QCoreApplication::processEvents();
        QCOMPARE(int(window_->frames().size()), 1);
        QVERIFY(!window_->inspectorText().contains("pixel"));
        QCOMPARE(window_->pdfPlot()->plot()->graphCount(), 0);
        QVERIFY(!compare->isChecked());
        QVERIFY(window_->snapshots().empty());
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // The convergence plot's log axes are labelled at powers of ten, also when the points span less than a decade.
    void labelsLogAxesAtPowersOfTen() {
        ConvergencePlot plot;
        plot.resize(600, 400);
        plot.setSeries({"a"}, {{{4, 0.1, 0.02}, {6, 0.2, 0.013}, {8, 0.3, 0.011}}});
        plot.plot()->replot();
        for (QCPAxis* axis : {plot.plot()->xAxis, plot.plot()->yAxis}) {
            const QVector<double> ticks = axis->tickVector();
            QVERIFY(ticks.size() >= 2);
            for (double t : ticks)
                QVERIFY2(std::abs(std::log10(t) - std::round(std::log10(t))) < 1e-9, qPrintable(QString::number(t)));
        }
    }

    // Help and hidden state: F1 opens the shortcuts overlay, which lists every menu shortcut (Ctrl+Y among them) and
    // the mouse bindings; a Help menu holds it with the docs and the version; single-letter keys act while the Views
    // list has the focus (its keyboard search swallowed them) and the toolbar follows the layout; the status bar shows
    // the display exposure offset and the zoom; the Parameters dock names its exposure "view exposure".
    void helpsAndShowsHiddenState() {
        QVERIFY(window_->openProject(kDefaultProject, false));
        window_->activateWindow();
        QVERIFY(QTest::qWaitForWindowActive(window_.get()));
        QTest::keyClick(window_.get(), Qt::Key_F1);
        auto* overlay = window_->findChild<QDialog*>("shortcutsOverlay");
        QVERIFY(overlay);
        QTRY_VERIFY(overlay->isVisible());
        const QString text = window_->shortcutsText();
        int listed = 0;
        for (QAction* menu : window_->menuBar()->actions()) {
            QList<QAction*> actions = menu->menu()->actions();
            for (int i = 0; i < actions.size(); ++i) {
                if (actions[i]->menu()) actions += actions[i]->menu()->actions();
                for (const QKeySequence& k : actions[i]->shortcuts()) {
                    QVERIFY2(text.contains(k.toString(QKeySequence::NativeText).toHtmlEscaped()), qPrintable(k.toString()));
                    ++listed;
                }
            }
        }
        QVERIFY(listed >= 30);
        for (const char* s : {"Ctrl+Y", "Alt+drag", "Ctrl+wheel", "Frame the scene", "Swap the wipe"})
            QVERIFY2(text.contains(s), s);
        overlay->close();
        bool hasHelp = false;
        for (QAction* menu : window_->menuBar()->actions())
            hasHelp |= menu->text() == "&Help" && menu->menu()->actions().size() >= 3;
        QVERIFY(hasHelp);

        auto* list = window_->findChild<QListWidget*>("viewList");
        QVERIFY(list);
        list->setFocus();
        QTRY_VERIFY(list->hasFocus());
        const bool swapped = window_->compositorState().swapped;
        QTest::keyClick(list, Qt::Key_T);
        QCOMPARE(window_->compositorState().swapped, !swapped);
        QTest::keyClick(list, Qt::Key_T);
        QTest::keyClick(list, Qt::Key_E);
        QCOMPARE(window_->compositorState().exposureOffset, 0.5);
        auto* display = window_->findChild<QLabel*>("displayStatus");
        QVERIFY(display);
        QVERIFY2(display->text().contains("+0.5 EV"), qPrintable(display->text()));
        QTest::keyClick(list, Qt::Key_E, Qt::ShiftModifier);
        QCOMPARE(window_->compositorState().exposureOffset, 0.0);
        QTest::keyClick(list, Qt::Key_3);
        QCOMPARE(window_->compositorState().current, 2);
        QCOMPARE(window_->compositorState().layout, Layout::Single);
        QAction* single = nullptr;
        for (QAction* a : window_->findChildren<QAction*>())
            if (a->text() == "&Single") single = a;
        QVERIFY(single && single->isChecked());  // the toolbar follows the layout chosen by a key
        window_->compositorState().zoom = 2.0;
        window_->recompose();
        QVERIFY2(display->text().contains("zoom 2x"), qPrintable(display->text()));
        QTest::keyClick(list, Qt::Key_Z);
        QCOMPARE(window_->compositorState().zoom, 1.0);
        QTest::keyClick(list, Qt::Key_G);
        QCOMPARE(window_->compositorState().layout, Layout::Grid);
        QVERIFY(window_->findChild<QDoubleSpinBox*>("exposure"));
        bool named = false;
        for (QLabel* label : window_->findChildren<QLabel*>())
            named |= label->text() == "view exposure";
        QVERIFY(named);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // A wipe whose reference is not ready says so on its side (it was plain black), and so does its tile.
    void wipeSaysWhenTheReferenceIsNotReady() {
        auto image = std::make_shared<Image>(Image::rgb(48, 36));
        for (int y = 0; y < 36; ++y)
            for (int x = 0; x < 48; ++x)
                for (int c = 0; c < 3; ++c) image->at(x, y, c) = 0.5f;
        ViewFrame f;
        f.name = "v";
        f.technique = "t";
        f.image = image;
        f.referenceRendering = true;
        CompositorState state;
        state.layout = Layout::Split;
        const QImage frame = compose({f}, state, QSize(480, 400));
        const QRect r = viewRects({f}, state, frame.size())[0];
        const QImage right = frame.copy(QRect(r.center().x() + 4, r.y(), r.right() - r.center().x() - 4, r.height()));
        QVERIFY(distinctColours(right) > 2);  // text, not one colour
    }

    // The default layout gives the docks room: every row of the metrics table is visible, and the Scene dock shows
    // more than a couple of rows.
    void hasARoomyDefaultLayout() {
        MainWindow fresh(vulkan_, kSmall);
        fresh.setRecovery(MainWindow::Recovery::Never);
        fresh.show();
        QVERIFY(QTest::qWaitForWindowExposed(&fresh));
        QVERIFY(fresh.openProject(kDefaultProject, false));
        QTest::qWait(100);  // the default dock sizes are applied once the window is laid out
        auto* table = fresh.findChild<QTableWidget*>("metrics");
        QVERIFY(table && table->rowCount() == 4);
        QVERIFY2(table->rowViewportPosition(3) + table->rowHeight(3) <= table->viewport()->height(),
                 qPrintable(QString("%1 px for the rows").arg(table->viewport()->height())));
        QVERIFY2(fresh.findChild<QDockWidget*>("sceneDock")->height() >= 300,
                 qPrintable(QString::number(fresh.findChild<QDockWidget*>("sceneDock")->height())));
        QTRY_VERIFY_WITH_TIMEOUT(fresh.settled(), 120000);
    }

    // The window's size and dock layout come back on the next start (QSettings, saved on close).
    void restoresTheWindowLayout() {
        {
            MainWindow first(vulkan_, kSmall);
            first.show();
            QVERIFY(QTest::qWaitForWindowExposed(&first));
            first.resize(1100, 700);
            first.findChild<QDockWidget*>("snapshotsDock")->hide();
            QTRY_COMPARE(first.size(), QSize(1100, 700));
            QVERIFY(first.close());
        }
        MainWindow second(vulkan_, kSmall);
        QCOMPARE(second.size(), QSize(1100, 700));
        QVERIFY(second.findChild<QDockWidget*>("snapshotsDock")->isHidden());
        QVERIFY(!second.findChild<QDockWidget*>("metricsDock")->isHidden());
        QSettings().remove("window");
    }

    // File > Export runs in the background with a progress dialog, and lists every view: one whose reference is not
    // ready yet is exported alone and named in the notes (it was left out silently).
    void exportsInTheBackgroundListingEveryView() {
        QDir(MainWindow::referenceCacheFolder()).removeRecursively();
        QVERIFY(window_->openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(std::all_of(window_->frames().begin(), window_->frames().end(),
                                             [](const ViewFrame& f) { return bool(f.image); }),
                                 120000);
        QStringList waiting;
        for (const ViewFrame& f : window_->frames())
            if (!referencePair(f).against) waiting << f.name;
        const QString folder = QString(TYNDALL_TEST_TMP) + "/export-background";
        QDir(folder).removeRecursively();
        QSignalSpy finished(window_.get(), &MainWindow::exportFinished);
        window_->startExport(folder);
        QVERIFY(window_->findChild<QProgressDialog*>("exportProgress"));
        QTRY_COMPARE_WITH_TIMEOUT(finished.count(), 1, 120000);
        if (auto* report = window_->findChild<QMessageBox*>("exportReport")) {
            QVERIFY(!report->isModal());  // the studio goes on while it is open
            report->close();
        }
        QVERIFY2(finished[0][0].toBool(), qPrintable(finished[0][1].toString()));
        QFile json(folder + "/metrics.json");
        QVERIFY(json.open(QIODevice::ReadOnly));
        const nlohmann::json metrics = nlohmann::json::parse(json.readAll().toStdString());
        QCOMPARE(int(metrics.size()), int(window_->frames().size()));
        for (std::size_t i = 0; i < metrics.size(); ++i) {
            const QString name = window_->frames()[i].name;
            QCOMPARE(QString::fromStdString(metrics[i]["view"].get<std::string>()), name);
            QVERIFY(QFile::exists(folder + "/" + name + ".exr"));
            if (waiting.contains(name)) {
                QVERIFY(metrics[i].contains("missing"));
                QVERIFY(finished[0][1].toString().contains(name));
            }
        }
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // Shift+N makes view N every other view's reference: the convergence plot follows (it kept plotting against the
    // path-traced reference), its last point being the relMSE the metrics report against view N.
    void convergenceFollowsTheChosenReferenceView() {
        QVERIFY(window_->openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        auto lastPoint = [&](int view) {
            QCPGraph* graph = window_->convergencePlot()->plot()->graph(view);
            return graph && graph->dataCount() > 0 ? (graph->data()->constEnd() - 1)->value : -1.0;
        };
        const double againstReference = lastPoint(1);
        QVERIFY(againstReference > 0.0);
        window_->chooseReferenceView(0);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        const ViewFrame& f = window_->frames()[1];
        QVERIFY(f.alternate && f.metrics);
        const double last = lastPoint(1);
        QVERIFY2(std::abs(last - f.metrics->relMSE) <= 1e-6 * f.metrics->relMSE,
                 qPrintable(QString("plotted %1, metrics %2").arg(last).arg(f.metrics->relMSE)));
        QVERIFY(std::abs(last - againstReference) > 1e-6 * againstReference);
        window_->chooseReferenceView(-1);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QVERIFY(std::abs(lastPoint(1) - againstReference) <= 1e-6 * againstReference);
    }

    // Views are authored from the GUI: add (named after its technique, selected, rendered with its reference),
    // duplicate, rename (a taken name is refused with the reason), change the technique from the Parameters dock,
    // remove; each is one undo step, and undo brings the project back.
    void authorsViews() {
        QVERIFY(window_->openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        Session& session = window_->session();
        const int n = int(window_->frames().size());
        const nlohmann::json original = projectToJson(session.project());
        QString error;
        QVERIFY2(session.addView("wvds", &error), qPrintable(error));
        QCOMPARE(int(window_->frames().size()), n + 1);
        QCOMPARE(window_->findChild<QListWidget*>("viewList")->count(), n + 1);
        QCOMPARE(window_->compositorState().current, n);
        QCOMPARE(window_->frames()[std::size_t(n)].name, QString("wvds"));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QVERIFY(window_->frames()[std::size_t(n)].image && window_->frames()[std::size_t(n)].reference);

        QVERIFY2(session.duplicateView(1, &error), qPrintable(error));
        QCOMPARE(session.project().views[2].name, std::string("light shaft copy"));
        QCOMPARE(session.project().views[2].technique, session.project().views[1].technique);
        QVERIFY2(session.renameView(2, "shaft B", &error), qPrintable(error));
        QCOMPARE(window_->frames()[2].name, QString("shaft B"));
        QVERIFY(!session.renameView(2, "everything", &error));
        QVERIFY2(error.contains("everything"), qPrintable(error));

        window_->selectView(2);
        auto* technique = window_->findChild<QComboBox*>("technique");
        QVERIFY(technique);
        QCOMPARE(technique->currentText(), QString("wvds"));
        technique->setCurrentText("reference");
        QCoreApplication::processEvents();
        QCOMPARE(session.project().views[2].technique, std::string("reference"));
        QCOMPARE(window_->frames()[2].technique, window_->frames()[0].technique);

        QVERIFY2(session.removeView(0, &error), qPrintable(error));
        QCOMPARE(session.project().views[0].name, std::string("light shaft"));
        QCOMPARE(int(window_->frames().size()), n + 1);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        QCOMPARE(session.undoStack()->count(), 5);
        session.undoStack()->setIndex(0);
        QVERIFY(projectToJson(session.project()) == original);
        QCOMPARE(int(window_->frames().size()), n);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // The Parameters dock lists every light and medium of the scene for the view: the ones it renders checked, those
    // its technique cannot render disabled with the reason; toggling one is an undoable edit of the view's part that
    // renders the view (and its reference) again.
    void choosesAViewsLightsAndMedia() {
        QVERIFY(window_->openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        window_->selectView(1);  // the light shaft: sun and fog
        const Project& project = window_->session().project();
        const std::size_t elements = project.scene.pointLights.size() + project.scene.directionalLights.size() +
                                     project.scene.areaLights.size() + project.scene.media.size() +
                                     project.scene.particleMedia.size();
        auto partBoxes = [&] {
            QList<QCheckBox*> boxes;
            for (QCheckBox* b : window_->findChildren<QCheckBox*>())
                if (b->objectName().startsWith("part:")) boxes << b;
            return boxes;
        };
        QList<QCheckBox*> boxes = partBoxes();
        QCOMPARE(std::size_t(boxes.size()), elements);
        int disabled = 0;
        for (QCheckBox* b : boxes) {
            const bool own = b->objectName() == "part:sun" || b->objectName() == "part:fog";
            QCOMPARE(b->isChecked(), own);
            if (!b->isEnabled()) QVERIFY2(b->toolTip().contains("cannot render"), qPrintable(b->toolTip()));
            disabled += !b->isEnabled();
        }
        QVERIFY(disabled > 0);  // WVDS renders the sun and fog only

        window_->selectView(3);  // the glow, path traced: everything can be chosen
        boxes = partBoxes();
        QCheckBox* toggle = nullptr;
        for (QCheckBox* b : boxes)
            if (b->isEnabled() && !b->isChecked()) toggle = b;
        QVERIFY(toggle);
        const quint64 state = window_->frames()[3].state;
        const std::string name = toggle->objectName().mid(5).toStdString();
        toggle->setChecked(true);
        QCoreApplication::processEvents();
        const ScenePart part = *window_->session().project().views[3].part;
        QVERIFY(std::find(part.lights.begin(), part.lights.end(), name) != part.lights.end() ||
                std::find(part.media.begin(), part.media.end(), name) != part.media.end());
        QVERIFY(window_->frames()[3].state != state);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        window_->session().undoStack()->undo();
        QCoreApplication::processEvents();
        QVERIFY(!window_->findChild<QCheckBox*>(toggle->objectName())->isChecked());
        QCOMPARE(window_->frames()[3].state, state);
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    // The phase panel plots the media's phase functions (the selected view's first and bold) over cos theta and in
    // polar form: the curve is the phase function the renderers evaluate, normalised over the sphere, and it follows
    // a scene edit of g.
    void plotsThePhaseFunctions() {
        QVERIFY(window_->openProject(kDefaultProject, false));
        window_->selectView(1);  // the light shaft: fog
        PhasePlot* cosine = window_->phaseCosinePlot();
        PhasePlot* polar = window_->phasePolarPlot();
        const Project& project = window_->session().project();
        const int media = int(project.scene.media.size() + project.scene.particleMedia.size());
        QCOMPARE(int(cosine->curves().size()), media);
        QVERIFY(cosine->curves()[0].selected && cosine->curves()[0].name.startsWith("fog"));
        QCOMPARE(cosine->plot()->graphCount(), media);
        QCOMPARE(polar->plot()->plottableCount(), media);
        const PhaseFunction& fog = project.scene.media[0].phase;
        QCPGraph* graph = cosine->plot()->graph(0);
        QCOMPARE(graph->dataCount(), PhasePlot::kSamples);
        double integral = 0.0;  // 2 pi times the integral over mu, by the trapezoid rule
        for (int k = 0; k + 1 < graph->dataCount(); ++k) {
            const auto a = graph->data()->at(k), b = graph->data()->at(k + 1);
            integral += 0.5 * (a->value + b->value) * (b->key - a->key);
            QCOMPARE(a->value, phaseValue(fog, a->key));
        }
        // HG with g = 0.55 at 361 points: the trapezoid rule's error is ~1e-4 of the integral.
        QVERIFY2(std::abs(2.0 * std::numbers::pi * integral - 1.0) < 2e-3, qPrintable(QString::number(integral)));
        auto* forward = static_cast<QCPCurve*>(polar->plot()->plottable(0));
        QCOMPARE(forward->data()->at(0)->key, phaseValue(fog, 1.0));  // theta = 0: forward, on +x
        const double before = graph->data()->at(PhasePlot::kSamples - 1)->value;
        QString error;
        QVERIFY2(window_->session().editScene({"media[fog].phase.g=0.8"}, "g", &error), qPrintable(error));
        QVERIFY(cosine->plot()->graph(0)->data()->at(PhasePlot::kSamples - 1)->value > before);  // more forward
        window_->session().undoStack()->undo();
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
    }

    void cleanupTestCase() { window_.reset(); }

private:
    // Opens a fresh copy of the default project in TYNDALL_TEST_TMP/<folder> (no autosave of it to recover): its
    // path, or empty when it could not.
    QString openCopyOfTheDefaultProject(const QString& folder) {
        const QString dir = QString(TYNDALL_TEST_TMP) + "/" + folder;
        QDir(dir).removeRecursively();
        QDir().mkpath(dir);
        const QString path = dir + "/room.json";
        if (!QFile::copy(kDefaultProject, path)) return {};
        QFile::remove(MainWindow::autosavePath(path));
        window_->setRecovery(MainWindow::Recovery::Never);
        return window_->openProject(path, false) ? path : QString();
    }

    QVulkanInstance* vulkan_;
    std::unique_ptr<MainWindow> window_;
};

// The LTSD plots (issue 18, item 5), a short case of its own (Studio.LtsdPlots, `--ltsd-plots`): the selected view's
// medium's HG against its fit, sampled from the table as ltsdPolarCurve samples it, the fit in two pieces that leave
// the horizon's jump open, the error over g with the medium's g marked, a message (not an empty plot) for a phase
// function without a table and for a missing or corrupt table, and exports; checked on the drawn pixels as well.
class LtsdPlotsTest : public QObject {
    Q_OBJECT
public:
    explicit LtsdPlotsTest(QVulkanInstance* vulkan) : vulkan_(vulkan) {}

private:
    // Is a pixel of about `colour` within `radius` pixels of `at`? (Antialiased lines: the core keeps the colour.)
    static bool colourNear(const QImage& image, QPointF at, const QColor& colour, int radius) {
        for (int dy = -radius; dy <= radius; ++dy)
            for (int dx = -radius; dx <= radius; ++dx) {
                const int x = int(std::lround(at.x())) + dx, y = int(std::lround(at.y())) + dy;
                if (x < 0 || y < 0 || x >= image.width() || y >= image.height()) continue;
                const QColor c = image.pixelColor(x, y);
                if (std::abs(c.red() - colour.red()) <= 30 && std::abs(c.green() - colour.green()) <= 30 &&
                    std::abs(c.blue() - colour.blue()) <= 30)
                    return true;
            }
        return false;
    }

    // The plot on screen, drawn now: its tab is made current and it replots at once.
    QImage drawn(Plot* plot) {
        auto* tabs = window_->plots()->findChild<QTabWidget*>();
        tabs->setCurrentWidget(plot);
        QCoreApplication::processEvents();
        plot->plot()->replot(QCustomPlot::rpImmediateRefresh);
        QCoreApplication::processEvents();  // a queued replot after a change of the axes' ranges (keepSquare)
        plot->plot()->replot(QCustomPlot::rpImmediateRefresh);
        const QImage image = plot->plot()->grab().toImage();
        image.save(QString(TYNDALL_TEST_TMP) + "/" + plot->name() + "-drawn.png");  // to look at when a check fails
        return image;
    }

    static QPointF pixelOf(QCustomPlot* plot, double x, double y) {
        return QPointF(plot->xAxis->coordToPixel(x), plot->yAxis->coordToPixel(y));
    }

    LtsdTable table_;

private slots:
    void initTestCase() {
        QDir(QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave").removeRecursively();
        QSettings().remove("window");
        window_ = std::make_unique<MainWindow>(vulkan_, kSmall);
        window_->resize(1400, 950);
        window_->show();
        QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
        // A tall Plots dock, so that the polar plot's curves are apart by more than their width in most places.
        auto* dock = window_->findChild<QDockWidget*>("plotsDock");
        QVERIFY(dock);
        window_->resizeDocks({dock}, {560}, Qt::Vertical);
        QVERIFY(window_->openProject(kDefaultProject, false));
        table_ = loadLtsdTable(ltsdTablePath("hg"));
    }

    // The light shaft's fog at g = 0.6: every point of HG and of the fit is ltsdPolarCurve's at its psi, on the
    // plot's radius scale; the fit's pieces stay in their hemispheres and jump at the horizon; the caption quotes g
    // and the error there; the pixels show both curves where the data puts them and no line across the jump.
    void drawsThePhaseFunctionAgainstItsFit() {
        window_->selectView(1);
        QString error;
        QVERIFY2(window_->session().editScene({"media[fog].phase.g=0.6"}, "g", &error), qPrintable(error));
        LtsdPolarPlot* polar = window_->ltsdPolarPlot();
        QVERIFY2(polar->fit().table, qPrintable(polar->caption()));
        QCOMPARE(polar->fit().g, 0.6);
        QCOMPARE(polar->fit().view, QString("light shaft"));
        QVERIFY(polar->logRadius());  // the default: HG spans decades

        const std::vector<LtsdPolarPoint> curve = ltsdPolarCurve(table_, 0.6, LtsdPolarPlot::kSamples);
        QCPCurve *hg = polar->phaseCurve(), *upper = polar->fitUpperCurve(), *lower = polar->fitLowerCurve();
        QVERIFY(hg && upper && lower);
        QCOMPARE(hg->dataCount(), LtsdPolarPlot::kSamples + 1);  // closed
        QCOMPARE(upper->dataCount() + lower->dataCount(), LtsdPolarPlot::kSamples);
        auto radius = [](const QCPCurveData& d) { return std::hypot(d.key, d.value); };
        for (int k = 0; k < LtsdPolarPlot::kSamples; k += 37) {
            const LtsdPolarPoint& p = curve[std::size_t(k)];
            const QCPCurveData h = *hg->data()->at(k);
            QCOMPARE(h.t, p.psi);
            QVERIFY(std::abs(radius(h) - polar->radiusOf(p.phase)) < 1e-9);
            QVERIFY(std::abs(std::atan2(h.key, h.value) - std::atan2(std::sin(p.psi), std::cos(p.psi))) < 1e-9);
            const bool up = std::cos(p.psi) > 0.0;
            const double t = up && p.psi > std::numbers::pi ? p.psi - 2.0 * std::numbers::pi : p.psi;
            QCPCurve* piece = up ? upper : lower;
            auto it = piece->data()->findBegin(t, false);
            QVERIFY(it != piece->data()->constEnd());
            QCOMPARE(it->t, t);
            QVERIFY2(std::abs(radius(*it) - polar->radiusOf(p.fitted)) < 1e-9, qPrintable(QString::number(k)));
        }
        // Each piece in its own hemisphere (y = cos psi > 0 is the upper), none across the horizon.
        for (auto it = upper->data()->constBegin(); it != upper->data()->constEnd(); ++it)
            QVERIFY(std::cos(it->t) > 0.0 && it->value >= 0.0);
        for (auto it = lower->data()->constBegin(); it != lower->data()->constEnd(); ++it)
            QVERIFY(std::cos(it->t) < 0.0 && it->value <= 0.0);
        // The jump: the fit's values just above and just below the horizon differ (the paper's Fig. 12 shows it).
        const double above = curve[LtsdPolarPlot::kSamples / 4 - 1].fitted, below = curve[LtsdPolarPlot::kSamples / 4].fitted;
        QVERIFY2(std::abs(above - below) > 0.2 * std::max(above, below),
                 qPrintable(QString("%1 %2").arg(above).arg(below)));
        const LtsdFitError err = ltsdFitErrorAt(table_, 0.6);
        QVERIFY2(polar->caption().contains("g = 0.600"), qPrintable(polar->caption()));
        QVERIFY2(polar->caption().contains(QString::number(err.bound, 'e', 2)), qPrintable(polar->caption()));
        QVERIFY(polar->title().contains(QString::number(err.bound, 'e', 1)));

        // The pixels: orange where HG is, blue where the fit is (dashed: within a dash's gap), in both hemispheres.
        const QImage image = drawn(polar);
        QCustomPlot* plot = polar->plot();
        // Where the two curves come within a few pixels of each other the one drawn last hides the other: those
        // points are left out (and counted).
        int checked = 0, upperChecked = 0, lowerChecked = 0;
        for (int k = 3; k < LtsdPolarPlot::kSamples; k += 6) {
            const LtsdPolarPoint& p = curve[std::size_t(k)];
            const QCPCurveData h = *hg->data()->at(k);
            const double r = polar->radiusOf(p.fitted);
            const QPointF atHg = pixelOf(plot, h.key, h.value), atFit = pixelOf(plot, r * std::sin(p.psi), r * std::cos(p.psi));
            if (QLineF(atHg, atFit).length() < 6.0 || r < 0.05) continue;
            QVERIFY2(colourNear(image, atHg, LtsdPolarPlot::phaseColour(), 2), qPrintable(QString("HG at point %1").arg(k)));
            QVERIFY2(colourNear(image, atFit, LtsdPolarPlot::fitColour(), 6), qPrintable(QString("fit at point %1").arg(k)));
            ++checked;
            (std::cos(p.psi) > 0.0 ? upperChecked : lowerChecked)++;
        }
        QVERIFY2(upperChecked >= 3 && lowerChecked >= 3, qPrintable(QString("%1 %2").arg(upperChecked).arg(lowerChecked)));
        // No line across the jump: the segment that would join the fit's ends at the horizon carries no blue where it
        // is clear of both pieces (at g = 0.6 the lower piece starts at the centre, as its source vanishes at the
        // horizon, and leaves it close to the horizon: the clearest point of the segment is taken).
        const QPointF a = pixelOf(plot, (upper->data()->constEnd() - 1)->key, (upper->data()->constEnd() - 1)->value);
        const QPointF b = pixelOf(plot, lower->data()->constBegin()->key, lower->data()->constBegin()->value);
        QVERIFY2(QLineF(a, b).length() > 20.0, qPrintable(QString::number(QLineF(a, b).length())));
        auto distanceToPiece = [&](QCPCurve* piece, QPointF m) {
            double d = 1e300;
            for (auto it = piece->data()->constBegin(); it + 1 != piece->data()->constEnd(); ++it) {
                const QPointF p = pixelOf(plot, it->key, it->value), q = pixelOf(plot, (it + 1)->key, (it + 1)->value);
                const QPointF pq = q - p;
                const double len2 = QPointF::dotProduct(pq, pq);
                const double s = len2 > 0.0 ? std::clamp(QPointF::dotProduct(m - p, pq) / len2, 0.0, 1.0) : 0.0;
                d = std::min(d, QLineF(m, p + s * pq).length());
            }
            return d;
        };
        QPointF clearest;
        double clearance = 0.0;
        for (double f = 0.05; f < 0.96; f += 0.05) {
            const QPointF m = a + f * (b - a);
            const double d = std::min(distanceToPiece(upper, m), distanceToPiece(lower, m));
            if (d > clearance) {
                clearance = d;
                clearest = m;
            }
        }
        QVERIFY2(clearance >= 5.0, qPrintable(QString::number(clearance)));
        QVERIFY(!colourNear(image, clearest, LtsdPolarPlot::fitColour(), 1));
        bool horizonThere = false;  // the horizon itself is drawn there: grey
        for (int dy = -2; dy <= 2; ++dy) {
            const QColor c = image.pixelColor(int(std::lround(clearest.x())), int(std::lround(clearest.y())) + dy);
            horizonThere |= std::abs(c.red() - c.green()) < 10 && std::abs(c.green() - c.blue()) < 10 && c.red() < 200;
        }
        QVERIFY(horizonThere);

        // What a scene edit costs the plots (reported, not asserted: no timed tests).
        QElapsedTimer timer;
        timer.start();
        for (int i = 0; i < 10; ++i) {
            polar->showFit(polar->fit());
            window_->ltsdErrorPlot()->showFit(polar->fit());
        }
        qInfo("LTSD plots: %.2f ms per update of both (data and items; the replot is queued)", timer.nsecsElapsed() / 1e7);

        // Linear radius: the radius is the value.
        polar->setLogRadius(false);  // the curves are drawn again: new QCPCurves
        QVERIFY(std::abs(radius(*polar->phaseCurve()->data()->at(0)) - curve[0].phase) < 1e-12);
        const QCPCurveData forward = *polar->phaseCurve()->data()->at(LtsdPolarPlot::kSamples / 2);  // psi ~ pi: HG's peak
        QVERIFY(forward.value < 0.0);
        const QImage linear = drawn(polar);  // first: drawing settles the axes' ranges that pixelOf reads
        QVERIFY(colourNear(linear, pixelOf(polar->plot(), forward.key, forward.value), LtsdPolarPlot::phaseColour(), 2));
        polar->setLogRadius(true);
    }

    // The error plot: the table's error over g, the medium's g marked, and the marker follows an edit of g.
    void marksTheMediumsGOnTheErrorPlot() {
        LtsdErrorPlot* plot = window_->ltsdErrorPlot();
        QVERIFY(plot->boundGraph());
        QCOMPARE(plot->boundGraph()->dataCount(), LtsdTables::kErrorSamples);
        QVERIFY(plot->marker());
        QCOMPARE(plot->marker()->point1->key(), 0.6);
        QCOMPARE(plot->markedG(), 0.6);
        const std::vector<LtsdFitError> curve = ltsdFitErrorCurve(table_, LtsdTables::kErrorSamples);
        QCOMPARE(plot->boundGraph()->data()->at(50)->value, curve[50].bound);
        const QImage image = drawn(plot);
        const QPointF at = pixelOf(plot->plot(), 0.6, ltsdFitErrorAt(table_, 0.6).bound);
        QVERIFY(colourNear(image, at, Qt::black, 4));  // the marked point
        QString error;
        QVERIFY2(window_->session().editScene({"media[fog].phase.g=-0.3"}, "g", &error), qPrintable(error));
        QCOMPARE(plot->marker()->point1->key(), -0.3);
        QCOMPARE(window_->ltsdPolarPlot()->fit().g, -0.3);
        window_->selectView(2);  // another view of the same medium
        QCOMPARE(window_->ltsdPolarPlot()->fit().view, QString("area light"));
    }

    // A phase function without a table: a message naming it and the tables there are, no curves; back with undo.
    void explainsAPhaseFunctionWithoutATable() {
        QString error;
        QVERIFY2(window_->session().editScene({"media[fog].phase={\"type\":\"legendre\",\"coefficients\":[1,0.5]}"},
                                              "phase", &error),
                 qPrintable(error));
        LtsdPolarPlot* polar = window_->ltsdPolarPlot();
        QVERIFY2(polar->caption().contains("No LTSD table for legendre"), qPrintable(polar->caption()));
        QVERIFY2(polar->caption().contains("tables exist for: hazy-mie, hg, murky-mie, rayleigh"),
                 qPrintable(polar->caption()));
        QCOMPARE(polar->title(), polar->caption());  // in the exports, too
        QVERIFY(!polar->phaseCurve());
        QCOMPARE(polar->plot()->plottableCount(), 0);
        const QImage shown = drawn(polar);  // no curve on screen: not a stale one, nor one of another medium
        int curvePixels = 0;
        for (int y = 0; y < shown.height(); y += 2)
            for (int x = 0; x < shown.width(); x += 2)
                curvePixels += colourNear(shown, QPointF(x, y), LtsdPolarPlot::phaseColour(), 0) ||
                               colourNear(shown, QPointF(x, y), LtsdPolarPlot::fitColour(), 0);
        QCOMPARE(curvePixels, 0);
        QVERIFY(window_->ltsdErrorPlot()->caption().contains("No LTSD table for legendre"));
        QVERIFY(!window_->ltsdErrorPlot()->marker());
        window_->session().undoStack()->undo();
        QVERIFY(polar->phaseCurve());
    }

    // A corrupt or missing table: the loader's error, naming the file, on both plots; nothing crashes.
    void showsTheLoadersErrorForABadTable() {
        const QString dir = QString(TYNDALL_TEST_TMP) + "/ltsd-bad-table";
        QDir(dir).removeRecursively();
        QVERIFY(QDir().mkpath(dir));
        QFile good(QString::fromStdString(ltsdTablePath("hg").string()));
        QVERIFY(good.open(QIODevice::ReadOnly));
        QFile bad(dir + "/hg.ltsd");
        QVERIFY(bad.open(QIODevice::WriteOnly));
        bad.write(good.read(good.size() / 2));  // truncated
        bad.close();
        window_->setLtsdTablesDirectory(dir);
        LtsdPolarPlot* polar = window_->ltsdPolarPlot();
        QVERIFY2(polar->caption().startsWith("Cannot read the LTSD table of hg: ") &&
                     polar->caption().contains(dir + "/hg.ltsd"),
                 qPrintable(polar->caption()));
        QVERIFY(!polar->phaseCurve());
        QVERIFY(window_->ltsdErrorPlot()->caption().contains(dir + "/hg.ltsd"));
        QFile::remove(dir + "/hg.ltsd");
        window_->setLtsdTablesDirectory(dir);
        QVERIFY2(polar->caption().contains("cannot open"), qPrintable(polar->caption()));
        window_->setLtsdTablesDirectory("");
        QVERIFY(polar->phaseCurve());
    }

    // Both plots export to non-empty PNG and SVG, alone and with File > Export's plots.
    void exportsPngAndSvg() {
        const QString dir = QString(TYNDALL_TEST_TMP) + "/ltsd-export";
        QDir(dir).removeRecursively();
        QVERIFY(QDir().mkpath(dir));
        for (Plot* plot : {static_cast<Plot*>(window_->ltsdPolarPlot()), static_cast<Plot*>(window_->ltsdErrorPlot())}) {
            for (const char* suffix : {".png", ".svg"}) {
                const QString path = dir + "/" + plot->name() + suffix;
                QString why;
                QVERIFY2(plot->exportTo(path, &why), qPrintable(why));
                QVERIFY2(QFile(path).size() > 1000, qPrintable(path));
            }
            const QImage png(dir + "/" + plot->name() + ".png");
            QVERIFY(png.width() >= 640 && png.height() >= 420);
            QVERIFY(distinctColours(png) > 10);
            QFile svg(dir + "/" + plot->name() + ".svg");
            QVERIFY(svg.open(QIODevice::ReadOnly));
            const QByteArray text = svg.readAll();
            QVERIFY(text.contains("<svg"));
        }
        QCOMPARE(window_->plots()->plots().size(), std::size_t(6));  // File > Export writes every plot
    }

    void cleanupTestCase() {
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 120000);
        window_.reset();
    }

private:
    QVulkanInstance* vulkan_;
    std::unique_ptr<MainWindow> window_;
};

// The particle simulation driven from the studio (issue 20, item 6), a case of its own (Studio.Animation,
// `--animation`) on the bundled smoke cloud, small, with one ISV view and the path tracer as a (progressive) view: play
// advances the steps only as the views follow and shows a moving cloud, undo takes the whole play back, a Ctrl+click
// pushes the particles under the cursor, Ctrl+Shift+drag and the Scene dock move the targets, reset goes back to the
// start, and a saved frame is the one on screen (loadProject, and a render of the file equals the studio's image).
class AnimationTest : public QObject {
    Q_OBJECT
public:
    explicit AnimationTest(QVulkanInstance* vulkan) : vulkan_(vulkan) {}

private:
    const ParticleMedium& smoke() const { return window_->session().project().scene.particleMedia.at(0); }
    int steps() const { return smoke().simulation ? smoke().simulation->steps : 0; }
    // The ISV view's final image of the current state (waits up to 2 minutes for it; null if none came).
    std::shared_ptr<const Image> currentIsv() {
        QElapsedTimer clock;
        clock.start();
        while (clock.elapsed() < 120000) {
            const ViewFrame& f = window_->frames()[0];
            if (f.image && f.imageState == f.state && !f.rendering) return f.image;
            QTest::qWait(20);
        }
        return nullptr;
    }
    QPoint isvCentre() const {
        const QRect r = viewRects(window_->frames(), window_->compositorState(), window_->viewport()->pixelSize())[0];
        return r.center();
    }
    void shoot(const QString& name) {
        window_->recompose();
        const QImage frame = window_->composedFrame();
        frame.save(QString(TYNDALL_TEST_TMP) + "/animation-" + name + ".png");  // to look at
        QVERIFY2(distinctColours(frame) > 50, qPrintable(name));
    }

private slots:
    void initTestCase() {
        QDir(QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave").removeRecursively();
        QSettings().remove("window");
        QDir().mkpath(TYNDALL_TEST_TMP);
        std::vector<std::string> overrides = kSmall;
        overrides.push_back(R"(views=[{"name": "isv", "technique": "isv"}, {"name": "path traced", "technique": "reference"}])");
        window_ = std::make_unique<MainWindow>(vulkan_, overrides);
        window_->show();
        QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
        QVERIFY(window_->openProject(kSmoke, false));
        QVERIFY(!smoke().simulation);
        QVERIFY(window_->findChild<QAction*>("playAnimation")->isEnabled());
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 240000);
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
        QTRY_VERIFY_WITH_TIMEOUT(window_->settled(), 240000);
    }

    // P plays: the steps grow at the wall clock's rate, but only as the views deliver their frames (the ISV view shows
    // several states, each a different picture); P pauses; one undo takes the whole play back.
    void playAdvancesAsTheViewsFollow() {
        // The targets moved to the right: the particles start at rest at their places and drift after them. (At step 0
        // nothing has moved yet: the same picture.)
        const std::shared_ptr<const Image> still = currentIsv();
        QString error;
        QVERIFY2(window_->animation().setOffset(0, Vec3(0.6, 0.0, 0.0), &error), qPrintable(error));
        QCOMPARE(steps(), 0);
        const std::shared_ptr<const Image> start = currentIsv();
        QVERIFY(still && start && samePixels(*still, *start));
        shoot("before-play");
        const int undoBefore = window_->session().undoStack()->count();
        QElapsedTimer clock;
        clock.start();
        QTest::keyClick(window_->viewport(), Qt::Key_P);
        QVERIFY(window_->animation().playing());
        QVERIFY(window_->findChild<QAction*>("playAnimation")->isChecked());
        // Every ISV image of a new state that arrives while playing.
        std::vector<std::shared_ptr<const Image>> images;
        std::vector<int> stepsSeen;
        std::set<quint64> states;
        while (images.size() < 3 && clock.elapsed() < 180000) {
            QTest::qWait(10);
            const ViewFrame& f = window_->frames()[0];
            if (f.image && f.image != start && f.imageState == f.state && !states.count(f.imageState)) {
                states.insert(f.imageState);
                images.push_back(f.image);
                stepsSeen.push_back(steps());
                if (images.size() == 2) shoot("playing");
            }
        }
        QTest::keyClick(window_->viewport(), Qt::Key_P);
        const double seconds = clock.elapsed() * 1e-3;
        QVERIFY(!window_->animation().playing());
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
        QCOMPARE(window_->session().undoStack()->count(), undoBefore + 1);
        window_->session().undoStack()->undo();
        QCOMPARE(steps(), 0);
        const std::shared_ptr<const Image> undone = currentIsv();
        QVERIFY(undone && samePixels(*undone, *start));  // the same frame again (ISV is deterministic)
        window_->session().undoStack()->redo();
        QCOMPARE(steps(), played);
    }

    // A Ctrl+click on the ISV view adds one impulse at the current step, on the camera ray through the pixel inside the
    // cloud, and steps once with it: the particles near it are pushed away, those beyond its radius move as without it.
    void ctrlClickAddsAnImpulse() {
        QTest::keyClick(window_->viewport(), Qt::Key_1);  // the ISV view alone: a large target
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
        QCOMPARE(steps(), s + 1);
        QCOMPARE(impulse.radius, window_->animation().impulseRadius());
        QCOMPARE(impulse.speed, window_->animation().impulseSpeed());
        for (int c = 0; c < 3; ++c)
            QVERIFY2(impulse.position[c] > lo[c] && impulse.position[c] < hi[c], qPrintable(QString::number(c)));
        // On the ray through the clicked pixel, and at a particle (the ray meets the cloud there).
        int view;
        QPoint pixel;
        QVERIFY(window_->viewAt(at, view, pixel));
        bool hit = false;
        const std::optional<Vec3> expected =
            impulsePoint(window_->session().project().scene.camera, rest, pixel.x() + 0.5, pixel.y() + 0.5, &hit);
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
                ++near;
                QVERIFY(glm::length(pushed[i].centre - impulse.position) > glm::length(unpushed[i].centre - impulse.position));
            } else if (d >= impulse.radius) {
                ++far;
                QVERIFY(pushed[i].centre == unpushed[i].centre);
            }
        }
        QVERIFY2(near > 10 && far > 10, qPrintable(QString("%1 %2").arg(near).arg(far)));
        const std::shared_ptr<const Image> after = currentIsv();
        QVERIFY(before && after && !samePixels(*after, *before));
        shoot("impulse");
        // One undo step.
        window_->session().undoStack()->undo();
        QCOMPARE(smoke().simulation->impulses.size(), impulsesBefore);
        QCOMPARE(steps(), s);
        window_->session().undoStack()->redo();
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
        window_->session().undoStack()->undo();  // the drag is one edit
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
        QVERIFY2(window_->saveProjectAs(path, &error), qPrintable(error));
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
        window_->session().undoStack()->undo();
        QCOMPARE(steps(), s);
        window_->session().undoStack()->redo();
        QCOMPARE(steps(), 0);
    }

    void cleanupTestCase() { window_.reset(); }

private:
    const QString kSmoke = TYNDALL_SOURCE_DIR "/projects/isv/smoke.json";
    QVulkanInstance* vulkan_;
    std::unique_ptr<MainWindow> window_;
};

int main(int argc, char** argv) {
    QApplication app(argc, argv);
    QStandardPaths::setTestModeEnabled(true);  // settings and autosaves in a test location, not the user's
    QApplication::setOrganizationName("Tyndall");
    QApplication::setApplicationName("Tyndall Studio tests");
    QDir(MainWindow::referenceCacheFolder()).removeRecursively();  // every run renders its references once
    QVulkanInstance vulkan;
    vulkan.setApiVersion(QVersionNumber(1, 2));
    if (!vulkan.create()) {
        std::fprintf(stderr, "no Vulkan instance: %d\n", vulkan.errorCode());
        return 1;
    }
    // `--ltsd-plots` runs the LTSD plots' short case (Studio.LtsdPlots) instead of the GUI flows.
    std::vector<char*> args(argv, argv + argc);
    const auto ltsd = std::find_if(args.begin(), args.end(), [](const char* a) { return std::strcmp(a, "--ltsd-plots") == 0; });
    if (ltsd != args.end()) {
        args.erase(ltsd);
        LtsdPlotsTest test(&vulkan);
        return QTest::qExec(&test, int(args.size()), args.data());
    }
    const auto animation =
        std::find_if(args.begin(), args.end(), [](const char* a) { return std::strcmp(a, "--animation") == 0; });
    if (animation != args.end()) {
        args.erase(animation);
        AnimationTest test(&vulkan);
        return QTest::qExec(&test, int(args.size()), args.data());
    }
    StudioTest test(&vulkan);
    return QTest::qExec(&test, argc, argv);
}

#include "test_studio.moc"
