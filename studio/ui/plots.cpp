#include "plots.h"

#include <qcustomplot.h>

#include <QCheckBox>
#include <QLabel>
#include <QResizeEvent>
#include <QScrollArea>
#include <QScrollBar>
#include <QSignalBlocker>
#include <QSvgGenerator>
#include <QTabWidget>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

namespace tyndall::studio {

namespace {

// Distinct colours for series (Okabe-Ito, colour-blind safe).
QColor seriesColour(int i) {
    static const QColor colours[] = {QColor(0, 114, 178), QColor(230, 159, 0), QColor(0, 158, 115), QColor(204, 121, 167),
                                     QColor(86, 180, 233), QColor(213, 94, 0), QColor(240, 228, 66), QColor(0, 0, 0)};
    return colours[i % 8];
}

// A series' pen and marker: the colours repeat after eight series, so each further eight differ in line and marker
// (ten views never show two alike).
QPen seriesPen(int i, double width) {
    static const Qt::PenStyle styles[] = {Qt::SolidLine, Qt::DashLine, Qt::DotLine, Qt::DashDotLine};
    return QPen(seriesColour(i), width, styles[(i / 8) % 4]);
}

QCPScatterStyle::ScatterShape seriesMarker(int i) {
    static const QCPScatterStyle::ScatterShape shapes[] = {QCPScatterStyle::ssCircle, QCPScatterStyle::ssSquare,
                                                           QCPScatterStyle::ssTriangle, QCPScatterStyle::ssDiamond};
    return shapes[(i / 8) % 4];
}

}  // namespace

Plot::Plot(const QString& name, QWidget* parent) : QWidget(parent), name_(name) {
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(2, 2, 2, 2);
    plot_ = new QCustomPlot(this);
    plot_->setObjectName("plot:" + name);
    plot_->setMinimumSize(320, 180);
    plot_->legend->setVisible(true);
    // The caption under the plot, at most kCaptionLines lines high and scrolled beyond: in a short dock a long caption
    // would otherwise be laid over the plot (it covered the polar plot's axis label and lower lobe).
    caption_ = new QLabel;
    caption_->setWordWrap(true);
    caption_->setAlignment(Qt::AlignLeft | Qt::AlignTop);
    captionArea_ = new QScrollArea(this);
    captionArea_->setObjectName("caption:" + name);
    captionArea_->setWidget(caption_);
    captionArea_->setWidgetResizable(true);
    captionArea_->setFrameShape(QFrame::NoFrame);
    captionArea_->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    captionArea_->setSizePolicy(QSizePolicy::Preferred, QSizePolicy::Fixed);
    layout->addWidget(plot_, 1);
    layout->addWidget(captionArea_);
    fitCaption();
}

QString Plot::caption() const { return caption_->text(); }

void Plot::setCaption(const QString& text) {
    if (caption_->text() == text) return;
    caption_->setText(text);
    fitCaption();
}

void Plot::fitCaption() {
    // The caption's height at the area's width, up to kCaptionLines lines (the rest scrolls).
    const int lines = caption_->fontMetrics().lineSpacing() * kCaptionLines;
    const int width = std::max(1, captionArea_->width() - captionArea_->verticalScrollBar()->sizeHint().width());
    const int needed = caption_->text().isEmpty() ? 0 : caption_->heightForWidth(width);
    const int height = std::min(needed, lines);
    if (captionArea_->height() != height || captionArea_->minimumHeight() != height)
        captionArea_->setFixedHeight(height);
}

void Plot::resizeEvent(QResizeEvent* event) {
    QWidget::resizeEvent(event);
    fitCaption();
}

QString Plot::title() const { return title_ ? title_->text().replace('\n', ' ') : QString(); }

void Plot::setTitle(const QString& text) {
    if (!title_) {
        plot_->plotLayout()->insertRow(0);
        title_ = new QCPTextElement(plot_, text, QFont(font().family(), 10, QFont::Bold));
        plot_->plotLayout()->addElement(0, 0, title_);
    }
    // QCPTextElement does not wrap: lines of at most ~90 characters, broken at spaces (a loader's error names a path).
    QString wrapped;
    int line = 0;
    for (const QString& word : text.split(' ')) {
        if (line > 0 && line + word.size() > 90) {
            wrapped += '\n';
            line = 0;
        } else if (line > 0) {
            wrapped += ' ';
            ++line;
        }
        wrapped += word;
        line += int(word.size());
    }
    title_->setText(wrapped);
}

void Plot::legendOutside() {
    setTitle(title());
    plot_->legend->setFont(QFont(font().family(), 8));
    plot_->legend->setMargins(QMargins(4, 2, 4, 2));
    plot_->axisRect()->insetLayout()->take(plot_->legend);
    auto* side = new QCPLayoutGrid;  // the legend at the top, an empty element under it taking the rest
    plot_->plotLayout()->addElement(1, 1, side);
    plot_->plotLayout()->setColumnStretchFactor(1, 0.001);
    side->addElement(0, 0, plot_->legend);
    side->addElement(1, 0, new QCPLayoutElement(plot_));
    side->setRowStretchFactor(0, 0.001);
}

bool Plot::exportTo(const QString& path, QString* error) {
    const int width = std::max(plot_->width(), 640), height = std::max(plot_->height(), 420);
    bool ok = false;
    if (path.endsWith(".svg", Qt::CaseInsensitive)) {
        // QCustomPlot has no SVG writer: paint it into Qt's SVG generator.
        QSvgGenerator svg;
        svg.setFileName(path);
        svg.setSize(QSize(width, height));
        svg.setViewBox(QRect(0, 0, width, height));
        svg.setTitle(name_);
        QCPPainter painter;
        ok = painter.begin(&svg);
        if (ok) {
            plot_->toPainter(&painter, width, height);
            ok = painter.end();
        }
    } else {
        ok = plot_->savePng(path, width, height);
    }
    if (!ok && error) *error = "cannot write " + path;
    return ok;
}

ConvergencePlot::ConvergencePlot(QWidget* parent) : Plot("convergence", parent) {
    plot_->xAxis->setScaleType(QCPAxis::stLogarithmic);
    plot_->yAxis->setScaleType(QCPAxis::stLogarithmic);
    plot_->xAxis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
    plot_->yAxis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
    plot_->yAxis->setNumberFormat("eb");  // 10^-3, not 0.001
    plot_->yAxis->setNumberPrecision(0);
    plot_->yAxis->setLabel("relMSE");  // (a long label was cut at the plot's height)
    setCaption(
        "Each view's relMSE against its reference (or the view chosen with Shift+1-9) as it refines, "
        "log-log.");
    redraw();
}

void ConvergencePlot::setSeries(const std::vector<QString>& names,
                                const std::vector<std::vector<ConvergencePoint>>& points) {
    names_ = names;
    points_ = points;
    redraw();
}

void ConvergencePlot::setOverTime(bool overTime) {
    overTime_ = overTime;
    redraw();
}

void ConvergencePlot::redraw() {
    plot_->clearGraphs();
    plot_->xAxis->setLabel(overTime_ ? "render time (s)" : "samples per pixel");
    double xMin = 1e300, xMax = 0.0, yMin = 1e300, yMax = 0.0;
    for (std::size_t i = 0; i < points_.size(); ++i) {
        QCPGraph* graph = plot_->addGraph();
        graph->setName(i < names_.size() ? names_[i] : QString::number(i));
        graph->setPen(seriesPen(int(i), 2));
        graph->setScatterStyle(QCPScatterStyle(seriesMarker(int(i)), 5));
        for (const ConvergencePoint& p : points_[i]) {
            const double x = overTime_ ? p.seconds : double(p.spp);
            if (!(x > 0.0) || !(p.relMSE > 0.0)) continue;  // log axes
            graph->addData(x, p.relMSE);
            xMin = std::min(xMin, x);
            xMax = std::max(xMax, x);
            yMin = std::min(yMin, p.relMSE);
            yMax = std::max(yMax, p.relMSE);
        }
    }
    // Whole decades on both axes, so that the log ticker labels powers of ten (within a decade it had one tick or
    // none, and the labels read 2.5, 5, 7.5).
    auto decades = [](double lo, double hi) {
        const double l = std::pow(10.0, std::floor(std::log10(lo))), h = std::pow(10.0, std::ceil(std::log10(hi)));
        return QCPRange(l, h > l ? h : 10.0 * l);
    };
    if (xMax > 0.0) {
        plot_->xAxis->setRange(decades(xMin / 1.5, xMax * 1.5));
        plot_->yAxis->setRange(decades(yMin / 2.0, yMax * 2.0));
    } else {
        plot_->xAxis->setRange(1.0, 100.0);
        plot_->yAxis->setRange(1e-4, 1.0);
    }
    plot_->replot(QCustomPlot::rpQueuedReplot);  // once per pass of the event loop
}

PdfPlot::PdfPlot(QWidget* parent) : Plot("pdf", parent) {
    setCaption("Move the cursor over a view whose technique samples distances (WVDS).");
}

void PdfPlot::showProbe(const ProbeResult& result) {
    plot_->clearGraphs();
    plot_->xAxis->setLabel(QString::fromStdString(result.xLabel));
    plot_->yAxis->setLabel(QString::fromStdString(result.yLabel));
    double yMax = 0.0, xMin = 1e300, xMax = -1e300;
    for (std::size_t i = 0; i < result.series.size(); ++i) {
        const ProbeSeries& s = result.series[i];
        QCPGraph* graph = plot_->addGraph();
        graph->setName(QString::fromStdString(s.label));
        // Histograms as steps, pdfs as lines, a pair per strategy in one colour.
        const bool histogram = s.label.find("samples") != std::string::npos;
        graph->setPen(QPen(seriesColour(int(i / 2)), histogram ? 1 : 2, histogram ? Qt::SolidLine : Qt::DashLine));
        if (histogram) graph->setLineStyle(QCPGraph::lsStepCenter);
        for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
            graph->addData(s.x[k], s.y[k]);
            yMax = std::max(yMax, s.y[k]);
            xMin = std::min(xMin, s.x[k]);
            xMax = std::max(xMax, s.x[k]);
        }
    }
    if (xMax > xMin) plot_->xAxis->setRange(xMin, xMax);
    plot_->yAxis->setRange(0.0, yMax > 0.0 ? yMax * 1.1 : 1.0);
    setCaption(QString::fromStdString(result.title));
    plot_->replot(QCustomPlot::rpQueuedReplot);  // once per pass of the event loop
}

void PdfPlot::showMessage(const QString& message) {
    plot_->clearGraphs();
    plot_->replot(QCustomPlot::rpQueuedReplot);  // once per pass of the event loop
    setCaption(message);
}

PhasePlot::PhasePlot(Kind kind, QWidget* parent)
    : Plot(kind == Kind::Polar ? "phase-polar" : "phase-cosine", parent), kind_(kind) {
    if (kind_ == Kind::Polar) {
        // p(theta) as the distance from the origin in the scattering plane: forward scattering points right (+x).
        plot_->xAxis->setLabel("p(theta) cos theta  [1/sr]");
        plot_->yAxis->setLabel("p(theta) sin theta  [1/sr]");
        setCaption(
            "Phase functions of the project's media in the scattering plane (the selected view's "
            "media bold); light arrives from the left.");
    } else {
        plot_->yAxis->setScaleType(QCPAxis::stLogarithmic);
        plot_->yAxis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
        plot_->yAxis->setNumberFormat("eb");
        plot_->yAxis->setNumberPrecision(0);
        plot_->xAxis->setLabel("cos theta");
        plot_->yAxis->setLabel("p  [1/sr]");
        setCaption("Phase functions of the project's media over the cosine of the scattering angle (log).");
    }
    redraw();
}

void PhasePlot::setCurves(std::vector<PhaseCurve> curves) {
    curves_ = std::move(curves);
    redraw();
}

void PhasePlot::redraw() {
    plot_->clearPlottables();
    double extent = 0.0, lo = 1e300, hi = 0.0;
    for (std::size_t i = 0; i < curves_.size(); ++i) {
        const PhaseCurve& c = curves_[i];
        const QPen pen(seriesColour(int(i)), c.selected ? 2.5 : 1.2);
        if (kind_ == Kind::Polar) {
            // A closed curve over theta in [0, 2 pi] (QCPCurve keeps the order of its points, a graph would sort x).
            auto* curve = new QCPCurve(plot_->xAxis, plot_->yAxis);
            curve->setName(c.name);
            curve->setPen(pen);
            QVector<QCPCurveData> data;
            for (int k = 0; k < kSamples; ++k) {
                const double theta = 2.0 * std::numbers::pi * k / (kSamples - 1), r = c.value(std::cos(theta));
                data.append(QCPCurveData(k, r * std::cos(theta), r * std::sin(theta)));
                extent = std::max(extent, r);
            }
            curve->data()->set(data, true);
        } else {
            QCPGraph* graph = plot_->addGraph();
            graph->setName(c.name);
            graph->setPen(pen);
            for (int k = 0; k < kSamples; ++k) {
                const double mu = -1.0 + 2.0 * k / (kSamples - 1), v = c.value(mu);
                if (!(v > 0.0)) continue;  // log axis
                graph->addData(mu, v);
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
        }
    }
    if (kind_ == Kind::Polar) {
        const double e = extent > 0.0 ? extent * 1.05 : 1.0;
        plot_->xAxis->setRange(-e, e);
        plot_->yAxis->setRange(-e, e);
        // One unit the same length on both axes, so that the shape is the phase function's.
        plot_->yAxis->setScaleRatio(plot_->xAxis, 1.0);
    } else {
        plot_->xAxis->setRange(-1.0, 1.0);
        if (hi > 0.0) {
            const double l = std::pow(10.0, std::floor(std::log10(lo))), h = std::pow(10.0, std::ceil(std::log10(hi)));
            plot_->yAxis->setRange(l, h > l ? h : 10.0 * l);
        }
    }
    plot_->replot(QCustomPlot::rpQueuedReplot);
}

// ---------------------------------------------------------------------------------------------------------------------
// LTSD plots

QColor LtsdPolarPlot::phaseColour() { return QColor(230, 159, 0); }  // the paper's Fig. 12: HG orange, solid
QColor LtsdPolarPlot::fitColour() { return QColor(0, 114, 178); }    // the fit blue, broken

LtsdPolarPlot::LtsdPolarPlot(QWidget* parent) : Plot("ltsd-polar", parent) {
    logBox_ = new QCheckBox("log radius", this);
    logBox_->setObjectName("ltsdLogRadius");
    logBox_->setChecked(logRadius_);
    logBox_->setToolTip("Radius = log10 of the value (HG at g = 0.9 spans four decades), or the value itself");
    static_cast<QVBoxLayout*>(layout())->insertWidget(0, logBox_);
    connect(logBox_, &QCheckBox::toggled, this, [this](bool on) { setLogRadius(on); });
    legendOutside();
    connect(plot_, &QCustomPlot::afterLayout, this, [this] { keepSquare(); });
    showFit(LtsdFit{});
}

void LtsdPolarPlot::keepSquare() {
    const QRect rect = plot_->axisRect()->rect();
    if (extent_ <= 0.0 || rect.width() <= 0 || rect.height() <= 0) return;
    const double aspect = double(rect.width()) / double(rect.height());
    const double ex = extent_ * std::max(aspect, 1.0), ey = extent_ * std::max(1.0 / aspect, 1.0);
    const QCPRange x = plot_->xAxis->range(), y = plot_->yAxis->range();
    if (std::abs(x.upper - ex) + std::abs(x.lower + ex) + std::abs(y.upper - ey) + std::abs(y.lower + ey) < 1e-9 * extent_)
        return;
    plot_->xAxis->setRange(-ex, ex);
    plot_->yAxis->setRange(-ey, ey);
    plot_->replot(QCustomPlot::rpQueuedReplot);  // drawn with these ranges now; again for the ticks, which were laid out
}

void LtsdPolarPlot::showFit(const LtsdFit& fit) {
    fit_ = fit;
    if (!fit_.table && fit_.message.isEmpty()) fit_.message = "No medium selected.";
    redraw();
}

void LtsdPolarPlot::setLogRadius(bool log) {
    logRadius_ = log;
    const QSignalBlocker quiet(logBox_);
    logBox_->setChecked(log);
    redraw();
}

double LtsdPolarPlot::radiusOf(double value) const {
    if (!logRadius_) return std::max(value, 0.0);
    return value > 0.0 ? std::max(std::log10(value) - floorLog10_, 0.0) : 0.0;
}

void LtsdPolarPlot::redraw() {
    plot_->clearPlottables();
    plot_->clearItems();
    phase_ = fitUpper_ = fitLower_ = nullptr;
    if (!fit_.table) {
        extent_ = 0.0;
        setTitle(fit_.message);
        setCaption(fit_.message);
        plot_->legend->setVisible(false);
        plot_->xAxis->setLabel("");
        plot_->xAxis->setRange(-1.0, 1.0);
        plot_->yAxis->setRange(-1.0, 1.0);
        plot_->replot(QCustomPlot::rpQueuedReplot);
        return;
    }
    const LtsdTable& table = *fit_.table;
    const double g = fit_.g;
    plot_->legend->setVisible(true);
    const std::vector<LtsdPolarPoint> points = ltsdPolarCurve(table, g, kSamples);

    // The log scale's floor: a decade under HG's smallest value (HG is positive everywhere), at most six decades under
    // its peak; fitted values below it (the fit vanishes towards the horizon where its source does) are drawn at 0.
    double hgMin = 1e300, hgMax = 0.0;
    for (const LtsdPolarPoint& p : points) {
        hgMin = std::min(hgMin, p.phase);
        hgMax = std::max(hgMax, p.phase);
    }
    const double top = std::ceil(std::log10(hgMax));
    floorLog10_ = std::max(std::floor(std::log10(hgMin)) - 1.0, top - 6.0);

    // omega_o up: the plane's direction (sin psi, cos psi); psi = pi (forward scattering) points down.
    auto at = [this](double psi, double value) {
        const double r = radiusOf(value);
        return QPointF(r * std::sin(psi), r * std::cos(psi));
    };
    QVector<QCPCurveData> hg, upper, lower;
    double extent = 0.0;
    for (const LtsdPolarPoint& p : points) {
        const QPointF a = at(p.psi, p.phase), b = at(p.psi, p.fitted);
        hg.append(QCPCurveData(p.psi, a.x(), a.y()));
        // The fit in two pieces so that no line bridges its jump at the horizon: upper around omega_o (t = psi in
        // (-pi/2, pi/2)), lower around the forward direction (t = psi in (pi/2, 3 pi/2)).
        if (std::cos(p.psi) > 0.0) {
            const double t = p.psi > std::numbers::pi ? p.psi - 2.0 * std::numbers::pi : p.psi;
            upper.append(QCPCurveData(t, b.x(), b.y()));
        } else {
            lower.append(QCPCurveData(p.psi, b.x(), b.y()));
        }
        extent = std::max({extent, radiusOf(p.phase), radiusOf(p.fitted)});
    }
    hg.append(QCPCurveData(points.front().psi + 2.0 * std::numbers::pi, hg.front().key, hg.front().value));  // closed

    // Rings: each decade on the log scale, a few round values on the linear one; grey, outside the legend.
    std::vector<std::pair<double, QString>> rings;  // radius, label
    if (logRadius_) {
        for (double d = floorLog10_ + 1.0; d <= top; d += 1.0)
            rings.emplace_back(d - floorLog10_, QString("1e%1").arg(int(d)));
    } else {
        const double raw = extent / 3.0, decade = std::pow(10.0, std::floor(std::log10(raw)));
        const double step = raw / decade < 2.0 ? decade : raw / decade < 5.0 ? 2.0 * decade : 5.0 * decade;
        for (double r = step; r <= extent * 1.0001; r += step)
            rings.emplace_back(r, QString::number(r, 'g', 3));
    }
    const QPen ringPen(QColor(190, 190, 190), 0.8, Qt::DotLine);
    for (const auto& [r, label] : rings) {
        auto* ring = new QCPCurve(plot_->xAxis, plot_->yAxis);
        ring->removeFromLegend();
        ring->setLayer("grid");  // under the curves
        ring->setPen(ringPen);
        QVector<QCPCurveData> circle;
        for (int k = 0; k <= 120; ++k) {
            const double a = 2.0 * std::numbers::pi * k / 120.0;
            circle.append(QCPCurveData(k, r * std::cos(a), r * std::sin(a)));
        }
        ring->data()->set(circle, true);
        auto* text = new QCPItemText(plot_);
        text->position->setCoords(r * std::cos(0.25 * std::numbers::pi), r * std::sin(0.25 * std::numbers::pi));
        text->setPositionAlignment(Qt::AlignLeft | Qt::AlignBottom);
        text->setColor(QColor(130, 130, 130));
        text->setText(label);
    }

    phase_ = new QCPCurve(plot_->xAxis, plot_->yAxis);
    phase_->setName(QString("HG, g = %1").arg(g, 0, 'f', 3));
    phase_->setPen(QPen(phaseColour(), 2.5));
    phase_->data()->set(hg, true);
    const QPen fitPen(fitColour(), 2.0, Qt::DashLine);
    fitUpper_ = new QCPCurve(plot_->xAxis, plot_->yAxis);
    fitUpper_->setName("LTSD fit (" + QString::fromStdString(std::filesystem::path(table.path).filename().string()) +
                       ")");
    fitUpper_->setPen(fitPen);
    fitUpper_->data()->set(upper, false);  // t wraps: psi in (3 pi / 2, 2 pi) came last, sorts first
    fitLower_ = new QCPCurve(plot_->xAxis, plot_->yAxis);
    fitLower_->removeFromLegend();
    fitLower_->setPen(fitPen);
    fitLower_->data()->set(lower, true);

    // The horizon and omega_o.
    const double e = (extent > 0.0 ? extent : 1.0) * 1.12;
    auto* horizon = new QCPItemStraightLine(plot_);
    horizon->point1->setCoords(-1.0, 0.0);
    horizon->point2->setCoords(1.0, 0.0);
    horizon->setPen(QPen(QColor(110, 110, 110), 1.0));
    horizon->setLayer("grid");
    auto* horizonText = new QCPItemText(plot_);
    horizonText->position->setTypeX(QCPItemPosition::ptAxisRectRatio);  // at the left edge, whatever the range
    horizonText->position->setCoords(0.01, 0.0);
    horizonText->setPositionAlignment(Qt::AlignLeft | Qt::AlignBottom);
    horizonText->setText("horizon");
    horizonText->setColor(QColor(90, 90, 90));
    auto* omega = new QCPItemLine(plot_);
    omega->start->setCoords(0.0, 0.0);
    omega->end->setCoords(0.0, e * 0.95);
    omega->setHead(QCPLineEnding::esSpikeArrow);
    omega->setPen(QPen(QColor(60, 60, 60), 1.2));
    omega->setLayer("grid");
    auto* omegaText = new QCPItemText(plot_);
    omegaText->position->setCoords(0.0, e * 0.95);
    omegaText->setPositionAlignment(Qt::AlignLeft | Qt::AlignTop);
    omegaText->setText(QString::fromUtf8(" \u03c9o"));
    omegaText->setColor(QColor(60, 60, 60));

    extent_ = e;
    plot_->xAxis->setRange(-e, e);
    plot_->yAxis->setRange(-e, e);
    keepSquare();
    const QString scale = logRadius_ ? QString("radius log10(p) from 1e%1 [1/sr]").arg(int(floorLog10_))
                                     : QString("radius p [1/sr]");
    plot_->xAxis->setLabel(scale);
    plot_->yAxis->setLabel("");
    for (QCPAxis* axis : {plot_->xAxis, plot_->yAxis}) {  // on the log scale the rings carry the values
        axis->setTicks(!logRadius_);
        axis->setTickLabels(!logRadius_);
    }

    const LtsdFitError err = ltsdFitErrorAt(table, g);
    const bool clamped = std::abs(g) > double(table.gMax);
    setTitle(QString("HG g = %1 and its LTSD fit: error bound %2")
                 .arg(g, 0, 'f', 3)
                 .arg(err.bound, 0, 'e', 1));
    setCaption(
        QString(
            "Medium '%1' of view '%2': Henyey-Greenstein with g = %3 (orange) against its LTSD fit (blue, "
            "dashed) in a plane through omega_o (up: towards the viewer; forward scattering points down), as in the "
            "LTSD paper's Fig. 12. The fit is two pieces, one per hemisphere, and jumps at the horizon. Its error at "
            "this g%4: total variation %5 (upper), %6 (lower); the integral of the phase function over any region is "
            "off by at most %7.")
            .arg(fit_.medium, fit_.view)
            .arg(g, 0, 'f', 3)
            .arg(clamped ? QString(" (the table clamps g to %1)").arg(double(table.gMax), 0, 'f', 2) : QString())
            .arg(err.tvUpper, 0, 'e', 2)
            .arg(err.tvLower, 0, 'e', 2)
            .arg(err.bound, 0, 'e', 2));
    plot_->replot(QCustomPlot::rpQueuedReplot);
}

LtsdErrorPlot::LtsdErrorPlot(QWidget* parent) : Plot("ltsd-error", parent) {
    plot_->yAxis->setScaleType(QCPAxis::stLogarithmic);
    plot_->yAxis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
    plot_->yAxis->setNumberFormat("eb");
    plot_->yAxis->setNumberPrecision(0);
    plot_->xAxis->setLabel("g");
    plot_->yAxis->setLabel("fit error");
    legendOutside();
    showFit(LtsdFit{});
}

void LtsdErrorPlot::showFit(const LtsdFit& fit) {
    plot_->clearPlottables();
    plot_->clearItems();
    bound_ = nullptr;
    marker_ = nullptr;
    if (!fit.table || !fit.errorCurve) {
        const QString message = fit.message.isEmpty() ? QString("No medium selected.") : fit.message;
        setTitle(message);
        setCaption(message);
        plot_->legend->setVisible(false);
        plot_->replot(QCustomPlot::rpQueuedReplot);
        return;
    }
    plot_->legend->setVisible(true);
    const LtsdTable& table = *fit.table;
    const std::vector<LtsdFitError>& curve = *fit.errorCurve;
    const char* names[] = {"TV, upper hemisphere", "TV, lower hemisphere", "error bound"};
    double lo = 1e300, hi = 0.0;
    for (int s = 0; s < 3; ++s) {
        QCPGraph* graph = plot_->addGraph();
        graph->setName(names[s]);
        // Not the polar plot's orange and blue, which mean HG and the fit there.
        graph->setPen(QPen(seriesColour(s == 0 ? 4 : s == 1 ? 5 : 2), s == 2 ? 2.5 : 1.2,
                           s == 2 ? Qt::SolidLine : Qt::DashLine));
        for (const LtsdFitError& e : curve) {
            const double v = s == 0 ? e.tvUpper : s == 1 ? e.tvLower : e.bound;
            if (!(v > 0.0)) continue;  // log axis
            graph->addData(e.g, v);
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        if (s == 2) bound_ = graph;
    }
    const LtsdFitError here = ltsdFitErrorAt(table, fit.g);
    markedG_ = here.g;
    QCPGraph* point = plot_->addGraph();
    point->setName(QString("medium '%1', g = %2").arg(fit.medium).arg(fit.g, 0, 'f', 3));
    point->setPen(QPen(Qt::black));
    point->setLineStyle(QCPGraph::lsNone);
    point->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssCircle, QPen(Qt::black, 1.5), QBrush(Qt::white), 8));
    if (here.bound > 0.0) point->addData(here.g, here.bound);
    marker_ = new QCPItemStraightLine(plot_);
    marker_->point1->setCoords(here.g, 1.0);
    marker_->point2->setCoords(here.g, 2.0);
    marker_->setPen(QPen(Qt::black, 1.0, Qt::DashLine));

    plot_->xAxis->setRange(-double(table.gMax) - 0.02, double(table.gMax) + 0.02);
    if (hi > 0.0) {
        const double l = std::pow(10.0, std::floor(std::log10(lo))), h = std::pow(10.0, std::ceil(std::log10(hi)));
        plot_->yAxis->setRange(l, h > l ? h : 10.0 * l);
    }
    setTitle(QString("LTSD fit error against g; g = %1: bound %2").arg(fit.g, 0, 'f', 3).arg(here.bound, 0, 'e', 1));
    setCaption(QString("How well the LTSD table (%1) fits HG at each g: the total-variation distance of each "
                       "hemisphere's fit (in [0, 2]) and the resulting bound on the error of any region's "
                       "integral of the phase function. Marked: medium '%2' of view '%3' at g = %4 (bound %5).")
                   .arg(QString::fromStdString(table.path), fit.medium, fit.view)
                   .arg(fit.g, 0, 'f', 3)
                   .arg(here.bound, 0, 'e', 2));
    plot_->replot(QCustomPlot::rpQueuedReplot);
}

DataPlot::DataPlot(const QString& name, QWidget* parent) : Plot(name, parent) {}

void DataPlot::draw(const DataPlotSpec& spec) {
    plot_->clearGraphs();
    plot_->clearPlottables();
    pointsDrawn_ = 0;
    for (auto [axis, log, label] :
         {std::tuple{plot_->xAxis, spec.xLog, spec.xLabel}, std::tuple{plot_->yAxis, spec.yLog, spec.yLabel}}) {
        axis->setLabel(label);
        axis->setScaleType(log ? QCPAxis::stLogarithmic : QCPAxis::stLinear);
        if (log) {
            axis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
            axis->setNumberFormat("eb");  // 10^-3, not 0.001
            axis->setNumberPrecision(0);
        } else {
            axis->setTicker(QSharedPointer<QCPAxisTicker>(new QCPAxisTicker));
            axis->setNumberFormat("g");
            axis->setNumberPrecision(6);
        }
    }
    double xMin = 1e300, xMax = -1e300, yMin = 1e300, yMax = -1e300;
    for (std::size_t i = 0; i < spec.series.size(); ++i) {
        const DataSeries& s = spec.series[i];
        QCPGraph* graph = plot_->addGraph();
        graph->setName(s.label);
        graph->setPen(seriesPen(int(i), 2));
        graph->setScatterStyle(QCPScatterStyle(seriesMarker(int(i)), 6));
        QVector<double> errors;
        for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
            const double x = s.x[k], y = s.y[k];
            if (!std::isfinite(x) || !std::isfinite(y) || (spec.xLog && !(x > 0.0)) || (spec.yLog && !(y > 0.0)))
                continue;
            graph->addData(x, y);
            const double e = k < s.yError.size() ? s.yError[k] : 0.0;
            errors.push_back(e);
            ++pointsDrawn_;
            xMin = std::min(xMin, x);
            xMax = std::max(xMax, x);
            yMin = std::min(yMin, spec.yLog ? y : y - e);
            yMax = std::max(yMax, y + e);
        }
        if (std::any_of(errors.begin(), errors.end(), [](double e) { return e > 0.0; })) {
            auto* bars = new QCPErrorBars(plot_->xAxis, plot_->yAxis);
            bars->removeFromLegend();
            bars->setDataPlottable(graph);
            bars->setData(errors);
            bars->setPen(QPen(seriesColour(int(i)), 1));
        }
    }
    const auto range = [](double lo, double hi, bool log) {
        if (lo > hi) return log ? QCPRange(1e-4, 1.0) : QCPRange(0.0, 1.0);
        if (log) {  // whole decades, so that the ticker labels powers of ten
            const double l = std::pow(10.0, std::floor(std::log10(lo / 1.2)));
            const double h = std::pow(10.0, std::ceil(std::log10(hi * 1.2)));
            return QCPRange(l, h > l ? h : 10.0 * l);
        }
        const double pad = hi > lo ? 0.05 * (hi - lo) : std::max(1.0, std::abs(lo)) * 0.1;
        return QCPRange(lo - pad, hi + pad);
    };
    plot_->xAxis->setRange(range(xMin, xMax, spec.xLog));
    plot_->yAxis->setRange(range(yMin, yMax, spec.yLog));
    if (!spec.title.isEmpty()) setTitle(spec.title);
    if (!legendMoved_) {  // beside the axes: a sweep's curves would hide under it
        legendOutside();
        legendMoved_ = true;
    }
    plot_->replot();
}

PlotPanel::PlotPanel(QWidget* parent) : QWidget(parent) {
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(0, 0, 0, 0);
    tabs_ = new QTabWidget(this);
    layout->addWidget(tabs_);
}

void PlotPanel::addPlot(Plot* plot) {
    plots_.push_back(plot);
    tabs_->addTab(plot, plot->name());
}

}  // namespace tyndall::studio
