// Loading, saving and hashing projects. Reading and validation are in project_read.cpp, writing in
// project_write.cpp, saving as an edit of the user's text in project_text.cpp and --set overrides in
// project_overrides.cpp.
#include "tyndall/project/project.h"

#include "project_internal.h"

#include "tyndall/core/hash.h"
#include "tyndall/core/output.h"

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
    checkJsonText(text, file);
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

std::string readFile(const std::string& path, const std::string& what) {
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (std::filesystem::is_directory(status))
        throw InputError(InputLocation{.file = path}, "is a directory, not a " + what);
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
        throw InputError(InputLocation{.file = path},
                         "is not a regular file (a device, pipe or socket), not a " + what);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(InputLocation{.file = path}, "cannot open the " + what + ": " + errnoText(errno));
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw InputError(InputLocation{.file = path}, "cannot read the " + what);
    return text.str();
}

}  // namespace

Project parseProject(const TechniqueCatalogue& techniques, const std::string& text, const std::string& pathForErrors,
                     const std::vector<std::string>& overrides) {
    json document = parseJsonText(text, pathForErrors);
    applyOverrides(techniques, document, overrides);
    return projectFromJson(techniques, document, pathForErrors);
}

std::string readProjectText(const std::string& path) {
    return readFile(path, "project file");
}

nlohmann::json readJsonFile(const std::string& path, const std::string& what) {
    return parseJsonText(readFile(path, what), path);
}

Project loadProject(const TechniqueCatalogue& techniques, const std::string& path,
                    const std::vector<std::string>& overrides) {
    return parseProject(techniques, readProjectText(path), path, overrides);
}

void saveProject(const Project& project, const std::string& path) {
    writeFileAtomically(path, projectText(project));
}

ProjectFile saveProject(const TechniqueCatalogue& techniques, const Project& project, const std::string& path,
                        const ProjectFile& original) {
    ProjectFile saved{.path = path, .text = updateProjectText(techniques, original, project), .project = project};
    writeFileAtomically(path, saved.text);
    return saved;
}

std::string projectHash(const Project& project) {
    return hex16(fnv1a(projectToJson(project).dump()));
}

ScenePart resolvePart(const TechniqueCatalogue& techniques, const Project& project, const View& view) {
    if (view.part) return *view.part;
    return techniques.defaultPart(view.technique, project.scene);
}

}  // namespace tyndall
