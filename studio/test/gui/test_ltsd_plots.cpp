#include "gui_test.h"

namespace tyndall::studio::gui {

// The LTSD plots (issue 18, item 5), a short case of its own (Studio.Gui.LtsdPlots, suite `ltsd-plots`): the selected
// view's medium's HG against its fit, sampled from the table as ltsdPolarCurve samples it, the fit in two pieces that
// leave the horizon's jump open, the error over g with the medium's g marked, a message (not an empty plot) for a phase
// function without a table and for a missing or corrupt table, and exports; checked on the drawn pixels as well.
class LtsdPlotsTest final : public QObject {
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
        window_->studio().selectView(1);
        QString error;
        QVERIFY2(window_->studio().session().editScene({"media[fog].phase.g=0.6"}, "g", &error), qPrintable(error));
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
        const double above = curve[LtsdPolarPlot::kSamples / 4 - 1].fitted,
                     below = curve[LtsdPolarPlot::kSamples / 4].fitted;
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
            const QPointF atHg = pixelOf(plot, h.key, h.value),
                          atFit = pixelOf(plot, r * std::sin(p.psi), r * std::cos(p.psi));
            if (QLineF(atHg, atFit).length() < 6.0 || r < 0.05) continue;
            QVERIFY2(colourNear(image, atHg, LtsdPolarPlot::phaseColour(), 2),
                     qPrintable(QString("HG at point %1").arg(k)));
            QVERIFY2(colourNear(image, atFit, LtsdPolarPlot::fitColour(), 6),
                     qPrintable(QString("fit at point %1").arg(k)));
            ++checked;
            (std::cos(p.psi) > 0.0 ? upperChecked : lowerChecked)++;
        }
        QVERIFY2(upperChecked >= 3 && lowerChecked >= 3,
                 qPrintable(QString("%1 %2").arg(upperChecked).arg(lowerChecked)));
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
        qInfo("LTSD plots: %.2f ms per update of both (data and items; the replot is queued)",
              timer.nsecsElapsed() / 1e7);

        // Linear radius: the radius is the value.
        polar->setLogRadius(false);  // the curves are drawn again: new QCPCurves
        QVERIFY(std::abs(radius(*polar->phaseCurve()->data()->at(0)) - curve[0].phase) < 1e-12);
        const QCPCurveData forward =
            *polar->phaseCurve()->data()->at(LtsdPolarPlot::kSamples / 2);  // psi ~ pi: HG's peak
        QVERIFY(forward.value < 0.0);
        const QImage linear = drawn(polar);  // first: drawing settles the axes' ranges that pixelOf reads
        QVERIFY(
            colourNear(linear, pixelOf(polar->plot(), forward.key, forward.value), LtsdPolarPlot::phaseColour(), 2));
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
        QVERIFY2(window_->studio().session().editScene({"media[fog].phase.g=-0.3"}, "g", &error), qPrintable(error));
        QCOMPARE(plot->marker()->point1->key(), -0.3);
        QCOMPARE(window_->ltsdPolarPlot()->fit().g, -0.3);
        window_->studio().selectView(2);  // another view of the same medium
        QCOMPARE(window_->ltsdPolarPlot()->fit().view, QString("area light"));
    }

    // A phase function without a table: a message naming it and the tables there are, no curves; back with undo.
    void explainsAPhaseFunctionWithoutATable() {
        QString error;
        QVERIFY2(window_->studio().session().editScene(
                     {"media[fog].phase={\"type\":\"legendre\",\"coefficients\":[1,0.5]}"}, "phase", &error),
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
        window_->studio().session().undoStack()->undo();
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
        window_->studio().setLtsdTablesDirectory(dir);
        LtsdPolarPlot* polar = window_->ltsdPolarPlot();
        QVERIFY2(polar->caption().startsWith("Cannot read the LTSD table of hg: ") &&
                     polar->caption().contains(dir + "/hg.ltsd"),
                 qPrintable(polar->caption()));
        QVERIFY(!polar->phaseCurve());
        QVERIFY(window_->ltsdErrorPlot()->caption().contains(dir + "/hg.ltsd"));
        QFile::remove(dir + "/hg.ltsd");
        window_->studio().setLtsdTablesDirectory(dir);
        QVERIFY2(polar->caption().contains("cannot open"), qPrintable(polar->caption()));
        window_->studio().setLtsdTablesDirectory("");
        QVERIFY(polar->phaseCurve());
    }

    // Both plots export to non-empty PNG and SVG, alone and with File > Export's plots.
    void exportsPngAndSvg() {
        const QString dir = QString(TYNDALL_TEST_TMP) + "/ltsd-export";
        QDir(dir).removeRecursively();
        QVERIFY(QDir().mkpath(dir));
        for (Plot* plot :
             {static_cast<Plot*>(window_->ltsdPolarPlot()), static_cast<Plot*>(window_->ltsdErrorPlot())}) {
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
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
        window_.reset();
    }

private:
    QVulkanInstance* vulkan_;
    std::unique_ptr<MainWindow> window_;
};

QObject* makeLtsdPlotsTest(QVulkanInstance* vulkan) {
    return new LtsdPlotsTest(vulkan);
}

}  // namespace tyndall::studio::gui

#include "test_ltsd_plots.moc"
