// A project: a scene, the views that render parts of it, and the reference settings. Stored as versioned JSON
// ({"tyndall": 1, ...}), documented field by field in docs/project-format.md.
#pragma once

#include "tyndall/core/scene.h"
#include "tyndall/project/catalogue.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace tyndall {

inline constexpr int kProjectFormatVersion = 1;

struct View {
    std::string name;                 // unique among views
    std::string technique;            // registry name
    nlohmann::json parameters = nlohmann::json::object();  // technique parameters that differ from the defaults
    std::optional<ScenePart> part;    // what it renders; absent: the lights and media its technique supports
    double exposure = 0.0;            // EV stops applied before tonemapping for display, PNG and PSNR
};

// Settings of the reference renders that views are compared against.
struct ReferenceSettings {
    enum class Mode { Single, Multiple };
    Mode mode = Mode::Single;   // what the techniques approximate: single scattering (docs/conventions.md)
    int maxDepth = 16;          // Multiple: scattering events at most, [1, 1024]
    int spp = 256;              // samples per pixel of a reference render, [1, 1 << 20]
    std::uint64_t seed = 1;
};

struct Project {
    std::string name;
    Scene scene;
    std::vector<View> views;
    ReferenceSettings reference;
};

// Parses and validates a project; its views may name the techniques of `techniques` (with their parameters). `path` is
// used in error messages and to resolve relative paths; overrides are "field.path=value" strings (the CLI's --set)
// applied to the JSON before validation. Throws InputError naming the file, line and column (malformed JSON) or the
// field path, the value and what is allowed.
Project loadProject(const TechniqueCatalogue& techniques, const std::string& path,
                    const std::vector<std::string>& overrides = {});
Project parseProject(const TechniqueCatalogue& techniques, const std::string& text, const std::string& pathForErrors,
                     const std::vector<std::string>& overrides = {});

nlohmann::json projectToJson(const Project& project);
Project projectFromJson(const TechniqueCatalogue& techniques, const nlohmann::json& json,
                        const std::string& pathForErrors);

// Writes atomically: a temporary file in the same folder, then rename. Throws InputError when the folder is not
// writable; the previous file is untouched on failure.
void saveProject(const Project& project, const std::string& path);

// A project file as it was read: its text and the project that text loads as (without --set overrides). Saving an
// edited project against it keeps the user's text wherever a value did not change (updateProjectText).
struct ProjectFile {
    std::string path;  // where the text was read from: relative paths in it resolve against its folder
    std::string text;  // empty: no text to keep, the whole project is written
    Project project;
};

// The text of a project file (InputError naming the path when it cannot be read), as loadProject reads it.
std::string readProjectText(const std::string& path);

// Another JSON file (`what`: "sweep spec", ...) read and parsed with a project file's checks: an InputError with the
// line and column of malformed JSON, duplicate keys and runaway nesting refused.
nlohmann::json readJsonFile(const std::string& path, const std::string& what);

// The text of `edited` as an edit of `original.text`: values equal in original.project and `edited` keep their text
// (key order, number spelling, omitted defaults, layout); changed values are written over theirs as saveProject writes
// them, on one line where they were; added keys and elements go after their neighbours in their layout, removed ones
// are cut. Elements with a "name" are paired by name, others by index. Where the text cannot be mapped (it does not
// load as original.project, as after --set overrides; an object spells a changed field another way, such as albedo for
// sigma_s) that object, or at worst the whole project, is written as saveProject(project, path) would. The result
// always loads as `edited`: it is checked, and the whole project written when it does not.
std::string updateProjectText(const TechniqueCatalogue& techniques, const ProjectFile& original, const Project& edited);

// saveProject(project, path) with the text of updateProjectText(original, project). Returns the file as saved: the
// original to save the next edit against.
ProjectFile saveProject(const TechniqueCatalogue& techniques, const Project& project, const std::string& path,
                        const ProjectFile& original);

// A stable hash (16 hex digits, FNV-1a over the saved JSON) of the whole project, for render metadata and caches.
std::string projectHash(const Project& project);

// The part a view renders: its explicit part, or the default part of its technique.
ScenePart resolvePart(const TechniqueCatalogue& techniques, const Project& project, const View& view);

}  // namespace tyndall
