// A project: a scene, the views that render parts of it, and the reference settings. Stored as versioned JSON
// ({"tyndall": 1, ...}), documented field by field in docs/project-format.md.
#pragma once

#include "tyndall/scene.h"

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

// Parses and validates a project. `path` is used in error messages and to resolve relative paths; overrides are
// "field.path=value" strings (the CLI's --set) applied to the JSON before validation. Throws InputError naming the file,
// line and column (malformed JSON) or the field path, the value and what is allowed.
Project loadProject(const std::string& path, const std::vector<std::string>& overrides = {});
Project parseProject(const std::string& text, const std::string& pathForErrors,
                     const std::vector<std::string>& overrides = {});

nlohmann::json projectToJson(const Project& project);
Project projectFromJson(const nlohmann::json& json, const std::string& pathForErrors);

// Writes atomically: a temporary file in the same folder, then rename. Throws InputError when the folder is not
// writable; the previous file is untouched on failure.
void saveProject(const Project& project, const std::string& path);

// A stable hash (16 hex digits, FNV-1a over the saved JSON) of the whole project, for render metadata and caches.
std::string projectHash(const Project& project);

// The part a view renders: its explicit part, or the default part of its technique.
ScenePart resolvePart(const Project& project, const View& view);

}  // namespace tyndall
