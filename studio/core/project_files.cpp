#include "project_files.h"

#include <QCryptographicHash>
#include <QDateTime>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QPointer>
#include <QSaveFile>
#include <QSettings>
#include <QStandardPaths>
#include <QThreadPool>

#include <nlohmann/json.hpp>

#include <memory>

namespace tyndall::studio {

namespace {
constexpr int kAutosaveIntervalMs = 20000;
constexpr int kRecentProjects = 8;
}  // namespace

ProjectFiles::ProjectFiles(Session& session, QObject* parent) : QObject(parent), session_(session) {
    writes_ = new QThreadPool(this);
    writes_->setMaxThreadCount(1);
    writes_->setExpiryTimeout(-1);
    timer_.setInterval(kAutosaveIntervalMs);
    connect(&timer_, &QTimer::timeout, this, [this] { autosaveNow(); });
    timer_.start();
    // Changes discarded on purpose stay unsaved until the next project or edit.
    connect(session_.undoStack(), &QUndoStack::indexChanged, this, [this] { discarded_ = false; });
    connect(&session_, &Session::projectReplaced, this, [this] { discarded_ = false; });
    connect(&session_, &Session::modifiedChanged, this, [this](bool modified) {
        // Saved, or undone back to the file: nothing to recover. (Opening a project is neither.)
        if (!modified && !opening_) removeAutosave();
    });
}

ProjectFiles::~ProjectFiles() {
    writes_->waitForDone();  // a failed write would say so
}

QString ProjectFiles::autosavePath(const QString& projectPath) {
    const QString dir = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave";
    QDir().mkpath(dir);
    const QByteArray hash =
        QCryptographicHash::hash(QFileInfo(projectPath).absoluteFilePath().toUtf8(), QCryptographicHash::Sha1).toHex();
    return dir + "/" + QFileInfo(projectPath).completeBaseName() + "-" + QString::fromLatin1(hash.left(12)) + ".json";
}

bool ProjectFiles::autosaveNow() {
    if (!session_.modified() || session_.path().isEmpty() || discarded_) return false;
    const QString path = autosavePath(session_.path());
    auto text = std::make_shared<const std::string>(projectToJson(session_.project()).dump(2) + "\n");
    QPointer<ProjectFiles> self(this);
    writes_->start([path, text, self] {
        QSaveFile file(path);
        if (file.open(QIODevice::WriteOnly) && file.write(text->data(), qint64(text->size())) >= 0 && file.commit())
            return;
        const QString message = "Autosave failed: cannot write " + path + " (" + file.errorString() + ")";
        QMetaObject::invokeMethod(
            self,
            [self, message] {
                if (self) emit self->autosaveFailed(message);
            },
            Qt::QueuedConnection);
    });
    return true;
}

void ProjectFiles::removeAutosave(const QString& projectPath) {
    const QString project = projectPath.isEmpty() ? session_.path() : projectPath;
    if (project.isEmpty()) return;
    writes_->start([path = autosavePath(project)] { QFile::remove(path); });
}

void ProjectFiles::waitForAutosaves() { writes_->waitForDone(); }

void ProjectFiles::discardChanges() {
    removeAutosave();
    discarded_ = true;
}

std::optional<QString> ProjectFiles::newerAutosave(const QString& projectPath) {
    waitForAutosaves();  // this studio's own writes and removals of it come first
    const QFileInfo autosave(autosavePath(projectPath)), file(projectPath);
    if (!autosave.exists() || autosave.lastModified() < file.lastModified()) return std::nullopt;
    return autosave.filePath();
}

bool ProjectFiles::recover(const QString& autosave, QString* error) {
    QFile in(autosave);
    try {
        if (!in.open(QIODevice::ReadOnly)) throw std::runtime_error("cannot read " + autosave.toStdString());
        const nlohmann::json j = nlohmann::json::parse(in.readAll().toStdString());
        // One undoable edit on top of the file's version: the title shows it unsaved, undo goes back.
        session_.editProjectJson(j, "recover unsaved changes");
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

QStringList ProjectFiles::recentProjects() const {
    return QSettings().value("recentProjects").toStringList();
}

void ProjectFiles::addRecent(const QString& path) {
    QStringList recent = recentProjects();
    const QString absolute = QFileInfo(path).absoluteFilePath();
    recent.removeAll(absolute);
    recent.prepend(absolute);
    while (recent.size() > kRecentProjects)
        recent.removeLast();
    QSettings().setValue("recentProjects", recent);
    emit recentChanged();
}

}  // namespace tyndall::studio
