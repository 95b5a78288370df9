// What the studio keeps of a project outside the project's own file: crash-recovery autosaves and the recent list.
//
// Every 20 s while the session has unsaved changes, the project goes to autosavePath() of its file; a save, an undo
// back to the file or a clean close removes it. The project is serialised on the GUI thread and written (atomically,
// with its fsync) by a thread of its own, in order with the removals: a commit's fsync took ~30 ms here, a stall every
// 20 s. A write that fails says so (autosaveFailed).
#pragma once

#include "session.h"

#include <QObject>
#include <QString>
#include <QStringList>
#include <QTimer>

#include <optional>

class QThreadPool;

namespace tyndall::studio {

class ProjectFiles : public QObject {
    Q_OBJECT
public:
    explicit ProjectFiles(Session& session, QObject* parent = nullptr);
    ~ProjectFiles() override;

    // What opening a project does with an autosave newer than its file: ask, always recover, or never.
    enum class Recovery { Ask, Always, Never };
    void setRecovery(Recovery recovery) { recovery_ = recovery; }
    Recovery recovery() const { return recovery_; }

    // Where the autosave of `projectPath` goes: the user's data folder, named by the file and a hash of its path.
    static QString autosavePath(const QString& projectPath);
    // Queues a write of the session's project, when it has unsaved changes worth keeping; false when there is nothing
    // to save.
    bool autosaveNow();
    // Queues the removal of the autosave of `projectPath` (the current project's when empty), after the writes.
    void removeAutosave(const QString& projectPath = {});
    // Waits until the queued writes and removals are on disk.
    void waitForAutosaves();

    // Opening: while it runs, the session's "saved" state is not the user's doing (the autosave stays).
    void setOpening(bool opening) { opening_ = opening; }
    // The user discarded the unsaved changes on purpose (Discard on Open): no autosave until the next edit.
    void discardChanges();
    // The autosave of `projectPath` when it is newer than the file (the studio stopped with unsaved changes).
    std::optional<QString> newerAutosave(const QString& projectPath);
    // Applies the autosave of the current project as one undoable edit on top of the file's version. False with the
    // reason when it cannot be read or is not a valid project.
    bool recover(const QString& autosave, QString* error);

    // The last 8 projects opened or saved, newest first (QSettings "recentProjects", absolute paths).
    QStringList recentProjects() const;
    void addRecent(const QString& path);

signals:
    void autosaveFailed(const QString& message);
    void recentChanged();

private:
    Session& session_;
    QThreadPool* writes_ = nullptr;  // one thread: the autosave's writes and removals, in order
    QTimer timer_;
    Recovery recovery_ = Recovery::Ask;
    bool opening_ = false;
    bool discarded_ = false;
};

}  // namespace tyndall::studio
