// The parameter panel of the selected view, generated from its technique's reflected parameters (ParamInfo): spin
// boxes with sliders for ranges, check boxes, combo boxes for enumerations, three fields for colours, tooltips from
// the parameters' docs. Every edit goes through the session's undo stack; the widgets follow undo and redo.
#pragma once

#include "session.h"

#include <QWidget>

class QFormLayout;

namespace tyndall::studio {

class ParameterPanel : public QWidget {
    Q_OBJECT
public:
    ParameterPanel(Session& session, QWidget* parent = nullptr);

    void showView(int view);
    int view() const { return view_; }

private:
    void rebuild();

    Session& session_;
    int view_ = -1;
    QFormLayout* form_ = nullptr;
    bool updating_ = false;
};

}  // namespace tyndall::studio
