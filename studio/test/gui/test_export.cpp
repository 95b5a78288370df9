// Export of a comparison: the files of every view, and in the background with every view listed.
#include "gui_test.h"

namespace tyndall::studio::gui {

class ExportTest final : public FlowCase {
    Q_OBJECT
public:
    using FlowCase::FlowCase;

private slots:
    void initTestCase() { startOnTheDefaultProject(); }

    // The comparison export writes every view, reference and difference, the viewport, the metrics, the plots and the
    // region's insets.
    void exportsAComparison() {
        const QString folder = QString(TYNDALL_TEST_TMP) + "/export";
        QDir(folder).removeRecursively();
        window_->studio().setRegion(QRect(20, 20, 40, 30));
        QString error;
        QVERIFY2(window_->studio().exportComparison(folder, &error), qPrintable(error));
        for (const ViewFrame& f : window_->studio().frames())
            for (const char* suffix :
                 {".exr", ".png", "-reference.exr", "-reference.png", "-diff.png", "-flip.png", "-flip.exr"})
                QVERIFY2(QFile::exists(folder + "/" + f.name + suffix), qPrintable(f.name + suffix));
        QFile json(folder + "/metrics.json");
        QVERIFY(json.open(QIODevice::ReadOnly));
        const nlohmann::json metrics = nlohmann::json::parse(json.readAll().toStdString());
        QCOMPARE(int(metrics.size()), 4);
        // Every pair's metrics, those of the files written (computed by the export when the model's were in flight).
        for (std::size_t i = 0; i < metrics.size(); ++i) {
            const ViewFrame& f = window_->studio().frames()[i];
            QVERIFY2(metrics[i].contains("relMSE"), metrics[i].dump().c_str());
            const QString stem = folder + "/" + f.name;
            const Metrics m = computeMetrics(readImage((stem + ".exr").toStdString()),
                                             readImage((stem + "-reference.exr").toStdString()), f.exposure);
            QVERIFY2(std::abs(metrics[i]["relMSE"].get<double>() - m.relMSE) <= 1e-6 * m.relMSE, qPrintable(f.name));
            // HDR-FLIP of the files written: the exported map and metrics.json's summary (the FLIP view, D's fifth
            // mode, as a magma PNG beside it).
            const Image flipMap = readImage((stem + "-flip.exr").toStdString());
            const HdrFlipResult flip =
                hdrFlip(readImage((stem + "-reference.exr").toStdString()), readImage((stem + ".exr").toStdString()));
            QCOMPARE(std::vector<float>(flipMap.data(), flipMap.data() + flipMap.size()), flip.error);
            QVERIFY2(std::abs(metrics[i]["flip"]["mean"].get<double>() - flipStatistics(flip.error).mean) < 1e-9,
                     metrics[i].dump().c_str());
            QCOMPARE(QImage(stem + "-flip.png").size(), QSize(flipMap.width(), flipMap.height()));
        }
        QVERIFY2(metrics[1]["region"].contains("flip"), metrics[1].dump().c_str());
        // The region's metrics beside the whole image's (they were in the dock only).
        QVERIFY2(metrics[1].contains("region") && metrics[1]["region"]["width"] == 40, metrics[1].dump().c_str());
        const QImage viewport(folder + "/viewport.png");
        QCOMPARE(viewport.size(), window_->studio().composedFrame().size());
        QVERIFY(QFile::exists(folder + "/metrics.csv"));
        for (const char* plot : {"/plot-convergence.png", "/plot-convergence.svg", "/plot-pdf.png", "/plot-pdf.svg"})
            QVERIFY2(QFile(folder + plot).size() > 1000, plot);
        QFile svg(folder + "/plot-pdf.svg");
        QVERIFY(svg.open(QIODevice::ReadOnly));
        QVERIFY(svg.readAll().contains("<svg"));
        QVERIFY(QImage(folder + "/light shaft-region.png").size() == QSize(40, 30));
        window_->studio().setRegion(QRect());
    }

    // File > Export runs in the background with a progress dialog, and lists every view: one whose reference is not
    // ready yet is exported alone and named in the notes (it was left out silently).
    void exportsInTheBackgroundListingEveryView() {
        QDir(Studio::referenceCacheFolder()).removeRecursively();
        QVERIFY(window_->openProject(kDefaultProject, false));
        QTRY_VERIFY_WITH_TIMEOUT(std::all_of(window_->studio().frames().begin(), window_->studio().frames().end(),
                                             [](const ViewFrame& f) { return bool(f.image); }),
                                 120000);
        QStringList waiting;
        for (const ViewFrame& f : window_->studio().frames())
            if (!referencePair(f).against) waiting << f.name;
        const QString folder = QString(TYNDALL_TEST_TMP) + "/export-background";
        QDir(folder).removeRecursively();
        QSignalSpy finished(&window_->studio().exporter(), &Exporter::finished);
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
        QCOMPARE(int(metrics.size()), int(window_->studio().frames().size()));
        for (std::size_t i = 0; i < metrics.size(); ++i) {
            const QString name = window_->studio().frames()[i].name;
            QCOMPARE(QString::fromStdString(metrics[i]["view"].get<std::string>()), name);
            QVERIFY(QFile::exists(folder + "/" + name + ".exr"));
            if (waiting.contains(name)) {
                QVERIFY(metrics[i].contains("missing"));
                QVERIFY(finished[0][1].toString().contains(name));
            }
        }
        QTRY_VERIFY_WITH_TIMEOUT(window_->studio().settled(), 120000);
    }
};

QObject* makeExportTest(QVulkanInstance* vulkan) {
    return new ExportTest(vulkan);
}

}  // namespace tyndall::studio::gui

#include "test_export.moc"
