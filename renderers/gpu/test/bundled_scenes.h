// The geometry of every project bundled with Tyndall (projects/*.json and projects/examples/*.json), for tests that
// compare GPU visibility with Embree on real scenes.
#pragma once

#include "test_paths.h"
#include "tyndall/core/geometry.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace tyndall::gpu::test {

struct BundledScene {
    std::string name;                  // the project's file name
    std::vector<TriangleMesh> meshes;  // world space, in the project's order
};

inline std::vector<BundledScene> bundledScenes() {
    std::vector<std::filesystem::path> paths;
    for (const char* folder : {"/projects", "/projects/examples"})
        for (const auto& entry : std::filesystem::directory_iterator(tyndall::test::sourceDir() + folder))
            if (entry.is_regular_file() && entry.path().extension() == ".json") paths.push_back(entry.path());
    std::sort(paths.begin(), paths.end());
    std::vector<BundledScene> scenes;
    for (const auto& path : paths) {
        Project project = loadProject(techniqueCatalogue(), path.string());
        BundledScene scene{path.filename().string(), {}};
        for (const Mesh& mesh : project.scene.meshes)
            scene.meshes.push_back(buildMesh(mesh, path.parent_path().string()));
        scenes.push_back(std::move(scene));
    }
    return scenes;
}

}  // namespace tyndall::gpu::test
