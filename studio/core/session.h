// The studio's document: the project being edited, where it lives, and the undo stack every edit goes through.
// Loading never replaces the current project unless the new one is valid; saving is atomic and keeps the file's text
// where values did not change (saveProject against the file as last read or saved).
#pragma once

#include "tyndall/project/project.h"

#include <QObject>
#include <QString>
#include <QUndoStack>

#include <functional>

namespace tyndall::studio {

class Session : public QObject {
    Q_OBJECT
public:
    explicit Session(QObject* parent = nullptr);

    // Loads `path` with `overrides` (as the CLI's --set). On failure returns false with the error (file, field, what is
    // allowed) and keeps the current project. The overrides are edits of the file: saving writes them as such.
    bool open(const QString& path, QString* error, const std::vector<std::string>& overrides = {});
    bool save(QString* error);
    bool saveAs(const QString& path, QString* error);

    const Project& project() const { return project_; }
    const QString& path() const { return path_; }
    bool modified() const { return !undo_.isClean(); }
    QUndoStack* undoStack() { return &undo_; }

    // An undoable edit of view `view`'s parameter: `value` null restores the technique's default.
    void setParameter(int view, const std::string& name, const nlohmann::json& value);
    void setExposure(int view, double exposure);
    // An undoable edit of the scene by `overrides` ("camera.fovY=50", "lights[sun].irradiance=[3,3,3]": the CLI's
    // --set paths). The result is validated like a loaded file: on failure nothing changes and `error` says why.
    // Edits with the same non-negative mergeId in a row are one undo step (a drag).
    bool editScene(const std::vector<std::string>& overrides, const QString& text, QString* error, int mergeId = -1);
    // Authoring views, each one undoable edit of the project, validated like a file and by the technique (it must
    // be able to render the view's part): on failure nothing changes and `error` says why. A new view is named after
    // its technique (unique); a technique change drops the parameters of the old one. They emit sceneChanged, with
    // the views' list changed.
    bool addView(const std::string& technique, QString* error);
    // Whether a view of `technique` could be added (it renders something of the scene), else why not.
    bool canAddView(const std::string& technique, QString* why) const;
    bool duplicateView(int view, QString* error);
    bool removeView(int view, QString* error);
    bool renameView(int view, const std::string& name, QString* error);
    bool setTechnique(int view, const std::string& technique, QString* error);
    // The lights and media the view renders (its technique must support each).
    bool setViewPart(int view, const ScenePart& part, QString* error);
    // An undoable replacement of the whole project by `json` (crash recovery); it must be a valid project.
    void editProjectJson(const nlohmann::json& json, const QString& text);
    void applyProjectJson(const nlohmann::json& json);
    // What the commands call; not undoable by themselves.
    void applyParameter(int view, const std::string& name, const nlohmann::json& value);
    void applyExposure(int view, double exposure);

signals:
    void projectReplaced();        // a new project was opened
    void viewChanged(int view);    // a view's parameters or exposure changed
    void sceneChanged();           // the scene (camera, media, lights, ...) changed
    void modifiedChanged(bool modified);

private:
    bool editViews(const std::function<void(nlohmann::json& views)>& edit, const QString& text, QString* error);
    std::string uniqueViewName(const std::string& stem) const;

    Project project_;
    QString path_;
    ProjectFile file_;  // the file as last read or saved, without overrides: what a save is an edit of
    QUndoStack undo_;
};

}  // namespace tyndall::studio
