// Tests of saving a project as an edit of its file (updateProjectText, issue #19 item 10): what did not change keeps
// the user's text, a one-value edit is a one-line diff, and what is saved always loads as the edited project.
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace tyndall {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The lines one text removes from another and the lines it adds (a longest-common-subsequence diff, as git shows).
struct LineDiff {
    std::vector<std::string> removed, added;
};

std::vector<std::string> linesOf(const std::string& text) {
    std::vector<std::string> lines;
    std::size_t start = 0;
    for (std::size_t end; (end = text.find('\n', start)) != std::string::npos; start = end + 1)
        lines.push_back(text.substr(start, end - start));
    if (start < text.size()) lines.push_back(text.substr(start));
    return lines;
}

LineDiff diffLines(const std::string& before, const std::string& after) {
    const std::vector<std::string> a = linesOf(before), b = linesOf(after);
    // common[i][j]: the longest common subsequence of a[i..] and b[j..].
    std::vector<std::vector<int>> common(a.size() + 1, std::vector<int>(b.size() + 1, 0));
    for (std::size_t i = a.size(); i-- > 0;)
        for (std::size_t j = b.size(); j-- > 0;)
            common[i][j] = a[i] == b[j] ? common[i + 1][j + 1] + 1 : std::max(common[i + 1][j], common[i][j + 1]);
    LineDiff diff;
    std::size_t i = 0, j = 0;
    while (i < a.size() || j < b.size()) {
        if (i < a.size() && j < b.size() && a[i] == b[j]) {
            ++i, ++j;
        } else if (j < b.size() && (i == a.size() || common[i][j + 1] >= common[i + 1][j])) {
            diff.added.push_back(b[j++]);
        } else {
            diff.removed.push_back(a[i++]);
        }
    }
    return diff;
}

using Lines = std::vector<std::string>;

std::string readText(const fs::path& path) {
    return readProjectText(path.string());
}

ProjectFile projectFile(const fs::path& path) {
    const std::string text = readText(path);
    return ProjectFile{
        .path = path.string(), .text = text, .project = parseProject(techniqueCatalogue(), text, path.string())};
}

ProjectFile bundled(const std::string& relativePath) {
    return projectFile(fs::path(TYNDALL_SOURCE_DIR) / "projects" / relativePath);
}

ProjectFile fromText(const std::string& text) {
    const std::string path = (fs::path(TYNDALL_TEST_TMP) / "project-text.json").string();
    return ProjectFile{.path = path, .text = text, .project = parseProject(techniqueCatalogue(), text, path)};
}

// The project of `file` edited by --set overrides, as the studio's scene edits are.
Project editedBy(const ProjectFile& file, const std::vector<std::string>& overrides) {
    return parseProject(techniqueCatalogue(), file.text, file.path, overrides);
}

// updateProjectText, checked to load as the edited project.
std::string updated(const ProjectFile& file, const Project& edited) {
    const std::string text = updateProjectText(techniqueCatalogue(), file, edited);
    EXPECT_EQ(projectToJson(parseProject(techniqueCatalogue(), text, file.path)), projectToJson(edited)) << text;
    return text;
}

std::vector<fs::path> bundledProjects() {
    std::vector<fs::path> paths;
    for (const auto& entry : fs::recursive_directory_iterator(fs::path(TYNDALL_SOURCE_DIR) / "projects"))
        if (entry.is_regular_file() && entry.path().extension() == ".json" &&
            !entry.path().filename().string().ends_with(".sweep.json"))  // sweep specs (projects/sweeps)
            paths.push_back(entry.path());
    std::sort(paths.begin(), paths.end());
    return paths;
}

const char* const kSmallProject = R"({
  "tyndall": 1,
  "camera": {"fovY": 30},
  "media": [
    {"name": "fog", "sigma_s": 1e-3, "sigma_a": 0.10, "phase": {"type": "hg", "g": 0.50}}
  ],
  "lights": [
    {"name": "sun", "type": "directional", "direction": [0, -2, 1], "irradiance": 3}
  ],
  "views": [
    {"name": "main", "technique": "reference"}
  ]
}
)";

// ---------------------------------------------------------------------------------------------------------------------

TEST(ProjectText, SavingAnUnchangedBundledProjectKeepsItsFileByteForByte) {
    const fs::path dir = fs::path(TYNDALL_TEST_TMP) / "project-text";
    fs::create_directories(dir);
    for (const fs::path& path : bundledProjects()) {
        SCOPED_TRACE(path.string());
        const ProjectFile file = projectFile(path);
        const ProjectFile saved =
            saveProject(techniqueCatalogue(), file.project, (dir / path.filename()).string(), file);
        EXPECT_EQ(readText(dir / path.filename()), file.text);
        EXPECT_EQ(saved.text, file.text);
        // The same project reached another way (the studio rebuilds it from JSON on every edit) saves the same.
        EXPECT_EQ(updateProjectText(techniqueCatalogue(), file,
                                    projectFromJson(techniqueCatalogue(), projectToJson(file.project), file.path)),
                  file.text);
    }
}

TEST(ProjectText, EditingOneValueOfABundledProjectChangesOneLine) {
    for (const fs::path& path : bundledProjects()) {
        SCOPED_TRACE(path.string());
        const ProjectFile file = projectFile(path);
        Project edited = file.project;
        edited.scene.camera.fovY = 33.5;  // every bundled project gives it
        const LineDiff diff = diffLines(file.text, updated(file, edited));
        EXPECT_EQ(diff.removed.size(), 1u);
        ASSERT_EQ(diff.added.size(), 1u);
        EXPECT_NE(diff.added[0].find("\"fovY\": 33.5"), std::string::npos) << diff.added[0];
    }
}

TEST(ProjectText, OneValueEditIsAOneLineDiff) {
    struct Case {
        const char* project;
        const char* edit;
        const char* removed;
        const char* added;
    };
    const Case cases[] = {
        {"default.json", "lights[lamp].intensity=[3, 1.5, 0.7]", R"(      "intensity": [2.4, 1.5, 0.7])",
         R"(      "intensity": [3.0, 1.5, 0.7])"},
        {"default.json", "camera.fovY=50", R"(    "fovY": 62.0,)", R"(    "fovY": 50.0,)"},
        {"default.json", "views[everything].exposure=-2",
         R"(    {"name": "everything", "technique": "reference", "parameters": {"distanceSampling": "mis"}, "exposure": 0.0},)",
         R"(    {"name": "everything", "technique": "reference", "parameters": {"distanceSampling": "mis"}, "exposure": -2.0},)"},
        // A key the view leaves out is added on its line.
        {"default.json", "views[glow].exposure=1",
         R"(    {"name": "glow", "technique": "reference", "parameters": {"distanceSampling": "distance"}, "lights": ["lamp"], "media": ["fog"]})",
         R"(    {"name": "glow", "technique": "reference", "parameters": {"distanceSampling": "distance"}, "lights": ["lamp"], "media": ["fog"], "exposure": 1.0})"},
        {"examples/wvds-box.json", "views[reds].parameters.estimator=rm", R"(        "estimator": "reds")",
         R"(        "estimator": "rm")"},
        // One component of a vector written one number per line.
        {"examples/wvds-box.json", "lights[sun].irradiance=[9, 8.5, 7.2]", "        8.3,", "        8.5,"},
        {"examples/wvds-box.json", "reference.spp=64", R"(    "spp": 256,)", R"(    "spp": 64,)"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string(c.project) + ": " + c.edit);
        const ProjectFile file = bundled(c.project);
        const LineDiff diff = diffLines(file.text, updated(file, editedBy(file, {c.edit})));
        EXPECT_EQ(diff.removed, Lines{c.removed});
        EXPECT_EQ(diff.added, Lines{c.added});
    }
}

TEST(ProjectText, RemovingAViewOrALightCutsOnlyItsLines) {
    const ProjectFile file = bundled("default.json");
    Project withoutView = file.project;
    withoutView.views.erase(withoutView.views.begin() + 2);  // "area light", between two others
    LineDiff diff = diffLines(file.text, updated(file, withoutView));
    EXPECT_EQ(diff.removed,
              Lines{R"(    {"name": "area light", "technique": "ltsd", "lights": ["panel"], "media": ["fog"]},)"});
    EXPECT_TRUE(diff.added.empty());

    Project withoutLight = file.project;
    withoutLight.scene.areaLights.clear();  // "panel", the second of three
    for (View& view : withoutLight.views)
        if (view.part) std::erase(view.part->lights, "panel");
    diff = diffLines(file.text, updated(file, withoutLight));
    EXPECT_EQ(diff.removed.size(), 8u);  // the light's 7 lines and the line of the view that rendered it
    EXPECT_EQ(std::count(diff.removed.begin(), diff.removed.end(), R"(      "name": "panel",)"), 1);
    EXPECT_EQ(diff.added,
              Lines{R"(    {"name": "area light", "technique": "ltsd", "lights": [], "media": ["fog"]},)"});

    Project withoutLastView = file.project;
    withoutLastView.views.pop_back();  // the last: the comma before it goes too
    diff = diffLines(file.text, updated(file, withoutLastView));
    EXPECT_EQ(diff.removed,
              (Lines{R"(    {"name": "area light", "technique": "ltsd", "lights": ["panel"], "media": ["fog"]},)",
                     R"(    {"name": "glow", "technique": "reference", "parameters": {"distanceSampling": "distance"}, "lights": ["lamp"], "media": ["fog"]})"}));
    EXPECT_EQ(diff.added,
              Lines{R"(    {"name": "area light", "technique": "ltsd", "lights": ["panel"], "media": ["fog"]})"});
}

TEST(ProjectText, AddedViewsAndLightsFollowTheirNeighboursLayout) {
    const ProjectFile file = bundled("default.json");
    // A view in a list of one-line views: on one line, after the last.
    const Project withView =
        editedBy(file, {R"(views[+]={"name": "fill", "technique": "reference", "lights": ["lamp"], "media": []})"});
    LineDiff diff = diffLines(file.text, updated(file, withView));
    EXPECT_EQ(diff.removed,
              Lines{R"(    {"name": "glow", "technique": "reference", "parameters": {"distanceSampling": "distance"}, "lights": ["lamp"], "media": ["fog"]})"});
    EXPECT_EQ(
        diff.added,
        (Lines{
            R"(    {"name": "glow", "technique": "reference", "parameters": {"distanceSampling": "distance"}, "lights": ["lamp"], "media": ["fog"]},)",
            R"(    {"name": "fill", "technique": "reference", "parameters": {}, "lights": ["lamp"], "media": [], "exposure": 0.0})"}));

    // A point light in a list of lights written one key per line: the same, after the point light before it in the
    // project (the file's last light), at the file's indentation. (The diff pairs the closing brace of the light
    // before with the new light's.)
    const Project withLight =
        editedBy(file, {R"(lights[+]={"type": "point", "name": "fill", "position": [0, 2, 0], "intensity": 2})"});
    diff = diffLines(file.text, updated(file, withLight));
    EXPECT_TRUE(diff.removed.empty());
    EXPECT_EQ(diff.added, (Lines{"    },", "    {", R"(      "type": "point",)", R"(      "name": "fill",)",
                                 R"(      "position": [0.0, 2.0, 0.0],)", R"(      "intensity": [2.0, 2.0, 2.0],)",
                                 R"(      "distribution": {)", R"(        "type": "isotropic")", "      }"}));
}

TEST(ProjectText, UnchangedValuesKeepTheirSpellingAndOmittedDefaultsStayOmitted) {
    const ProjectFile file = fromText(kSmallProject);
    const std::string text = updated(file, editedBy(file, {"lights[sun].irradiance=4"}));
    const LineDiff diff = diffLines(file.text, text);
    EXPECT_EQ(diff.removed,
              Lines{R"(    {"name": "sun", "type": "directional", "direction": [0, -2, 1], "irradiance": 3})"});
    // The direction (normalised when loaded) stays as written; only the irradiance is new.
    EXPECT_EQ(
        diff.added,
        Lines{R"(    {"name": "sun", "type": "directional", "direction": [0, -2, 1], "irradiance": [4.0, 4.0, 4.0]})"});
    for (const char* kept : {R"("sigma_s": 1e-3)", R"("sigma_a": 0.10)", R"("g": 0.50)", R"("camera": {"fovY": 30})"})
        EXPECT_NE(text.find(kept), std::string::npos) << kept;
    for (const char* omitted : {"\"width\":", "\"reference\":", "\"materials\":", "\"shape\":", "\"exposure\":"})
        EXPECT_EQ(text.find(omitted), std::string::npos) << omitted;
}

TEST(ProjectText, AChangedDefaultIsAddedToItsObject) {
    const ProjectFile file = fromText(kSmallProject);
    const LineDiff diff = diffLines(file.text, updated(file, editedBy(file, {"camera.width=640", "reference.spp=16"})));
    EXPECT_EQ(diff.removed, (Lines{R"(  "camera": {"fovY": 30},)", "  ]"}));
    EXPECT_EQ(diff.added, (Lines{R"(  "camera": {"fovY": 30, "width": 640},)", "  ],", R"(  "reference": {)",
                                 R"(    "mode": "single",)", R"(    "maxDepth": 16,)", R"(    "spp": 16,)",
                                 R"(    "seed": 1)", "  }"}));
}

TEST(ProjectText, AnEmptyListAloneOnItsLineTakesTheLayoutOfSavedFiles) {
    const ProjectFile file = fromText(R"({
  "tyndall": 1,
  "media": [],
  "views": [{"name": "main", "technique": "reference", "parameters": {}}]
}
)");
    Project edited = editedBy(file, {R"(media[+]={"name": "fog"})", "views[main].parameters.mode=multiple"});
    const LineDiff diff = diffLines(file.text, updated(file, edited));
    EXPECT_EQ(diff.removed, (Lines{R"(  "media": [],)",
                                   R"(  "views": [{"name": "main", "technique": "reference", "parameters": {}}])"}));
    EXPECT_EQ(
        diff.added,
        (Lines{R"(  "media": [)", "    {", R"(      "name": "fog",)", R"(      "sigma_s": [0.1, 0.1, 0.1],)",
               R"(      "sigma_a": [0.0, 0.0, 0.0],)", R"(      "phase": {)", R"(        "type": "isotropic")",
               "      },", R"(      "shape": "infinite")", "    }", "  ],",
               R"(  "views": [{"name": "main", "technique": "reference", "parameters": {"mode": "multiple"}}])"}));
}

TEST(ProjectText, AFieldSpelledAnotherWayIsRespelledWhenItChanges) {
    // albedo and extinction load as sigma_s and sigma_a: a change of sigma_s spells the medium's coefficients as
    // sigma_s and sigma_a (the medium's other keys stay).
    const ProjectFile file = bundled("bench/fog-point.json");
    Project edited = file.project;
    edited.scene.media[0].sigma_s = Rgb(0.2);
    LineDiff diff = diffLines(file.text, updated(file, edited));
    EXPECT_EQ(diff.removed.size(), 2u);  // the medium's two lines
    ASSERT_EQ(diff.added.size(), 2u);
    EXPECT_EQ(diff.added[0], R"(    {"name": "fog", "phase": {"type": "hg", "g": 0.5},)");
    EXPECT_NE(diff.added[1].find(R"(, "sigma_s": [0.2, 0.2, 0.2], "sigma_a": [)"), std::string::npos) << diff.added[1];
    // Another field of that medium is edited in place: albedo and extinction still say what they said.
    diff = diffLines(file.text, updated(file, editedBy(file, {"media[fog].phase.g=0.7"})));
    EXPECT_EQ(diff.removed,
              Lines{R"(    {"name": "fog", "albedo": 0.9, "extinction": 0.3, "phase": {"type": "hg", "g": 0.5},)"});
    EXPECT_EQ(diff.added,
              Lines{R"(    {"name": "fog", "albedo": 0.9, "extinction": 0.3, "phase": {"type": "hg", "g": 0.7},)"});

    // alphaX and alphaY equal load as alpha.
    const ProjectFile room = bundled("default.json");
    Project rougher = room.project;
    rougher.scene.materials[2].alphaX = rougher.scene.materials[2].alphaY = 0.3;
    diff = diffLines(room.text, updated(room, rougher));
    EXPECT_EQ(diff.added, Lines{R"(    {"name": "brass", "type": "ggx", "f0": [0.9, 0.72, 0.4], "alpha": 0.3})"});
}

TEST(ProjectText, APlaneWhoseNormalChangesKeepsItsOffsetRight) {
    // The offset is divided by the normal's length when loaded: with a new normal, the written offset must change too.
    const ProjectFile file = fromText(R"({
  "tyndall": 1,
  "media": [{"name": "cube", "shape": "polyhedron", "planes": [
    {"normal": [2, 0, 0], "offset": 2}, {"normal": [-1, 0, 0], "offset": 1},
    {"normal": [0, 1, 0], "offset": 1}, {"normal": [0, -1, 0], "offset": 1},
    {"normal": [0, 0, 1], "offset": 1}, {"normal": [0, 0, -1], "offset": 1}]}]
}
)");
    Project edited = file.project;
    edited.scene.media[0].planes[0].normal = Vec3(1.0, 0.0, 0.0);
    edited.scene.media[0].planes[0].offset = 1.5;
    const LineDiff diff = diffLines(file.text, updated(file, edited));
    EXPECT_EQ(diff.added,
              Lines{R"(    {"normal": [1.0, 0.0, 0.0], "offset": 1.5}, {"normal": [-1, 0, 0], "offset": 1},)"});

    Project turned = file.project;  // only the normal (unit length): the offset the file says (2) would mean 2, not 1
    turned.scene.media[0].planes[0].normal = Vec3(0.6, 0.0, 0.8);
    const std::string text = updated(file, turned);
    EXPECT_NE(text.find(R"({"normal": [0.6, 0, 0.8], "offset": 1.0})"), std::string::npos) << text;
}

TEST(ProjectText, WindowsLineEndsAndOtherIndentationAreKept) {
    std::string text = R"({
    "tyndall": 1,
    "views": [
        {"name": "main", "technique": "reference"}
    ]
}
)";
    for (std::size_t at = 0; (at = text.find('\n', at)) != std::string::npos; at += 2)
        text.replace(at, 1, "\r\n");
    const ProjectFile file = fromText(text);
    const std::string saved = updated(file, editedBy(file, {"reference.seed=9"}));
    const std::size_t kept = file.text.size() - 5;  // all but the line ends around the last "}"
    EXPECT_EQ(saved.substr(0, kept), file.text.substr(0, kept));
    EXPECT_NE(saved.find("    ],\r\n    \"reference\": {\r\n        \"mode\": \"single\",\r\n"), std::string::npos)
        << saved;
}

TEST(ProjectText, ASetOverrideAtLoadIsSavedAgainstTheFileWithoutIt) {
    const ProjectFile file = bundled("default.json");
    const Project overridden = editedBy(file, {"camera.fovY=50"});
    // Against the file as it loads without the override, the override is one more edit: one line.
    const LineDiff diff = diffLines(file.text, updated(file, overridden));
    EXPECT_EQ(diff.added, Lines{R"(    "fovY": 50.0,)"});
    // Against a project that the text does not load as, nothing of the text can be trusted: the whole project is
    // written, as by saveProject(project, path). So it is without a text.
    const fs::path whole = fs::path(TYNDALL_TEST_TMP) / "project-text" / "whole.json";
    fs::create_directories(whole.parent_path());
    saveProject(overridden, whole.string());
    EXPECT_EQ(updated(ProjectFile{.path = file.path, .text = file.text, .project = overridden}, overridden),
              readText(whole));
    EXPECT_EQ(updated(ProjectFile{.path = file.path}, overridden), readText(whole));
}

TEST(ProjectText, EveryEditOfEveryBundledProjectLoadsAsTheEditedProject) {
    for (const fs::path& path : bundledProjects()) {
        SCOPED_TRACE(path.string());
        const ProjectFile file = projectFile(path);
        ASSERT_FALSE(file.project.views.empty());
        // Each edit with the most lines it may remove: the edited ones, or one that gains a comma.
        std::vector<std::pair<Project, std::size_t>> edits(4, {file.project, 1});
        edits[0].first.views.pop_back();
        edits[0].second = 1000;
        edits[1].first.views.push_back(edits[1].first.views.front());
        edits[1].first.views.back().name = "copy";
        edits[2].first.views.front().name = "renamed";
        edits[3].first.reference.spp = 7;
        edits[3].first.name = "renamed project";
        edits[3].second = 2;
        for (const auto& [edited, mostRemoved] : edits)
            EXPECT_LE(diffLines(file.text, updated(file, edited)).removed.size(), mostRemoved);
    }
}

}  // namespace
}  // namespace tyndall
