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
    // The legend in a column of its own right of the axes, where it hides no curve.
    void legendOutside();
    QCustomPlot* plot_;
    QLabel* caption_;
    QCPTextElement* title_ = nullptr;

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

// The LTSD tables the studio has read, by phase type, each loaded once (and again after setDirectory): the table, its
// error over g (computed once, ~10 ms), or the loader's error.
class LtsdTables {
public:
    struct Entry {
        std::shared_ptr<const LtsdTable> table;                       // null: `error` says why
        std::shared_ptr<const std::vector<LtsdFitError>> errorCurve;  // over the table's g range
        QString error;
    };
    // "" is the default search (ltsdTablesDirectory).
    void setDirectory(const QString& directory);
    const QString& directory() const { return directory_; }
    const Entry& get(const std::string& phaseType);
    static constexpr int kErrorSamples = 101;

private:
    QString directory_;
    std::map<std::string, Entry> entries_;
};

// What the LTSD plots show: a medium's HG phase function and its table, or why there is none.
struct LtsdFit {
    QString medium;  // its name, and the view it belongs to, for the caption
    QString view;
    double g = 0.0;
    std::shared_ptr<const LtsdTable> table;  // null: `message` says why
    std::shared_ptr<const std::vector<LtsdFitError>> errorCurve;
    QString message;
};

// The fit of a medium's phase function: its table when the phase function is HG and the table loads, else the reason.
LtsdFit ltsdFitOf(const QString& medium, const QString& view, const PhaseFunction& phase, LtsdTables& tables);

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
