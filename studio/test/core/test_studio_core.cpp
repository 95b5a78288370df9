// The studio's core without a window (QGuiApplication on the offscreen platform): the comparison model and the
// compositor on images made here, and the session, the render scheduler and the Studio that wires them on the
// bundled default project at a small size. What the window shows is tested in test/gui.
#include "resolution_schedule.h"
#include "studio.h"
#include "tyndall/image/colour_map.h"
#include "tyndall/image/flip.h"
#include "tyndall/image/image_io.h"

#include <QDir>
#include <QGuiApplication>
#include <QSignalSpy>
#include <QStandardPaths>
#include <QTemporaryDir>
#include <QTest>
#include <QThread>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <set>

using namespace tyndall;
using namespace tyndall::studio;

namespace {

const QString kDefaultProject = TYNDALL_SOURCE_DIR "/projects/default.json";
// Small renders: the project's camera and its reference at a few spp.
const std::vector<std::string> kSmall = {"camera.width=48", "camera.height=36", "reference.spp=4"};

std::shared_ptr<const Image> flat(int width, int height, float value) {
    auto image = std::make_shared<Image>(Image::rgb(width, height));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c)
                image->at(x, y, c) = value;
    return image;
}

RenderOutput output(int view, bool reference, quint64 state, std::shared_ptr<const Image> image) {
    RenderOutput out;
    out.view = view;
    out.reference = reference;
    out.state = state;
    out.image = std::move(image);
    out.spp = 4;
    out.final = true;
    return out;
}

bool waitFor(const std::function<bool()>& done, int ms = 240000) {
    QElapsedTimer clock;
    clock.start();
    while (!done() && clock.elapsed() < ms)
        QTest::qWait(20);
    return done();
}

}  // namespace

class StudioCoreTest : public QObject {
    Q_OBJECT

private:
    // A view whose first image at 1/F of its resolution takes fixed + full / F^2 seconds, scheduled on a simulated
    // clock: the factors of one edit's sequence, each stage's time, and the time until full resolution.
    struct Sequence {
        std::vector<int> factors;
        std::vector<double> seconds;
        double untilFull = 0.0;
    };
    static Sequence edit(ResolutionSchedule& schedule, double& now, double fixed, double full) {
        Sequence s;
        for (int f = schedule.begin(); f > 0;) {
            const double cost = fixed + full / (double(f) * f);
            now += cost;
            s.factors.push_back(f);
            s.seconds.push_back(cost);
            s.untilFull += cost;
            f = schedule.delivered(f);
        }
        return s;
    }

private slots:
    // Issue 31's schedule on simulated timings: full resolution until a render was measured; then the first image of
    // an edit within the 33 ms budget, the reduction halving towards full resolution, and the reduced stages costing
    // at most 20 % of the full-resolution render they come before.
    void resolutionScheduleMeetsTheBudgetOnSimulatedTimings() {
        double now = 0.0;
        ResolutionSchedule schedule([&now] { return now; });
        QVERIFY(!schedule.predicted(1));
        // A path tracer's first pass: 8 s at full resolution, 1 ms of it fixed.
        Sequence first = edit(schedule, now, 0.001, 8.0);
        QCOMPARE(first.factors, std::vector<int>{1});  // nothing measured yet
        Sequence s = edit(schedule, now, 0.001, 8.0);
        QCOMPARE(s.factors, (std::vector<int>{16, 8, 4, 1}));  // 1/2 (2 s) would delay full resolution too much
        QVERIFY(s.seconds.front() <= schedule.budget());
        QVERIFY(s.untilFull <= 1.2 * s.seconds.back());
        QVERIFY(std::abs(*schedule.predicted(2) - (0.001 + 8.0 / 4.0)) < 1e-9);  // the model recovers the costs
        // LTSD-like: 405 ms at full resolution; 1/4 fits the budget, 1/2 would cost too much before full resolution.
        ResolutionSchedule ltsd([&now] { return now; });
        edit(ltsd, now, 0.005, 0.4);
        s = edit(ltsd, now, 0.005, 0.4);
        QCOMPARE(s.factors, (std::vector<int>{4, 1}));
        QVERIFY(s.seconds.front() <= ltsd.budget());
        QVERIFY(s.untilFull <= 1.2 * s.seconds.back());
        // WVDS-like: 100 ms. 1/2 would fit the budget (26.5 ms) but delay full resolution by 26 %: 1/4 it is.
        ResolutionSchedule wvds([&now] { return now; });
        edit(wvds, now, 0.002, 0.098);
        s = edit(wvds, now, 0.002, 0.098);
        QCOMPARE(s.factors, (std::vector<int>{4, 1}));
        QVERIFY(s.untilFull <= 1.2 * s.seconds.back());
        // A technique fast at full resolution (Pegoraro, 20 ms) renders no reduced image.
        ResolutionSchedule fast([&now] { return now; });
        edit(fast, now, 0.002, 0.018);
        QCOMPARE(edit(fast, now, 0.002, 0.018).factors, std::vector<int>{1});
    }

    // A fixed cost that does not shrink with the image (ISV's sort and shadow maps: 300 of its 800 ms): the first
    // guess reduces, the measurement shows that it does not pay, and the next edits render at full resolution.
    void resolutionScheduleLearnsAFixedCost() {
        double now = 0.0;
        ResolutionSchedule schedule([&now] { return now; });
        edit(schedule, now, 0.3, 0.5);
        const Sequence guess = edit(schedule, now, 0.3, 0.5);
        QVERIFY(guess.factors.size() == 2 && guess.factors.front() > 1 && guess.factors.back() == 1);
        QVERIFY(std::abs(*schedule.predicted(1) - 0.8) < 1e-9 &&
                std::abs(*schedule.predicted(16) - (0.3 + 0.5 / 256)) < 1e-9);
        QCOMPARE(edit(schedule, now, 0.3, 0.5).factors, std::vector<int>{1});
    }

    // A new edit restarts the sequence: an image of the sequence before changes nothing, the new one goes on.
    void resolutionScheduleRestartsOnANewEdit() {
        double now = 0.0;
        ResolutionSchedule schedule([&now] { return now; });
        edit(schedule, now, 0.001, 8.0);
        edit(schedule, now, 0.001, 8.0);
        QCOMPARE(schedule.begin(), 16);
        now += 0.03;
        QCOMPARE(schedule.delivered(16), 8);
        QCOMPARE(schedule.begin(), 16);      // the user edits again while 1/8 renders
        QCOMPARE(schedule.delivered(8), 0);  // the old sequence's image: ignored
        QCOMPARE(schedule.current(), 16);
        now += 0.03;
        QCOMPARE(schedule.delivered(16), 8);
    }

    // What the scheduler asks during a drag (RenderScheduler::flushDirty): until a stage of the edit has delivered, a
    // newer edit waits for the reduced stage in flight, whose predicted cost is about the budget; once one has, what
    // renders only refines the image on screen and a newer edit replaces it at once.
    void resolutionScheduleSaysWhenAnEditsImageIsOnScreen() {
        double now = 0.0;
        ResolutionSchedule schedule([&now] { return now; });
        edit(schedule, now, 0.001, 8.0);
        edit(schedule, now, 0.001, 8.0);
        QVERIFY(schedule.shown());  // the finished sequence's image
        const int first = schedule.begin();
        QCOMPARE(first, 16);
        QVERIFY(!schedule.shown());
        QVERIFY(*schedule.predicted(schedule.current()) <= schedule.budget());
        now += 0.03;
        QCOMPARE(schedule.delivered(first), 8);
        QVERIFY(schedule.shown());  // 1/8 only refines
        QCOMPARE(schedule.begin(), 16);
        QVERIFY(!schedule.shown());
    }

    void initTestCase() {
        // The reference cache and autosaves of these tests stay apart from the user's.
        QStandardPaths::setTestModeEnabled(true);
        QDir(Studio::referenceCacheFolder()).removeRecursively();  // every run renders its references
    }

    // --- ComparisonModel: images of one state are compared; an edit makes them stale until the new reference.
    void comparesOnlyImagesOfOneState() {
        Background background;
        ComparisonModel model(background);
        model.reset({{"a", "Technique A", 0.0, 11}, {"b", "Technique B", 0.0, 21}});
        QCOMPARE(model.size(), 2);
        model.addOutput(output(0, true, 11, flat(8, 6, 1.0f)));
        model.addOutput(output(0, false, 11, flat(8, 6, 1.1f)));
        background.waitForDone();
        QTRY_VERIFY(model.frames()[0].metrics.has_value());
        // relMSE of a uniform 10 % error: (0.1)^2 / (1^2 + eps) per pixel.
        QVERIFY(std::abs(model.frames()[0].metrics->relMSE - 0.01) < 1e-3);
        QVERIFY(!model.frames()[0].metricsStale);
        QVERIFY(!model.frames()[1].metrics.has_value());  // nothing rendered for b

        // An edit of a's part: the old pair's numbers stay, marked stale, until a reference of the new state comes.
        model.setState(0, 12);
        model.addOutput(output(0, false, 12, flat(8, 6, 1.0f)));
        background.waitForDone();
        QTRY_VERIFY(model.frames()[0].metricsStale);
        model.addOutput(output(0, true, 12, flat(8, 6, 1.0f)));
        background.waitForDone();
        QTRY_VERIFY(!model.frames()[0].metricsStale && model.frames()[0].metrics->relMSE < 1e-12);
        QVERIFY(model.idle());
    }

    // Shift+N: every other view is compared against view N's image; the same again goes back to the reference.
    void comparesAgainstAnotherView() {
        Background background;
        ComparisonModel model(background);
        model.reset({{"a", "A", 0.0, 1}, {"b", "B", 0.0, 2}});
        for (int v = 0; v < 2; ++v)
            model.addOutput(output(v, true, quint64(v + 1), flat(4, 4, 1.0f)));
        model.addOutput(output(0, false, 1, flat(4, 4, 2.0f)));
        model.addOutput(output(1, false, 2, flat(4, 4, 2.0f)));
        model.chooseReferenceView(0);
        QCOMPARE(model.referenceView(), 0);
        QVERIFY(model.frames()[1].alternate);
        QCOMPARE(model.frames()[1].alternateName, QString("a"));
        background.waitForDone();
        QTRY_VERIFY(model.frames()[1].metrics.has_value());
        QVERIFY(model.frames()[1].metrics->relMSE < 1e-12);  // b equals a
        model.chooseReferenceView(-1);
        QVERIFY(!model.frames()[1].alternate);
    }

    // An image opened from a file is a read-only view after the project's, compared against a project view's
    // reference; removing it leaves the project's views.
    void imageViewsFollowTheProjectViews() {
        Background background;
        ComparisonModel model(background);
        model.reset({{"a", "A", 0.0, 1}});
        const int image = model.addImage("shot.exr", "EXR", flat(4, 4, 0.5f));
        QCOMPARE(image, 1);
        QVERIFY(model.isImage(image));
        QCOMPARE(model.projectViews(), 1);
        QCOMPARE(model.imageAgainst(image), 0);
        model.addOutput(output(0, true, 1, flat(4, 4, 0.5f)));
        background.waitForDone();
        QTRY_VERIFY(model.frames()[std::size_t(image)].metrics.has_value());
        model.removeImage(image);
        QCOMPARE(model.size(), 1);
    }

    // The convergence plot keeps one point per bucket of spp, four buckets per octave.
    void keepsOneConvergencePointPerBucket() {
        std::vector<ConvergencePoint> points;
        for (int spp = 1; spp <= 1024; ++spp)
            addConvergencePoint(points, ConvergencePoint{spp, 0.0, 1.0 / spp});
        QVERIFY(points.size() >= 36 && points.size() <= 44);
        for (std::size_t i = 1; i < points.size(); ++i)
            QVERIFY(ComparisonModel::convergenceBucket(points[i].spp) >
                    ComparisonModel::convergenceBucket(points[i - 1].spp));
        QCOMPARE(points.back().spp, 1024);
        addConvergencePoint(points, ConvergencePoint{1, 0.0, 1.0});  // a new render starts a new list
        QCOMPARE(points.size(), std::size_t(1));
    }

    // --- Compositor: where each view goes, and what the frame shows.
    void placesTheViews() {
        std::vector<ViewFrame> frames(3);
        for (ViewFrame& f : frames)
            f.image = flat(40, 30, 0.5f);
        CompositorState state;
        const QSize size(400, 300);
        std::vector<QRect> grid = viewRects(frames, state, size);
        QCOMPARE(grid.size(), std::size_t(3));
        for (std::size_t i = 0; i < grid.size(); ++i) {
            QVERIFY(!grid[i].isEmpty());
            QVERIFY(QRect(QPoint(0, 0), size).contains(grid[i]));
            for (std::size_t j = 0; j < i; ++j)
                QVERIFY(!grid[i].intersects(grid[j]));
            // The image's aspect ratio is kept.
            QVERIFY(std::abs(double(grid[i].width()) / grid[i].height() - 4.0 / 3.0) < 0.05);
        }
        state.layout = Layout::Single;
        state.current = 1;
        const std::vector<QRect> single = viewRects(frames, state, size);
        QVERIFY(single[0].isEmpty() && single[2].isEmpty());
        QVERIFY(single[1].width() > grid[1].width());
        // At 4x zoom a quarter of the image shows, around the centre.
        state.zoom = 4.0;
        const QRectF visible = visiblePart(QSize(40, 30), state);
        QCOMPARE(visible.width(), 10.0);
        QCOMPARE(visible.center(), QPointF(20.0, 15.0));

        // With a difference or false-colour mode, the colour bar at the bottom (its top 30 px above the frame's end)
        // never covers a caption (issue 33: it covered the bottom-right tile's, also in the exported viewport.png).
        for (bool falseColour : {false, true}) {
            CompositorState bars;
            bars.diff = falseColour ? DiffMode::Off : DiffMode::Signed;
            bars.displayTransform = falseColour ? Tonemap::FalseColour : Tonemap::Srgb;
            for (QSize frame : {QSize(400, 300), QSize(900, 260), QSize(300, 600)})
                for (const QRect& r : viewRects(frames, bars, frame))
                    QVERIFY2(
                        r.bottom() + 36 <= frame.height() - 30,
                        qPrintable(QString("caption to %1 in a frame of %2").arg(r.bottom() + 36).arg(frame.height())));
        }
    }

    void composesWhatTheViewsShow() {
        std::vector<ViewFrame> frames(2);
        frames[0].image = flat(40, 30, 0.0f);  // black
        frames[1].image = flat(40, 30, 1.0f);  // white
        CompositorState state;
        const QSize size(400, 300);
        const QImage frame = compose(frames, state, size);
        QCOMPARE(frame.size(), size);
        const std::vector<QRect> rects = viewRects(frames, state, size);
        auto centre = [&](int view) { return QColor(frame.pixel(rects[std::size_t(view)].center())); };
        QVERIFY(centre(0).value() < 10);
        QVERIFY(centre(1).value() > 245);
        // The display exposure darkens every view: -1 EV halves linear white (sRGB 0.5 -> ~188).
        state.exposureOffset = -1.0;
        const QImage darker = compose(frames, state, size);
        const int white = QColor(darker.pixel(rects[1].center())).value();
        QVERIFY2(white > 180 && white < 195, qPrintable(QString::number(white)));

        // A reduced image is captioned with its factor, and with the work its technique reduced too.
        frames[0].preview = flat(10, 8, 0.5f);
        frames[0].previewFactor = 4;
        QVERIFY(tileCaption(frames[0], false, 2000, QFont()).front().contains("(1/4 resolution)"));
        auto lessWork = std::make_shared<Image>(*frames[0].preview);
        lessWork->metadata["reducedWork"] = "coarser shadow maps";
        frames[0].preview = lessWork;
        QVERIFY(tileCaption(frames[0], false, 2000, QFont()).front().contains("(1/4 resolution, coarser shadow maps)"));
    }

    // The FLIP difference (D's fifth mode): identical images are magma's black, a step against a flat grey shows each
    // pixel's HDR-FLIP error in magma, and the colour bar runs from magma(0) to magma(1).
    void composesTheFlipDifference() {
        std::vector<ViewFrame> frames(2);
        frames[0].image = flat(40, 30, 0.5f);
        frames[0].reference = flat(40, 30, 0.5f);
        auto step = std::make_shared<Image>(Image::rgb(40, 30));
        for (int y = 0; y < 30; ++y)
            for (int x = 0; x < 40; ++x)
                for (int c = 0; c < 3; ++c)
                    step->at(x, y, c) = x < 20 ? 0.05f : 2.0f;
        frames[1].image = step;
        frames[1].reference = flat(40, 30, 0.5f);
        CompositorState state;
        state.diff = DiffMode::Flip;
        const QSize size(400, 300);
        const QImage frame = compose(frames, state, size);
        const std::vector<QRect> rects = viewRects(frames, state, size);
        auto srgb = [](const Rgb& c) {
            return QColor(int(srgbEncode(float(c.r)) * 255.0f + 0.5f), int(srgbEncode(float(c.g)) * 255.0f + 0.5f),
                          int(srgbEncode(float(c.b)) * 255.0f + 0.5f));
        };
        auto near = [](QColor a, QColor b) {
            return std::abs(a.red() - b.red()) <= 2 && std::abs(a.green() - b.green()) <= 2 &&
                   std::abs(a.blue() - b.blue()) <= 2;
        };
        const QColor same(frame.pixel(rects[0].center()));
        QVERIFY2(near(same, srgb(magma(0.0))), qPrintable(same.name()));
        const HdrFlipResult flip = hdrFlip(*frames[1].reference, *step);
        for (int x : {5, 34}) {  // well inside each half of the step, in the middle row
            const QPoint p(rects[1].left() + int((x + 0.5) * rects[1].width() / 40.0), rects[1].center().y());
            const QColor shown(frame.pixel(p));
            const QColor expected = srgb(magma(flip.error[std::size_t(15 * 40 + x)]));
            QVERIFY2(near(shown, expected), qPrintable(shown.name() + " against " + expected.name()));
            QVERIFY(flip.error[std::size_t(15 * 40 + x)] > 0.1f);
        }
        // The colour bar's ends (its bar sits 30 px above the frame's bottom, at the right).
        const int barWidth = std::min(256, size.width() / 3), barY = size.height() - 10 - 20 + 5;
        QVERIFY(near(QColor(frame.pixel(size.width() - barWidth - 12, barY)), srgb(magma(0.5 / barWidth))));
        QVERIFY(near(QColor(frame.pixel(size.width() - 13, barY)), srgb(magma(1.0 - 0.5 / barWidth))));
    }

    // --- Session: an edit is undoable; a broken project is refused and the current one stays.
    void sessionEditsAndRefusals() {
        Session session;
        QString error;
        QVERIFY2(session.open(kDefaultProject, &error, kSmall), qPrintable(error));
        QVERIFY(!session.modified());
        const double before = session.project().views[0].exposure;
        QSignalSpy changed(&session, &Session::viewChanged);
        session.setExposure(0, before + 1.0);
        QCOMPARE(changed.count(), 1);
        QVERIFY(session.modified());
        QCOMPARE(session.project().views[0].exposure, before + 1.0);
        session.undoStack()->undo();
        QCOMPARE(session.project().views[0].exposure, before);
        QVERIFY(!session.modified());

        QTemporaryDir dir;
        const QString broken = dir.filePath("broken.json");
        QFile file(broken);
        QVERIFY(file.open(QIODevice::WriteOnly));
        file.write("{\"version\": 1, \"scene\": ");
        file.close();
        const std::string name = session.project().name;
        QVERIFY(!session.open(broken, &error));
        QVERIFY2(error.contains("broken.json"), qPrintable(error));
        QCOMPARE(session.project().name, name);
    }

    // --- Studio: the whole flow without a window. Every view renders with its reference and metrics; an edit of one
    // view renders that view again and leaves the others' images as they were; the display's operations; picking.
    void rendersAndEditsWithoutAWindow() {
        Studio studio(kSmall);
        studio.setRecovery(Studio::Recovery::Never);
        studio.setViewportSize([] { return QSize(400, 300); });
        QSignalSpy rebuilt(&studio, &Studio::viewsRebuilt);
        QString error;
        QVERIFY2(studio.openProject(kDefaultProject, &error), qPrintable(error));
        QCOMPARE(rebuilt.count(), 1);
        QVERIFY(waitFor([&] { return studio.settled(); }));
        const std::vector<ViewFrame>& frames = studio.frames();
        QCOMPARE(int(frames.size()), 4);
        for (const ViewFrame& f : frames) {
            QVERIFY2(f.image && f.reference, qPrintable(f.name + ": " + f.error));
            QVERIFY(f.metrics.has_value());
        }
        const QImage composed = studio.composedFrame();
        QCOMPARE(composed.size(), QSize(400, 300));

        // An edit of view 1's exposure renders nothing: the tile shows the same image brighter, and PSNR follows.
        const std::shared_ptr<const Image> other = frames[0].image, edited = frames[1].image;
        const double psnrBefore = frames[1].metrics->psnr, exposureBefore = frames[1].exposure;
        QSignalSpy started(&studio.scheduler(), &RenderScheduler::started);
        studio.session().setExposure(1, exposureBefore + 1.0);
        QVERIFY(studio.scheduler().settled());
        QVERIFY(waitFor([&] { return studio.frames()[1].metrics && studio.frames()[1].metrics->psnr != psnrBefore; }));
        QTest::qWait(300);
        QCOMPARE(started.count(), 0);
        QCOMPARE(studio.frames()[1].image, edited);
        QCOMPARE(studio.frames()[1].exposure, exposureBefore + 1.0);
        QVERIFY(studio.composedFrame() != composed);
        // An edit of its parameters renders it again; the other views keep their images.
        studio.session().setParameter(1, "shadows", false);
        QVERIFY(waitFor([&] { return studio.settled() && studio.frames()[1].image != edited; }));
        QVERIFY(started.count() > 0);
        QCOMPARE(studio.frames()[0].image, other);
        QVERIFY(studio.title().contains("[*]"));

        // The display: 2 alone switches the grid to the single layout; D cycles the difference; the zoom clamps.
        studio.showViewAlone(2);
        QCOMPARE(studio.currentView(), 2);
        QCOMPARE(studio.compositorState().layout, Layout::Single);
        studio.cycleDifference();
        QCOMPARE(studio.compositorState().diff, DiffMode::Signed);
        for (DiffMode next :
             {DiffMode::Absolute, DiffMode::Relative, DiffMode::Flip, DiffMode::Off, DiffMode::Signed}) {
            studio.cycleDifference();
            QCOMPARE(studio.compositorState().diff, next);
        }
        studio.zoomBy(100.0);
        QCOMPARE(studio.compositorState().zoom, 64.0);
        studio.resetZoom();
        QCOMPARE(studio.compositorState().zoom, 1.0);

        // Picking: the centre of the single view is the centre pixel of its image.
        int view = -1;
        QPoint pixel;
        const QRect r = viewRects(studio.frames(), studio.compositorState(), studio.viewportSize())[2];
        QVERIFY(studio.viewAt(QPointF(r.center()) + QPointF(0.5, 0.5), view, pixel));
        QCOMPARE(view, 2);
        QVERIFY(std::abs(pixel.x() - 24) <= 1 && std::abs(pixel.y() - 18) <= 1);
        QSignalSpy inspected(&studio, &Studio::inspected);
        studio.inspect(QPointF(r.center()));
        QCOMPARE(inspected.count(), 1);
        QVERIFY(inspected.first().first().toString().contains(studio.frames()[0].name));
        studio.waitForBackgroundWork();

        // Snapshots: of the current view, compared against instead of its reference.
        const int shot = studio.takeSnapshot();
        QCOMPARE(shot, 0);
        studio.compareWithSnapshot(shot);
        QCOMPARE(studio.comparedSnapshot(), 0);
        QVERIFY(studio.frames()[2].snapshot);

        // Export without a window: the images and metrics of every view.
        QTemporaryDir dir;
        QVERIFY2(studio.exportComparison(dir.path(), &error), qPrintable(error));
        for (const char* file : {"metrics.json", "metrics.csv", "display.json", "viewport.png"})
            QVERIFY2(QFile::exists(dir.filePath(file)), file);
        QVERIFY(QFile::exists(dir.filePath(studio.frames()[0].name + ".exr")));
        // The PNGs went through the display transform the viewport shows, said in display.json and in each PNG: the
        // shipped config's default, then its ACES view.
        const auto displayJson = [&] {
            QFile f(dir.filePath("display.json"));
            return f.open(QIODevice::ReadOnly) ? nlohmann::json::parse(f.readAll().toStdString()) : nlohmann::json();
        };
        QCOMPARE(displayJson().value("display", ""), std::string("sRGB"));
        QCOMPARE(displayJson().value("view", ""), std::string("Standard"));
        QCOMPARE(displayJson().value("ocioConfig", ""), ColourConfig::shippedConfigPath().string());
        const std::vector<DisplayTransform>& transforms = studio.displayTransforms();
        const auto aces = std::find_if(transforms.begin(), transforms.end(),
                                       [](const DisplayTransform& t) { return t.view() == "ACES 1.0 - SDR Video"; });
        QVERIFY(aces != transforms.end());
        studio.setDisplayTransform(int(aces - transforms.begin()));
        QTemporaryDir again;
        QVERIFY2(studio.exportComparison(again.path(), &error), qPrintable(error));
        QFile second(again.filePath("display.json"));
        QVERIFY(second.open(QIODevice::ReadOnly));
        QCOMPARE(nlohmann::json::parse(second.readAll().toStdString()).value("view", ""),
                 std::string("ACES 1.0 - SDR Video"));
        const Image png = readImage(again.filePath(studio.frames()[0].name + ".png").toStdString());
        QCOMPARE(png.metadata.at("view"), std::string("ACES 1.0 - SDR Video"));
        QCOMPARE(png.metadata.at("display"), std::string("sRGB"));
        studio.waitForBackgroundWork();
    }

    // A value that is slow to render, replaced by another while it renders (typed 65536 then 2), does not hold the
    // new one back (issue 33: nodes = 1 rendered for 2.7 s before the 16 typed after it): once it has run a second,
    // the render in flight is cancelled and the newest state renders; its image never arrives.
    void cancelsARenderThatANewerStateSupersedes() {
        Studio studio(kSmall);
        studio.setRecovery(Studio::Recovery::Never);
        QString error;
        QVERIFY2(studio.openProject(kDefaultProject, &error), qPrintable(error));
        QVERIFY(waitFor([&] { return studio.settled(); }));
        const int view = 1;  // the light shaft, WVDS: samplesPerPixel is a parameter
        QCOMPARE(studio.session().project().views[view].technique, std::string("wvds"));
        std::vector<int> finals;
        connect(&studio.scheduler(), &RenderScheduler::output, this, [&](const RenderOutput& out) {
            if (out.view == view && !out.reference && out.final && out.image) finals.push_back(out.spp);
        });
        studio.session().setParameter(view, "samplesPerPixel", std::int64_t(65536));
        QTest::qWait(100);
        studio.session().setParameter(view, "samplesPerPixel", std::int64_t(2));
        QVERIFY2(waitFor([&] { return !finals.empty(); }, 60000), qPrintable(studio.frames()[view].error));
        QCOMPARE(finals, std::vector<int>{2});
        QCOMPARE(studio.frames()[view].spp, 2);
        QVERIFY(waitFor([&] { return studio.settled(); }));
    }

    // A view shown alone is the one dragged at: during a drag of the scene (the fog's g, which every view renders) the
    // views off screen render nothing; once the edits pause and the view on screen shows its full image they render
    // at full resolution, and every view ends on the last state. A view that comes on screen before then renders at
    // once.
    void viewsOffScreenWaitForTheEditsToPause() {
        Studio studio(kSmall);
        studio.setRecovery(Studio::Recovery::Never);
        QString error;
        QVERIFY2(studio.openProject(kDefaultProject, &error), qPrintable(error));
        QVERIFY(waitFor([&] { return studio.settled(); }));
        studio.showViewAlone(1);
        std::vector<std::pair<int, qint64>> starts;  // technique renders: view, when
        QElapsedTimer clock;
        clock.start();
        connect(&studio.scheduler(), &RenderScheduler::started, this, [&](int view, bool reference, int) {
            if (!reference) starts.push_back({view, clock.elapsed()});
        });
        std::vector<int> factors;  // of the images of views off screen
        qint64 caughtUp = -1;      // when view 1 showed its first full image of the drag's last state
        connect(&studio.scheduler(), &RenderScheduler::output, this, [&](const RenderOutput& out) {
            if (out.view != 1 && !out.reference && out.image) factors.push_back(out.factor);
            if (out.view == 1 && !out.reference && out.image && out.factor == 1 && caughtUp < 0 &&
                out.state == studio.scheduler().state(1))
                caughtUp = clock.elapsed();
        });
        for (int step = 0; step < 8; ++step) {
            QVERIFY(studio.session().editScene({"media[fog].phase.g=" + std::to_string(0.3 + 0.02 * step)}, "g", &error,
                                               79));
            QTest::qWait(60);
        }
        const qint64 dragEnd = clock.elapsed();
        QVERIFY(!starts.empty());
        for (const auto& [view, at] : starts)
            QVERIFY2(view == 1, qPrintable(QString("view %1 started %2 ms into the drag").arg(view).arg(at)));
        QVERIFY(waitFor([&] { return studio.settled(); }));
        // They started after the drag, and after view 1 showed its full image (none of its stages interrupted them).
        QVERIFY(caughtUp >= 0);
        for (int view : {0, 2, 3})
            QVERIFY(std::any_of(starts.begin(), starts.end(),
                                [&](const auto& s) { return s.first == view && s.second >= dragEnd; }));
        for (const auto& [view, at] : starts)
            if (view != 1)
                QVERIFY2(at >= caughtUp,
                         qPrintable(QString("view %1 at %2 ms, view 1 full at %3 ms").arg(view).arg(at).arg(caughtUp)));
        QVERIFY(!factors.empty());
        QVERIFY(std::all_of(factors.begin(), factors.end(), [](int f) { return f == 1; }));
        for (const ViewFrame& f : studio.frames())
            QVERIFY2(f.image && f.imageState == f.state, qPrintable(f.name));

        // An edit, and view 2 selected before the pause: it renders at once.
        starts.clear();
        clock.restart();
        QVERIFY(studio.session().editScene({"media[fog].phase.g=0.5"}, "g", &error));
        QTest::qWait(20);
        studio.selectView(2);
        QVERIFY(waitFor(
            [&] { return std::any_of(starts.begin(), starts.end(), [](const auto& s) { return s.first == 2; }); }));
        const auto two = std::find_if(starts.begin(), starts.end(), [](const auto& s) { return s.first == 2; });
        QVERIFY2(two->second < 250, qPrintable(QString("%1 ms").arg(two->second)));  // the debounce is 300 ms
        QVERIFY(waitFor([&] { return studio.settled(); }));
        for (const ViewFrame& f : studio.frames())
            QVERIFY2(f.image && f.imageState == f.state, qPrintable(f.name));

        // A view off screen whose render (started at a pause) is in flight when the next edit comes stops it: it
        // would take the cores from the view on screen for an image of a state nobody sees. It renders the new state
        // once the edits pause again.
        studio.showViewAlone(1);
        std::set<int> inFlight;  // hidden views started and not finished
        std::vector<int> stoppedViews;
        connect(&studio.scheduler(), &RenderScheduler::started, this, [&](int view, bool reference, int) {
            if (!reference && view != 1) inFlight.insert(view);
        });
        connect(&studio.scheduler(), &RenderScheduler::output, this, [&](const RenderOutput& out) {
            if (!out.reference && out.final) inFlight.erase(out.view);
        });
        connect(&studio.scheduler(), &RenderScheduler::stopped, this, [&](int view, bool reference) {
            if (!reference) stoppedViews.push_back(view);
        });
        QVERIFY(studio.session().editScene({"media[fog].phase.g=0.45"}, "g", &error));
        QVERIFY(waitFor([&] { return !inFlight.empty(); }));
        const std::set<int> running = inFlight;  // the scene edit below flushes synchronously: no output in between
        QVERIFY(studio.session().editScene({"media[fog].phase.g=0.4"}, "g", &error));
        for (int view : running)
            QVERIFY2(std::count(stoppedViews.begin(), stoppedViews.end(), view) == 1,
                     qPrintable(QString("view %1 kept rendering an old state off screen").arg(view)));
        QVERIFY(waitFor([&] { return studio.settled(); }));
        for (const ViewFrame& f : studio.frames())
            QVERIFY2(f.image && f.imageState == f.state, qPrintable(f.name));
    }

    // Views authored through the studio: a duplicate is selected; an image view cannot be duplicated, is renamed and
    // closed without touching the project.
    void authorsViews() {
        Studio studio(kSmall);
        studio.setRecovery(Studio::Recovery::Never);
        QString error;
        QVERIFY(studio.openProject(kDefaultProject, &error));
        const int n = int(studio.session().project().views.size());
        QVERIFY2(studio.duplicateView(0, &error), qPrintable(error));
        QCOMPARE(int(studio.session().project().views.size()), n + 1);
        // The copy comes right after its original, and is selected.
        QCOMPARE(studio.currentView(), 1);
        QCOMPARE(studio.session().project().views[1].technique, studio.session().project().views[0].technique);
        QVERIFY(studio.session().project().views[1].name != studio.session().project().views[0].name);
        const int image = studio.openImageView(TYNDALL_SOURCE_DIR "/tests/data/images/glow-16x12.exr", &error);
        QVERIFY2(image == n + 1, qPrintable(error));
        QCOMPARE(studio.currentView(), image);
        QVERIFY(!studio.duplicateView(image, &error));
        QVERIFY(error.contains("image opened from a file"));
        QVERIFY(studio.renameView(image, "glow", &error));
        QCOMPARE(studio.frames()[std::size_t(image)].name, QString("glow"));
        QVERIFY(studio.removeView(image, &error));
        QCOMPARE(studio.comparison().size(), n + 1);
        QCOMPARE(int(studio.session().project().views.size()), n + 1);
        QVERIFY(waitFor([&] { return studio.settled(); }));
    }

    // An image of another size than its reference (issue 33: the export stopped there, half written) is exported
    // alone, listed with the reason in the notes and metrics.json, and every other file is written. An export that
    // cannot start or is cancelled leaves nothing behind: no target folder, no hidden staging folder.
    void exportsWhatItCanAndLeavesNoHalfFolder() {
        Studio studio(kSmall);
        studio.setRecovery(Studio::Recovery::Never);
        studio.setViewportSize([] { return QSize(200, 150); });
        QString error;
        QVERIFY(studio.openProject(kDefaultProject, &error));
        const int odd = studio.openImageView(TYNDALL_SOURCE_DIR "/tests/data/images/glow-16x12.exr", &error);
        QVERIFY2(odd >= 0, qPrintable(error));
        QVERIFY(waitFor([&] { return studio.settled(); }));
        const QString name = studio.frames()[std::size_t(odd)].name;
        QTemporaryDir parent;
        const QString folder = parent.filePath("export");
        QVERIFY2(studio.exportComparison(folder, &error), qPrintable(error));
        auto leftovers = [&] {
            return QDir(parent.path()).entryList(QDir::Dirs | QDir::Hidden | QDir::NoDotAndDotDot);
        };
        QCOMPARE(leftovers(), QStringList{"export"});
        const QString notes = studio.exportNotes().join("\n");
        QVERIFY2(notes.contains(name + ": not exported: the difference") && notes.contains("differs"),
                 qPrintable(notes));
        QVERIFY(QFile::exists(folder + "/" + name + ".exr"));
        QVERIFY(!QFile::exists(folder + "/" + name + "-diff.png"));
        for (const char* file : {"metrics.json", "metrics.csv", "display.json", "viewport.png"})
            QVERIFY2(QFile::exists(folder + "/" + file), file);
        for (const ViewFrame& f : studio.frames())
            if (f.name != name) QVERIFY2(QFile::exists(folder + "/" + f.name + "-diff.png"), qPrintable(f.name));
        QFile json(folder + "/metrics.json");
        QVERIFY(json.open(QIODevice::ReadOnly));
        const nlohmann::json metrics = nlohmann::json::parse(json.readAll().toStdString());
        QCOMPARE(int(metrics.size()), int(studio.frames().size()));
        const nlohmann::json& entry = metrics[std::size_t(odd)];
        QVERIFY2(entry.contains("notExported") && !entry.contains("relMSE"), entry.dump().c_str());
        QVERIFY(metrics[0].contains("relMSE") && !metrics[0].contains("notExported"));

        // An exposure edit renders nothing, and the next export's EXRs carry the view's exposure as it is now.
        studio.session().setExposure(0, 1.75);
        QVERIFY(waitFor([&] { return studio.settled(); }));
        const QString again = parent.filePath("export-exposure");
        QVERIFY2(studio.exportComparison(again, &error), qPrintable(error));
        const std::string first = studio.frames()[0].name.toStdString();
        for (const std::string suffix : {".exr", "-reference.exr"}) {
            const Image exported = readImage((again + "/").toStdString() + first + suffix);
            QCOMPARE(std::stod(exported.metadata.at("exposure")), 1.75);
        }
        QVERIFY(QDir(again).removeRecursively());

        // A target that is a file: refused before anything is written.
        QFile blocker(parent.filePath("a-file"));
        QVERIFY(blocker.open(QIODevice::WriteOnly));
        blocker.close();
        QVERIFY(!studio.exportComparison(blocker.fileName(), &error));
        QVERIFY2(error.startsWith("Nothing was exported") && error.contains("is a file"), qPrintable(error));
        QCOMPARE(leftovers(), QStringList{"export"});

        // Cancelled before its first file (the pool's two threads held until the cancel): nothing is left.
        std::atomic<bool> hold{true};
        for (int i = 0; i < 2; ++i)
            studio.background().run([&hold] {
                while (hold)
                    QThread::msleep(5);
            });
        QSignalSpy finished(&studio.exporter(), &Exporter::finished);
        studio.startExport(parent.filePath("cancelled"));
        studio.exporter().cancel();
        hold = false;
        QVERIFY(waitFor([&] { return finished.count() == 1; }));
        QCOMPARE(finished[0][0].toBool(), false);
        QCOMPARE(finished[0][1].toString(), QString("cancelled"));
        QCOMPARE(leftovers(), QStringList{"export"});
        studio.waitForBackgroundWork();
    }

    // A project that does not open keeps the current one, says why, and its renders go on.
    void refusesABrokenProject() {
        Studio studio(kSmall);
        studio.setRecovery(Studio::Recovery::Never);
        QString error;
        QVERIFY(studio.openProject(kDefaultProject, &error));
        QSignalSpy said(&studio, &Studio::message);
        QVERIFY(!studio.openProject(TYNDALL_SOURCE_DIR "/projects/missing.json", &error));
        QVERIFY2(error.contains("missing.json"), qPrintable(error));
        QCOMPARE(said.count(), 1);
        QVERIFY(said.first().first().toString().startsWith("Not opened"));
        QCOMPARE(int(studio.frames().size()), 4);
        QVERIFY(waitFor([&] { return studio.settled(); }));
        for (const ViewFrame& f : studio.frames())
            QVERIFY(f.image);
    }
};

int main(int argc, char** argv) {
    qunsetenv("OCIO");  // the shipped OpenColorIO config's display transforms, whatever the user's $OCIO
    QGuiApplication app(argc, argv);
    QGuiApplication::setOrganizationName("Tyndall");
    QGuiApplication::setApplicationName("Tyndall Studio core tests");
    StudioCoreTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "test_studio_core.moc"
