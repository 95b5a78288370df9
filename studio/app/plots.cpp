#include "plots.h"

#include <qcustomplot.h>

#include <QLabel>
#include <QSvgGenerator>
#include <QTabWidget>
#include <QVBoxLayout>

#include <cmath>
#include <numbers>

namespace tyndall::studio {

namespace {

// Distinct colours for series (Okabe-Ito, colour-blind safe).
QColor seriesColour(int i) {
    static const QColor colours[] = {QColor(0, 114, 178), QColor(230, 159, 0), QColor(0, 158, 115), QColor(204, 121, 167),
                                     QColor(86, 180, 233), QColor(213, 94, 0), QColor(240, 228, 66), QColor(0, 0, 0)};
    return colours[i % 8];
}

}  // namespace

Plot::Plot(const QString& name, QWidget* parent) : QWidget(parent), name_(name) {
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(2, 2, 2, 2);
    plot_ = new QCustomPlot(this);
    plot_->setObjectName("plot:" + name);
    plot_->setMinimumSize(320, 220);
    plot_->legend->setVisible(true);
    caption_ = new QLabel(this);
    caption_->setWordWrap(true);
    layout->addWidget(plot_, 1);
    layout->addWidget(caption_);
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
    plot_->yAxis->setLabel("relMSE against the reference (or the view chosen with Shift+1-9)");
    caption_->setText("Each view's error against its reference as it refines (log-log).");
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
        graph->setPen(QPen(seriesColour(int(i)), 2));
        graph->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssCircle, 5));
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
    caption_->setText("Move the cursor over a view whose technique samples distances (WVDS).");
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
    caption_->setText(QString::fromStdString(result.title));
    plot_->replot(QCustomPlot::rpQueuedReplot);  // once per pass of the event loop
}

void PdfPlot::showMessage(const QString& message) {
    plot_->clearGraphs();
    plot_->replot(QCustomPlot::rpQueuedReplot);  // once per pass of the event loop
    caption_->setText(message);
}

PhasePlot::PhasePlot(Kind kind, QWidget* parent)
    : Plot(kind == Kind::Polar ? "phase-polar" : "phase-cosine", parent), kind_(kind) {
    if (kind_ == Kind::Polar) {
        // p(theta) as the distance from the origin in the scattering plane: forward scattering points right (+x).
        plot_->xAxis->setLabel("p(theta) cos theta  [1/sr]");
        plot_->yAxis->setLabel("p(theta) sin theta  [1/sr]");
        caption_->setText("Phase functions of the project's media in the scattering plane (the selected view's "
                          "media bold); light arrives from the left.");
    } else {
        plot_->yAxis->setScaleType(QCPAxis::stLogarithmic);
        plot_->yAxis->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
        plot_->yAxis->setNumberFormat("eb");
        plot_->yAxis->setNumberPrecision(0);
        plot_->xAxis->setLabel("cos theta");
        plot_->yAxis->setLabel("p  [1/sr]");
        caption_->setText("Phase functions of the project's media over the cosine of the scattering angle (log).");
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
