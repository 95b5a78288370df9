#include "snapshot_store.h"

#include "tyndall/core/error.h"
#include "tyndall/core/output.h"
#include "tyndall/image/image_io.h"

#include <QDir>
#include <QFile>
#include <QFileInfo>

#include <fstream>
#include <sstream>

namespace tyndall::studio {

namespace {
constexpr const char* kIndexFile = "snapshots.json";
constexpr int kFormatVersion = 1;

QString imageFileOf(std::size_t index) {
    return QString("snapshot-%1.exr").arg(index + 1, 3, 10, QLatin1Char('0'));
}
}  // namespace

SnapshotStore::SnapshotStore(Session& session, QObject* parent) : QObject(parent), session_(session) {}

int SnapshotStore::take(int view, std::shared_ptr<const Image> image) {
    const std::vector<View>& views = session_.project().views;
    if (view < 0 || view >= int(views.size()) || !image) return -1;
    const View& v = views[std::size_t(view)];
    Snapshot shot;
    shot.view = view;
    shot.viewName = v.name;
    shot.image = std::move(image);
    shot.parameters = v.parameters;
    shot.exposure = v.exposure;
    shot.name = QString("%1 #%2").arg(QString::fromStdString(v.name)).arg(snapshots_.size() + 1);
    snapshots_.push_back(std::move(shot));
    emit changed();
    return int(snapshots_.size()) - 1;
}

bool SnapshotStore::restore(int index) {
    if (index < 0 || index >= int(snapshots_.size())) return false;
    const Snapshot& s = snapshots_[std::size_t(index)];
    if (s.view < 0 || s.view >= int(session_.project().views.size())) return false;
    const nlohmann::json current = session_.project().views[std::size_t(s.view)].parameters;
    session_.undoStack()->beginMacro("restore " + s.name);
    for (const auto& [key, value] : current.items())
        if (!s.parameters.contains(key)) session_.setParameter(s.view, key, nlohmann::json());
    for (const auto& [key, value] : s.parameters.items())
        session_.setParameter(s.view, key, value);
    session_.setExposure(s.view, s.exposure);
    session_.undoStack()->endMacro();
    return true;
}

void SnapshotStore::followViews() {
    const std::vector<View>& views = session_.project().views;
    std::vector<Snapshot> kept;
    for (Snapshot& s : snapshots_) {
        int found = -1;
        for (std::size_t v = 0; v < views.size(); ++v)
            if (views[v].name == s.viewName) found = int(v);
        if (found < 0 && s.view >= 0 && s.view < int(views.size()) && viewCount_ == int(views.size()))
            found = s.view;  // renamed
        s.view = found;
        if (found >= 0) s.viewName = views[std::size_t(found)].name;
        kept.push_back(std::move(s));
    }
    snapshots_ = std::move(kept);
    viewCount_ = int(views.size());
    emit changed();
}

void SnapshotStore::clear() {
    if (snapshots_.empty()) return;
    snapshots_.clear();
    emit changed();
}

QString SnapshotStore::folderOf(const QString& projectPath) {
    const QFileInfo file(projectPath);
    return file.absoluteDir().filePath(file.completeBaseName() + ".snapshots");
}

bool SnapshotStore::save(const QString& projectPath, QString* error) const {
    const QDir folder(folderOf(projectPath));
    try {
        if (snapshots_.empty() && !folder.exists()) return true;
        if (!folder.exists() && !QDir().mkpath(folder.path()))
            throw OutputError("cannot create the snapshot folder " + folder.path().toStdString());
        OutputSet outputs;
        nlohmann::json index = {{"tyndallSnapshots", kFormatVersion}, {"snapshots", nlohmann::json::array()}};
        QStringList written;
        for (std::size_t i = 0; i < snapshots_.size(); ++i) {
            const Snapshot& s = snapshots_[i];
            const QString image = imageFileOf(i);
            outputs.stage(folder.filePath(image).toStdString(), encodeImage(*s.image, image.toStdString()));
            written << image;
            index["snapshots"].push_back({{"name", s.name.toStdString()},
                                          {"view", s.viewName},
                                          {"parameters", s.parameters},
                                          {"exposure", s.exposure},
                                          {"image", image.toStdString()}});
        }
        outputs.stage(folder.filePath(kIndexFile).toStdString(), index.dump(2) + "\n");
        outputs.commit();
        // The images of snapshots that are gone (the index no longer names them).
        for (const QString& old : folder.entryList({"snapshot-*.exr"}, QDir::Files))
            if (!written.contains(old)) QFile::remove(folder.filePath(old));
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

bool SnapshotStore::load(const QString& projectPath, QString* error) {
    snapshots_.clear();
    viewCount_ = int(session_.project().views.size());
    const QDir folder(folderOf(projectPath));
    const QString indexPath = folder.filePath(kIndexFile);
    if (!QFileInfo::exists(indexPath)) {
        emit changed();
        return true;
    }
    try {
        std::ifstream in(indexPath.toStdString());
        std::stringstream text;
        text << in.rdbuf();
        if (!in) throw InputError(indexPath.toStdString() + ": cannot read the file");
        nlohmann::json index;
        try {
            index = nlohmann::json::parse(text.str());
        } catch (const nlohmann::json::parse_error& e) {
            throw InputError(indexPath.toStdString() + ": malformed JSON (" + e.what() + ")");
        }
        if (!index.is_object() || index.value("tyndallSnapshots", 0) != kFormatVersion || !index["snapshots"].is_array())
            throw InputError(indexPath.toStdString() + ": not a snapshot index of format " +
                             std::to_string(kFormatVersion) + " ({\"tyndallSnapshots\": 1, \"snapshots\": [...]})");
        const std::vector<View>& views = session_.project().views;
        std::vector<Snapshot> loaded;
        for (std::size_t i = 0; i < index["snapshots"].size(); ++i) {
            const nlohmann::json& s = index["snapshots"][i];
            const std::string field = indexPath.toStdString() + ": snapshots[" + std::to_string(i) + "]";
            if (!s.is_object() || !s.value("name", nlohmann::json()).is_string() ||
                !s.value("view", nlohmann::json()).is_string() || !s.value("image", nlohmann::json()).is_string() ||
                !s.value("exposure", nlohmann::json()).is_number() || !s.value("parameters", nlohmann::json()).is_object())
                throw InputError(field + ": needs name, view and image (strings), exposure (a number) and parameters "
                                         "(an object)");
            const std::string image = s["image"];
            if (image.find('/') != std::string::npos || image.find('\\') != std::string::npos)
                throw InputError(field + ".image: '" + image + "' is not a file name in the snapshot folder");
            Snapshot shot;
            shot.view = -1;
            for (std::size_t v = 0; v < views.size(); ++v)
                if (views[v].name == s["view"].get<std::string>()) shot.view = int(v);
            if (shot.view < 0) continue;  // the view is gone: its snapshot with it
            shot.viewName = s["view"].get<std::string>();
            shot.name = QString::fromStdString(s["name"].get<std::string>());
            shot.parameters = s["parameters"];
            shot.exposure = s["exposure"];
            shot.image = std::make_shared<const Image>(readImage(folder.filePath(QString::fromStdString(image)).toStdString()));
            loaded.push_back(std::move(shot));
        }
        snapshots_ = std::move(loaded);
        emit changed();
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        emit changed();
        return false;
    }
}

}  // namespace tyndall::studio
