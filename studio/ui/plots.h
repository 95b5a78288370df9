// Plot panels in a dock (QCustomPlot), behind one small interface so that techniques can add plots later (the LTSD
// technique's polar plot of the phase function against its fit will be one more Plot): each has a name, a QCustomPlot,
// and exports itself to PNG and SVG.
//   ConvergencePlot  error of each view against its reference over spp and over time, log-log;
//   PdfPlot          at the pixel under the cursor, the sampled-distance histograms and analytic pdfs of a technique
//                    that provides them through its "distances" probe (WVDS does);
//   PhasePlot        phase functions, as a polar plot over the scattering angle or as a curve over cos theta, any
//                    number overlaid (the selected medium's first and bold; a fit can be added as one more curve).
//   LtsdPolarPlot    the selected view's medium's phase function against its LTSD fit, in a plane through omega_o
//                    (the LTSD paper's Fig. 12), both hemispheres, the fit's jump at the horizon left open;
//   LtsdErrorPlot    the fit's error against g, the medium's g marked.
#pragma once

#include "comparison_model.h"
#include "phase_curves.h"

#include "tyndall/core/scene.h"
#include "tyndall/framework/technique.h"
#include "tyndall/tables/ltsd_table.h"

#include <QString>
#include <QWidget>

#include <functional>
#include <map>
#include <memory>
#include <vector>

class QCheckBox;
class QCustomPlot;
class QCPCurve;
class QCPGraph;
class QCPItemStraightLine;
class QCPTextElement;
class QTabWidget;
class QLabel;
class QScrollArea;

namespace tyndall::studio {

class Plot : public QWidget {
    Q_OBJECT
public:
    explicit Plot(const QString& name, QWidget* parent = nullptr);
    const QString& name() const { return name_; }
    QCustomPlot* plot() { return plot_; }
    QString caption() const;
    // The line above the plot, part of its exports (empty: none).
    QString title() const;
    // Writes the plot; the format follows the suffix (.png or .svg). Returns false with the reason.
    bool exportTo(const QString& path, QString* error);

protected:
    void setTitle(const QString& text);
    void setCaption(const QString& text);
    void resizeEvent(QResizeEvent* event) override;
    // The legend in a column of its own right of the axes, where it hides no curve.
    void legendOutside();
    QCustomPlot* plot_;
    QLabel* caption_;
    QCPTextElement* title_ = nullptr;

private:
    void fitCaption();
    static constexpr int kCaptionLines = 3;
    QScrollArea* captionArea_;
    QString name_;
};

class ConvergencePlot final : public Plot {
    Q_OBJECT
public:
    explicit ConvergencePlot(QWidget* parent = nullptr);
    // Every view's points; x is spp or seconds.
    void setSeries(const std::vector<QString>& names, const std::vector<std::vector<ConvergencePoint>>& points);
    void setOverTime(bool overTime);

private:
    void redraw();
    std::vector<QString> names_;
    std::vector<std::vector<ConvergencePoint>> points_;
    bool overTime_ = false;
};

class PdfPlot final : public Plot {
    Q_OBJECT
public:
    explicit PdfPlot(QWidget* parent = nullptr);
    void showProbe(const ProbeResult& result);
    void showMessage(const QString& message);
};

class PhasePlot final : public Plot {
    Q_OBJECT
public:
    enum class Kind { Polar, OverCosine };
    explicit PhasePlot(Kind kind, QWidget* parent = nullptr);
    void setCurves(std::vector<PhaseCurve> curves);
    const std::vector<PhaseCurve>& curves() const { return curves_; }
    static constexpr int kSamples = 361;  // points per curve

private:
    void redraw();
    Kind kind_;
    std::vector<PhaseCurve> curves_;
};

class LtsdPolarPlot final : public Plot {
    Q_OBJECT
public:
    explicit LtsdPolarPlot(QWidget* parent = nullptr);
    void showFit(const LtsdFit& fit);
    const LtsdFit& fit() const { return fit_; }
    // Radius: log10 of the value above a floor some decades under the peak (HG at g = 0.9 spans four decades), or
    // linear. Log by default.
    void setLogRadius(bool log);
    bool logRadius() const { return logRadius_; }
    // The radius drawn for a value (per sr) on the current scale; 0 at and below the log scale's floor.
    double radiusOf(double value) const;
    // The curves: HG closed over the whole circle, the fit in two pieces (upper: psi in (-pi/2, pi/2) around omega_o,
    // lower: psi in (pi/2, 3 pi/2)); null while a message is shown. Point k of each is the plane's direction
    // (sin psi, cos psi) times radiusOf(value), omega_o up.
    QCPCurve* phaseCurve() const { return phase_; }
    QCPCurve* fitUpperCurve() const { return fitUpper_; }
    QCPCurve* fitLowerCurve() const { return fitLower_; }
    static constexpr int kSamples = 720;  // points of ltsdPolarCurve; none falls on the horizon
    static QColor phaseColour();
    static QColor fitColour();

private:
    void redraw();
    void keepSquare();  // one unit as long on both axes and [-extent, extent] on both, whatever the widget's shape
    LtsdFit fit_;
    double extent_ = 0.0;
    bool logRadius_ = true;
    double floorLog10_ = 0.0;  // log scale: log10 of the value drawn at radius 0
    QCheckBox* logBox_;
    QCPCurve *phase_ = nullptr, *fitUpper_ = nullptr, *fitLower_ = nullptr;
};

class LtsdErrorPlot final : public Plot {
    Q_OBJECT
public:
    explicit LtsdErrorPlot(QWidget* parent = nullptr);
    void showFit(const LtsdFit& fit);
    // The graphs (upper tv, lower tv, bound on a region's integral) and the marker at the medium's g (null while a
    // message is shown or the marker is hidden).
    QCPGraph* boundGraph() const { return bound_; }
    QCPItemStraightLine* marker() const { return marker_; }
    double markedG() const { return markedG_; }

private:
    QCPGraph* bound_ = nullptr;
    QCPItemStraightLine* marker_ = nullptr;
    double markedG_ = 0.0;
};

// A plot drawn from data alone: the sweep's plots (tyndall sweep writes their data as plots/plots.json, and
// tyndall-plot draws them). Each series is a curve with markers and, where given, error bars.
struct DataSeries {
    QString label;
    std::vector<double> x, y, yError;  // yError empty or one per point (0: none)
};
struct DataPlotSpec {
    QString title, xLabel, yLabel;
    bool xLog = false, yLog = false;
    std::vector<DataSeries> series;
};

class DataPlot final : public Plot {
    Q_OBJECT
public:
    explicit DataPlot(const QString& name, QWidget* parent = nullptr);
    void draw(const DataPlotSpec& spec);
    // The points drawn (a log axis leaves out values <= 0), for tests.
    int pointsDrawn() const { return pointsDrawn_; }

private:
    int pointsDrawn_ = 0;
    bool legendMoved_ = false;
};

// The dock's content: the plots in tabs.
class PlotPanel final : public QWidget {
    Q_OBJECT
public:
    explicit PlotPanel(QWidget* parent = nullptr);
    void addPlot(Plot* plot);
    const std::vector<Plot*>& plots() const { return plots_; }

private:
    QTabWidget* tabs_;
    std::vector<Plot*> plots_;
};

}  // namespace tyndall::studio
