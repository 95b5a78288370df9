// The scene panel: the camera, every medium and every light as fields generated from the project's own JSON (numbers
// and RGB triples), each edit an undoable, validated scene edit (Session::editScene) addressed by the CLI's --set
// paths. An invalid value is refused with the reason in the panel, and the project stays as it was.
#pragma once

#include "session.h"

#include <QWidget>

class QFormLayout;
class QLabel;

namespace tyndall::studio {

class ScenePanel : public QWidget {
    Q_OBJECT
public:
    ScenePanel(Session& session, QWidget* parent = nullptr);
    void rebuild();
    const QString& lastError() const { return lastError_; }

private:
    void addField(const QString& label, const std::string& path, const nlohmann::json& value);

    Session& session_;
    QFormLayout* form_ = nullptr;
    QLabel* status_ = nullptr;
    QString lastError_;
    bool updating_ = false;
};

}  // namespace tyndall::studio
