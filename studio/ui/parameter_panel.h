// The parameter panel of the selected view, generated from its technique's reflected parameters (ParamInfo): spin
// boxes with sliders for ranges, check boxes, combo boxes for enumerations, three fields for colours, tooltips from
// the parameters' docs. Every edit goes through the session's undo stack; the widgets follow undo and redo.
// An edit (its own, an undo, a scene edit) updates the widgets' values in place: an editor is never deleted inside its
// own signal (the exposure spin box was, from its stepBy, and the studio crashed in QWidget::style()). Only a change
// of what the panel shows (another view, technique or project) rebuilds it, from the event loop.
#pragma once

#include "session.h"

#include "tyndall/core/params.h"

#include <QWidget>

#include <functional>
#include <optional>
#include <string>
#include <vector>

class QFormLayout;

namespace tyndall::studio {

class ParameterPanel : public QWidget {
    Q_OBJECT
public:
    ParameterPanel(Session& session, QWidget* parent = nullptr);

    void showView(int view);
    int view() const { return view_; }

signals:
    void techniqueRefused(const QString& reason);  // the technique chosen cannot render the view

private:
    void rebuild();
    void refresh();          // the widgets' values from the project, or a rebuild when the rows would differ
    void scheduleRebuild();  // once, from the event loop
    // The view's parameters, and in `key` what the rows depend on (the view, its technique, its parameters' names and
    // types, or the error that makes them unavailable).
    std::optional<ParamSet> parameters(std::string& key) const;

    Session& session_;
    int view_ = -1;
    QFormLayout* form_ = nullptr;
    bool updating_ = false;
    bool rebuildQueued_ = false;
    std::string builtKey_;
    // Each row's way to show a value of the view (its exposure, or its parameter from the technique's ParamSet).
    std::vector<std::function<void(const View&, const ParamSet&)>> refreshers_;
};

}  // namespace tyndall::studio
