// Reliability of the tyndall CLI (issue 21): no crash on any input, exit 2 with file and field for bad input, exit 1
// for environment failures, and outputs that appear completely or not at all. The inputs are files in tests/data/.
#include "tyndall/core/output.h"
#include "tyndall/core/scene.h"
#include "tyndall/image/image_io.h"
#include "tyndall/project/project.h"
#include "tyndall/tables/ltsd_table.h"
#include "tyndall/techniques/registry.h"

#include <gtest/gtest.h>

#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct CliRun {
    int exitCode = -1;  // -1 when killed by a signal
    std::string output;  // stdout and stderr
};

// `environment` is prefixed to the command line, e.g. "TYNDALL_TABLES_DIR='/tmp/x' ".
CliRun tyndall(const std::string& args, const std::string& environment = "") {
    const std::string command = environment + std::string(TYNDALL_CLI) + " " + args + " 2>&1";
    CliRun run;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return run;
    std::array<char, 4096> buffer{};
    while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe))
        run.output.append(buffer.data(), n);
    const int status = pclose(pipe);
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

std::string data(const std::string& name) {
    return std::string(TYNDALL_SOURCE_DIR) + "/tests/data/" + name;
}

fs::path scratch(const std::string& name) {
    const fs::path dir = fs::path(TYNDALL_TEST_TMP) / "reliability" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string writeFile(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
}

std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> filesIn(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

// A scene that renders in milliseconds: an area light over a floor, seen by the reference.
std::string tinyProject(const fs::path& dir) {
    return writeFile(dir / "tiny.json", R"({
  "tyndall": 1,
  "camera": {"position": [0, 1, 3], "target": [0, 0, 0], "width": 24, "height": 16},
  "lights": [{"name": "panel", "type": "area", "vertices": [[-1, 2, -1], [-1, 2, 1], [1, 2, 1], [1, 2, -1]],
              "radiance": 2.0, "twoSided": true}],
  "materials": [{"name": "floor", "albedo": 0.5}],
  "meshes": [{"name": "floor", "shape": "plane", "material": "floor", "transform": {"scale": [4, 1, 4]}}],
  "views": [{"name": "ref", "technique": "reference"}]
})");
}

void expectRefused(const CliRun& run, const std::string& what, const std::vector<std::string>& phrases) {
    const std::string shown = run.output.substr(0, 4000);  // a failure must not print megabytes
    EXPECT_EQ(run.exitCode, 2) << what << ": " << shown;
    EXPECT_EQ(run.output.find("contract violated"), std::string::npos) << what << ": " << shown;
    for (const std::string& phrase : phrases)
        EXPECT_NE(run.output.find(phrase), std::string::npos) << what << ": expected '" << phrase << "' in " << shown;
}

// ---------------------------------------------------------------------------------------------------------------------
// Items 1-5 and 9-10: inputs that crashed, aborted, passed validate but failed render, or were accepted silently.

struct BadProject {
    const char* file;
    std::vector<std::string> phrases;  // each must appear in the message
};

const std::vector<BadProject>& badProjects() {
    static const std::vector<BadProject> projects = {
        {"deep_nesting.json", {"deep_nesting.json:1:", "name", "nested deeper than 64"}},
        {"legendre_no_coefficients.json", {"lights[0].distribution.coefficients"}},
        {"mesh_scaled_1e200.json", {"mesh \"big\"", "beyond the limit of +-1e+08 m"}},
        {"mesh_scaled_1e10.json", {"mesh \"big\"", "beyond the limit of +-1e+08 m"}},
        {"camera_target_1e-300_away.json", {"camera.target", "must be at least 1e-06 m from the position"}},
        {"camera_extreme_coordinates.json", {"camera.position", "limited to +-1e+08 m"}},
        {"particle_region_1e308.json", {"particleMedia[0].generator.region.size", "limited to +-1e+08 m"}},
        {"particle_region_1e12.json", {"particleMedia[0].generator.region.size", "limited to +-1e+08 m"}},
        {"gobo_tiny.json", {"lights[0].gobo", "the smallest allowed is 1e-06 m"}},
        {"area_light_tiny.json", {"lights[0].vertices", "the smallest allowed is 1e-06 m"}},
        {"area_light_huge.json", {"lights[0].vertices", "beyond the limit of +-1e+08 m"}},
        {"obj_without_triangles.json", {"has no triangles"}},
        {"obj_bad_face_index.json", {"a face refers to vertex"}},
        {"mesh_singular_transform.json", {"the transform is singular"}},
        {"pegoraro_over_order_limit.json", {"the Pegoraro technique takes"}},
        {"duplicate_key.json", {"duplicate_key.json:3:", "camera.fovY", "duplicate key 'fovY'"}},
        {"nul_byte.json", {"nul_byte.json:2:1", "NUL byte"}},
        {"number_too_large.json", {"number_too_large.json:4:", "camera.fovY", "1e999 is too large"}},
        {"polyhedron_1100_planes.json", {"media[0].planes", "at most 1024 planes, got 1100"}},
        {"particles_over_total_limit.json", {"particleMedia[2]", "at most 2000000 in all"}},
        // Rendered as all-black images with exit 0 (every sample overflowed and was zeroed).
        {"light_radiance_1e300.json", {"lights[0].radiance", "must be in [0, 1e+15]"}},
        {"medium_sigma_s_1e300.json", {"media[0].sigma_s", "must be in [0, 1e+06]"}},
        // Issue 34: validated, then failed to render with most samples non-finite.
        {"distribution_coefficients_1e308.json",
         {"distribution_coefficients_1e308.json", "lights[0].distribution.coefficients[0]",
          "must be in [-1e+15, 1e+15]"}},
        {"particle_region_1e-308.json",
         {"particle_region_1e-308.json", "particleMedia[0].generator.region.size",
          "each side must be at least 1e-06 m"}},
        {"distribution_peak_over_limit.json",
         {"lights[0].distribution.coefficients", "peak intensity", "must be at most 1e+15 W/sr"}},
        // Issue 34: refused at render time without the file or the field.
        {"box_medium_tiny.json", {"box_medium_tiny.json", "media[0].box.size", "the smallest allowed is 1e-06 m"}},
    };
    return projects;
}

TEST(Reliability, ValidateRefusesWhatCannotBeRenderedWithFileAndField) {
    for (const BadProject& p : badProjects())
        expectRefused(tyndall("validate '" + data(p.file) + "'"), p.file, p.phrases);
}

TEST(Reliability, RenderRefusesTheSameInputsWithoutCrashing) {
    const fs::path dir = scratch("render-refuses");
    for (const BadProject& p : badProjects()) {
        const std::string out = (dir / "out.exr").string();
        const CliRun run = tyndall("render '" + data(p.file) + "' --view " +
                                   (std::string(p.file) == "pegoraro_over_order_limit.json" ? "closed" : "ref") +
                                   " --spp 1 -o '" + out + "'");
        EXPECT_EQ(run.exitCode, 2) << p.file << ": " << run.output.substr(0, 4000);
        EXPECT_FALSE(fs::exists(out)) << p.file;
    }
    EXPECT_TRUE(filesIn(dir).empty());
}

TEST(Reliability, DeepNestingThroughSetIsRefused) {
    const std::string deep = std::string(50000, '[') + std::string(50000, ']');
    const CliRun run = tyndall("validate '" + std::string(TYNDALL_SOURCE_DIR) + "/projects/default.json' --set 'name=" +
                               deep + "'");
    expectRefused(run, "--set name=[[[...]]]", {"--set name", "nested deeper than 64"});
}

TEST(Reliability, LegendreConversionOfShortSeriesStaysInBounds) {
    EXPECT_TRUE(tyndall::legendreToMonomial({}).empty());
    EXPECT_EQ(tyndall::legendreToMonomial({1.0}), std::vector<double>({1.0}));
    // a_0 P_0 + a_1 P_1 = 1 + 0.5 mu.
    EXPECT_EQ(tyndall::legendreToMonomial({1.0, 0.5}), std::vector<double>({1.0, 0.5}));
}

TEST(Reliability, AHugeValueIsNotEchoedWhole) {
    const fs::path dir = scratch("huge-value");
    const std::string project =
        writeFile(dir / "huge.json", R"({"tyndall": 1, "views": [{"name": "v", "technique": ")" +
                                         std::string(10'000'000, 'x') + R"("}]})");
    const CliRun run = tyndall("validate '" + project + "'");
    expectRefused(run, "10 MB technique name", {"views[0].technique", "(10000000 bytes)"});
    EXPECT_LT(run.output.size(), 2000u);
}

TEST(Reliability, CommandLineValuesThatWouldChangeMeaningAreRefused) {
    const fs::path dir = scratch("arguments");
    const std::string project = tinyProject(dir);
    const std::string out = (dir / "x.png").string();
    const std::string render = "render '" + project + "' --view ref --spp 1 -o '" + out + "' ";
    expectRefused(tyndall(render + "--seed -1"), "--seed -1", {"--seed"});
    expectRefused(tyndall(render + "--seed 18446744073709551616"), "--seed 2^64", {"--seed"});
    expectRefused(tyndall(render + "--threads -5"), "--threads -5", {"--threads"});
    expectRefused(tyndall(render + "--exposure nan"), "--exposure nan", {"--exposure"});
    expectRefused(tyndall(render + "--size 100000x100000"), "--size", {"--size", "[1, 16384]"});
    expectRefused(tyndall(render + "--set 'lights[99999999999999999999999].radiance=1'"), "huge index",
                  {"--set lights[99999999999999999999999].radiance", "too large"});
    expectRefused(tyndall(render + "--set \"name=$(printf '\\377\\376')\""), "invalid UTF-8", {"--set name", "UTF-8"});
    EXPECT_FALSE(fs::exists(out));
    expectRefused(tyndall("probe '" + project + "' --view ref --probe distances --spp 0"), "probe --spp 0", {"--spp"});
}

TEST(Reliability, AProjectThatIsNotAFileIsNamedAsSuch) {
    const fs::path dir = scratch("not-a-file");
    expectRefused(tyndall("validate '" + dir.string() + "'"), "a directory", {"is a directory"});
    expectRefused(tyndall("validate /dev/null"), "/dev/null", {"/dev/null", "not a regular file"});
}

// ---------------------------------------------------------------------------------------------------------------------
// Items 6-8 and 11: outputs are all-or-nothing; environment failures exit 1.

TEST(Reliability, RenderWritesEveryOutputOrNone) {
    const fs::path dir = scratch("all-or-nothing");
    const std::string project = tinyProject(dir);
    const std::string ok = (dir / "ok.exr").string();
    // /proc refuses new files even to root: the second output fails after the render.
    const CliRun run = tyndall("render '" + project + "' --view ref --spp 1 -o '" + ok + "' -o /proc/tyndall-x.png");
    EXPECT_EQ(run.exitCode, 1) << run.output;
    EXPECT_NE(run.output.find("/proc/tyndall-x.png"), std::string::npos) << run.output;
    EXPECT_EQ(filesIn(dir), std::vector<std::string>({"tiny.json"}));
}

TEST(Reliability, AFailedWriteLeavesTheExistingFileAndNoTemporary) {
    const fs::path dir = scratch("full-disk");
    const fs::path mountPoint = dir / "tiny-fs";
    fs::create_directories(mountPoint);
    if (::mount("tyndall-test", mountPoint.c_str(), "tmpfs", 0, "size=64k") != 0)
        GTEST_SKIP() << "cannot mount a 64 KiB tmpfs here (needs root and a mount namespace that allows it)";
    const std::string project = tinyProject(dir);
    const std::string exr = (mountPoint / "x.exr").string();
    writeFile(exr, "the good file");
    writeFile(mountPoint / "filler", std::string(60 * 1024, 'f'));  // leaves 4 KiB, less than a noisy 96 x 64 EXR
    const CliRun run = tyndall("render '" + project + "' --view ref --spp 1 --size 96x64 -o '" + exr + "'");
    const std::string kept = readFile(exr);
    const std::vector<std::string> files = filesIn(mountPoint);
    ::umount(mountPoint.c_str());
    EXPECT_EQ(run.exitCode, 1) << run.output;
    EXPECT_NE(run.output.find("No space left on device"), std::string::npos) << run.output;
    EXPECT_EQ(run.output.find("wrote"), std::string::npos) << run.output;
    EXPECT_EQ(kept, "the good file");
    EXPECT_EQ(files, std::vector<std::string>({"filler", "x.exr"}));
}

TEST(Reliability, TextOutputsIgnorePlantedFilesAndUpdateSymlinkTargets) {
    const fs::path dir = scratch("symlinks");
    const std::string project = tinyProject(dir);
    const std::string ref = (dir / "ref.exr").string();
    ASSERT_EQ(tyndall("render '" + project + "' --view ref --spp 1 -o '" + ref + "'").exitCode, 0);

    // A symlink planted at the old predictable temporary name must not be followed.
    writeFile(dir / "victim", "precious");
    fs::create_symlink(dir / "victim", dir / "metrics.json.tmp");
    // metrics-link.json is a symlink to real.json: the target is updated, the link stays.
    writeFile(dir / "real.json", "old");
    fs::create_symlink("real.json", dir / "metrics-link.json");
    const CliRun run = tyndall("compare '" + ref + "' -r '" + ref + "' --json '" + (dir / "metrics.json").string() +
                               "' --csv '" + (dir / "metrics-link.json").string() + "'");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_EQ(readFile(dir / "victim"), "precious");
    EXPECT_TRUE(fs::is_symlink(dir / "metrics-link.json"));
    EXPECT_NE(readFile(dir / "real.json").find("relMSE"), std::string::npos);
    EXPECT_NE(readFile(dir / "metrics.json").find("differenceScale"), std::string::npos);

    // A directory as an output is bad input, reported as such (not "Success").
    const CliRun onDir = tyndall("compare '" + ref + "' -r '" + ref + "' --json '" + dir.string() + "'");
    expectRefused(onDir, "--json <directory>", {"--json", "is a directory"});
}

TEST(Reliability, CompareWritesNothingWhenAnyInputFails) {
    const fs::path dir = scratch("compare-partial");
    const std::string project = tinyProject(dir);
    const std::string a = (dir / "a.exr").string();
    ASSERT_EQ(tyndall("render '" + project + "' --view ref --spp 1 -o '" + a + "'").exitCode, 0);
    const CliRun run = tyndall("compare '" + a + "' '" + (dir / "missing.exr").string() + "' -r '" + a +
                               "' --diff '" + (dir / "{name}-diff.png").string() + "' --json '" +
                               (dir / "m.json").string() + "'");
    EXPECT_EQ(run.exitCode, 2) << run.output;
    EXPECT_NE(run.output.find("missing.exr"), std::string::npos) << run.output;
    EXPECT_EQ(filesIn(dir), std::vector<std::string>({"a.exr", "tiny.json"}));

    // A PNG holds display values, not linear ones.
    const std::string png = (dir / "a.png").string();
    ASSERT_EQ(tyndall("render '" + project + "' --view ref --spp 1 -o '" + png + "'").exitCode, 0);
    expectRefused(tyndall("compare '" + png + "' -r '" + a + "'"), "a PNG",
                  {"a.png", "must be an OpenEXR image (.exr)"});
    expectRefused(tyndall("compare '" + a + "' -r '" + a + "' --diff-scale nan"), "--diff-scale nan", {"--diff-scale"});
    // A size mismatch names the file.
    const std::string small = (dir / "small.exr").string();
    ASSERT_EQ(tyndall("render '" + project + "' --view ref --spp 1 --size 8x8 -o '" + small + "'").exitCode, 0);
    expectRefused(tyndall("compare '" + small + "' -r '" + a + "'"), "size mismatch", {"small.exr"});
}

TEST(Reliability, SavingAProjectThroughASymlinkUpdatesItsTarget) {
    const fs::path dir = scratch("save-symlink");
    const std::string project = tinyProject(dir);
    fs::create_directories(dir / "elsewhere");
    fs::rename(project, dir / "elsewhere" / "real.json");
    fs::create_symlink("elsewhere/real.json", dir / "link.json");
    tyndall::Project loaded = tyndall::loadProject(tyndall::techniqueCatalogue(), (dir / "link.json").string());
    loaded.name = "saved through the link";
    tyndall::saveProject(loaded, (dir / "link.json").string());
    EXPECT_TRUE(fs::is_symlink(dir / "link.json"));
    EXPECT_EQ(tyndall::loadProject(tyndall::techniqueCatalogue(), (dir / "elsewhere" / "real.json").string()).name,
              "saved through the link");
    EXPECT_EQ(filesIn(dir / "elsewhere"), std::vector<std::string>({"real.json"}));
}

TEST(Reliability, StaleTemporariesOfDeadWritersAreRemoved) {
    const fs::path dir = scratch("stale");
    const std::string project = tinyProject(dir);
    // Left by a writer that was killed (no process has this pid: pids stay below 2^22 on Linux) and by one that runs.
    const std::string stale = ".out.exr.tyndall-999999999-AbC123";
    const std::string live = ".out.exr.tyndall-" + std::to_string(::getpid()) + "-XyZ789";
    writeFile(dir / stale, "partial");
    writeFile(dir / live, "in progress");
    ASSERT_EQ(tyndall("render '" + project + "' --view ref --spp 1 -o '" + (dir / "out.exr").string() + "'").exitCode,
              0);
    EXPECT_FALSE(fs::exists(dir / stale));
    EXPECT_TRUE(fs::exists(dir / live));
    EXPECT_EQ(tyndall::removeStaleTemporaries((dir / "out.exr").string()), 0);
}

// ---------------------------------------------------------------------------------------------------------------------
// Issue 34: refusals name their file and field; what validates renders; compare never reports NaN as a result.

TEST(Reliability, PerViewLimitsNameTheFileAndTheView) {
    const std::string isv = data("isv_two_lights.json"), ltsd = data("ltsd_nine_area_lights.json");
    expectRefused(tyndall("validate '" + ltsd + "'"), "LTSD, nine area lights",
                  {"ltsd_nine_area_lights.json: views[1].lights: view 'panels': ", "area lights per view, got 9"});
    const fs::path dir = scratch("per-view");
    const std::string out = (dir / "x.exr").string();
    expectRefused(tyndall("render '" + ltsd + "' --view panels --spp 1 -o '" + out + "'"), "render LTSD",
                  {"ltsd_nine_area_lights.json: views[1].lights: ", "area lights per view, got 9"});
    EXPECT_FALSE(fs::exists(out));
    // The reference of the same project renders: the limit is the view's, not the project's.
    EXPECT_EQ(tyndall("render '" + ltsd + "' --view ref --spp 1 -o '" + out + "'").exitCode, 0);
    // ISV renders several lights (issue 32; it refused a second one before): the two-light view validates and renders.
    const CliRun valid = tyndall("validate '" + isv + "'");
    EXPECT_EQ(valid.exitCode, 0) << valid.output;
    const CliRun render = tyndall("render '" + isv + "' --view smoke --spp 1 -o '" + out + "'");
    EXPECT_EQ(render.exitCode, 0) << render.output;
}

TEST(Reliability, AnImageTooLargeNamesTheFile) {
    const fs::path dir = scratch("too-large");
    const std::string project = tinyProject(dir);
    expectRefused(tyndall("validate '" + project + "' --set camera.width=16384 --set camera.height=16384"),
                  "16384 x 16384", {"tiny.json: camera: ", "16384 x 16384 pixels is too large"});
}

TEST(Reliability, ABoxMediumFarFromTheOriginRendersWithinTheWorldLimits) {
    // Centred 1e6 m away (the world is +-1e8 m): refused as an "empty intersection" before.
    const std::string project = data("box_medium_far.json");
    const CliRun validate = tyndall("validate '" + project + "'");
    EXPECT_EQ(validate.exitCode, 0) << validate.output;
    const fs::path dir = scratch("far-box");
    const std::string out = (dir / "far.exr").string();
    const CliRun render = tyndall("render '" + project + "' --view ref --spp 4 -o '" + out + "'");
    ASSERT_EQ(render.exitCode, 0) << render.output;
    // The camera looks into the lit fog: the image is finite and not black.
    const tyndall::Image image = tyndall::readImage(out);
    double sum = 0.0;
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x) {
            ASSERT_TRUE(std::isfinite(image.at(x, y, 0)));
            sum += image.at(x, y, 0);
        }
    EXPECT_GT(sum, 0.0);
}

namespace {

// A copy of the shipped tables in `dir`, hg.ltsd changed by `edit` and its checksum recomputed.
void corruptHgTable(const fs::path& dir, const std::function<void(std::vector<std::uint8_t>&)>& edit) {
    fs::create_directories(dir);
    for (const auto& entry : fs::directory_iterator(std::string(TYNDALL_SOURCE_DIR) + "/tables")) {
        const std::string ext = entry.path().extension().string();
        if (ext == ".ltsd" || ext == ".ltc" || ext == ".json")
            fs::copy_file(entry.path(), dir / entry.path().filename(), fs::copy_options::overwrite_existing);
    }
    const std::string text = readFile(dir / "hg.ltsd");
    std::vector<std::uint8_t> bytes(text.begin(), text.end());
    edit(bytes);
    const std::uint64_t checksum = tyndall::ltsdTableChecksum(bytes);
    std::memcpy(bytes.data() + 48, &checksum, 8);
    writeFile(dir / "hg.ltsd", std::string(bytes.begin(), bytes.end()));
}

void setFloat(std::vector<std::uint8_t>& bytes, std::size_t offset, float value) {
    std::memcpy(bytes.data() + offset, &value, 4);
}

}  // namespace

TEST(Reliability, ACorruptedTableIsRefusedByEveryCommandThatReadsIt) {
    const fs::path dir = scratch("corrupt-tables");
    const std::string polygon = "'[[0.3,0.2,-1],[-0.3,0.2,-1],[0,-0.3,-1]]'";
    const std::string hgEval = "tables eval --phase '{\"type\":\"hg\",\"g\":0.5}' --polygon " + polygon;
    const std::string ltsdProject = std::string(TYNDALL_SOURCE_DIR) + "/projects/examples/ltsd-room.json";

    // The header's phase type changed to another table's (the checksum recomputed): a contract failure before.
    corruptHgTable(dir / "phase", [](std::vector<std::uint8_t>& b) {
        std::memset(b.data() + 24, 0, 16);
        std::memcpy(b.data() + 24, "rayleigh", 8);
    });
    const std::string tables = " --tables '" + (dir / "phase").string() + "'";
    const std::vector<std::string> phrases = {"hg.ltsd", "header.phase", "fits 'rayleigh'", "must hold the 'hg' table"};
    expectRefused(tyndall("tables hg" + tables), "tables hg", phrases);
    expectRefused(tyndall("tables" + tables), "tables", phrases);
    expectRefused(tyndall(hgEval + tables), "tables eval", phrases);
    const std::string env = "TYNDALL_TABLES_DIR='" + (dir / "phase").string() + "' ";
    expectRefused(tyndall("validate '" + ltsdProject + "'", env), "validate an LTSD project", phrases);
    // The view with the paper's S, which reads the table (the accurate S reads none).
    const std::string out = (dir / "room.exr").string();
    const CliRun render =
        tyndall("render '" + ltsdProject + "' --view 'ltsd paper' --spp 1 --size 16x12 -o '" + out + "'", env);
    expectRefused(render, "render an LTSD view", phrases);
    EXPECT_FALSE(fs::exists(out));

    // A NaN or an out-of-order per-entry g: accepted and rendered before.
    corruptHgTable(dir / "nan-g", [](std::vector<std::uint8_t>& b) { setFloat(b, 64 + 48 * 5 + 44, std::nanf("")); });
    expectRefused(tyndall("tables hg --tables '" + (dir / "nan-g").string() + "'"), "NaN g",
                  {"hg.ltsd", "entries[5].g", "got nan"});
    corruptHgTable(dir / "swapped-g", [](std::vector<std::uint8_t>& b) {
        std::swap_ranges(b.begin() + 64 + 48 * 3, b.begin() + 64 + 48 * 4, b.begin() + 64 + 48 * 7);
    });
    expectRefused(tyndall(hgEval + " --tables '" + (dir / "swapped-g").string() + "'"), "swapped entries",
                  {"hg.ltsd", "entries[3].g", "must be the entry's table coordinate"});
}

TEST(Reliability, CompareRefusesWhatIsNotAFiniteLinearImage) {
    const fs::path dir = scratch("compare-inputs");
    const std::string project = tinyProject(dir);
    const std::string a = (dir / "a.exr").string(), png = (dir / "a.png").string();
    ASSERT_EQ(tyndall("render '" + project + "' --view ref --spp 1 -o '" + a + "' -o '" + png + "'").exitCode, 0);

    // A PNG renamed .exr is display values still.
    fs::copy_file(png, dir / "renamed.exr");
    expectRefused(tyndall("compare '" + (dir / "renamed.exr").string() + "' -r '" + a + "'"), "PNG named .exr",
                  {"renamed.exr", "holds a png image"});
    // Another extension is named as such (not as a PNG).
    fs::copy_file(a, dir / "a.hdr");
    const CliRun hdr = tyndall("compare '" + (dir / "a.hdr").string() + "' -r '" + a + "'");
    expectRefused(hdr, ".hdr", {"a.hdr", "got '.hdr'"});
    EXPECT_EQ(hdr.output.find("PNG"), std::string::npos) << hdr.output;

    // NaN pixels: exit 0 with "nan" metrics before.
    tyndall::Image image = tyndall::readImage(a);
    image.at(3, 2, 1) = std::nanf("");
    tyndall::writeImage(image, (dir / "nan.exr").string());
    const std::string json = (dir / "m.json").string();
    const CliRun nan = tyndall("compare '" + (dir / "nan.exr").string() + "' -r '" + a + "' --json '" + json + "'");
    expectRefused(nan, "NaN pixels", {"nan.exr", "not finite", "pixel (3, 2), channel G"});
    EXPECT_FALSE(fs::exists(json));
    expectRefused(tyndall("compare '" + a + "' -r '" + (dir / "nan.exr").string() + "'"), "NaN reference",
                  {"nan.exr", "--reference"});

    // The reference's exposure metadata: NaN was refused naming the other file, "abc" was read as 0.
    for (const char* bad : {"nan", "abc", "1e999", ""}) {
        tyndall::Image withExposure = tyndall::readImage(a);
        withExposure.metadata["exposure"] = bad;
        const std::string ref = (dir / "exposure.exr").string();
        tyndall::writeImage(withExposure, ref);
        const CliRun run = tyndall("compare '" + a + "' -r '" + ref + "'");
        expectRefused(run, std::string("exposure '") + bad + "'", {"exposure.exr: metadata.exposure: ", "[-20, 20]"});
        // --exposure replaces the metadata, so the comparison runs.
        EXPECT_EQ(tyndall("compare '" + a + "' -r '" + ref + "' --exposure 0").exitCode, 0) << bad;
    }
}

TEST(Reliability, SmallArgumentProblemsHaveExactAnswers) {
    const fs::path dir = scratch("small");
    const std::string project = tinyProject(dir);
    // -0 is the number 0.
    const CliRun seed = tyndall("validate '" + project + "' --set reference.seed=-0");
    EXPECT_EQ(seed.exitCode, 0) << seed.output;
    // Any finite direction normalises, 1e308 included.
    const CliRun huge = tyndall(
        "tables eval --phase '{\"type\":\"isotropic\"}' --polygon "
        "'[[1e308,0,1e308],[0,1e308,1e308],[-1e308,-1e308,1e308]]'");
    EXPECT_EQ(huge.exitCode, 0) << huge.output;
    expectRefused(tyndall("tables eval --phase '{\"type\":\"isotropic\"}' --polygon '[[1e308,0,0],[0,0,0],[0,1,1]]'"),
                  "a zero vertex", {"--polygon", "vertex 1 must be a finite, non-zero direction"});
    // An empty --pixel is not the centre.
    expectRefused(tyndall("probe '" + project + "' --view ref --probe distances --pixel ''"), "--pixel ''",
                  {"--pixel", "is not x,y"});
    // A name the file system cannot hold (with the temporary's suffix) is bad input, exit 2.
    const std::string longName = (dir / (std::string(300, 'n') + ".exr")).string();
    expectRefused(tyndall("render '" + project + "' --view ref --spp 1 -o '" + longName + "'"), "300-byte name",
                  {"names are limited to 231 bytes"});
    const std::string nearLimit = (dir / (std::string(240, 'n') + ".png")).string();
    expectRefused(tyndall("render '" + project + "' --view ref --spp 1 -o '" + nearLimit + "'"), "244-byte name",
                  {"names are limited to 231 bytes"});
    EXPECT_EQ(filesIn(dir), std::vector<std::string>({"tiny.json"}));
}

}  // namespace
