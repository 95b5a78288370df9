// The tyndall CLI end to end, as a user runs it: exit codes (0 ok, 1 failure, 2 bad input), messages and outputs.
#include "tyndall/image/colour_management.h"
#include "tyndall/image/colour_map.h"
#include "tyndall/image/image_io.h"
#include "tyndall/image/metrics.h"
#include "tyndall/image/tonemap.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <numbers>
#include <set>
#include <tuple>
#include <utility>

namespace fs = std::filesystem;

namespace {

// The CLI's PNGs go through the shipped OpenColorIO config's default display and view, whatever the user's $OCIO
// (the tests that want another set it for their command).
const bool kOcioUnset = (unsetenv("OCIO"), true);

struct CliRun {
    int exitCode = -1;
    std::string output;  // stdout and stderr
};

// Which of the CLI's output streams a run keeps: both (interleaved), or one with the other discarded.
enum class Streams { Both, Stdout, Stderr };

// `env`: assignments before the command, e.g. "TYNDALL_ROOT='/x' ".
CliRun tyndall(const std::string& args, const std::string& env = "", Streams streams = Streams::Both) {
    const char* redirect = streams == Streams::Both     ? " 2>&1"
                           : streams == Streams::Stdout ? " 2>/dev/null"
                                                        : " 2>&1 >/dev/null";
    std::string command = env + std::string(TYNDALL_CLI) + " " + args + redirect;
    CliRun run;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return run;
    std::array<char, 4096> buffer{};
    while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe))
        run.output.append(buffer.data(), n);
    int status = pclose(pipe);
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

std::string source(const std::string& relative) {
    return std::string(TYNDALL_SOURCE_DIR) + "/" + relative;
}

fs::path scratch(const std::string& name) {
    fs::path dir = fs::path(TYNDALL_TEST_TMP) / "cli" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string writeFile(const fs::path& path, const std::string& text) {
    std::ofstream(path) << text;
    return path.string();
}

std::vector<std::string> bundledProjects() {
    std::vector<std::string> out;
    for (const auto& entry : fs::recursive_directory_iterator(source("projects")))
        if (entry.path().extension() == ".json" && !entry.path().filename().string().ends_with(".sweep.json"))
            out.push_back(entry.path().string());  // projects, not sweep specs (projects/sweeps)
    std::sort(out.begin(), out.end());
    return out;
}

TEST(Cli, InfoListsTheReferenceAndItsParameters) {
    CliRun r = tyndall("info");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("reference"), std::string::npos);
    EXPECT_NE(r.output.find("distanceSampling"), std::string::npos);
    CliRun j = tyndall("info --json");
    EXPECT_EQ(j.exitCode, 0);
    EXPECT_NE(j.output.find("\"techniques\""), std::string::npos);
}

// The device's driver and features are listed; without any Vulkan driver (the loader pointed at none) everything else
// is still printed, one line on stderr says why, and the exit status is 1 (issue 37: scripts check `tyndall info`).
TEST(Cli, InfoNamesTheDriverAndExitsOneWithoutAVulkanDevice) {
    const CliRun j = tyndall("info --json", "", Streams::Stdout);
    ASSERT_EQ(j.exitCode, 0) << j.output;
    const nlohmann::json info = nlohmann::json::parse(j.output);
    ASSERT_GE(info["devices"].size(), 2u) << j.output;
    EXPECT_NE(info["devices"][1]["driver"].get<std::string>().find("llvmpipe"), std::string::npos) << j.output;
    for (const char* feature : {"float64", "rayQuery", "meshShader", "geometryShader", "timestamps"})
        EXPECT_TRUE(info["devices"][1].contains(feature)) << feature;

    const std::string noDriver = "VK_DRIVER_FILES=/nonexistent/icd.json VK_ICD_FILENAMES= ";
    const CliRun why = tyndall("info", noDriver, Streams::Stderr);
    EXPECT_EQ(why.exitCode, 1) << why.output;
    EXPECT_EQ(std::count(why.output.begin(), why.output.end(), '\n'), 1) << why.output;
    EXPECT_NE(why.output.find("tyndall: no Vulkan device ("), std::string::npos) << why.output;
    EXPECT_NE(why.output.find("views with device = auto render on the CPU"), std::string::npos) << why.output;
    const CliRun listed = tyndall("info", noDriver, Streams::Stdout);
    EXPECT_EQ(listed.exitCode, 1);
    EXPECT_NE(listed.output.find("  ltsd - LTSD"), std::string::npos) << listed.output;
    const CliRun json = tyndall("info --json", noDriver, Streams::Stdout);
    EXPECT_EQ(json.exitCode, 1);
    EXPECT_TRUE(nlohmann::json::parse(json.output).contains("vulkanError")) << json.output;
}

TEST(Cli, EveryBundledProjectValidates) {
    std::vector<std::string> projects = bundledProjects();
    ASSERT_FALSE(projects.empty());
    for (const std::string& p : projects) {
        CliRun r = tyndall("validate '" + p + "'");
        EXPECT_EQ(r.exitCode, 0) << p << ": " << r.output;
    }
}

TEST(Cli, EveryBundledProjectRoundTripsExactly) {
    fs::path dir = scratch("roundtrip");
    for (const std::string& p : bundledProjects()) {
        tyndall::Project project = tyndall::loadProject(tyndall::techniqueCatalogue(), p);
        fs::path once = dir / "once.json", twice = dir / "twice.json";
        tyndall::saveProject(project, once.string());
        tyndall::saveProject(tyndall::loadProject(tyndall::techniqueCatalogue(), once.string()), twice.string());
        std::ifstream a(once), b(twice);
        std::string textA((std::istreambuf_iterator<char>(a)), {}), textB((std::istreambuf_iterator<char>(b)), {});
        EXPECT_EQ(textA, textB) << p;
        EXPECT_EQ(tyndall::projectHash(project),
                  tyndall::projectHash(tyndall::loadProject(tyndall::techniqueCatalogue(), once.string())))
            << p;
    }
}

TEST(Cli, RendersTheDefaultProjectsReferenceWithMetadata) {
    fs::path dir = scratch("render");
    std::string exr = (dir / "ref.exr").string(), png = (dir / "ref.png").string();
    CliRun r = tyndall("render '" + source("projects/default.json") +
                       "' --reference --size 32x24 --spp 4 --seed 7 -o '" + exr + "' -o '" + png + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("wrote"), std::string::npos);
    ASSERT_TRUE(fs::exists(png));
    tyndall::Image image = tyndall::readImage(exr);
    EXPECT_EQ(image.width(), 32);
    EXPECT_EQ(image.height(), 24);
    EXPECT_GE(image.channelIndex("variance.R"), 0);
    EXPECT_EQ(image.metadata.at("technique"), "reference");
    EXPECT_EQ(image.metadata.at("spp"), "4");
    EXPECT_EQ(image.metadata.at("seed"), "7");
    EXPECT_EQ(image.metadata.at("mode"), "single");
    EXPECT_FALSE(image.metadata.at("projectHash").empty());
    EXPECT_FALSE(image.metadata.at("tyndallVersion").empty());
    EXPECT_FALSE(image.metadata.at("renderTime").empty());
    // The image is not black: the room is lit.
    double sum = 0.0;
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            sum += image.at(x, y, 0) + image.at(x, y, 1) + image.at(x, y, 2);
    EXPECT_GT(sum, 0.0);
}

// --tonemap: each operator's PNG holds tonemapRgb() of the EXR's pixels (the studio's viewport and exports use the same
// function), and the operators give different pictures.
TEST(Cli, PngsGoThroughTheChosenTonemapOperator) {
    fs::path dir = scratch("tonemap");
    const std::string exr = (dir / "v.exr").string();
    const std::string common = "render '" + source("projects/default.json") + "' --view glow --size 16x12 --spp 2 --seed 3 ";
    ASSERT_EQ(tyndall(common + "-o '" + exr + "'").exitCode, 0);
    const tyndall::Image linear = tyndall::readImage(exr);
    std::vector<double> means;
    for (const std::string& name : tyndall::tonemapNames()) {
        const std::string png = (dir / (name + ".png")).string();
        CliRun r = tyndall(common + "--exposure 1 --tonemap " + name + " -o '" + png + "'");
        ASSERT_EQ(r.exitCode, 0) << r.output;
        const tyndall::Image shown = tyndall::readImage(png);  // 8-bit values as floats in [0, 1]
        ASSERT_EQ(shown.width(), linear.width());
        const tyndall::Tonemap op = tyndall::tonemapFromName(name, "test");
        double mean = 0.0;
        for (int y = 0; y < linear.height(); ++y)
            for (int x = 0; x < linear.width(); ++x) {
                const auto d = tyndall::tonemapRgb(linear.at(x, y, 0), linear.at(x, y, 1), linear.at(x, y, 2), 1.0, op);
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(shown.at(x, y, c), std::round(d[std::size_t(c)] * 255.0f) / 255.0f, 0.5 / 255.0)
                        << name << " at " << x << ", " << y;
                    mean += shown.at(x, y, c);
                }
            }
        means.push_back(mean);
    }
    for (std::size_t i = 0; i < means.size(); ++i)
        for (std::size_t j = i + 1; j < means.size(); ++j) EXPECT_NE(means[i], means[j]) << i << " vs " << j;
}

// Without --tonemap, PNGs go through an OpenColorIO display and view (issue 35): the config's default (the shipped
// config's sRGB / Standard) or --display and --ocio-view, each pixel the transform of the EXR's, and the PNG says which
// (its text chunks). A broken $OCIO is passed over with a message naming it; an unknown display or view exits 2
// naming the option and what the config has; `tyndall info` lists the displays and views of the config in use.
TEST(Cli, PngsGoThroughTheOpenColorIoDisplayAndView) {
    fs::path dir = scratch("ocio");
    const std::string exr = (dir / "v.exr").string();
    const std::string common =
        "render '" + source("projects/default.json") + "' --view glow --size 16x12 --spp 2 --seed 3 ";
    ASSERT_EQ(tyndall(common + "-o '" + exr + "'").exitCode, 0);
    const tyndall::Image linear = tyndall::readImage(exr);
    const auto config = tyndall::ColourConfig::load();
    ASSERT_EQ(config->origin(), "shipped");
    for (const auto& [options, display, view] : std::vector<std::tuple<std::string, std::string, std::string>>{
             {"", "sRGB", "Standard"},
             {"--display Rec.1886 ", "Rec.1886", "Standard"},
             {"--display sRGB --ocio-view 'ACES 1.0 - SDR Video' ", "sRGB", "ACES 1.0 - SDR Video"}}) {
        const std::string png = (dir / (display + "-" + view.substr(0, 4) + ".png")).string();
        const CliRun r = tyndall(common + "--exposure 1 " + options + "-o '" + png + "'");
        ASSERT_EQ(r.exitCode, 0) << r.output;
        const tyndall::Image shown = tyndall::readImage(png);
        EXPECT_EQ(shown.metadata.at("display"), display);
        EXPECT_EQ(shown.metadata.at("view"), view);
        EXPECT_EQ(shown.metadata.at("ocioConfig"), tyndall::ColourConfig::shippedConfigPath().string());
        const tyndall::DisplayTransform transform(config, display, view);
        for (int y = 0; y < linear.height(); ++y)
            for (int x = 0; x < linear.width(); ++x) {
                const auto d = transform.apply(linear.at(x, y, 0), linear.at(x, y, 1), linear.at(x, y, 2), 1.0);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(shown.at(x, y, c), std::round(d[std::size_t(c)] * 255.0f) / 255.0f, 0.5 / 255.0)
                        << display << " / " << view << " at " << x << ", " << y;
            }
    }
    const std::string data = source("tests/data/ocio/");
    const CliRun broken =
        tyndall(common + "-o '" + (dir / "fallback.png").string() + "'", "OCIO='" + data + "broken.ocio' ");
    EXPECT_EQ(broken.exitCode, 0) << broken.output;
    EXPECT_NE(broken.output.find("passed over $OCIO"), std::string::npos) << broken.output;
    EXPECT_NE(broken.output.find("broken.ocio"), std::string::npos) << broken.output;
    EXPECT_EQ(tyndall::readImage((dir / "fallback.png").string()).metadata.at("view"), "Standard");
    const CliRun cinema =
        tyndall(common + "-o '" + (dir / "film.png").string() + "'", "OCIO='" + data + "cinema.ocio' ");
    EXPECT_EQ(cinema.exitCode, 0) << cinema.output;
    EXPECT_EQ(tyndall::readImage((dir / "film.png").string()).metadata.at("display"), "Cinema");

    const CliRun display = tyndall(common + "--display P3 -o '" + (dir / "p3.png").string() + "'");
    EXPECT_EQ(display.exitCode, 2);
    EXPECT_NE(display.output.find("--display"), std::string::npos) << display.output;
    EXPECT_NE(display.output.find("\"sRGB\", \"Rec.1886\""), std::string::npos) << display.output;
    const CliRun view = tyndall(common + "--ocio-view Filmic -o '" + (dir / "filmic.png").string() + "'");
    EXPECT_EQ(view.exitCode, 2);
    EXPECT_NE(view.output.find("--ocio-view"), std::string::npos) << view.output;
    EXPECT_FALSE(fs::exists(dir / "p3.png") || fs::exists(dir / "filmic.png"));
    const CliRun both = tyndall(common + "--tonemap aces --display sRGB -o '" + (dir / "both.png").string() + "'");
    EXPECT_EQ(both.exitCode, 2);
    EXPECT_NE(both.output.find("one or the other"), std::string::npos) << both.output;

    const CliRun info = tyndall("info", "", Streams::Stdout);
    EXPECT_NE(info.output.find("Colour (OpenColorIO, PNG output): the shipped config"), std::string::npos);
    EXPECT_NE(info.output.find("  display sRGB (default): Standard, ACES 1.0 - SDR Video, Raw"), std::string::npos)
        << info.output;
    const CliRun json = tyndall("info --json --ocio '" + data + "cinema.ocio'", "", Streams::Stdout);
    const nlohmann::json colour = nlohmann::json::parse(json.output)["colour"];
    EXPECT_EQ(colour["origin"], "--ocio");
    EXPECT_EQ(colour["displays"]["Cinema"], nlohmann::json({"Film", "Raw"}));
}

TEST(Cli, RendersAViewsPartOnlyAndTheSetOverridesAField) {
    fs::path dir = scratch("view");
    std::string a = (dir / "glow.exr").string(), b = (dir / "glow-dark.exr").string();
    std::string common = "render '" + source("projects/default.json") + "' --view glow --size 16x12 --spp 2 ";
    ASSERT_EQ(tyndall(common + "-o '" + a + "'").exitCode, 0);
    CliRun r = tyndall(common + "--set 'lights[lamp].intensity=[0,0,0]' -o '" + b + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    tyndall::Image lit = tyndall::readImage(a), dark = tyndall::readImage(b);
    double litSum = 0.0, darkSum = 0.0;
    for (int y = 0; y < lit.height(); ++y)
        for (int x = 0; x < lit.width(); ++x) {
            litSum += lit.at(x, y, 0);
            darkSum += dark.at(x, y, 0);
        }
    EXPECT_GT(litSum, 0.0);
    EXPECT_EQ(darkSum, 0.0) << "the glow view renders only the lamp, which the override switched off";
    EXPECT_EQ(lit.metadata.at("view"), "glow");
}

TEST(Cli, BadInputExitsWithTwoAndSaysWhy) {
    fs::path dir = scratch("bad");
    std::string project = source("projects/default.json");
    struct Case {
        std::string args, expected;
    };
    std::string malformed =
        writeFile(dir / "malformed.json", "{\n  \"tyndall\": 1,\n  \"camera\": {\n    \"fovY\": ,\n  }\n}\n");
    const Case cases[] = {
        {"render '" + project + "' --reference --size 1000000x1000000 -o '" + (dir / "huge.exr").string() + "'",
         "--size"},
        {"render '" + project + "' --reference --spp 1 -o '" + (dir / "missing/ref.exr").string() + "'",
         "does not exist"},
        {"render '" + project + "' --reference --spp 1 -o '" + (dir / "ref.tiff").string() + "'", ".exr or .png"},
        {"render '" + project + "' --view nope -o '" + (dir / "v.exr").string() + "'", "no view named 'nope'"},
        {"render '" + project + "' --reference --set 'camera.fovy=40' -o '" + (dir / "s.exr").string() + "'", "fovY"},
        {"render '" + project + "' --reference --set 'media[0].sigma_s=[-1,0,0]' -o '" + (dir / "n.exr").string() + "'",
         "sigma_s"},
        {"validate '" + malformed + "'", "malformed.json:4:"},
        {"validate '" + (dir / "absent.json").string() + "'", "absent.json"},
        {"render --frobnicate", ""},
        {"render '" + project + "' --reference --spp 1 --tonemap filmic -o '" + (dir / "t.png").string() + "'",
         "--tonemap: unknown tonemap operator \"filmic\" (allowed: srgb, reinhard, aces, falsecolour)"},
        {"compare '" + (dir / "absent.exr").string() + "' -r '" + (dir / "absent.exr").string() + "'", "absent.exr"},
    };
    for (const Case& c : cases) {
        CliRun r = tyndall(c.args);
        EXPECT_EQ(r.exitCode, 2) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.args << "\n" << r.output;
    }
    // Nothing was written for the refused renders.
    for (const char* name : {"huge.exr", "ref.tiff", "v.exr", "s.exr", "n.exr", "t.png"})
        EXPECT_FALSE(fs::exists(dir / name)) << name;
    EXPECT_FALSE(fs::exists(dir / "missing"));
}

// `tyndall validate` reports every error of a file (up to a bound), not only its first (issue 33): a medium, a light
// and a view wrong at once are named together, with the first error's location first, and exit 2.
TEST(Cli, ValidateReportsEveryErrorOfAFile) {
    fs::path dir = scratch("errors");
    std::ifstream in(source("projects/default.json"));
    nlohmann::json j = nlohmann::json::parse(in);
    j["media"][0]["sigma_s"] = {-1.0, 0.0, 0.0};
    j["lights"][0]["irradiance"] = {-2.0, 1.0, 1.0};
    j["views"][1]["technique"] = "nope";
    const std::string path = writeFile(dir / "three.json", j.dump(2));
    CliRun r = tyndall("validate '" + path + "'");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    for (const char* field : {"sigma_s", "irradiance", "nope", "3 errors"})
        EXPECT_NE(r.output.find(field), std::string::npos) << field << "\n" << r.output;
    // A bound: 30 broken lights report 20 errors and how many more.
    nlohmann::json many = nlohmann::json::parse(std::ifstream(source("projects/default.json")));
    for (int i = 0; i < 30; ++i)
        many["lights"].push_back({{"type", "point"}, {"name", "p" + std::to_string(i)}, {"intensity", {-1, 0, 0}}});
    r = tyndall("validate '" + writeFile(dir / "many.json", many.dump(2)) + "'");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find("and 10 more errors"), std::string::npos) << r.output;
}

// The Pegoraro example renders on both paths with its report in the metadata; what the technique cannot render, or a
// parameter value it does not know, is refused with exit code 2 and a reason.
TEST(Cli, RendersThePegoraroExampleAndRefusesWhatItCannotRender) {
    fs::path dir = scratch("pegoraro");
    const std::string project = source("projects/examples/pegoraro-street.json");
    for (const std::string device : {"cpu", "gpu"}) {
        const std::string exr = (dir / ("street-" + device + ".exr")).string();
        CliRun r = tyndall("render '" + project + "' --view 'closed form' --size 24x18 --set " +
                           "'views[closed form].parameters.device=" + device + "' -o '" + exr + "'");
        ASSERT_EQ(r.exitCode, 0) << r.output;
        tyndall::Image image = tyndall::readImage(exr);
        EXPECT_EQ(image.metadata.at("technique"), "pegoraro");
        EXPECT_EQ(image.metadata.at("pegoraro:precision"), "double");  // order 12 > 4
        EXPECT_EQ(image.metadata.at("pegoraro:shadowOverflowPixels"), "0");
        EXPECT_GE(image.channelIndex("fallbacks"), 0);
        if (device == "cpu")
            EXPECT_EQ(image.metadata.at("device"), "cpu");
        else
            EXPECT_NE(image.metadata.at("device"), "cpu");
        double sum = 0.0;
        for (int y = 0; y < image.height(); ++y)
            for (int x = 0; x < image.width(); ++x)
                sum += image.at(x, y, 0);
        EXPECT_GT(sum, 0.0);
    }
    const std::string out = (dir / "refused.exr").string();
    // A view that names the medium (a view without a part takes what its technique supports).
    CliRun boxed = tyndall("render '" + project + "' --view 'spot only' --size 8x6 --set 'media[haze].shape=box' -o '" +
                           out + "'");
    EXPECT_EQ(boxed.exitCode, 2) << boxed.output;
    EXPECT_NE(boxed.output.find("infinite medium"), std::string::npos) << boxed.output;
    CliRun precision = tyndall("render '" + project + "' --view 'closed form' --size 8x6 --set " +
                               "'views[closed form].parameters.precision=quad' -o '" + out + "'");
    EXPECT_EQ(precision.exitCode, 2) << precision.output;
    EXPECT_NE(precision.output.find("double"), std::string::npos) << precision.output;
    EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, RendersTheIsvSmokeOnBothDevicesAndRefusesAnAreaLight) {
    fs::path dir = scratch("isv");
    const std::string project = source("projects/isv/smoke.json");
    std::vector<tyndall::Image> images;
    for (const std::string device : {"cpu", "gpu"}) {
        const std::string exr = (dir / ("smoke-" + device + ".exr")).string();
        CliRun r = tyndall("render '" + project + "' --view isv --size 40x30 --set 'particleMedia[0].generator.count=300' " +
                           "--set 'views[isv].parameters.device=" + device + "' -o '" + exr + "'");
        ASSERT_EQ(r.exitCode, 0) << r.output;
        images.push_back(tyndall::readImage(exr));
        EXPECT_EQ(images.back().metadata.at("technique"), "isv");
        EXPECT_EQ(images.back().metadata.at("isv:particles"), "300");
        EXPECT_EQ(images.back().metadata.at("device") == "cpu", device == "cpu");
    }
    const tyndall::Metrics m = tyndall::computeMetrics(images[1], images[0]);
    EXPECT_LT(m.relMSE, 1e-4) << "the GPU and the CPU model render the same image";
    EXPECT_GT(m.pixels, 0);
    const std::string out = (dir / "refused.exr").string();
    CliRun area = tyndall("render '" + project + "' --view isv --size 8x6 --set " +
                          "'lights[+]={\"name\": \"panel\", \"type\": \"area\", \"vertices\": [[0, 3, 0], [1, 3, 0], [1, 3, 1]]}' " +
                          "--set 'views[isv].lights=[\"panel\"]' --set 'views[isv].media=[\"smoke\"]' -o '" + out + "'");
    EXPECT_EQ(area.exitCode, 2) << area.output;
    EXPECT_NE(area.output.find("not a directional light"), std::string::npos) << area.output;
    EXPECT_FALSE(fs::exists(out));
}

// The data files are found through resourceRoot() (tyndall/core/resources.h): with $TYNDALL_ROOT set, a GPU view
// compiles the shaders and the paper's S reads the table found there, so that an installed or unpacked copy runs away
// from the source tree; a root without them is an error that names the file looked for, not an image.
TEST(Cli, DataFilesComeFromTyndallRoot) {
    const fs::path dir = scratch("root");
    const fs::path root = dir / "share";
    fs::create_directories(root);
    fs::copy(source("shaders"), root / "shaders", fs::copy_options::recursive);
    fs::copy(source("tables"), root / "tables", fs::copy_options::recursive);
    const std::string project = source("projects/examples/ltsd-room.json");
    const std::string view =
        "--view 'ltsd paper' --size 16x12 --set 'views[ltsd paper].parameters.device=gpu' "
        "--set 'views[ltsd paper].parameters.shadows=off' -o '";
    const std::string exr = (dir / "room.exr").string();
    const CliRun run = tyndall("render '" + project + "' " + view + exr + "'", "TYNDALL_ROOT='" + root.string() + "' ");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const tyndall::Image image = tyndall::readImage(exr);
    EXPECT_NE(image.metadata.at("device"), "cpu");
    EXPECT_EQ(image.metadata.at("ltsd:table"), (root / "tables" / "hg.ltsd").string());

    const fs::path empty = dir / "empty";
    fs::create_directories(empty);
    const std::string none = (dir / "none.exr").string();
    const CliRun missing =
        tyndall("render '" + project + "' " + view + none + "'", "TYNDALL_ROOT='" + empty.string() + "' ");
    EXPECT_NE(missing.exitCode, 0) << missing.output;
    EXPECT_NE(missing.output.find((empty / "tables" / "hg.ltsd").string()), std::string::npos) << missing.output;
    EXPECT_FALSE(fs::exists(none));
    // The tables but no shaders: the GPU view's kernel is looked for under the root, not in the source tree.
    fs::copy(source("tables"), empty / "tables", fs::copy_options::recursive);
    const CliRun noShaders =
        tyndall("render '" + project + "' " + view + none + "'", "TYNDALL_ROOT='" + empty.string() + "' ");
    EXPECT_NE(noShaders.exitCode, 0) << noShaders.output;
    EXPECT_NE(noShaders.output.find((empty / "shaders" / "ltsd" / "ltsd.comp.glsl").string()), std::string::npos)
        << noShaders.output;
    EXPECT_FALSE(fs::exists(none));
}

// Shards (issue 36): two 8-spp shards of the default project's reference, merged, against a 16-spp render with another
// seed. The sum of their squared differences over all pixels and channels must be what the two variance channels
// predict (a z-test over 1296 values; a merge that dropped a shard's variance, or mis-weighted the means, leaves the
// bounds). Bad shards and
// bad --shard values are refused.
TEST(Cli, ShardsMergeIntoOneRenderWithinItsVariance) {
    const fs::path dir = scratch("shards");
    const std::string project = source("projects/default.json");
    const std::string common = "render '" + project + "' --reference --size 24x18 --spp 16 ";
    for (int i = 0; i < 2; ++i) {
        const CliRun r = tyndall(common + "--shard " + std::to_string(i) + "/2 -o '" +
                                 (dir / ("shard" + std::to_string(i) + ".exr")).string() + "'");
        ASSERT_EQ(r.exitCode, 0) << r.output;
    }
    const CliRun whole = tyndall(common + "--seed 99 -o '" + (dir / "whole.exr").string() + "'");
    ASSERT_EQ(whole.exitCode, 0) << whole.output;
    const std::string shards = "'" + (dir / "shard0.exr").string() + "' '" + (dir / "shard1.exr").string() + "'";
    const CliRun merge = tyndall("merge " + shards + " -o '" + (dir / "merged.exr").string() + "'");
    ASSERT_EQ(merge.exitCode, 0) << merge.output;

    const tyndall::Image shard0 = tyndall::readImage((dir / "shard0.exr").string());
    const tyndall::Image shard1 = tyndall::readImage((dir / "shard1.exr").string());
    EXPECT_EQ(shard0.metadata.at("spp"), "8");
    EXPECT_EQ(shard0.metadata.at("shard"), "0/2");
    EXPECT_NE(shard0.metadata.at("seed"), shard1.metadata.at("seed"));
    const tyndall::Image merged = tyndall::readImage((dir / "merged.exr").string());
    const tyndall::Image single = tyndall::readImage((dir / "whole.exr").string());
    EXPECT_EQ(merged.metadata.at("spp"), "16");
    EXPECT_EQ(merged.metadata.at("shards"), "0/2,1/2");
    EXPECT_EQ(merged.metadata.at("projectHash"), single.metadata.at("projectHash"));
    // Averaged before dividing: each pixel's variance estimate has few degrees of freedom, so the mean of per-pixel
    // ratios d^2 / v would be biased high (E[1 / v] > 1 / E[v]); the ratio of the means is not.
    double squared = 0.0, predicted = 0.0;
    int values = 0;
    for (const char* c : {"R", "G", "B"}) {
        const int m = merged.channelIndex(c), v = merged.channelIndex(std::string("variance.") + c);
        ASSERT_GE(v, 0);
        for (int y = 0; y < merged.height(); ++y)
            for (int x = 0; x < merged.width(); ++x) {
                const double d = double(merged.at(x, y, m)) - double(single.at(x, y, m));
                squared += d * d;
                predicted += double(merged.at(x, y, v)) + double(single.at(x, y, v));
                ++values;
            }
    }
    const double ratio = squared / predicted;
    std::printf("merged shards against one render: sum of squared differences / predicted %.3f over %d values\n", ratio,
                values);
    EXPECT_GT(ratio, 0.6);
    EXPECT_LT(ratio, 1.6);

    // A shard twice, a shard of another size, a PNG: exit 2 naming the file; no output.
    const std::string out = (dir / "bad.exr").string();
    const CliRun twice = tyndall("merge " + shards + " '" + (dir / "shard0.exr").string() + "' -o '" + out + "'");
    EXPECT_EQ(twice.exitCode, 2) << twice.output;
    EXPECT_NE(twice.output.find("not independent"), std::string::npos) << twice.output;
    ASSERT_EQ(tyndall("render '" + project + "' --reference --size 12x9 --spp 8 --shard 1/2 -o '" +
                      (dir / "small.exr").string() + "'")
                  .exitCode,
              0);
    const CliRun size = tyndall("merge " + shards + " '" + (dir / "small.exr").string() + "' -o '" + out + "'");
    EXPECT_EQ(size.exitCode, 2) << size.output;
    EXPECT_NE(size.output.find("small.exr"), std::string::npos) << size.output;
    EXPECT_FALSE(fs::exists(out));
    for (const std::string bad : {"2/2", "1", "a/b", "0/0"}) {
        const CliRun r = tyndall(common + "--shard " + bad + " -o '" + out + "'");
        EXPECT_EQ(r.exitCode, 2) << bad << ": " << r.output;
        EXPECT_NE(r.output.find("--shard"), std::string::npos) << r.output;
    }
    const CliRun timed = tyndall(common + "--time 1 --shard 0/2 -o '" + out + "'");
    EXPECT_EQ(timed.exitCode, 2) << timed.output;
    EXPECT_FALSE(fs::exists(out));
}

// FLIP in compare (issue 35): on a clear-cut case, renders of the default project's reference at 1 and 16 spp against
// one of 128 spp, FLIP orders them as relMSE does; the error map is written with values in [0, 1]; images of another
// size, or an unknown metric, exit 2 naming the file or the option.
TEST(Cli, CompareReportsFlipInTheOrderOfRelMse) {
    const fs::path dir = scratch("flip");
    const std::string project = source("projects/default.json");
    for (const auto& [name, spp, seed] :
         {std::tuple{"ref", 128, 1}, std::tuple{"spp1", 1, 2}, std::tuple{"spp16", 16, 3}}) {
        const CliRun r =
            tyndall("render '" + project + "' --reference --size 32x24 --spp " + std::to_string(spp) + " --seed " +
                    std::to_string(seed) + " -o '" + (dir / (std::string(name) + ".exr")).string() + "'");
        ASSERT_EQ(r.exitCode, 0) << r.output;
    }
    const std::string images = "'" + (dir / "spp1.exr").string() + "' '" + (dir / "spp16.exr").string() + "'";
    const std::string ref = " -r '" + (dir / "ref.exr").string() + "'";
    const CliRun run =
        tyndall("compare " + images + ref + " --metric flip --json '" + (dir / "m.json").string() + "' --flip-map '" +
                (dir / "{name}-flip.exr").string() + "' --flip-map '" + (dir / "{name}-flip.png").string() +
                "' --flip-histogram '" + (dir / "{name}-flip.csv").string() + "'");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    EXPECT_NE(run.output.find("FLIP mean"), std::string::npos) << run.output;
    const nlohmann::json m = nlohmann::json::parse(std::ifstream(dir / "m.json"));
    const double flip1 = m["images"][0]["flip"]["mean"], flip16 = m["images"][1]["flip"]["mean"];
    const double rel1 = m["images"][0]["relMSE"], rel16 = m["images"][1]["relMSE"];
    std::printf("1 spp: FLIP %.4f relMSE %.3g; 16 spp: FLIP %.4f relMSE %.3g\n", flip1, rel1, flip16, rel16);
    EXPECT_GT(rel1, rel16);
    EXPECT_GT(flip1, flip16);
    EXPECT_GT(flip16, 0.0);
    EXPECT_GE(int(m["images"][0]["flip"]["exposures"]), 2);
    const tyndall::Image map = tyndall::readImage((dir / "spp1-flip.exr").string());
    ASSERT_EQ(map.channelIndex("FLIP"), 0);
    for (int y = 0; y < map.height(); ++y)
        for (int x = 0; x < map.width(); ++x) {
            ASSERT_GE(map.at(x, y, 0), 0.0f);
            ASSERT_LE(map.at(x, y, 0), 1.0f);
        }
    // The PNG map: each pixel the magma colour of the EXR map's error, to one 8-bit step.
    const tyndall::Image png = tyndall::readImage((dir / "spp1-flip.png").string());
    ASSERT_EQ(png.width(), map.width());
    ASSERT_EQ(png.height(), map.height());
    for (int y = 0; y < map.height(); ++y)
        for (int x = 0; x < map.width(); ++x) {
            const tyndall::Rgb expected = tyndall::magma(map.at(x, y, 0));
            for (int c = 0; c < 3; ++c)
                ASSERT_NEAR(png.at(x, y, c), tyndall::srgbEncode(float(expected[c])), 0.6 / 255.0) << x << " " << y;
        }

    ASSERT_EQ(
        tyndall("render '" + project + "' --reference --size 16x12 --spp 1 -o '" + (dir / "small.exr").string() + "'")
            .exitCode,
        0);
    // The histogram: 100 bins whose pixels are the image's and whose weighted shares sum to 1.
    std::ifstream csv(dir / "spp1-flip.csv");
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "low,high,pixels,weightedShare");
    long pixels = 0;
    double share = 0.0;
    int bins = 0;
    while (std::getline(csv, line)) {
        std::istringstream fields(line);
        std::string low, high, count, weighted;
        std::getline(fields, low, ',');
        std::getline(fields, high, ',');
        std::getline(fields, count, ',');
        std::getline(fields, weighted, ',');
        pixels += std::stol(count);
        share += std::stod(weighted);
        ++bins;
    }
    EXPECT_EQ(bins, 100);
    EXPECT_EQ(pixels, 32 * 24);
    EXPECT_NEAR(share, 1.0, 1e-9);

    const CliRun size = tyndall("compare '" + (dir / "small.exr").string() + "'" + ref + " --metric flip");
    EXPECT_EQ(size.exitCode, 2) << size.output;
    EXPECT_NE(size.output.find("small.exr"), std::string::npos) << size.output;
    EXPECT_NE(size.output.find("ref.exr"), std::string::npos) << size.output;
    const CliRun unknown = tyndall("compare " + images + ref + " --metric ssim");
    EXPECT_EQ(unknown.exitCode, 2) << unknown.output;
    EXPECT_NE(unknown.output.find("--metric"), std::string::npos) << unknown.output;
    const CliRun tiff =
        tyndall("compare " + images + ref + " --metric flip --flip-map '" + (dir / "{name}-flip.tiff").string() + "'");
    EXPECT_EQ(tiff.exitCode, 2) << tiff.output;
    EXPECT_NE(tiff.output.find("--flip-map"), std::string::npos) << tiff.output;
    EXPECT_NE(tiff.output.find("or a .png (the error in magma)"), std::string::npos) << tiff.output;
    EXPECT_FALSE(fs::exists(dir / "spp1-flip.tiff"));
}

TEST(Cli, RendersTheWvdsExampleAndWritesItsDistanceProbe) {
    fs::path dir = scratch("wvds");
    const std::string project = source("projects/examples/wvds-box.json");
    const std::string exr = (dir / "box.exr").string();
    CliRun r = tyndall("render '" + project + "' --view reds --size 24x18 --spp 4 --set " +
                       "'views[reds].parameters.device=cpu' -o '" + exr + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    tyndall::Image image = tyndall::readImage(exr);
    EXPECT_EQ(image.metadata.at("technique"), "wvds");
    EXPECT_EQ(image.metadata.at("wvds:estimator"), "reds");
    EXPECT_EQ(image.metadata.at("spp"), "4");
    EXPECT_GE(image.channelIndex("variance.R"), 0);

    const std::string csv = (dir / "probe.csv").string(), json = (dir / "probe.json").string();
    CliRun p = tyndall("probe '" + project + "' --view mcwvds --probe distances --size 64x48 --pixel 30,20 --csv '" +
                       csv + "' --json '" + json + "'");
    ASSERT_EQ(p.exitCode, 0) << p.output;
    EXPECT_NE(p.output.find("Sampled distances at pixel (30, 20)"), std::string::npos) << p.output;
    std::ifstream in(json);
    const nlohmann::json j = nlohmann::json::parse(in);
    ASSERT_EQ(j["series"].size(), 6u);
    EXPECT_EQ(j["series"][0]["x"].size(), 256u);
    std::ifstream csvIn(csv);
    std::string header;
    std::getline(csvIn, header);
    EXPECT_EQ(header, "series,x,y");

    CliRun unknown = tyndall("probe '" + project + "' --view mcwvds --probe polar --size 8x6");
    EXPECT_EQ(unknown.exitCode, 2) << unknown.output;
    EXPECT_NE(unknown.output.find("it has distances, convergence"), std::string::npos) << unknown.output;
    CliRun outside = tyndall("probe '" + project + "' --view mcwvds --probe distances --size 8x6 --pixel 9,2");
    EXPECT_EQ(outside.exitCode, 2) << outside.output;
    CliRun estimator = tyndall("render '" + project + "' --view reds --size 8x6 --set " +
                               "'views[reds].parameters.estimator=me' -o '" + (dir / "x.exr").string() + "'");
    EXPECT_EQ(estimator.exitCode, 2) << estimator.output;
    EXPECT_NE(estimator.output.find("mcwvds"), std::string::npos) << estimator.output;
}

TEST(Cli, CompareWritesMetricsAndADifferenceImage) {
    fs::path dir = scratch("compare");
    std::string project = source("projects/default.json");
    std::string ref = (dir / "ref.exr").string(), img = (dir / "img.exr").string();
    ASSERT_EQ(tyndall("render '" + project + "' --reference --size 24x18 --spp 16 -o '" + ref + "'").exitCode, 0);
    ASSERT_EQ(tyndall("render '" + project + "' --reference --size 24x18 --spp 2 --seed 9 -o '" + img + "'").exitCode,
              0);
    std::string json = (dir / "m.json").string(), csv = (dir / "m.csv").string(),
                diff = (dir / "{name}-diff.png").string();
    CliRun r = tyndall("compare '" + img + "' '" + ref + "' -r '" + ref + "' --json '" + json + "' --csv '" + csv +
                       "' --diff '" + diff + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("reference noise"), std::string::npos);
    ASSERT_TRUE(fs::exists(json));
    ASSERT_TRUE(fs::exists(csv));
    EXPECT_TRUE(fs::exists(dir / "img-diff.png"));
    EXPECT_TRUE(fs::exists(dir / "ref-diff.png"));
    std::ifstream in(json);
    nlohmann::json metrics = nlohmann::json::parse(in);
    ASSERT_EQ(metrics["images"].size(), 2u);
    EXPECT_GT(metrics["images"][0]["rmse"].get<double>(), 0.0) << "a 2 spp image differs from a 16 spp one";
    EXPECT_EQ(metrics["images"][1]["rmse"].get<double>(), 0.0) << "the reference against itself";
    EXPECT_EQ(metrics["images"][1]["psnr"], "inf");
}


// --time alone means "until this time": the technique's default spp (WVDS: 16) does not stop the render first, and
// --spp beside it is a cap. Neither assertion depends on the machine's speed: 16 samples of 48 pixels take
// microseconds, far below the 1.5 s bound, and the cap holds however long the bound.
TEST(Cli, ATimeBoundRendersUntilItAndSppCapsIt) {
    fs::path dir = scratch("time");
    const std::string project = source("projects/examples/wvds-box.json");
    const std::string common = "render '" + project + "' --view analytic --size 8x6 --set " +
                               "'views[analytic].parameters.device=cpu' ";
    const std::string timed = (dir / "timed.exr").string(), capped = (dir / "capped.exr").string();
    CliRun r = tyndall(common + "--time 1.5 -o '" + timed + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_GT(std::stoi(tyndall::readImage(timed).metadata.at("spp")), 16) << r.output;
    CliRun c = tyndall(common + "--time 600 --spp 3 -o '" + capped + "'");
    ASSERT_EQ(c.exitCode, 0) << c.output;
    EXPECT_EQ(tyndall::readImage(capped).metadata.at("spp"), "3");
}

// A view without its own "lights"/"media" renders what its technique supports; what that leaves out is said on
// stderr by validate and render, and in the image's metadata, instead of silently rendering a different scene.
TEST(Cli, SaysWhatAViewWithoutAPartLeavesOut) {
    fs::path dir = scratch("leftout");
    const std::string project = source("projects/default.json");
    // A Pegoraro view of the default room takes only the lamp: the fog is bounded, the sun and the panel not punctual.
    const std::string pegoraro = R"( --set 'views[+]={"name": "closed form", "technique": "pegoraro"}')";
    CliRun v = tyndall("validate '" + project + "'" + pegoraro);
    EXPECT_EQ(v.exitCode, 0) << v.output;
    EXPECT_NE(v.output.find("view 'closed form' leaves out"), std::string::npos) << v.output;
    for (const char* left : {"medium 'fog'", "directional light 'sun'", "area light 'panel'"})
        EXPECT_NE(v.output.find(left), std::string::npos) << left << "\n" << v.output;
    EXPECT_EQ(v.output.find("point light 'lamp'"), std::string::npos) << v.output;
    EXPECT_NE(v.output.find("ok (5 views, 1 leaving out part of the scene)"), std::string::npos) << v.output;
    CliRun clean = tyndall("validate '" + project + "'");
    EXPECT_EQ(clean.output.find("leaves out"), std::string::npos) << clean.output;
    EXPECT_NE(clean.output.find("ok (4 views)"), std::string::npos) << clean.output;
    CliRun one = tyndall("validate '" + source("projects/examples/reference-smoke.json") + "'");
    EXPECT_NE(one.output.find("ok (1 view)"), std::string::npos) << one.output;

    const std::string exr = (dir / "closed-form.exr").string();
    CliRun r = tyndall("render '" + project + "' --view 'closed form' --size 8x6" + pegoraro + " -o '" + exr + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("warning: view 'closed form' leaves out"), std::string::npos) << r.output;
    const tyndall::Image image = tyndall::readImage(exr);
    ASSERT_TRUE(image.metadata.count("leftOut"));
    EXPECT_NE(image.metadata.at("leftOut").find("medium 'fog'"), std::string::npos);
    // The reference of that view leaves out the same, so that the comparison is at least like for like.
    const std::string ref = (dir / "closed-form-ref.exr").string();
    CliRun rr = tyndall("render '" + project + "' --reference --view 'closed form' --size 8x6 --spp 1" + pegoraro +
                        " -o '" + ref + "'");
    ASSERT_EQ(rr.exitCode, 0) << rr.output;
    EXPECT_EQ(tyndall::readImage(ref).metadata.at("leftOut"), image.metadata.at("leftOut"));
}

// --set 'array[+]=element' appends an element (a view, a light), which later overrides can then select by name.
TEST(Cli, SetAppendsAnArrayElement) {
    fs::path dir = scratch("append");
    const std::string project = source("projects/examples/reference-smoke.json");
    const std::string lamp =
        R"('lights[+]={"type": "point", "name": "extra", "position": [0, 1, 0], "intensity": [1, 1, 1]}')";
    const std::string view = R"('views[+]={"name": "extra only", "technique": "reference", "lights": ["extra"], "media": []}')";
    CliRun v = tyndall("validate '" + project + "' --set " + lamp + " --set " + view +
                       " --set 'lights[extra].intensity=[0,0,0]'");
    EXPECT_EQ(v.exitCode, 0) << v.output;
    EXPECT_NE(v.output.find("ok (2 views)"), std::string::npos) << v.output;

    const std::string exr = (dir / "extra.exr").string();
    CliRun r = tyndall("render '" + project + "' --view 'extra only' --size 8x6 --spp 1 --set " + lamp + " --set " +
                       view + " --set 'lights[extra].intensity=[0,0,0]' -o '" + exr + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const tyndall::Image image = tyndall::readImage(exr);
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x) EXPECT_EQ(image.at(x, y, 0), 0.0f) << "the extra light is off";

    const struct {
        std::string set, expected;
    } bad[] = {
        {"'lights[+].intensity=1'", "[+] appends the value as a whole new element"},
        {"'camera[+]=1'", "is not an array"},
        {"'lights[99999999999999999999999].intensity=1'", "is too large"},
    };
    for (const auto& b : bad) {
        CliRun e = tyndall("validate '" + project + "' --set " + b.set);
        EXPECT_EQ(e.exitCode, 2) << b.set << "\n" << e.output;
        EXPECT_NE(e.output.find(b.expected), std::string::npos) << b.set << "\n" << e.output;
    }
}

// `tyndall tables` prints every shipped table's layout and provenance (LTSD and LTC), a named table in detail; `tables eval` prints the LTSD value of a polygon's
// integral next to the exact one (a polygon around -z, HG's forward peak for g = 0.5: within the shipped fit's error,
// docs/tables.md), and bad phase functions, polygons and table folders are refused with exit code 2 and a reason.
TEST(Cli, TablesPrintsProvenanceAndEvaluatesAPolygon) {
    CliRun info = tyndall("tables --tables '" + source("tables") + "'");
    ASSERT_EQ(info.exitCode, 0) << info.output;
    EXPECT_NE(info.output.find("2 x 128 entries"), std::string::npos) << info.output;
    EXPECT_NE(info.output.find("\"loss\":\"sw\""), std::string::npos) << info.output;
    for (const char* expected : {"LTSD table of rayleigh", "LTSD table of murky-mie", "isotropic, 64 x 64 entries",
                                 "anisotropic, 8 x 8 x 8 x 8 entries", "fitted:   ", "total variation per entry"})
        EXPECT_NE(info.output.find(expected), std::string::npos) << expected << "\n" << info.output;
    CliRun ggx = tyndall("tables ggx-aniso --tables '" + source("tables") + "'");
    ASSERT_EQ(ggx.exitCode, 0) << ggx.output;
    EXPECT_EQ(ggx.output.find("LTSD table"), std::string::npos) << ggx.output;  // only the named table
    EXPECT_NE(ggx.output.find("ratio"), std::string::npos) << ggx.output;       // its error against alpha and ratio
    CliRun json = tyndall("tables --json hg ggx --tables '" + source("tables") + "'");
    ASSERT_EQ(json.exitCode, 0) << json.output;
    const nlohmann::json described = nlohmann::json::parse(json.output);
    ASSERT_EQ(described.size(), 2u);
    EXPECT_EQ(described[0]["kind"], "ltsd");
    EXPECT_EQ(described[1]["kind"], "ltc");
    EXPECT_EQ(described[1]["sizes"], nlohmann::json({64, 64}));
    EXPECT_TRUE(described[1]["provenance"].contains("errorSummary"));
    // A truncated table beside a good one fails the command, naming the file.
    const fs::path corrupt = scratch("corrupt-tables");
    fs::copy_file(source("tables") + "/ggx.ltc", corrupt / "ggx.ltc");
    {
        std::ifstream in(source("tables") + "/hg.ltsd", std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        std::ofstream(corrupt / "hg.ltsd", std::ios::binary) << bytes.substr(0, 100);
    }

    const std::string polygon = "'[[0.3,0.2,-1],[-0.3,0.25,-1],[-0.2,-0.3,-1],[0.25,-0.2,-1]]'";
    CliRun eval = tyndall("tables eval --phase '{\"type\":\"hg\",\"g\":0.5}' --polygon " + polygon);
    ASSERT_EQ(eval.exitCode, 0) << eval.output;
    const nlohmann::json j = nlohmann::json::parse(eval.output);
    EXPECT_GT(j["exact"].get<double>(), 0.05);
    EXPECT_NEAR(j["ltsd"].get<double>(), j["exact"].get<double>(), 0.05);  // the fit's worst case over test polygons
    EXPECT_NEAR(j["solidAngle"].get<double>(), 0.235, 0.01);
    EXPECT_EQ(j["clampedCosine"].get<double>(), 0.0);  // entirely below the horizon
    EXPECT_FALSE(j["gClamped"].get<bool>());
    // Every S method: the paper's is today's "ltsd"; the boundary form's is within 1e-3 relative of the exact value
    // (measured 4e-4 at worst over 360 polygons, docs/tables.md).
    EXPECT_EQ(j["sMethods"]["paper"].get<double>(), j["ltsd"].get<double>());
    EXPECT_NEAR(j["sMethods"]["accurate"].get<double>(), j["exact"].get<double>(), 1e-3 * j["exact"].get<double>());

    struct Case {
        std::string args, expected;
    };
    const Case cases[] = {
        {"tables eval --phase '{\"type\":\"legendre\"}' --polygon " + polygon, "cannot take 'legendre'"},
        {"tables eval --phase '{\"type\":\"rayleigh\",\"g\":0.3}' --polygon " + polygon, "unknown key for rayleigh"},
        {"tables eval --phase '{\"type\":\"hg\",\"g\":1.5}' --polygon " + polygon, "--phase.g"},
        {"tables eval --phase '{\"type\":\"hg\"' --polygon " + polygon, "not valid JSON"},
        {"tables eval --phase '{\"type\":\"hg\"}' --polygon '[[0,0,1],[1,0,0]]'", "3 to 9 directions"},
        {"tables eval --phase '{\"type\":\"hg\"}' --polygon '[[1,0,0],[0,1,0],[-1,0,0],[0,-1,0.5],[0,0,-1]]'",
         "convex"},
        {"tables --tables '" + scratch("no-tables").string() + "'", "no-tables: --tables: holds no tables"},
        {"tables --tables '" + (scratch("no-tables") / "absent").string() + "'", "absent: --tables: is not a folder"},
        {"tables nope --tables '" + source("tables") + "'", "no table named 'nope'"},
        {"tables --tables '" + corrupt.string() + "'", "hg.ltsd: payload: truncated"},
    };
    for (const Case& c : cases) {
        CliRun r = tyndall(c.args);
        EXPECT_EQ(r.exitCode, 2) << c.args << "\n" << r.output;
        EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.args << "\n" << r.output;
    }
}

// `tyndall plot ltsd-polar` writes HG against its LTSD fit as CSV (the studio's polar plot's data): HG's values are
// HG's formula at mu = -cos psi, each point names the fit's hemisphere, and the fit jumps at the horizon; `ltsd-error`
// writes the fit's error over g. Other outputs and bad arguments are refused with exit code 2 and a reason.
TEST(Cli, PlotWritesTheLtsdPlotsAsCsv) {
    const fs::path dir = scratch("plot");
    auto readLines = [](const fs::path& path) {
        std::vector<std::string> lines;
        std::ifstream file(path);
        for (std::string line; std::getline(file, line);)
            lines.push_back(line);
        return lines;
    };
    const fs::path polar = dir / "polar.csv";
    CliRun r = tyndall("plot ltsd-polar --g 0.6 --points 360 -o '" + polar.string() + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::vector<std::string> lines = readLines(polar);
    ASSERT_EQ(lines.size(), 361u);
    EXPECT_EQ(lines[0], "psi,phase,fitted,hemisphere");
    int upper = 0;
    double beforeHorizon = 0.0, afterHorizon = 0.0;  // the fit on either side of psi = pi / 2
    for (std::size_t i = 1; i < lines.size(); ++i) {
        double psi = 0.0, phase = 0.0, fitted = 0.0;
        char hemisphere[16] = {};
        ASSERT_EQ(std::sscanf(lines[i].c_str(), "%lf,%lf,%lf,%15s", &psi, &phase, &fitted, hemisphere), 4) << lines[i];
        const double g = 0.6, mu = -std::cos(psi), d = 1.0 + g * g - 2.0 * g * mu;
        EXPECT_NEAR(phase, (1.0 - g * g) / (4.0 * std::numbers::pi * d * std::sqrt(d)), 1e-7 * phase) << lines[i];
        EXPECT_TRUE(std::isfinite(fitted) && fitted >= 0.0) << lines[i];
        EXPECT_EQ(std::string(hemisphere), std::cos(psi) > 0.0 ? "upper" : "lower") << lines[i];
        upper += std::cos(psi) > 0.0;
        if (i == 90) beforeHorizon = fitted;  // psi = 2 pi 89.5 / 360: just above the horizon (upper)
        if (i == 91) afterHorizon = fitted;
    }
    EXPECT_EQ(upper, 180);
    EXPECT_GT(std::abs(beforeHorizon - afterHorizon), 0.2 * std::max(beforeHorizon, afterHorizon))
        << beforeHorizon << " " << afterHorizon;

    const fs::path error = dir / "error.csv";
    r = tyndall("plot ltsd-error -o '" + error.string() + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::vector<std::string> errorLines = readLines(error);
    ASSERT_EQ(errorLines.size(), 102u);
    EXPECT_EQ(errorLines[0], "g,tvUpper,tvLower,bound");
    double g0 = 0.0, tvUpper = 0.0, tvLower = 0.0, bound = 0.0;
    ASSERT_EQ(std::sscanf(errorLines[51].c_str(), "%lf,%lf,%lf,%lf", &g0, &tvUpper, &tvLower, &bound), 4);
    EXPECT_NEAR(g0, 0.0, 1e-9);
    EXPECT_GT(bound, 0.0);
    EXPECT_LE(bound, 0.5 * (tvUpper + tvLower));

    struct Case {
        std::string args, expected;
    };
    const Case cases[] = {
        {"plot ltsd-polar --g 0.5 -o '" + (dir / "a.png").string() + "'", "must end in .csv"},
        {"plot ltsd-polar --g 1.5 -o '" + (dir / "a.csv").string() + "'", "--g"},
        {"plot ltsd-polar --g nan -o '" + (dir / "a.csv").string() + "'", "finite"},
        {"plot ltsd-error --points 1 -o '" + (dir / "a.csv").string() + "'", "--points"},
        {"plot ltsd-error --tables '" + scratch("no-tables-plot").string() + "' -o '" + (dir / "a.csv").string() + "'",
         "no-tables-plot/hg.ltsd: cannot open"},
    };
    for (const Case& c : cases) {
        CliRun bad = tyndall(c.args);
        EXPECT_EQ(bad.exitCode, 2) << c.args << "\n" << bad.output;
        EXPECT_NE(bad.output.find(c.expected), std::string::npos) << c.args << "\n" << bad.output;
        EXPECT_FALSE(fs::exists(dir / "a.csv")) << c.args;
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// tyndall sweep (issue 36, docs/sweeps.md). A small sweep: LTSD and Volume-RIS at two values of g, two seeds, 1 and 2
// spp, against references of 32 spp in two shards each (20 tasks of well under a second at 32 x 24).

std::string sweepSpec(const fs::path& dir, const std::string& extra = "", int referenceSpp = 32) {
    const std::string spec = R"({"tyndallSweep": 1, "name": "test sweep",
        "project": ")" + source("projects/ltsd/fig10-nodes.json") +
                             R"(", "size": "32x24",
        "views": ["N 8 equiangular", "volume-ris"], "grid": {"media[fog].phase.g": [-0.5, 0.4]},
        "seeds": [1, 2], "spp": [1, 2], "reference": {"spp": )" +
                             std::to_string(referenceSpp) + R"(, "shards": 2})" + extra + "}";
    return writeFile(dir / "test.sweep.json", spec);
}

std::vector<std::vector<std::string>> readCsv(const fs::path& path) {
    std::vector<std::vector<std::string>> rows;
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) {
        std::vector<std::string> fields;
        std::string field;
        bool quoted = false;
        for (char c : line) {
            if (c == '"')
                quoted = !quoted;
            else if (c == ',' && !quoted)
                fields.push_back(std::exchange(field, ""));
            else
                field += c;
        }
        fields.push_back(field);
        rows.push_back(fields);
    }
    return rows;
}

// Every render of a local sweep against its merged reference: the CSV's metrics are tyndall compare's of the same
// images, the references are merges of their shards, and a second run renders nothing.
TEST(Sweep, RunsLocallyAndGathersMetricsAgainstMergedReferences) {
    const fs::path dir = scratch("sweep-local");
    const std::string spec = sweepSpec(dir);
    const std::string out = (dir / "out").string();
    const CliRun r = tyndall("sweep '" + spec + "' --out '" + out + "' --jobs 2");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("20 tasks"), std::string::npos) << r.output;

    const auto rows = readCsv(fs::path(out) / "results.csv");
    ASSERT_EQ(rows.size(), 17u);  // the header and 2 views x 2 g x 2 seeds x 2 spp
    const auto column = [&](const std::string& name) {
        const auto it = std::find(rows[0].begin(), rows[0].end(), name);
        EXPECT_NE(it, rows[0].end()) << name;
        return std::size_t(it - rows[0].begin());
    };
    const std::size_t relMSE = column("relMSE"), image = column("image"), reference = column("reference"),
                      g = column("media[fog].phase.g"), spp = column("spp"), view = column("view");
    std::set<std::string> references;
    for (std::size_t i = 1; i < rows.size(); ++i) {
        EXPECT_TRUE(rows[i][g] == "-0.5" || rows[i][g] == "0.4") << rows[i][g];
        EXPECT_TRUE(rows[i][spp] == "1" || rows[i][spp] == "2") << rows[i][spp];
        EXPECT_GT(std::stod(rows[i][relMSE]), 0.0);
        references.insert(rows[i][reference]);
    }
    EXPECT_EQ(references.size(), 2u);  // one per g: LTSD and Volume-RIS render the same part
    // A row's metrics are those of tyndall compare.
    const CliRun compare = tyndall("compare '" + out + "/" + rows[5][image] + "' -r '" + out + "/" +
                                   rows[5][reference] + "' --json '" + (dir / "compare.json").string() + "'");
    ASSERT_EQ(compare.exitCode, 0) << compare.output;
    const auto metrics = nlohmann::json::parse(std::ifstream(dir / "compare.json"))["images"][0];
    EXPECT_NEAR(std::stod(rows[5][relMSE]), metrics["relMSE"].get<double>(),
                1e-12 + 1e-9 * metrics["relMSE"].get<double>());
    // The references merge their two shards of 16 spp.
    const tyndall::Image merged = tyndall::readImage(out + "/" + *references.begin());
    EXPECT_EQ(merged.metadata.at("spp"), "32");
    EXPECT_EQ(merged.metadata.at("shards"), "0/2,1/2");
    // More samples, less error: Volume-RIS's mean relMSE over seeds and g at 2 spp is below that at 1 spp.
    double at1 = 0.0, at2 = 0.0;
    for (std::size_t i = 1; i < rows.size(); ++i)
        if (rows[i][view] == "volume-ris") (rows[i][spp] == "1" ? at1 : at2) += std::stod(rows[i][relMSE]);
    EXPECT_LT(at2, at1);

    const auto results = nlohmann::json::parse(std::ifstream(fs::path(out) / "results.json"));
    EXPECT_EQ(results["renders"].size(), 16u);
    EXPECT_EQ(results["references"].size(), 2u);
    const auto plots = nlohmann::json::parse(std::ifstream(fs::path(out) / "plots" / "plots.json"))["plots"];
    std::set<std::string> names;
    for (const auto& p : plots)
        names.insert(p["file"].get<std::string>());
    EXPECT_EQ(names, (std::set<std::string>{"error-vs-media-fog-phase-g", "error-vs-time", "error-vs-spp"}));
    // Against g: a curve per view and spp; against time and spp: a curve per view and g. Each point a mean over seeds.
    for (const auto& p : plots) {
        EXPECT_EQ(p["series"].size(), 4u) << p["file"];
        for (const auto& series : p["series"])
            EXPECT_EQ(series["y"].size(), 2u) << p["file"];
    }
    const auto table = readCsv(fs::path(out) / "plots" / "equal-time.csv");
    ASSERT_EQ(table.size(), 5u);  // the times, and a row per curve of error-vs-time
    EXPECT_EQ(table[0].size(), 5u);
    EXPECT_NE(table[0][1].find("relMSE at "), std::string::npos);
#ifdef TYNDALL_PLOT
    for (const std::string& name : names) {
        EXPECT_GT(fs::file_size(fs::path(out) / "plots" / (name + ".png")), 10000u) << name;
        std::ifstream svg(fs::path(out) / "plots" / (name + ".svg"));
        const std::string text{std::istreambuf_iterator<char>(svg), {}};
        EXPECT_NE(text.find("<svg"), std::string::npos) << name;
        EXPECT_NE(text.find("volume-ris"), std::string::npos) << name << ": the legend names the views";
    }
#endif

    // Run again: every task is done and verified, nothing renders; the status says so.
    const auto stamp = fs::last_write_time(fs::path(out) / rows[1][image]);
    const CliRun again = tyndall("sweep '" + spec + "' --out '" + out + "'");
    ASSERT_EQ(again.exitCode, 0) << again.output;
    EXPECT_NE(again.output.find("20 done before"), std::string::npos) << again.output;
    EXPECT_EQ(fs::last_write_time(fs::path(out) / rows[1][image]), stamp);
    const CliRun status = tyndall("sweep --status '" + out + "'");
    EXPECT_EQ(status.exitCode, 0);
    EXPECT_NE(status.output.find("20 done, 0 running, 0 failed"), std::string::npos) << status.output;
    // A task whose output changed is not done: it renders again.
    std::ofstream(fs::path(out) / rows[1][image], std::ios::app) << "x";
    const CliRun repaired = tyndall("sweep '" + spec + "' --out '" + out + "'");
    ASSERT_EQ(repaired.exitCode, 0) << repaired.output;
    EXPECT_NE(repaired.output.find("19 done before"), std::string::npos) << repaired.output;
}

// Starts a sweep in its own session (so that the test can kill it with its tasks) and returns its pid.
long startSweep(const std::string& args, const fs::path& log) {
    const fs::path pidFile = log.string() + ".pid";
    const std::string command = "setsid " + std::string(TYNDALL_CLI) + " sweep " + args + " > '" + log.string() +
                                "' 2>&1 & echo $! > '" + pidFile.string() + "'";
    EXPECT_EQ(std::system(command.c_str()), 0);
    long pid = 0;
    std::ifstream(pidFile) >> pid;
    return pid;
}

// Waits up to a minute for a file matching `suffix` in `dir`; its path, or "" on time-out.
fs::path waitForFile(const fs::path& dir, const std::string& suffix) {
    for (int i = 0; i < 3000; ++i) {
        std::error_code ec;
        for (const auto& entry : fs::directory_iterator(dir, ec))
            if (entry.path().filename().string().ends_with(suffix)) return entry.path();
        usleep(20000);
    }
    return {};
}

// The pid of the first task of a sweep that is running (from its tasks/<id>.running.json); 0 when none starts.
long runningTaskPid(const std::string& out) {
    const fs::path running = waitForFile(fs::path(out) / "tasks", ".running.json");
    for (int i = 0; i < 100 && !running.empty(); ++i) {
        try {
            if (const long pid = nlohmann::json::parse(std::ifstream(running)).value("pid", 0L); pid > 0) return pid;
        } catch (const std::exception&) {
        }
        usleep(20000);
    }
    return 0;
}

bool waitForExit(long pid) {
    for (int i = 0; i < 3000; ++i) {
        if (::kill(pid_t(pid), 0) != 0) return true;
        usleep(20000);
    }
    return false;
}

// Runs a sweep one task at a time, sends `signal` to its first task once it runs, waits for the sweep to end and
// returns what the sweep printed (empty, with a failure, when a step does not happen).
std::string signalTheFirstTask(const std::string& spec, const std::string& out, int signal) {
    fs::create_directories(fs::path(out) / "tasks");
    const fs::path log = fs::path(out).parent_path() / "sweep.log";
    const long pid = startSweep("'" + spec + "' --out '" + out + "' --jobs 1", log);
    EXPECT_GT(pid, 0);
    const long taskPid = runningTaskPid(out);
    EXPECT_GT(taskPid, 0) << "no task started";
    if (pid <= 0 || taskPid <= 0) return "";
    ::kill(pid_t(taskPid), signal);
    EXPECT_TRUE(waitForExit(pid));
    std::ifstream in(log);
    return std::string{std::istreambuf_iterator<char>(in), {}};
}

// A sweep killed with its tasks resumes: the tasks that finished are kept, the one that was running renders again.
TEST(Sweep, ResumesAfterItIsKilled) {
    const fs::path dir = scratch("sweep-killed");
    const std::string spec = sweepSpec(dir, "", 512);  // slower reference shards, to kill the sweep in the middle
    const std::string out = (dir / "out").string();
    fs::create_directories(fs::path(out) / "tasks");
    const long pid = startSweep("'" + spec + "' --out '" + out + "' --jobs 1", dir / "first.log");
    ASSERT_GT(pid, 0);
    ASSERT_FALSE(waitForFile(fs::path(out) / "tasks", ".done.json").empty()) << "no task finished";
    ::kill(-pid_t(pid), SIGKILL);  // the sweep and its running task
    ASSERT_TRUE(waitForExit(pid));
    EXPECT_FALSE(fs::exists(fs::path(out) / "results.csv"));
    const CliRun status = tyndall("sweep --status '" + out + "'");
    EXPECT_NE(status.output.find("interrupted"), std::string::npos) << status.output;

    const CliRun resumed = tyndall("sweep '" + spec + "' --out '" + out + "' --jobs 2");
    ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
    const std::size_t at = resumed.output.find(" done before");
    ASSERT_NE(at, std::string::npos) << resumed.output;
    const int doneBefore = std::stoi(resumed.output.substr(resumed.output.rfind('(', at) + 1));
    EXPECT_GE(doneBefore, 1) << resumed.output;
    EXPECT_LT(doneBefore, 20) << resumed.output;
    EXPECT_EQ(readCsv(fs::path(out) / "results.csv").size(), 17u);
}

// A task that dies (here killed, as by the OOM killer) fails the sweep: it is named with its log, nothing is gathered,
// a re-run leaves it failed until --retry-failed.
TEST(Sweep, AFailedTaskIsReportedAndNothingIsGathered) {
    const fs::path dir = scratch("sweep-failed");
    const std::string spec = sweepSpec(dir, "", 512);
    const std::string out = (dir / "out").string();
    const std::string log = signalTheFirstTask(spec, out, SIGKILL);
    EXPECT_NE(log.find("FAILED task 0"), std::string::npos) << log;
    EXPECT_NE(log.find("1 task(s) failed; nothing was gathered"), std::string::npos) << log;
    EXPECT_NE(log.find("logs/"), std::string::npos) << log;
    EXPECT_FALSE(fs::exists(fs::path(out) / "results.csv"));

    const CliRun status = tyndall("sweep --status '" + out + "'");
    EXPECT_NE(status.output.find("1 failed"), std::string::npos) << status.output;
    EXPECT_NE(status.output.find("killed by signal 9"), std::string::npos) << status.output;
    const CliRun gather = tyndall("sweep --gather --out '" + out + "'");
    EXPECT_EQ(gather.exitCode, 1) << gather.output;
    EXPECT_NE(gather.output.find("not done"), std::string::npos) << gather.output;
    EXPECT_FALSE(fs::exists(fs::path(out) / "results.csv"));

    // Without --retry-failed the failed task stays failed (the others run); with it, the sweep completes.
    const CliRun again = tyndall("sweep '" + spec + "' --out '" + out + "' --jobs 2");
    EXPECT_EQ(again.exitCode, 1) << again.output;
    EXPECT_NE(again.output.find("1 failed before, not re-run without --retry-failed"), std::string::npos)
        << again.output;
    EXPECT_FALSE(fs::exists(fs::path(out) / "results.csv"));
    const CliRun retried = tyndall("sweep '" + spec + "' --out '" + out + "' --jobs 2 --retry-failed");
    EXPECT_EQ(retried.exitCode, 0) << retried.output;
    EXPECT_TRUE(fs::exists(fs::path(out) / "results.csv"));
}

// A task cancelled on its own (SIGTERM: scancel, a time limit) is interrupted, not failed: the sweep says so, and
// the same command runs it again without --retry-failed.
TEST(Sweep, ACancelledTaskRunsAgain) {
    const fs::path dir = scratch("sweep-cancelled");
    const std::string spec = sweepSpec(dir, "", 512);
    const std::string out = (dir / "out").string();
    const std::string log = signalTheFirstTask(spec, out, SIGTERM);
    EXPECT_NE(log.find("CANCELLED task 0"), std::string::npos) << log;
    EXPECT_NE(log.find("1 task(s) were cancelled"), std::string::npos) << log;
    const CliRun status = tyndall("sweep --status '" + out + "'");
    EXPECT_NE(status.output.find("0 failed, 1 interrupted"), std::string::npos) << status.output;
    const CliRun again = tyndall("sweep '" + spec + "' --out '" + out + "' --jobs 2");
    EXPECT_EQ(again.exitCode, 0) << again.output;
    EXPECT_TRUE(fs::exists(fs::path(out) / "results.csv"));
}

// Bad specs are refused before anything runs, naming the spec and the field (the same checks as --set).
TEST(Sweep, BadSpecsNameTheFieldAndRunNothing) {
    const fs::path dir = scratch("sweep-bad");
    const std::string out = (dir / "out").string();
    const std::string project = source("projects/ltsd/fig10-nodes.json");
    const auto refused = [&](const std::string& body, const std::string& expected) {
        const std::string spec = writeFile(dir / "bad.sweep.json", "{\"tyndallSweep\": 1, \"project\": \"" + project +
                                                                       "\", \"size\": \"16x12\", " + body + "}");
        const CliRun r = tyndall("sweep '" + spec + "' --out '" + out + "'");
        EXPECT_EQ(r.exitCode, 2) << body << "\n" << r.output;
        EXPECT_NE(r.output.find("bad.sweep.json"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find(expected), std::string::npos) << body << "\n" << r.output;
        EXPECT_FALSE(fs::exists(fs::path(out) / "manifest.jsonl")) << body;
    };
    refused(R"("views": ["N 8 equiangulr"], "spp": 1)",
            "views[0]: the project has no view 'N 8 equiangulr'; did you "
            "mean 'N 8 equiangular'?");
    refused(R"("views": ["N 8 equiangular"], "grid": {"views[{view}].parameters.nodez": [1, 2]}, "spp": 1)",
            "grid[\"views[{view}].parameters.nodez\"]: no swept view's technique has this parameter");
    refused(R"("views": ["N 8 equiangular"], "grid": {"views[{view}].parameters.nodes": [1, 0]}, "spp": 1)",
            "grid[\"views[{view}].parameters.nodes\"]: view 'N 8 equiangular' at views[{view}].parameters.nodes = 0");
    refused(R"("grid": {"media[fog].phase.g": [0.2, 1.5]}, "spp": 1)", "grid[\"media[fog].phase.g\"]");
    refused(R"("grid": {"media[smoke].phase.g": [0.2]}, "spp": 1)", "grid[\"media[smoke].phase.g\"]");
    refused(R"("spp": 1, "seedz": [1])", "unknown key 'seedz'; did you mean 'seeds'?");
    refused(R"("spp": 1, "time": 2)", "give either \"spp\"");
    refused(R"("spp": [1, 0])", "spp[1]: must be an integer in [1, 1048576]");
    refused(R"("spp": 1, "reference": {"spp": 4, "shards": 8})", "reference.shards: leaves shards without samples");
    refused(R"("spp": 1, "grid": {"media[fog].phase.g": {"from": 0, "to": 0.5}})", "a range needs \"count\"");
    refused(R"("spp": 1, "metrics": ["flop"])", "metrics[0]: 'flop' is not an extra metric");
    refused(R"("spp": 1, "grid": {"media[fog].phase.g": [0.2, 0.4]}, "reference": {"image": ")" + project + R"("})",
            "reference.image: one image cannot be the reference of every render");
}

// --executor slurm: the batch scripts (an array over the manifest, a gather job after it), and a clear error without
// sbatch. The cluster itself is tested by tests/slurm/slurm-sweep.sh.
TEST(Sweep, SlurmScriptsAndNoSbatch) {
    const fs::path dir = scratch("sweep-slurm-scripts");
    const std::string spec = sweepSpec(dir);
    const std::string out = (dir / "out").string();
    const CliRun none = tyndall("sweep '" + spec + "' --out '" + out + "' --executor slurm", "PATH=/nonexistent ");
    EXPECT_EQ(none.exitCode, 2) << none.output;
    EXPECT_NE(none.output.find("needs sbatch on the PATH"), std::string::npos) << none.output;
    const CliRun scripts = tyndall("sweep '" + spec + "' --out '" + out +
                                   "' --executor slurm --no-submit --max-running 3 --partition "
                                   "night --time 10:00 --cpus-per-task 4");
    ASSERT_EQ(scripts.exitCode, 0) << scripts.output;
    std::ifstream arrayFile(fs::path(out) / "slurm" / "array.sh");
    const std::string array{std::istreambuf_iterator<char>(arrayFile), {}};
    for (const char* line : {"#SBATCH --array=0-19%3", "#SBATCH --partition=night", "#SBATCH --time=10:00",
                             "#SBATCH --cpus-per-task=4", "--run-task \"$SLURM_ARRAY_TASK_ID\""})
        EXPECT_NE(array.find(line), std::string::npos) << line << "\n" << array;
    std::ifstream gatherFile(fs::path(out) / "slurm" / "gather.sh");
    const std::string gather{std::istreambuf_iterator<char>(gatherFile), {}};
    EXPECT_NE(gather.find("sweep --gather --out"), std::string::npos) << gather;
    EXPECT_NE(scripts.output.find("--dependency=afterok:$id"), std::string::npos) << scripts.output;
    // The manifest: one task a line, in index order, each with its own output.
    std::ifstream manifest(fs::path(out) / "manifest.jsonl");
    int lines = 0;
    std::set<std::string> outputs;
    for (std::string line; std::getline(manifest, line); ++lines) {
        const auto task = nlohmann::json::parse(line);
        EXPECT_EQ(task["index"], lines);
        outputs.insert(task["output"].get<std::string>());
    }
    EXPECT_EQ(lines, 20);
    EXPECT_EQ(outputs.size(), 20u);

    // Task 3 runs on another node from that submission: a new one leaves it out, and a changed spec is refused while
    // it runs (its task reads the manifest by line).
    const auto task3 = nlohmann::json::parse([&] {
        std::ifstream in(fs::path(out) / "manifest.jsonl");
        std::string line;
        for (int i = 0; i <= 3; ++i)
            std::getline(in, line);
        return line;
    }());
    writeFile(fs::path(out) / "tasks" / (task3["id"].get<std::string>() + ".running.json"),
              R"({"host": "node-elsewhere", "pid": 4242, "since": "2026-12-07T00:00:00Z"})");
    const CliRun resubmit = tyndall("sweep '" + spec + "' --out '" + out + "' --executor slurm --no-submit");
    ASSERT_EQ(resubmit.exitCode, 0) << resubmit.output;
    EXPECT_NE(resubmit.output.find("1 task(s) are running from an earlier submission"), std::string::npos)
        << resubmit.output;
    std::ifstream again(fs::path(out) / "slurm" / "array.sh");
    const std::string rewritten{std::istreambuf_iterator<char>(again), {}};
    EXPECT_NE(rewritten.find("#SBATCH --array=0-2,4-19\n"), std::string::npos) << rewritten;
    const std::string changed = sweepSpec(dir, "", 64);
    const CliRun refused = tyndall("sweep '" + changed + "' --out '" + out + "' --executor slurm --no-submit");
    EXPECT_EQ(refused.exitCode, 2) << refused.output;
    EXPECT_NE(refused.output.find("while its task 3 is running (on node-elsewhere"), std::string::npos)
        << refused.output;
}

}  // namespace
