// All-or-nothing output files (docs/conventions.md, "Outputs"). Each output is written to an unpredictable temporary
// in its target's folder (created with O_EXCL, so a planted file or symlink is never followed), flushed, fsynced and
// closed with every step checked; only when every output of a set is complete are the temporaries renamed over their
// targets. On any failure the temporaries are removed and the existing files are untouched. A target that is a symlink
// is resolved first, so that the file it points to is updated and the link stays.
#pragma once

#include <string>
#include <vector>

namespace tyndall {

class OutputSet {
public:
    OutputSet() = default;
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;
    ~OutputSet();  // removes the temporaries of a set that was not committed

    // Writes `bytes` to a new temporary beside `path`. Throws InputError when `path` cannot name a file (its folder
    // does not exist, it is a folder), OutputError when the environment refuses (disk full, read-only folder, ...),
    // naming the path and the step that failed.
    void stage(const std::string& path, const std::string& bytes);
    // Renames every staged temporary over its target and syncs their folders. Throws OutputError when a rename fails
    // (the remaining temporaries are removed).
    void commit();

private:
    struct Staged {
        std::string target;     // symlinks resolved
        std::string temporary;  // in the target's folder
        std::string path;       // as given, for messages
    };
    std::vector<Staged> staged_;
};

// One output on its own: stage and commit.
void writeFileAtomically(const std::string& path, const std::string& bytes);

// Temporaries are named ".<file name>.tyndall-<pid>-<6 random characters>" in the target's folder. Removes those of
// `path` whose process has exited (left by a kill or a crash); each stage() does this for its own target. Returns the
// number removed.
int removeStaleTemporaries(const std::string& path);

}  // namespace tyndall
