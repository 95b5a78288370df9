// What the viewport shows and how: the default project on screen, tonemaps, layouts, the wipe and its differences,
// captions in narrow tiles, help and the state the display hides, the default and restored window layout.
#include "gui_test.h"

namespace tyndall::studio::gui {

class ViewingTest final : public FlowCase {
    Q_OBJECT
public:
    using FlowCase::FlowCase;

private:
    // At the first start's size (issue 33, problem 11): the Scene dock's rows fit its width, each field wide enough for
    // its value, with no horizontal scroll bar (the default project, and motion.json's vec3-heavy simulation); each
    // plot's caption sits under its plot, never over it (the ltsd-polar caption covered the axis label and the lower
    // lobe), and the polar plot's curves lie inside its axes.
    void docksFitAtTheirDefaultSize(MainWindow& window) {
        for (const QString& project :
             {QString(kDefaultProject), QString(TYNDALL_SOURCE_DIR "/projects/isv/motion.json")}) {
            QVERIFY(window.openProject(project, false));
            QTest::qWait(500);  // the dock's rebuild and layout are queued
            auto* scroll = window.findChild<ScenePanel*>()->findChild<QScrollArea*>();
            QVERIFY(scroll && scroll->isVisible());
            QVERIFY2(!scroll->horizontalScrollBar()->isVisible(), qPrintable(project));
            int fields = 0;
            for (auto* spin : scroll->findChildren<QDoubleSpinBox*>()) {
                if (!spin->isVisible()) continue;
                ++fields;
                const int text = spin->fontMetrics().horizontalAdvance(spin->text());
                QVERIFY2(spin->width() >= text + 6, qPrintable(spin->objectName() + ": " + spin->text()));
                const QRect inViewport(spin->mapTo(scroll->viewport(), QPoint(0, 0)), spin->size());
                QVERIFY2(inViewport.right() < scroll->viewport()->width(), qPrintable(spin->objectName()));
            }
            QVERIFY(fields > 10);
        }
        QVERIFY(window.openProject(kDefaultProject, false));
        window.studio().selectView(1);  // the light shaft: its fog's HG and the LTSD fit
        auto* tabs = window.plots()->findChild<QTabWidget*>();
        for (int i = 0; i < tabs->count(); ++i) {
            tabs->setCurrentIndex(i);
            QCoreApplication::processEvents();
            auto* plot = static_cast<Plot*>(tabs->widget(i));
            auto* caption = plot->findChild<QScrollArea*>("caption:" + plot->name());
            QVERIFY(caption);
            const QRect plotArea(plot->plot()->mapTo(plot, QPoint(0, 0)), plot->plot()->size());
            const QRect captionArea(caption->mapTo(plot, QPoint(0, 0)), caption->size());
            QVERIFY2(!plotArea.intersects(captionArea) && plotArea.height() >= 150,
                     qPrintable(QString("%1: plot %2 px high, bottom %3, caption top %4")
                                    .arg(plot->name())
                                    .arg(plotArea.height())
                                    .arg(plotArea.bottom())
                                    .arg(captionArea.top())));
            if (plot->name() != "ltsd-polar") continue;
            plot->plot()->replot(QCustomPlot::rpImmediateRefresh);
            QCoreApplication::processEvents();
            const QCPRange x = plot->plot()->xAxis->range(), y = plot->plot()->yAxis->range();
            int points = 0;
            for (int p = 0; p < plot->plot()->plottableCount(); ++p)
                if (auto* curve = qobject_cast<QCPCurve*>(plot->plot()->plottable(p)))
                    for (const QCPCurveData& d : *curve->data()) {
                        ++points;
                        QVERIFY2(x.contains(d.key) && y.contains(d.value),
                                 qPrintable(QString("(%1, %2) outside the axes").arg(d.key).arg(d.value)));
                    }
            QVERIFY(points > 100);
        }
    }

private slots:
    void initTestCase() { startOnTheDefaultProject(); }

    // The first start fills most of the screen (issue 33: a 1024 x 640 window with 190 x 135 tiles on a 1600 x 1000
    // screen), and a window saved off the screen comes back whole on it, its status bar included.
    void startsLargeAndStaysOnTheScreen() {
        QSettings().remove("window");
        {
            MainWindow first(vulkan_, kSmall);
            first.show();
            QVERIFY(QTest::qWaitForWindowExposed(&first));
            const QRect available = first.screen()->availableGeometry();
            QVERIFY2(first.width() >= 0.8 * available.width() && first.height() >= 0.8 * available.height(),
                     qPrintable(QString("%1 x %2").arg(first.width()).arg(first.height())));
            docksFitAtTheirDefaultSize(first);
            first.move(available.right() - 100, available.bottom() - 100);  // mostly off the screen
            QCoreApplication::processEvents();
            first.close();  // saves its geometry
        }
        MainWindow again(vulkan_, kSmall);
        again.show();
        QVERIFY(QTest::qWaitForWindowExposed(&again));
        const QRect available = again.screen()->availableGeometry();
        const QRect status(again.statusBar()->mapToGlobal(QPoint(0, 0)), again.statusBar()->size());
        QVERIFY2(available.contains(status),
                 qPrintable(QString("status bar at %1,%2").arg(status.x()).arg(status.y())));
        QSettings().remove("window");
    }

    // Every view rendered with its reference; the viewport presented the composed frame, and a screenshot of it shows
    // the same picture (Qt 6.4's grab of a BGRA swapchain swaps red and blue: either order is accepted).
    void startsOnTheDefaultProject() {
        const auto& frames = window_->studio().frames();
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
            // HDR-FLIP, computed after the metrics in the background, of the same pair once the studio settled.
            const ViewFrame& f = frames[std::size_t(row)];
            QVERIFY2(f.flip && f.flipImage == f.metricsImage && f.flipAgainst == f.metricsAgainst, qPrintable(f.name));
            QCOMPARE(table->item(row, 2)->text(), QString::number(*f.flip, 'g', 3));
            QCOMPARE(table->horizontalHeaderItem(2)->text(), QString("FLIP"));
        }
        QTRY_VERIFY(window_->viewport()->framesPresented() > 0);
        window_->studio().recompose();
        QVERIFY(distinctColours(window_->studio().composedFrame()) > 50);

        QTRY_VERIFY(window_->viewport()->framesPresented() > 1);
        const QImage shot = window_->viewport()->grab();
        const QImage composed = window_->studio().composedFrame();
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

    // The display transform (the toolbar's Display box, View > Display, M cycles) changes every view's display: the
    // shipped OpenColorIO config's displays and views, then Tyndall's own operators. What the viewport shows at a
    // pixel is the transform of the view's image there (DisplayTransform::apply, which the library's tests check
    // against the closed forms), and false colour adds its colour bar.
    void displayTransformsTheViewport() {
        window_->studio().setLayoutMode(Layout::Single);
        window_->studio().selectView(0);
        auto* combo = window_->findChild<QComboBox*>("display");
        QVERIFY(combo);
        const std::vector<DisplayTransform>& transforms = window_->studio().displayTransforms();
        QCOMPARE(transforms.size(), std::size_t(6 + tonemapNames().size()));  // sRGB and Rec.1886 x 3 views, ours
        // The config's default display and view to start with.
        QCOMPARE(QString::fromStdString(window_->studio().compositorState().displayTransform.name()),
                 QString("sRGB / Standard"));
        QCOMPARE(combo->currentText(), QString("sRGB / Standard"));
        auto* menu = window_->findChild<QMenu*>("displayMenu");
        QVERIFY(menu);
        QStringList menuDisplays;
        for (QAction* a : menu->actions())
            if (a->menu()) menuDisplays << a->text();
        QCOMPARE(menuDisplays, QStringList({"sRGB", "Rec.1886"}));
        const ViewFrame& f = window_->studio().frames()[0];
        std::map<std::string, QImage> frames;
        for (int item = 0; item < combo->count(); ++item) {
            if (!combo->itemData(item).isValid()) continue;  // the separator before Tyndall's operators
            combo->setCurrentIndex(item);
            const int index = combo->itemData(item).toInt();
            QCOMPARE(window_->studio().displayTransformIndex(), index);
            const DisplayTransform& transform = transforms[std::size_t(index)];
            const QImage frame = window_->studio().composedFrame();
            // (False colour keeps a strip free for its colour bar: the view's place depends on the operator.)
            const QPoint at =
                viewRects(window_->studio().frames(), window_->studio().compositorState(), frame.size())[0].center();
            int view = -1;
            QPoint pixel;
            QVERIFY(window_->studio().viewAt(at, view, pixel));
            QCOMPARE(view, 0);
            const QColor shown = frame.pixelColor(at);
            // The nearest-neighbour scaling may land on a neighbour of the pixel viewAt() names.
            bool found = false;
            for (int dy = -1; dy <= 1 && !found; ++dy)
                for (int dx = -1; dx <= 1 && !found; ++dx) {
                    const int x = std::clamp(pixel.x() + dx, 0, f.image->width() - 1);
                    const int y = std::clamp(pixel.y() + dy, 0, f.image->height() - 1);
                    const auto d = transform.apply(f.image->at(x, y, 0), f.image->at(x, y, 1), f.image->at(x, y, 2),
                                                   f.exposure + window_->studio().compositorState().exposureOffset);
                    found = std::abs(shown.red() - int(std::lround(d[0] * 255.0f))) <= 1 &&
                            std::abs(shown.green() - int(std::lround(d[1] * 255.0f))) <= 1 &&
                            std::abs(shown.blue() - int(std::lround(d[2] * 255.0f))) <= 1;
                }
            QVERIFY2(found, qPrintable(QString::fromStdString(transform.name()) + " shows " + shown.name()));
            frames[transform.name() + (transform.isOcio() ? "" : " (Tyndall)")] = frame;
        }
        // OpenColorIO's sRGB display is Tyndall's sRGB curve (within the one 8-bit level of Tyndall's table); its ACES
        // view and the Rec.1886 display are not.
        const auto levels = [](const QImage& a, const QImage& b) {
            int worst = a.size() == b.size() ? 0 : 256;
            for (int y = 0; y < a.height() && worst < 256; ++y)
                for (int x = 0; x < a.width(); ++x) {
                    const QColor p = a.pixelColor(x, y), q = b.pixelColor(x, y);
                    worst = std::max({worst, std::abs(p.red() - q.red()), std::abs(p.green() - q.green()),
                                      std::abs(p.blue() - q.blue())});
                }
            return worst;
        };
        QVERIFY(levels(frames.at("sRGB / Standard"), frames.at("srgb (Tyndall)")) <= 1);
        QVERIFY(frames.at("sRGB / ACES 1.0 - SDR Video") != frames.at("sRGB / Standard"));
        QVERIFY(frames.at("Rec.1886 / Standard") != frames.at("sRGB / Standard"));
        QVERIFY(frames.at("sRGB / Raw") != frames.at("sRGB / Standard"));
        // False colour draws the viridis bar at the bottom right: its left end is viridis(0), dark purple.
        const QImage falseColour = frames.at("falsecolour (Tyndall)");
        const int barWidth = std::min(256, falseColour.width() / 3);
        const QColor left = falseColour.pixelColor(falseColour.width() - barWidth - 12 + 1, falseColour.height() - 25);
        QVERIFY2(left.red() > 50 && left.red() < 90 && left.green() < 20 && left.blue() > 60, qPrintable(left.name()));
        // M (an application-wide shortcut, here typed in the viewport) cycles from false colour, the last, back to the
        // first, and the box and the menu follow.
        QCOMPARE(window_->studio().displayTransformIndex(), int(transforms.size()) - 1);
        QTest::keyClick(window_->viewport(), Qt::Key_M);
        QCOMPARE(window_->studio().displayTransformIndex(), 0);
        QCOMPARE(combo->currentIndex(), 0);
        const QAction* checked = nullptr;
        for (QAction* a : menu->findChildren<QAction*>())
            if (a->isCheckable() && a->isChecked()) checked = a;
        QVERIFY(checked);
        QCOMPARE(checked->data().toInt(), 0);
        QCOMPARE(window_->studio().composedFrame(), frames.at("sRGB / Standard"));
        window_->studio().setLayoutMode(Layout::Grid);
    }

    // Grid shows every view; single shows one (keys 1-9 select it, from the viewport), holding Shift shows its
    // reference.
    void switchesLayouts() {
        window_->studio().setLayoutMode(Layout::Grid);
        const QImage grid = window_->studio().composedFrame();
        QTest::keyClick(window_->viewport(), Qt::Key_2);
        QCOMPARE(window_->studio().compositorState().current, 1);
        QCOMPARE(window_->studio().compositorState().layout, Layout::Single);
        const QImage single = window_->studio().composedFrame();
        QVERIFY(single != grid);
        QTest::keyPress(window_->viewport(), Qt::Key_Shift);
        QVERIFY(window_->studio().compositorState().showReference);
        const QImage reference = window_->studio().composedFrame();
        QTest::keyRelease(window_->viewport(), Qt::Key_Shift);
        QVERIFY(!window_->studio().compositorState().showReference);
        QVERIFY(reference != single);

        // Shift+2 makes view 2 every other view's reference (its label and metrics follow); Shift+2 again undoes it.
        QTest::keyClick(window_->viewport(), Qt::Key_2, Qt::ShiftModifier);
        QCOMPARE(window_->studio().referenceView(), 1);
        QVERIFY(window_->studio().frames()[0].alternate == window_->studio().frames()[1].image);
        QVERIFY(!window_->studio().frames()[1].alternate);
        QTRY_VERIFY(window_->studio().settled());
        QVERIFY(window_->studio().frames()[0].metrics && window_->studio().frames()[0].metrics->relMSE > 0.0);
        QTest::keyClick(window_->viewport(), Qt::Key_2, Qt::ShiftModifier);
        QCOMPARE(window_->studio().referenceView(), -1);
        QVERIFY(!window_->studio().frames()[0].alternate);
        QTRY_VERIFY(window_->studio().settled());

        // Zoom shows the same part of every view: the frame changes, and the cursor maps to pixels of that part.
        window_->studio().setLayoutMode(Layout::Grid);
        const QImage unzoomed = window_->studio().composedFrame();
        const QRect r = viewRects(window_->studio().frames(), window_->studio().compositorState(),
                                  window_->viewport()->pixelSize())[0];
        int view = -1;
        QPoint pixel;
        QVERIFY(window_->studio().viewAt(QPointF(r.x() + 1, r.y() + 1), view, pixel));
        QCOMPARE(pixel, QPoint(0, 0));
        window_->studio().compositorState().zoom = 4.0;
        window_->studio().recompose();
        QVERIFY(window_->studio().composedFrame() != unzoomed);
        QVERIFY(window_->studio().viewAt(QPointF(r.x() + 1, r.y() + 1), view, pixel));
        QCOMPARE(view, 0);
        QCOMPARE(pixel, QPoint(36, 27));  // the centre quarter of 96 x 72 starts at (36, 27)
        QTest::keyClick(window_->viewport(), Qt::Key_Z);
        QCOMPARE(window_->studio().compositorState().zoom, 1.0);
        QCOMPARE(window_->studio().composedFrame(), unzoomed);
    }

    // The wipe shows the view left of the divider and its reference right of it; T swaps them; the difference mode
    // draws its colour bar.
    void wipesAndShowsDifferences() {
        window_->studio().selectView(1);
        window_->studio().setLayoutMode(Layout::Single);
        const QImage technique = window_->studio().composedFrame();
        window_->studio().compositorState().showReference = true;
        window_->studio().recompose();
        const QImage reference = window_->studio().composedFrame();
        window_->studio().compositorState().showReference = false;

        window_->studio().setLayoutMode(Layout::Split);
        window_->studio().compositorState().split = 0.5;
        window_->studio().recompose();
        const QImage split = window_->studio().composedFrame();
        const QRect r = viewRects(window_->studio().frames(), window_->studio().compositorState(), split.size())[1];
        QVERIFY(!r.isEmpty());
        const int y = r.center().y();
        const int leftX = r.x() + r.width() / 4, rightX = r.x() + 3 * r.width() / 4;
        QCOMPARE(split.pixel(leftX, y), technique.pixel(leftX, y));
        QCOMPARE(split.pixel(rightX, y), reference.pixel(rightX, y));
        QTest::keyClick(window_->viewport(), Qt::Key_T);
        QVERIFY(window_->studio().compositorState().swapped);
        QCOMPARE(window_->studio().composedFrame().pixel(leftX, y), reference.pixel(leftX, y));
        window_->studio().compositorState().swapped = false;

        window_->studio().setLayoutMode(Layout::Single);
        window_->studio().compositorState().diff = DiffMode::Signed;
        window_->studio().recompose();
        const QImage diff = window_->studio().composedFrame();
        QVERIFY(diff != technique);
        window_->studio().compositorState().diff = DiffMode::Off;
        window_->studio().setLayoutMode(Layout::Grid);
    }

    // Captions fit their tiles: in the default window's grid every view's metrics line shows its relMSE and PSNR whole
    // (the compact form drops the long names), and a wide tile gets the full caption with the technique's name.
    void captionsKeepTheirNumbersInNarrowTiles() {
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
        window_->studio().setLayoutMode(Layout::Grid);
        const std::vector<ViewFrame>& frames = window_->studio().frames();
        const std::vector<QRect> rects =
            viewRects(frames, window_->studio().compositorState(), window_->viewport()->pixelSize());
        const QString ellipsis(QChar(0x2026));
        for (std::size_t i = 0; i < frames.size(); ++i) {
            const ViewFrame& f = frames[i];
            QVERIFY(f.metrics);
            const QStringList caption = tileCaption(f, false, rects[i].width(), window_->font());
            QCOMPARE(caption.size(), 2);
            const QString relMSE = QString::number(f.metrics->relMSE, 'g', 3),
                          psnr = QString::number(f.metrics->psnr, 'g', 3);
            QVERIFY2(caption[1].contains(relMSE) && caption[1].contains(psnr + " dB") && !caption[1].contains(ellipsis),
                     qPrintable(QString("%1 px: %2").arg(rects[i].width()).arg(caption[1])));
            QVERIFY2(caption[0].startsWith(f.name) && !caption[0].contains(ellipsis), qPrintable(caption[0]));
            const QStringList wide = tileCaption(f, false, 2000, window_->font());
            QVERIFY(wide[0].contains(f.technique));
            QVERIFY(wide[1].contains("PSNR"));
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
                    QVERIFY2(text.contains(k.toString(QKeySequence::NativeText).toHtmlEscaped()),
                             qPrintable(k.toString()));
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
        const bool swapped = window_->studio().compositorState().swapped;
        QTest::keyClick(list, Qt::Key_T);
        QCOMPARE(window_->studio().compositorState().swapped, !swapped);
        QTest::keyClick(list, Qt::Key_T);
        QTest::keyClick(list, Qt::Key_E);
        QCOMPARE(window_->studio().compositorState().exposureOffset, 0.5);
        auto* display = window_->findChild<QLabel*>("displayStatus");
        QVERIFY(display);
        QVERIFY2(display->text().contains("+0.5 EV"), qPrintable(display->text()));
        QTest::keyClick(list, Qt::Key_E, Qt::ShiftModifier);
        QCOMPARE(window_->studio().compositorState().exposureOffset, 0.0);
        QTest::keyClick(list, Qt::Key_3);
        QCOMPARE(window_->studio().compositorState().current, 2);
        QCOMPARE(window_->studio().compositorState().layout, Layout::Single);
        QAction* single = nullptr;
        for (QAction* a : window_->findChildren<QAction*>())
            if (a->text() == "&Single") single = a;
        QVERIFY(single && single->isChecked());  // the toolbar follows the layout chosen by a key
        window_->studio().compositorState().zoom = 2.0;
        window_->studio().recompose();
        QVERIFY2(display->text().contains("zoom 2x"), qPrintable(display->text()));
        QTest::keyClick(list, Qt::Key_Z);
        QCOMPARE(window_->studio().compositorState().zoom, 1.0);
        QTest::keyClick(list, Qt::Key_G);
        QCOMPARE(window_->studio().compositorState().layout, Layout::Grid);
        QVERIFY(window_->findChild<QDoubleSpinBox*>("exposure"));
        bool named = false;
        for (QLabel* label : window_->findChildren<QLabel*>())
            named |= label->text() == "view exposure";
        QVERIFY(named);
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
    }

    // A wipe whose reference is not ready says so on its side (it was plain black), and so does its tile.
    void wipeSaysWhenTheReferenceIsNotReady() {
        auto image = std::make_shared<Image>(Image::rgb(48, 36));
        for (int y = 0; y < 36; ++y)
            for (int x = 0; x < 48; ++x)
                for (int c = 0; c < 3; ++c)
                    image->at(x, y, c) = 0.5f;
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
        fresh.studio().setRecovery(Studio::Recovery::Never);
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
        QTRY_VERIFY_WITH_TIMEOUT(fresh.studio().settled(), 120000);
    }

    // $OCIO chooses the config whose displays and views the Display box and menu list (issue 35); one that is
    // missing or broken is passed over for the shipped config with a message naming the file, and the studio works.
    void followsTheOcioConfig() {
        const QString data = TYNDALL_SOURCE_DIR "/tests/data/ocio/";
        const auto items = [](const MainWindow& w) {
            QStringList out;
            const auto* combo = w.findChild<QComboBox*>("display");
            for (int i = 0; i < combo->count(); ++i)
                if (combo->itemData(i).isValid()) out << combo->itemText(i);
            return out;
        };
        const auto menuDisplays = [](const MainWindow& w) {
            QStringList out;
            for (QAction* a : w.findChild<QMenu*>("displayMenu")->actions())
                if (a->menu()) out << a->text();
            return out;
        };
        const QStringList ours = {"Tyndall: sRGB (clamped)", "Tyndall: Reinhard", "Tyndall: ACES fit",
                                  "Tyndall: false colour"};
        qputenv("OCIO", (data + "cinema.ocio").toUtf8());
        {
            MainWindow cinema(vulkan_, kSmall);
            cinema.studio().setRecovery(Studio::Recovery::Never);
            QCOMPARE(items(cinema), QStringList({"Cinema / Film", "Cinema / Raw"}) + ours);
            QCOMPARE(menuDisplays(cinema), QStringList({"Cinema"}));
            QCOMPARE(cinema.findChild<QComboBox*>("display")->currentText(), QString("Cinema / Film"));
            QVERIFY(cinema.findChild<QComboBox*>("display")->toolTip().contains("cinema.ocio ($OCIO)"));
        }
        qputenv("OCIO", (data + "broken.ocio").toUtf8());
        {
            MainWindow fallback(vulkan_, kSmall);
            fallback.studio().setRecovery(Studio::Recovery::Never);
            fallback.show();
            QVERIFY(QTest::qWaitForWindowExposed(&fallback));
            const QString said = fallback.statusBar()->currentMessage();
            QVERIFY2(said.contains("broken.ocio") && said.contains("'missing'") && said.contains("the shipped config"),
                     qPrintable(said));
            QCOMPARE(menuDisplays(fallback), QStringList({"sRGB", "Rec.1886"}));
            QVERIFY(items(fallback).contains("sRGB / ACES 1.0 - SDR Video"));
            QVERIFY(fallback.openProject(kDefaultProject, false));  // and it works
            QTRY_VERIFY_WITH_TIMEOUT(fallback.studio().settled(), 120000);
            QVERIFY(distinctColours(fallback.studio().composedFrame()) > 20);
        }
        qunsetenv("OCIO");
        {
            // --ocio naming a file that is not there: said, and $OCIO's (unset) or the shipped config instead.
            MainWindow missing(vulkan_, kSmall, data + "nowhere.ocio");
            missing.studio().setRecovery(Studio::Recovery::Never);
            const QString said = missing.statusBar()->currentMessage();
            QVERIFY2(said.contains("nowhere.ocio") && said.contains("no such file"), qPrintable(said));
            QCOMPARE(missing.studio().colourConfig()->origin(), std::string("shipped"));
        }
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
};

QObject* makeViewingTest(QVulkanInstance* vulkan) {
    return new ViewingTest(vulkan);
}

}  // namespace tyndall::studio::gui

#include "test_viewing.moc"
