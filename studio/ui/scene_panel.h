// The scene panel: the camera, every medium (its coefficients, its phase function's type and the parameters that type
// uses), every light and every material (its type and the parameters that type uses) as fields generated from the
// project's own JSON (numbers, RGB triples and choices), each edit an undoable, validated scene edit
// (Session::editScene) addressed by the CLI's --set paths. An invalid value is refused with the reason in the panel, and the project stays as it was. Edits update the
// fields in place; only a change of the rows (another project, a light added) rebuilds them, from the event loop.
#pragma once

#include "session.h"

class QDoubleSpinBox;

#include <QWidget>

#include <functional>
#include <map>
#include <string>
#include <vector>

class QComboBox;
class QFormLayout;
class QLabel;

namespace tyndall::studio {

class ScenePanel : public QWidget {
    Q_OBJECT
public:
    ScenePanel(Session& session, QWidget* parent = nullptr);
    void rebuild();
    // The animation whose click impulse (radius, speed) the panel edits, for a project with particle media.
    void setAnimation(class Animation* animation);
    const QString& lastError() const { return lastError_; }

private:
    struct Field {
        QString section;  // a section's title (and no path), or empty for a field
        QString label;
        std::string path;  // the --set path
        nlohmann::json value;
        QStringList choices;  // a string field's allowed values (a combo box)
    };
    std::vector<Field> fields() const;  // the rows the project gives, in order
    void refresh();  // the rows' values in place when the rows are the same, else a rebuild from the event loop
    void addField(const Field& field);

    Session& session_;
    class Animation* animation_ = nullptr;
    QFormLayout* form_ = nullptr;
    QLabel* status_ = nullptr;
    QString lastError_;
    bool updating_ = false;
    bool rebuildQueued_ = false;
    std::vector<std::string> builtPaths_;
    std::map<std::string, std::function<void(const nlohmann::json&)>> setters_;
};

}  // namespace tyndall::studio
