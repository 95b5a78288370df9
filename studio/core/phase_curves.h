// What the studio's phase-function plots show, without the plots (ui/plots.h draws them): the project's media's phase
// functions as curves (the current view's own first and bold), and the LTSD fit of the current view's first medium
// with its error over g, from the LTSD tables, each read once.
#pragma once

#include "tyndall/core/scene.h"
#include "tyndall/project/project.h"
#include "tyndall/tables/ltsd_table.h"

#include <QString>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace tyndall::studio {

// A phase function to plot: its value per steradian at mu = cos theta.
struct PhaseCurve {
    QString name;
    std::function<double(double mu)> value;
    bool selected = false;  // drawn bold (the selected view's medium)
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

// Every medium of `project` as a curve, those of view `view` (-1: none) first and selected.
std::vector<PhaseCurve> phaseCurves(const Project& project, int view);
// The fit of view `view`'s first medium (a technique such as LTSD handles one at a time), or why there is none.
LtsdFit ltsdFitOfView(const Project& project, int view, LtsdTables& tables);

}  // namespace tyndall::studio
