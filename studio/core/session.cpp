#include "session.h"

#include "tyndall/core/error.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <QUndoCommand>

#include <algorithm>

namespace tyndall::studio {

namespace {

class SetParameterCommand final : public QUndoCommand {
public:
    SetParameterCommand(Session& session, int view, std::string name, nlohmann::json before, nlohmann::json after)
        : session_(session), view_(view), name_(std::move(name)), before_(std::move(before)), after_(std::move(after)) {
        setText(QString::fromStdString("set " + session.project().views[std::size_t(view)].name + "." + name_));
    }
    void undo() override { session_.applyParameter(view_, name_, before_); }
    void redo() override { session_.applyParameter(view_, name_, after_); }
    int id() const override { return 1; }
    // Dragging a slider is one edit: consecutive changes of the same number (or colour) merge. Choices (an
    // enumeration's value, a switch) are steps of their own: undo goes back one choice, not to the first.
    bool mergeWith(const QUndoCommand* other) override {
        const auto* o = dynamic_cast<const SetParameterCommand*>(other);
        if (!o || o->view_ != view_ || o->name_ != name_) return false;
        if (!continuous(after_) || !continuous(o->after_)) return false;
        after_ = o->after_;
        return true;
    }

private:
    static bool continuous(const nlohmann::json& v) {
        if (v.is_array()) return std::all_of(v.begin(), v.end(), [](const nlohmann::json& e) { return e.is_number(); });
        return v.is_number();
    }

    Session& session_;
    int view_;
    std::string name_;
    nlohmann::json before_, after_;
};

class SetExposureCommand final : public QUndoCommand {
public:
    SetExposureCommand(Session& session, int view, double before, double after)
        : session_(session), view_(view), before_(before), after_(after) {
        setText("exposure");
    }
    void undo() override { session_.applyExposure(view_, before_); }
    void redo() override { session_.applyExposure(view_, after_); }

private:
    Session& session_;
    int view_;
    double before_, after_;
};

class EditSceneCommand final : public QUndoCommand {
public:
    EditSceneCommand(Session& session, nlohmann::json before, nlohmann::json after, const QString& text, int mergeId)
        : session_(session), before_(std::move(before)), after_(std::move(after)), mergeId_(mergeId) {
        setText(text);
    }
    void undo() override { session_.applyProjectJson(before_); }
    void redo() override { session_.applyProjectJson(after_); }
    int id() const override { return mergeId_ < 0 ? -1 : 1000 + mergeId_; }
    bool mergeWith(const QUndoCommand* other) override {
        const auto* o = dynamic_cast<const EditSceneCommand*>(other);
        if (!o || o->mergeId_ != mergeId_) return false;
        after_ = o->after_;
        return true;
    }

private:
    Session& session_;
    nlohmann::json before_, after_;
    int mergeId_;
};

}  // namespace

Session::Session(QObject* parent) : QObject(parent) {
    connect(&undo_, &QUndoStack::cleanChanged, this, [this](bool clean) { emit modifiedChanged(!clean); });
}

bool Session::open(const QString& path, QString* error, const std::vector<std::string>& overrides) {
    try {
        const std::string file = path.toStdString();
        const std::string text = readProjectText(file);
        Project loaded = parseProject(techniqueCatalogue(), text, file, overrides);
        // A save compares against the file as it loads without the overrides, so that they are saved as edits of it,
        // in as few lines as other edits. A file that is valid only with its overrides has no such project: without
        // its text, it is saved whole.
        ProjectFile original{.path = file, .text = text, .project = loaded};
        if (!overrides.empty()) {
            try {
                original.project = parseProject(techniqueCatalogue(), text, file);
            } catch (const InputError&) {
                original.text.clear();
            }
        }
        project_ = std::move(loaded);
        file_ = std::move(original);
        path_ = path;
        undo_.clear();
        undo_.setClean();
        emit projectReplaced();
        emit modifiedChanged(false);
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

bool Session::save(QString* error) {
    return saveAs(path_, error);
}

bool Session::saveAs(const QString& path, QString* error) {
    try {
        file_ = saveProject(techniqueCatalogue(), project_, path.toStdString(), file_);
        path_ = path;
        undo_.setClean();
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

void Session::setParameter(int view, const std::string& name, const nlohmann::json& value) {
    const nlohmann::json& parameters = project_.views[std::size_t(view)].parameters;
    const nlohmann::json before = parameters.contains(name) ? parameters[name] : nlohmann::json();
    if (before == value) return;
    undo_.push(new SetParameterCommand(*this, view, name, before, value));
}

void Session::setExposure(int view, double exposure) {
    const double before = project_.views[std::size_t(view)].exposure;
    if (before == exposure) return;
    undo_.push(new SetExposureCommand(*this, view, before, exposure));
}

bool Session::editScene(const std::vector<std::string>& overrides, const QString& text, QString* error, int mergeId) {
    try {
        const nlohmann::json before = projectToJson(project_);
        const Project edited = parseProject(techniqueCatalogue(), before.dump(), path_.toStdString(), overrides);
        const nlohmann::json after = projectToJson(edited);
        if (after == before) return true;
        undo_.push(new EditSceneCommand(*this, before, after, text, mergeId));
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

bool Session::editViews(const std::function<void(nlohmann::json& views)>& edit, const QString& text, QString* error) {
    try {
        const nlohmann::json before = projectToJson(project_);
        nlohmann::json after = before;
        edit(after["views"]);
        const Project edited = projectFromJson(techniqueCatalogue(), after, path_.toStdString());
        for (const View& v : edited.views)  // each view must render: its technique supports its part
            makeViewJob(edited, path_.toStdString(), v.name);
        undo_.push(new EditSceneCommand(*this, before, projectToJson(edited), text, -1));
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

std::string Session::uniqueViewName(const std::string& stem) const {
    auto taken = [&](const std::string& name) {
        return std::any_of(project_.views.begin(), project_.views.end(), [&](const View& v) { return v.name == name; });
    };
    if (!taken(stem)) return stem;
    for (int i = 2;; ++i)
        if (!taken(stem + " " + std::to_string(i))) return stem + " " + std::to_string(i);
}

bool Session::canAddView(const std::string& technique, QString* why) const {
    try {
        nlohmann::json after = projectToJson(project_);
        const std::string name = uniqueViewName(technique);
        after["views"].push_back({{"name", name}, {"technique", technique}});
        const Project edited = projectFromJson(techniqueCatalogue(), after, path_.toStdString());
        const RenderJob job = makeViewJob(edited, path_.toStdString(), name);
        // A volumetric technique that renders none of the scene's media (ISV without a particle medium) would show
        // the surfaces alone: nothing it is for.
        const Scene& part = job.request.scene;
        const bool sceneHasMedia = !edited.scene.media.empty() || !edited.scene.particleMedia.empty();
        if (sceneHasMedia && part.media.empty() && part.particleMedia.empty()) {
            std::string leftOut;
            for (const std::string& line : job.leftOut)
                leftOut += (leftOut.empty() ? "" : "; ") + line;
            if (why)
                *why = QString::fromStdString(job.technique->displayName() + " renders none of this scene's media" +
                                              (leftOut.empty() ? std::string() : ": it leaves out " + leftOut));
            return false;
        }
        return true;
    } catch (const std::exception& e) {
        if (why) *why = QString::fromStdString(e.what());
        return false;
    }
}

bool Session::addView(const std::string& technique, QString* error) {
    const std::string name = uniqueViewName(technique);
    return editViews([&](nlohmann::json& views) { views.push_back({{"name", name}, {"technique", technique}}); },
                     QString::fromStdString("add view " + name), error);
}

bool Session::duplicateView(int view, QString* error) {
    if (view < 0 || view >= int(project_.views.size())) return false;
    const std::string name = uniqueViewName(project_.views[std::size_t(view)].name + " copy");
    return editViews(
        [&](nlohmann::json& views) {
            nlohmann::json copy = views[std::size_t(view)];
            copy["name"] = name;
            views.insert(views.begin() + view + 1, copy);
        },
        QString::fromStdString("duplicate view " + project_.views[std::size_t(view)].name), error);
}

bool Session::removeView(int view, QString* error) {
    if (view < 0 || view >= int(project_.views.size())) return false;
    return editViews([&](nlohmann::json& views) { views.erase(views.begin() + view); },
                     QString::fromStdString("remove view " + project_.views[std::size_t(view)].name), error);
}

bool Session::renameView(int view, const std::string& name, QString* error) {
    if (view < 0 || view >= int(project_.views.size())) return false;
    if (name == project_.views[std::size_t(view)].name) return true;
    return editViews([&](nlohmann::json& views) { views[std::size_t(view)]["name"] = name; },
                     QString::fromStdString("rename view " + project_.views[std::size_t(view)].name), error);
}

bool Session::setTechnique(int view, const std::string& technique, QString* error) {
    if (view < 0 || view >= int(project_.views.size())) return false;
    if (technique == project_.views[std::size_t(view)].technique) return true;
    return editViews(
        [&](nlohmann::json& views) {
            views[std::size_t(view)]["technique"] = technique;
            views[std::size_t(view)]["parameters"] = nlohmann::json::object();
        },
        QString::fromStdString("technique of " + project_.views[std::size_t(view)].name), error);
}

bool Session::setViewPart(int view, const ScenePart& part, QString* error) {
    if (view < 0 || view >= int(project_.views.size())) return false;
    return editViews(
        [&](nlohmann::json& views) {
            views[std::size_t(view)]["lights"] = part.lights;
            views[std::size_t(view)]["media"] = part.media;
        },
        QString::fromStdString("lights and media of " + project_.views[std::size_t(view)].name), error);
}

void Session::editProjectJson(const nlohmann::json& json, const QString& text) {
    projectFromJson(techniqueCatalogue(), json, path_.toStdString());  // throws before anything changes
    undo_.push(new EditSceneCommand(*this, projectToJson(project_), json, text, -1));
}

void Session::applyProjectJson(const nlohmann::json& json) {
    project_ = projectFromJson(techniqueCatalogue(), json, path_.toStdString());
    emit sceneChanged();
}

void Session::applyParameter(int view, const std::string& name, const nlohmann::json& value) {
    nlohmann::json& parameters = project_.views[std::size_t(view)].parameters;
    if (value.is_null())
        parameters.erase(name);
    else
        parameters[name] = value;
    emit viewChanged(view);
}

void Session::applyExposure(int view, double exposure) {
    project_.views[std::size_t(view)].exposure = exposure;
    emit viewChanged(view);
}

}  // namespace tyndall::studio
