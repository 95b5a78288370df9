// Plot panels in a dock (QCustomPlot), behind one small interface so that techniques can add plots later (the LTSD
// technique's polar plot of the phase function against its fit will be one more Plot): each has a name, a QCustomPlot,
// and exports itself to PNG and SVG.
//   ConvergencePlot  error of each view against its reference over spp and over time, log-log;
//   PdfPlot          at the pixel under the cursor, the sampled-distance histograms and analytic pdfs of a technique
//                    that provides them through its "distances" probe (WVDS does);
//   PhasePlot        phase functions, as a polar plot over the scattering angle or as a curve over cos theta, any
//                    number overlaid (the selected medium's first and bold; a fit can be added as one more curve).
#pragma once

#include "tyndall/technique.h"

#include <QString>
#include <QWidget>

#include <functional>
#include <vector>

class QCustomPlot;
class QTabWidget;
class QLabel;

namespace tyndall::studio {

class Plot : public QWidget {
    Q_OBJECT
public:
    explicit Plot(const QString& name, QWidget* parent = nullptr);
    const QString& name() const { return name_; }
    QCustomPlot* plot() { return plot_; }
    // Writes the plot; the format follows the suffix (.png or .svg). Returns false with the reason.
    bool exportTo(const QString& path, QString* error);

protected:
    QCustomPlot* plot_;
    QLabel* caption_;

private:
    QString name_;
};

// One point of a view's convergence: its error against the reference when it had `spp` samples.
struct ConvergencePoint {
    int spp = 0;
    double seconds = 0.0;
    double relMSE = 0.0;
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

// A phase function to plot: its value per steradian at mu = cos theta.
struct PhaseCurve {
    QString name;
    std::function<double(double mu)> value;
    bool selected = false;  // drawn bold (the selected view's medium)
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
