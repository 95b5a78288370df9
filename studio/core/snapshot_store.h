// Snapshots (render slots): a view's image kept with the parameters and exposure that made it, to compare the live
// view against or to put back. They belong to the project: saving the project saves them into a folder beside it
// (folderOf: "<project>.snapshots/" with snapshots.json and an EXR per snapshot, written all or nothing), and opening
// the project brings them back.
#pragma once

#include "session.h"

#include "tyndall/image/image.h"

#include <nlohmann/json.hpp>

#include <QObject>
#include <QString>

#include <memory>
#include <vector>

namespace tyndall::studio {

struct Snapshot {
    QString name;
    int view = 0;          // the view's index in the project; -1 while no view has its name
    std::string viewName;  // its name (how it is saved, and found again when the views change)
    std::shared_ptr<const Image> image;
    nlohmann::json parameters;
    double exposure = 0.0;
};

class SnapshotStore : public QObject {
    Q_OBJECT
public:
    explicit SnapshotStore(Session& session, QObject* parent = nullptr);

    const std::vector<Snapshot>& snapshots() const { return snapshots_; }
    // Keeps `image` as a snapshot of view `view` with the view's current parameters and exposure; returns its index.
    int take(int view, std::shared_ptr<const Image> image);
    // Its parameters and exposure back on its view, as one undoable edit. False for an index out of range.
    bool restore(int index);
    void clear();
    // The project's views were added, removed, renamed or reordered: each snapshot follows its view, by name (by
    // index when the view count did not change: a rename). A snapshot whose view is gone is kept with view -1 (not
    // compared nor restored) and finds its view again when a view of that name comes back (an undo).
    void followViews();

    // "<folder>/<project file's base name>.snapshots".
    static QString folderOf(const QString& projectPath);
    // Writes the snapshots beside `projectPath` (and removes the folder's files of snapshots that are gone); with no
    // snapshot, removes the folder's files. All or nothing: on failure the folder is as it was and `error` says why.
    bool save(const QString& projectPath, QString* error) const;
    // Replaces the snapshots by those saved beside `projectPath` (none when there is no folder). Snapshots of views the
    // project no longer has are dropped; an unreadable folder leaves no snapshot and says why.
    bool load(const QString& projectPath, QString* error);

signals:
    void changed();

private:
    Session& session_;
    std::vector<Snapshot> snapshots_;
    int viewCount_ = 0;  // the project's views when the snapshots last followed them
};

}  // namespace tyndall::studio
