// Loading, saving and hashing projects. Reading and validation are in project_read.cpp, writing in
// project_write.cpp and --set overrides in project_overrides.cpp.
#include "tyndall/project.h"

#include "project_internal.h"

#include "tyndall/technique.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

namespace tyndall {

namespace {

using nlohmann::json;

// nlohmann reports the byte offset (1-based) just past the last character read; count lines and columns up to it.
InputLocation locationOfByte(const std::string& text, const std::string& file, std::size_t byte) {
    const std::size_t end = std::min(byte > 0 ? byte - 1 : 0, text.size());
    InputLocation where{.file = file, .line = 1, .column = 1};
    for (std::size_t i = 0; i < end; ++i) {
        if (text[i] == '\n') {
            ++where.line;
            where.column = 1;
        } else {
            ++where.column;
        }
    }
    return where;
}

// "[json.exception.parse_error.101] parse error at line 1, column 2: syntax error ..." -> "syntax error ...".
std::string parseErrorMessage(const json::parse_error& e) {
    std::string message = e.what();
    const std::size_t bracket = message.find("] ");
    if (bracket != std::string::npos) message = message.substr(bracket + 2);
    if (message.rfind("parse error at line", 0) == 0) {
        const std::size_t colon = message.find(": ");
        if (colon != std::string::npos) message = message.substr(colon + 2);
    }
    return "malformed JSON: " + message;
}

json parseJsonText(const std::string& text, const std::string& file) {
    try {
        return json::parse(text);
    } catch (const json::parse_error& e) {
        throw InputError(locationOfByte(text, file, e.byte), parseErrorMessage(e));
    } catch (const json::exception& e) {  // e.g. out_of_range for a number like 1e999, without a position
        std::string message = e.what();
        const std::size_t bracket = message.find("] ");
        throw InputError(InputLocation{.file = file}, "malformed JSON: " + message.substr(bracket + 2));
    }
}

std::string errnoText(int error) {
    return std::error_code(error, std::generic_category()).message();
}

// A temporary name in the target's folder, unique enough for concurrent saves (O_EXCL settles any collision).
std::string temporaryName(const std::string& path, int attempt) {
    static std::atomic<unsigned> counter{0};
    const auto now = static_cast<unsigned long long>(std::chrono::steady_clock::now().time_since_epoch().count());
    const unsigned long long mix = now * 0x9E3779B97F4A7C15ull ^ (static_cast<unsigned long long>(::getpid()) << 20) ^
                                   (counter++ * 0x85EBCA6Bull) ^ static_cast<unsigned long long>(attempt);
    char suffix[16];
    std::snprintf(suffix, sizeof(suffix), "%06llx", mix & 0xFFFFFFull);
    return path + ".tmp-" + suffix;
}

// Writes the file to a temporary in the same folder, flushes it to disk and renames it over `path`, so that readers
// see either the old file or the new one. The temporary is removed on any failure.
void writeFileAtomically(const std::string& path, const std::string& text) {
    const auto fail = [&](const std::string& what, int error) {
        throw InputError(InputLocation{.file = path}, "cannot save: " + what + ": " + errnoText(error));
    };
    std::string temporary;
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        temporary = temporaryName(path, attempt);
        fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);  // the umask applies
        if (fd < 0 && errno != EEXIST) break;
    }
    if (fd < 0) fail("cannot create a temporary file next to it", errno);

    const auto abandon = [&](const std::string& what) {
        const int error = errno;
        if (fd >= 0) ::close(fd);
        ::unlink(temporary.c_str());
        fail(what, error);
    };
    struct stat existing {};
    if (::stat(path.c_str(), &existing) == 0 && S_ISREG(existing.st_mode)) ::fchmod(fd, existing.st_mode & 07777);
    for (std::size_t written = 0; written < text.size();) {
        const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) abandon("write failed");
        written += static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0) abandon("fsync failed");
    const int closed = ::close(fd);
    fd = -1;
    if (closed != 0) abandon("close failed");
    if (::rename(temporary.c_str(), path.c_str()) != 0) abandon("rename failed");

    // Make the rename itself durable; a failure here leaves a complete file, so it is not reported.
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    const int dir = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) {
        ::fsync(dir);
        ::close(dir);
    }
}

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(InputLocation{.file = path}, "cannot open the project file: " + errnoText(errno));
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw InputError(InputLocation{.file = path}, "cannot read the project file");
    return text.str();
}

// FNV-1a, 64 bit.
std::uint64_t fnv1a(const std::string& bytes) {
    std::uint64_t hash = 0xCBF29CE484222325ull;
    for (unsigned char c : bytes) {
        hash ^= c;
        hash *= 0x100000001B3ull;
    }
    return hash;
}

}  // namespace

Project parseProject(const std::string& text, const std::string& pathForErrors,
                     const std::vector<std::string>& overrides) {
    json document = parseJsonText(text, pathForErrors);
    applyOverrides(document, overrides);
    return projectFromJson(document, pathForErrors);
}

Project loadProject(const std::string& path, const std::vector<std::string>& overrides) {
    return parseProject(readFile(path), path, overrides);
}

void saveProject(const Project& project, const std::string& path) {
    writeFileAtomically(path, projectText(project));
}

std::string projectHash(const Project& project) {
    char hex[17];
    std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(fnv1a(projectToJson(project).dump())));
    return hex;
}

ScenePart resolvePart(const Project& project, const View& view) {
    if (view.part) return *view.part;
    return createTechnique(view.technique)->defaultPart(project.scene);
}

}  // namespace tyndall
