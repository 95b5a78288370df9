#include "tyndall/core/output.h"

#include "tyndall/core/error.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace tyndall {

namespace fs = std::filesystem;

namespace {

constexpr const char* kTemporaryInfix = ".tyndall-";

std::string errnoText(int error) {
    return std::error_code(error, std::generic_category()).message();
}

// A path as an error names it: a name too long for the file system is clipped.
std::string shownPath(const std::string& path) {
    return path.size() > 80 ? path.substr(0, 80) + "..." : path;
}

[[noreturn]] void fail(const std::string& path, const std::string& step, int error) {
    // A name the file system cannot hold is the caller's mistake (exit 2), not the environment's (exit 1).
    if (error == ENAMETOOLONG)
        throw InputError(InputLocation{.file = shownPath(path)},
                         "cannot save: " + step + ": " + errnoText(error) + " (a path is limited to " +
                             std::to_string(PATH_MAX) + " bytes, each name in it to " + std::to_string(NAME_MAX) + ")");
    throw OutputError("cannot write '" + path + "': " + step + ": " + errnoText(error));
}

// Follows symlinks (up to 40, like the kernel) so that writing replaces the file a link points to, not the link.
fs::path resolveSymlinks(const std::string& path) {
    fs::path p(path);
    for (int hops = 0; hops < 40; ++hops) {
        std::error_code ec;
        if (!fs::is_symlink(fs::symlink_status(p, ec))) return p;
        const fs::path target = fs::read_symlink(p, ec);
        if (ec) fail(path, "cannot read the symlink", ec.value());
        p = target.is_absolute() ? target : p.parent_path() / target;
    }
    fail(path, "resolving symlinks", ELOOP);
}

fs::path folderOf(const fs::path& p) {
    return p.parent_path().empty() ? fs::path(".") : p.parent_path();
}

void syncFolder(const fs::path& folder) {
    const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir < 0) return;  // the data is complete; durability of the rename is best effort
    ::fsync(dir);
    ::close(dir);
}

mode_t creationMode() {
    static const mode_t mode = [] {
        const mode_t mask = ::umask(0);
        ::umask(mask);
        return static_cast<mode_t>(0666 & ~mask);
    }();
    return mode;
}

}  // namespace

int removeStaleTemporaries(const std::string& path) {
    const fs::path target = resolveSymlinks(path);
    const std::string prefix = "." + target.filename().string() + kTemporaryInfix;
    DIR* dir = ::opendir(folderOf(target).c_str());
    if (!dir) return 0;
    int removed = 0;
    while (const dirent* entry = ::readdir(dir)) {
        const std::string name = entry->d_name;
        if (name.rfind(prefix, 0) != 0) continue;
        char* end = nullptr;
        const long pid = std::strtol(name.c_str() + prefix.size(), &end, 10);
        if (pid <= 0 || *end != '-') continue;
        if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // its writer may still be running
        if (::unlinkat(::dirfd(dir), name.c_str(), 0) == 0) ++removed;
    }
    ::closedir(dir);
    return removed;
}

OutputSet::~OutputSet() {
    for (const Staged& s : staged_)
        ::unlink(s.temporary.c_str());
}

void OutputSet::stage(const std::string& path, const std::string& bytes) {
    const fs::path target = resolveSymlinks(path);
    // A path that cannot name a file is the caller's mistake (exit 2), not the environment's.
    std::error_code ec;
    if (!fs::is_directory(folderOf(target), ec)) {
        throw InputError(InputLocation{.file = path},
                         "cannot save: the folder '" + folderOf(target).string() + "' does not exist");
    }
    if (fs::is_directory(target, ec)) throw InputError(InputLocation{.file = path}, "cannot save: it is a folder");
    // The temporary beside the file ("." + name + ".tyndall-<pid>-XXXXXX", the pid at most 7 digits on Linux) must fit
    // NAME_MAX too, so a name that the folder would take but its temporary would not is refused here, with the limit.
    const std::size_t overhead = 1 + std::char_traits<char>::length(kTemporaryInfix) + 7 + 7;
    const std::size_t nameBytes = target.filename().string().size();
    if (nameBytes + overhead > std::size_t(NAME_MAX)) {
        throw InputError(InputLocation{.file = shownPath(path)},
                         "cannot save: the file name is " + std::to_string(nameBytes) + " bytes long; names are " +
                             "limited to " + std::to_string(NAME_MAX - overhead) + " bytes (" +
                             std::to_string(NAME_MAX) + " for the folder, less the temporary name's suffix)");
    }
    removeStaleTemporaries(target.string());
    std::string name = (folderOf(target) / ("." + target.filename().string() + kTemporaryInfix +
                                           std::to_string(::getpid()) + "-XXXXXX"))
                           .string();
    const int fd = ::mkostemp(name.data(), O_CLOEXEC);  // O_EXCL with a random name: never an existing file
    if (fd < 0) fail(path, "cannot create a temporary file in its folder", errno);
    staged_.push_back({target.string(), name, path});

    const auto abandon = [&](const char* step) {
        const int error = errno;
        ::close(fd);
        ::unlink(name.c_str());
        staged_.pop_back();
        fail(path, step, error);
    };
    struct stat existing {};
    const mode_t mode = ::stat(target.c_str(), &existing) == 0 && S_ISREG(existing.st_mode) ? existing.st_mode & 07777
                                                                                           : creationMode();
    if (::fchmod(fd, mode) != 0) abandon("cannot set the file mode");
    for (std::size_t written = 0; written < bytes.size();) {
        const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) abandon("write failed");
        if (n == 0) {
            errno = EIO;
            abandon("write failed");
        }
        written += static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0) abandon("fsync failed");
    if (::close(fd) != 0) {
        const int error = errno;
        ::unlink(name.c_str());
        staged_.pop_back();
        fail(path, "close failed", error);
    }
}

void OutputSet::commit() {
    std::vector<Staged> staged = std::move(staged_);
    staged_.clear();
    for (std::size_t i = 0; i < staged.size(); ++i) {
        if (::rename(staged[i].temporary.c_str(), staged[i].target.c_str()) != 0) {
            const int error = errno;
            for (std::size_t k = i; k < staged.size(); ++k)
                ::unlink(staged[k].temporary.c_str());
            fail(staged[i].path, "rename failed", error);
        }
    }
    for (const Staged& s : staged)
        syncFolder(folderOf(s.target));
}

void writeFileAtomically(const std::string& path, const std::string& bytes) {
    OutputSet set;
    set.stage(path, bytes);
    set.commit();
}

}  // namespace tyndall
