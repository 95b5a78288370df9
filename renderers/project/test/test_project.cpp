// Tests of the scene model helpers and of project files: loading, every validation rule (each with the field path and
// the message a user sees), --set overrides, saving (atomic, byte-identical round trips), hashing and view parts.
#include "tyndall/project/project.h"

#include "reference/reference.h"

#include "tyndall/core/error.h"
#include "tyndall/framework/technique.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace tyndall {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---------------------------------------------------------------------------------------------------------------------
// A technique with one parameter of each type, registered for these tests so that they do not depend on the
// parameters of real techniques. It renders nothing and does not support particle media.

class ProjectTestTechnique final : public Technique {
public:
    std::string name() const override { return "project-test"; }
    std::string displayName() const override { return "Project test"; }
    std::vector<ParamInfo> parameters() const override {
        return {
            info("spp", ParamType::Int, 1.0, 65536.0, std::int64_t{16}),
            info("sigma", ParamType::Float, 0.0, 10.0, 1.0),
            info("jitter", ParamType::Bool, 0.0, 1.0, true),
            info("sampling", ParamType::Enum, 0.0, 1.0, std::string("mis"), {"mis", "light", "phase"}),
            info("tint", ParamType::Rgb, 0.0, 1.0, Rgb(1.0)),
        };
    }
    Support supports(const HomogeneousMedium&) const override { return Support::yes(); }
    Support supports(const ParticleMedium&) const override { return Support::no("no particles"); }
    Support supports(const PointLight&) const override { return Support::yes(); }
    Support supports(const DirectionalLight&) const override { return Support::yes(); }
    Support supports(const AreaLight&) const override { return Support::yes(); }
    Support supports(const Material&) const override { return Support::yes(); }
    RenderResult render(const RenderRequest&, const RenderCallbacks&) override {
        throw InputError("the project-test technique does not render");
    }

private:
    static ParamInfo info(std::string name, ParamType type, double min, double max, ParamValue value,
                          std::vector<std::string> enumValues = {}) {
        ParamInfo i;
        i.name = std::move(name);
        i.type = type;
        i.min = min;
        i.max = max;
        i.defaultValue = std::move(value);
        i.enumValues = std::move(enumValues);
        return i;
    }
};

[[maybe_unused]] const bool kTechniqueRegistered = [] {
    registerTechnique("project-test", [] { return std::make_unique<ProjectTestTechnique>(); });
    return true;
}();

// ---------------------------------------------------------------------------------------------------------------------
// Files

fs::path testDir() {
    const fs::path dir = fs::path(TYNDALL_TEST_TMP) / "project";
    fs::create_directories(dir / "meshes");
    return dir;
}

// Where projects under test "live": relative OBJ paths resolve against its folder, which holds meshes/tri.obj.
std::string projectPath() {
    const fs::path obj = testDir() / "meshes" / "tri.obj";
    if (!fs::exists(obj)) std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    return (testDir() / "scene.json").string();
}

std::string readText(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

void writeText(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

std::vector<std::string> filesIn(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

// ---------------------------------------------------------------------------------------------------------------------
// Documents

const char* const kFullProject = R"({
  "tyndall": 1,
  "name": "full",
  "camera": {"position": [0, 1, 6], "target": [0, 1, 0], "up": [0, 1, 0], "fovY": 40, "width": 320, "height": 240},
  "media": [
    {"name": "haze", "albedo": 0.5, "extinction": [0.2, 0.4, 0.8], "phase": {"type": "mix", "g": 0.7, "a": 0.4}},
    {"name": "slab", "sigma_s": [0.1, 0.2, 0.3], "sigma_a": 0.05,
     "phase": {"type": "legendre", "coefficients": [1, 0.5, 0.1]},
     "shape": "box", "box": {"centre": [0, 1, 0], "size": [2, 1, 2], "rotate": [0, 45, 0]}},
    {"name": "prism", "phase": {"type": "eddington", "b": -0.3}, "shape": "polyhedron",
     "planes": [{"normal": [1, 0, 0], "offset": 1}, {"normal": [-2, 0, 0], "offset": 2},
                {"normal": [0, 1, 0], "offset": 1}, {"normal": [0, -1, 0], "offset": 1},
                {"normal": [0, 0, 1], "offset": 1}, {"normal": [0, 0, -1], "offset": 1}]}
  ],
  "particleMedia": [
    {"name": "smoke", "extinction": 2, "albedo": 0.9, "phase": {"type": "hg", "g": -0.2},
     "particles": [{"centre": [0, 1, 0], "scale": 0.5, "orientation": [1, 0, 0, 0], "extinctionMultiplier": 7,
                    "falloff": 1.2}],
     "generator": {"count": 20, "seed": 42, "region": {"centre": [0, 1, 0], "size": [2, 2, 2], "rotate": [0, 0, 0]},
                   "scale": 0.2, "falloff": 1.6, "multiplierMin": 5, "multiplierMax": 10}}
  ],
  "lights": [
    {"type": "area", "name": "panel", "vertices": [[-1, 3, -1], [1, 3, -1], [1, 3, 1], [-1, 3, 1]],
     "radiance": [2, 2, 1.5], "twoSided": true},
    {"type": "point", "name": "bulb", "position": [0, 2, 0], "intensity": 5},
    {"type": "point", "name": "spot", "position": [1, 3, 0], "intensity": [10, 9, 8],
     "distribution": {"type": "spot", "axis": [0, -2, 0], "exponent": 8}},
    {"type": "point", "name": "lobe", "position": [-1, 3, 0], "intensity": 1,
     "distribution": {"type": "polynomial", "axis": [0, -1, 0], "coefficients": [0.5, 0.5]}},
    {"type": "directional", "name": "sun", "direction": [0, -1, -1], "irradiance": 3,
     "gobo": [[-1, 5, -1], [1, 5, -1], [1, 5, 1], [-1, 5, 1]]}
  ],
  "materials": [
    {"name": "grey", "type": "diffuse", "albedo": 0.5},
    {"name": "steel", "type": "ggx", "f0": [0.56, 0.57, 0.58], "alphaX": 0.2, "alphaY": 0.4}
  ],
  "meshes": [
    {"name": "floor", "shape": "plane", "material": "grey", "transform": {"scale": [10, 1, 10]}},
    {"name": "ball", "shape": "sphere", "subdivisions": 64, "material": "steel", "tangent": [0, 0, 1],
     "transform": {"translate": [0, 1, 0], "rotate": [0, 30, 0], "scale": [0.5, 0.5, 0.5]}},
    {"name": "tri", "shape": "obj", "file": "meshes/tri.obj", "material": "grey"}
  ],
  "views": [
    {"name": "test", "technique": "project-test", "exposure": 1.5,
     "parameters": {"spp": 64, "tint": [0.2, 0.3, 0.4], "sampling": "light"}},
    {"name": "sun only", "technique": "project-test", "lights": ["sun"], "media": ["haze", "smoke"]},
    {"name": "ref", "technique": "reference", "parameters": {"mode": "multiple"}}
  ],
  "reference": {"mode": "multiple", "maxDepth": 32, "spp": 1024, "seed": 7}
})";

// A small valid project that the validation tests break one field at a time.
json baseDocument() {
    return json::parse(R"({
      "tyndall": 1,
      "name": "base",
      "camera": {"position": [0, 1, 5], "target": [0, 1, 0], "up": [0, 1, 0], "fovY": 45, "width": 64, "height": 48},
      "media": [{"name": "fog", "sigma_s": 0.1, "sigma_a": 0.01, "phase": {"type": "hg", "g": 0.5}}],
      "particleMedia": [{"name": "smoke", "particles": [{"centre": [0, 1, 0]}]}],
      "lights": [
        {"type": "point", "name": "bulb", "position": [0, 2, 0], "intensity": 5},
        {"type": "directional", "name": "sun", "direction": [0, -1, 0], "irradiance": 3},
        {"type": "area", "name": "panel", "vertices": [[-1, 3, -1], [1, 3, -1], [1, 3, 1], [-1, 3, 1]], "radiance": 1}
      ],
      "materials": [{"name": "grey"}, {"name": "steel", "type": "ggx"}],
      "meshes": [{"name": "floor", "shape": "plane", "material": "grey"}],
      "views": [{"name": "main", "technique": "project-test"}]
    })");
}

json edited(const std::function<void(json&)>& edit) {
    json document = baseDocument();
    edit(document);
    return document;
}

Project parse(const json& document, const std::vector<std::string>& overrides = {}) {
    return parseProject(techniqueCatalogue(), document.dump(), projectPath(), overrides);
}

// Succeeds when parsing fails with an InputError at `field` whose message contains `phrase`.
::testing::AssertionResult failsAt(const json& document, const std::string& field, const std::string& phrase,
                                   const std::vector<std::string>& overrides = {}) {
    try {
        parse(document, overrides);
    } catch (const InputError& e) {
        if (e.where().field != field)
            return ::testing::AssertionFailure() << "field is not " << field << ": " << e.what();
        if (e.message().find(phrase) == std::string::npos) {
            return ::testing::AssertionFailure() << "message lacks \"" << phrase << "\": " << e.what();
        }
        return ::testing::AssertionSuccess();
    }
    return ::testing::AssertionFailure() << "no InputError";
}

::testing::AssertionResult failsAt(const std::function<void(json&)>& edit, const std::string& field,
                                   const std::string& phrase) {
    return failsAt(edited(edit), field, phrase);
}

// ---------------------------------------------------------------------------------------------------------------------
// Scene helpers

TEST(SceneTransform, RotatesEulerXyzWithXFirst) {
    Transform t;
    t.rotate = Vec3(90.0, 0.0, 0.0);
    const Vec3 y = t.rotation() * Vec3(0.0, 1.0, 0.0);
    EXPECT_NEAR(glm::distance(y, Vec3(0.0, 0.0, 1.0)), 0.0, 1e-12);
    // X first, then Y: +y -> (x 90) +z -> (y 90) +x.
    t.rotate = Vec3(90.0, 90.0, 0.0);
    EXPECT_NEAR(glm::distance(t.rotation() * Vec3(0.0, 1.0, 0.0), Vec3(1.0, 0.0, 0.0)), 0.0, 1e-12);
    t.rotate = Vec3(0.0, 0.0, 90.0);
    EXPECT_NEAR(glm::distance(t.rotation() * Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0)), 0.0, 1e-12);
}

TEST(SceneTransform, ScalesThenRotatesThenTranslates) {
    Transform t;
    t.translate = Vec3(1.0, 2.0, 3.0);
    t.rotate = Vec3(0.0, 0.0, 90.0);
    t.scale = Vec3(2.0, 1.0, 1.0);
    const glm::dvec4 p = t.worldFromLocal() * glm::dvec4(1.0, 0.0, 0.0, 1.0);
    EXPECT_NEAR(glm::distance(Vec3(p), Vec3(1.0, 4.0, 3.0)), 0.0, 1e-12);
    OrientedBox box;
    box.rotate = t.rotate;
    EXPECT_EQ(box.worldFromBoxRotation(), t.rotation());
}

TEST(ScenePhase, NamesKindsAsInProjectFiles) {
    EXPECT_STREQ(toString(PhaseKind::Isotropic), "isotropic");
    EXPECT_STREQ(toString(PhaseKind::HenyeyGreenstein), "hg");
    EXPECT_STREQ(toString(PhaseKind::IsoHgMix), "mix");
    EXPECT_STREQ(toString(PhaseKind::Rayleigh), "rayleigh");
    EXPECT_STREQ(toString(PhaseKind::Eddington), "eddington");
    EXPECT_STREQ(toString(PhaseKind::Legendre), "legendre");
}

TEST(SceneDistribution, ExpandsEveryKindAsAPolynomial) {
    AngularDistribution d;
    EXPECT_EQ(d.polynomial(), std::vector<double>{1.0});
    d.kind = AngularDistribution::Kind::Spot;
    d.spotExponent = 2.0;
    EXPECT_EQ(d.polynomial(), (std::vector<double>{0.25, 0.5, 0.25}));
    d.spotExponent = 0.0;
    EXPECT_EQ(d.polynomial(), std::vector<double>{1.0});
    d.kind = AngularDistribution::Kind::Polynomial;
    d.coefficients = {0.5, 0.5};
    EXPECT_EQ(d.polynomial(), d.coefficients);
    // Legendre: 1 + 0.5 P_1 + 0.5 P_2 = 0.75 + 0.5 mu + 0.75 mu^2.
    d.kind = AngularDistribution::Kind::Legendre;
    d.coefficients = {1.0, 0.5, 0.5};
    EXPECT_EQ(d.polynomial(), (std::vector<double>{0.75, 0.5, 0.75}));
}

TEST(SceneDistribution, SpotExpansionMatchesThePowerUpToExponent256) {
    AngularDistribution d;
    d.kind = AngularDistribution::Kind::Spot;
    for (double n : {1.0, 7.0, 64.0, 256.0}) {
        d.spotExponent = n;
        const std::vector<double> c = d.polynomial();
        ASSERT_EQ(c.size(), static_cast<std::size_t>(n) + 1);
        for (double mu : {-0.5, 0.0, 0.3, 0.9, 1.0}) {
            double value = 0.0;
            for (auto it = c.rbegin(); it != c.rend(); ++it)
                value = value * mu + *it;
            EXPECT_NEAR(value, std::pow((1.0 + mu) / 2.0, n), 1e-12) << "n = " << n << ", mu = " << mu;
        }
    }
    d.spotExponent = 2.5;
    EXPECT_THROW(d.polynomial(), ContractError);
}

TEST(SceneParticles, GeneratesDeterministicallyAfterTheExplicitOnes) {
    ParticleMedium medium;
    Particle explicitParticle;
    explicitParticle.centre = Vec3(9.0);
    medium.particles = {explicitParticle};
    ParticleGenerator g;
    g.count = 500;
    g.seed = 3;
    g.region.centre = Vec3(1.0, 2.0, 3.0);
    g.region.size = Vec3(2.0, 4.0, 6.0);
    g.region.rotate = Vec3(0.0, 90.0, 0.0);
    g.scale = 0.3;
    g.falloff = 1.4;
    medium.generator = g;

    const std::vector<Particle> all = medium.allParticles();
    ASSERT_EQ(all.size(), 501u);
    EXPECT_EQ(all[0].centre, Vec3(9.0));
    const glm::dmat3 boxFromWorld = glm::transpose(g.region.worldFromBoxRotation());
    for (std::size_t i = 1; i < all.size(); ++i) {
        const Particle& p = all[i];
        const Vec3 local = boxFromWorld * (p.centre - g.region.centre);
        EXPECT_TRUE(glm::all(glm::lessThanEqual(glm::abs(local), 0.5 * g.region.size + 1e-12))) << i;
        EXPECT_NEAR(glm::length(p.orientation), 1.0, 1e-12);
        EXPECT_GE(p.extinctionMultiplier, g.multiplierMin);
        EXPECT_LE(p.extinctionMultiplier, g.multiplierMax);
        EXPECT_EQ(p.scale, 0.3);
        EXPECT_EQ(p.falloff, 1.4);
    }
    const std::vector<Particle> again = medium.allParticles();
    for (std::size_t i = 0; i < all.size(); ++i)
        EXPECT_EQ(again[i].centre, all[i].centre);

    medium.generator->seed = 4;
    EXPECT_NE(medium.allParticles()[1].centre, all[1].centre);
}

TEST(SceneParticles, SpreadsCentresAndOrientationsUniformly) {
    ParticleMedium medium;
    ParticleGenerator g;
    g.count = 20000;
    medium.generator = g;
    Vec3 meanCentre(0.0);
    double meanAbsW = 0.0, meanSquaredX = 0.0, meanMultiplier = 0.0;
    for (const Particle& p : medium.allParticles()) {
        meanCentre += p.centre / double(g.count);
        meanAbsW += std::abs(p.orientation.w) / g.count;
        meanSquaredX += p.orientation.x * p.orientation.x / g.count;
        meanMultiplier += p.extinctionMultiplier / g.count;
    }
    // Centres uniform in a unit box about 0: mean 0 with sd 1 / sqrt(12 n) per axis. Quaternions uniform on the unit
    // 3-sphere: each coordinate has density (2 / pi) sqrt(1 - w^2), so E|w| = 4 / (3 pi) and E[x^2] = 1 / 4.
    EXPECT_NEAR(glm::length(meanCentre), 0.0, 0.01);
    EXPECT_NEAR(meanAbsW, 4.0 / (3.0 * std::numbers::pi), 0.01);
    EXPECT_NEAR(meanSquaredX, 0.25, 0.01);
    EXPECT_NEAR(meanMultiplier, 7.5, 0.05);
}

TEST(ScenePart, AppliesToLightsAndMediaByName) {
    const Project project = parseProject(techniqueCatalogue(), kFullProject, projectPath());
    const ScenePart everything = ScenePart::everything(project.scene);
    EXPECT_EQ(everything.lights, (std::vector<std::string>{"bulb", "spot", "lobe", "sun", "panel"}));
    EXPECT_EQ(everything.media, (std::vector<std::string>{"haze", "slab", "prism", "smoke"}));

    const Scene part = ScenePart{{"sun", "bulb"}, {"smoke"}}.apply(project.scene);
    ASSERT_EQ(part.pointLights.size(), 1u);
    EXPECT_EQ(part.pointLights[0].name, "bulb");
    ASSERT_EQ(part.directionalLights.size(), 1u);
    EXPECT_TRUE(part.areaLights.empty());
    EXPECT_TRUE(part.media.empty());
    ASSERT_EQ(part.particleMedia.size(), 1u);
    EXPECT_EQ(part.meshes.size(), project.scene.meshes.size());
    EXPECT_EQ(part.materials.size(), project.scene.materials.size());
    EXPECT_EQ(part.camera.width, 320);
}

// ---------------------------------------------------------------------------------------------------------------------
// Loading valid projects

TEST(ProjectLoad, AcceptsMinimalProjectWithDefaults) {
    const Project p = parseProject(techniqueCatalogue(), R"({"tyndall": 1})", "minimal.json");
    EXPECT_EQ(p.name, "");
    EXPECT_EQ(p.scene.camera.width, Camera{}.width);
    EXPECT_EQ(p.scene.camera.fovY, Camera{}.fovY);
    EXPECT_TRUE(p.scene.media.empty());
    EXPECT_TRUE(p.views.empty());
    EXPECT_EQ(p.reference.spp, ReferenceSettings{}.spp);
}

TEST(ProjectLoad, AcceptsFullProject) {
    const Project p = parseProject(techniqueCatalogue(), kFullProject, projectPath());
    const Scene& s = p.scene;
    EXPECT_EQ(p.name, "full");
    EXPECT_EQ(s.camera.height, 240);
    ASSERT_EQ(s.media.size(), 3u);
    EXPECT_EQ(s.media[0].sigma_s, Rgb(0.1, 0.2, 0.4));
    EXPECT_EQ(s.media[0].sigma_a, Rgb(0.1, 0.2, 0.4));
    EXPECT_EQ(s.media[0].phase.kind, PhaseKind::IsoHgMix);
    EXPECT_EQ(s.media[1].shape, MediumShape::Box);
    EXPECT_EQ(s.media[1].phase.legendre, (std::vector<double>{1.0, 0.5, 0.1}));
    EXPECT_EQ(s.media[2].planes[1].normal, Vec3(-1.0, 0.0, 0.0));
    EXPECT_EQ(s.media[2].planes[1].offset, 1.0);
    ASSERT_EQ(s.particleMedia.size(), 1u);
    EXPECT_EQ(s.particleMedia[0].allParticles().size(), 21u);
    ASSERT_EQ(s.pointLights.size(), 3u);
    EXPECT_EQ(s.pointLights[1].distribution.axis, Vec3(0.0, -1.0, 0.0));
    EXPECT_EQ(s.pointLights[1].distribution.spotExponent, 8.0);
    ASSERT_EQ(s.directionalLights.size(), 1u);
    EXPECT_NEAR(glm::length(s.directionalLights[0].direction), 1.0, 1e-15);
    EXPECT_EQ(s.directionalLights[0].gobo.size(), 4u);
    ASSERT_EQ(s.areaLights.size(), 1u);
    EXPECT_TRUE(s.areaLights[0].twoSided);
    EXPECT_EQ(s.materials[1].kind, Material::Kind::GGX);
    EXPECT_EQ(s.materials[1].alphaY, 0.4);
    EXPECT_EQ(s.meshes[2].source, Mesh::Source::Obj);
    ASSERT_EQ(p.views.size(), 3u);
    EXPECT_EQ(p.views[0].parameters["spp"], 64);
    EXPECT_FALSE(p.views[0].part.has_value());
    ASSERT_TRUE(p.views[1].part.has_value());
    EXPECT_EQ(p.views[1].part->media, (std::vector<std::string>{"haze", "smoke"}));
    EXPECT_EQ(p.reference.mode, ReferenceSettings::Mode::Multiple);
    EXPECT_EQ(p.reference.seed, 7u);
}

// Keeps docs/project-format.md true: its example must load.
TEST(ProjectLoad, AcceptsTheExampleOfTheFormatDocumentation) {
    const std::string doc = readText(fs::path(TYNDALL_SOURCE_DIR) / "docs" / "project-format.md");
    const std::size_t section = doc.find("## Example");
    ASSERT_NE(section, std::string::npos);
    const std::size_t begin = doc.find("```json\n", section);
    ASSERT_NE(begin, std::string::npos);
    const std::size_t end = doc.find("\n```", begin + 8);
    ASSERT_NE(end, std::string::npos);
    const Project p = parseProject(techniqueCatalogue(), doc.substr(begin + 8, end - begin - 8), projectPath());
    EXPECT_EQ(p.name, "foggy room");
    EXPECT_EQ(p.scene.particleMedia[0].allParticles().size(), 200u);
    EXPECT_EQ(p.views.size(), 2u);
}

TEST(ProjectLoad, ReadsFilesAndResolvesObjPathsAgainstTheirFolder) {
    const std::string path = projectPath();
    writeText(path, kFullProject);
    const Project p = loadProject(techniqueCatalogue(), path);
    EXPECT_EQ(p.scene.meshes[2].file, "meshes/tri.obj");
}

TEST(ProjectLoad, RejectsMissingFile) {
    const std::string path = (testDir() / "does-not-exist.json").string();
    try {
        loadProject(techniqueCatalogue(), path);
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().file, path);
        EXPECT_NE(e.message().find("cannot open"), std::string::npos) << e.what();
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Validation: one test per rule

TEST(ProjectLoad, RejectsMalformedJsonWithLineAndColumn) {
    const std::string text = "{\n  \"tyndall\": 1,\n  \"name\": \"x\"\n  \"camera\": {}\n}";
    try {
        parseProject(techniqueCatalogue(), text, "broken.json");
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().file, "broken.json");
        EXPECT_EQ(e.where().line, 4);
        EXPECT_EQ(e.where().column, 10);  // the last character read: the end of the unexpected "camera"
        EXPECT_NE(e.message().find("malformed JSON"), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).rfind("broken.json:4:10: ", 0), 0u) << e.what();
    }
    try {
        parseProject(techniqueCatalogue(), "", "empty.json");
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().line, 1);
        EXPECT_EQ(e.where().column, 1);
    }
}

TEST(ProjectLoad, RejectsNumbersTooLargeForADouble) {
    try {
        parseProject(techniqueCatalogue(), R"({"tyndall": 1, "camera": {"fovY": 1e999}})", "big.json");
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(e.message().find("1e999"), std::string::npos) << e.what();
    }
}

TEST(ProjectLoad, RejectsMissingVersion) {
    EXPECT_TRUE(failsAt([](json& j) { j.erase("tyndall"); }, "tyndall", "is missing"));
    EXPECT_TRUE(failsAt(json::array(), "", "must be a JSON object"));
}

TEST(ProjectLoad, RejectsUnsupportedVersion) {
    EXPECT_TRUE(failsAt([](json& j) { j["tyndall"] = 2; }, "tyndall", "unsupported project format version 2"));
    EXPECT_TRUE(failsAt([](json& j) { j["tyndall"] = "1"; }, "tyndall", "must be an integer"));
}

TEST(ProjectLoad, RejectsUnknownKeyWithSuggestion) {
    EXPECT_TRUE(failsAt([](json& j) { j["media"][0]["sigma_S"] = 0.1; }, "media[0].sigma_S",
                        "unknown key 'sigma_S'; did you mean 'sigma_s'?"));
    EXPECT_TRUE(failsAt([](json& j) { j["camera"]["fov"] = 30; }, "camera.fov", "did you mean 'fovY'?"));
    EXPECT_TRUE(failsAt([](json& j) { j["cameras"] = json::object(); }, "cameras", "did you mean 'camera'?"));
    EXPECT_TRUE(failsAt([](json& j) { j["media"][0]["phase"]["asymmetry"] = 0.1; }, "media[0].phase.asymmetry",
                        "allowed keys: type g a b coefficients"));
}

TEST(ProjectLoad, RejectsKeysOfAnotherLightType) {
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][0]["radiance"] = 1; }, "lights[0].radiance",
                        "'radiance' does not apply to a point light"));
}

TEST(ProjectLoad, RejectsUnknownLightType) {
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][1]["type"] = "directionl"; }, "lights[1].type",
                        "did you mean 'directional'?"));
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][1].erase("type"); }, "lights[1].type", "is missing"));
}

TEST(ProjectLoad, RejectsWrongTypes) {
    EXPECT_TRUE(
        failsAt([](json& j) { j["camera"]["fovY"] = "wide"; }, "camera.fovY", "must be a number, got string \"wide\""));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["camera"]["position"] = json::array({0, 1});
        },
        "camera.position", "an array of 3 numbers"));
    EXPECT_TRUE(failsAt([](json& j) { j["lights"] = json::object(); }, "lights", "must be an array"));
    EXPECT_TRUE(failsAt([](json& j) { j["camera"]["width"] = 64.5; }, "camera.width", "must be an integer"));
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][2]["twoSided"] = 1; }, "lights[2].twoSided", "true or false"));
}

TEST(ProjectLoad, RejectsNanAndInfinityWrittenAsStrings) {
    EXPECT_TRUE(failsAt([](json& j) { j["media"][0]["sigma_s"] = "nan"; }, "media[0].sigma_s", "got string \"nan\""));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][0]["intensity"] = json::array({1, "inf", 1});
        },
        "lights[0].intensity", "an array of 3 numbers"));
}

TEST(ProjectLoad, RejectsNegativeCoefficients) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["media"][0]["sigma_a"] = json::array({0.1, -1, 0});
        },
        "media[0].sigma_a", "each component must be in [0, 1e+06], got [0.1, -1, 0]"));
    EXPECT_TRUE(failsAt([](json& j) { j["particleMedia"][0]["extinction"] = -2; }, "particleMedia[0].extinction",
                        "each component must be in [0, 1e+06], got [-2, -2, -2]"));
    EXPECT_TRUE(failsAt([](json& j) { j["particleMedia"][0]["extinction"] = json::array({1.5, -0.5, 1}); },
                        "particleMedia[0].extinction", "each component must be in [0, 1e+06], got [1.5, -0.5, 1]"));
}

// A particle medium's extinction is one number (grey) or an RGB triple (chromatic: coloured shadows); both load and
// survive a save (an edit elsewhere keeps the number as it was written: updateProjectText).
TEST(ProjectLoad, ParticleExtinctionIsGreyOrChromatic) {
    const std::string grey = R"({"tyndall": 1, "camera": {"width": 8, "height": 6},
        "particleMedia": [{"name": "smoke", "extinction": 2.5, "particles": [{"centre": [0, 0, -3]}]}],
        "views": [{"name": "v", "technique": "reference"}]})";
    const Project a = parseProject(techniqueCatalogue(), grey, "grey.json");
    EXPECT_EQ(a.scene.particleMedia[0].extinction, Rgb(2.5));
    std::string chromatic = grey;
    chromatic.replace(chromatic.find("2.5"), 3, "[2.5, 1, 0.25]");
    const Project b = parseProject(techniqueCatalogue(), chromatic, "chromatic.json");
    EXPECT_EQ(b.scene.particleMedia[0].extinction, Rgb(2.5, 1.0, 0.25));
    for (const Project* p : {&a, &b})
        EXPECT_EQ(
            projectFromJson(techniqueCatalogue(), projectToJson(*p), "saved.json").scene.particleMedia[0].extinction,
            p->scene.particleMedia[0].extinction);
    Project edited = a;
    edited.scene.particleMedia[0].albedo = Rgb(0.5);
    const std::string text = updateProjectText(techniqueCatalogue(), ProjectFile{"grey.json", grey, a}, edited);
    EXPECT_NE(text.find("\"extinction\": 2.5,"), std::string::npos) << text;
}

TEST(ProjectLoad, RejectsBothCoefficientForms) {
    EXPECT_TRUE(failsAt([](json& j) { j["media"][0]["albedo"] = 0.5; }, "media[0].albedo", "not both forms"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["media"][0].erase("sigma_s");
            j["media"][0].erase("sigma_a");
            j["media"][0]["extinction"] = 1;
        },
        "media[0].albedo", "is required together with 'extinction'"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["media"][0] = json{{"name", "fog"}, {"albedo", 1.5}, {"extinction", 1}};
        },
        "media[0].albedo", "each component must be in [0, 1]"));
}

TEST(ProjectLoad, RejectsHgAsymmetryOfMagnitudeOne) {
    EXPECT_TRUE(
        failsAt([](json& j) { j["media"][0]["phase"]["g"] = 1; }, "media[0].phase.g", "must be in (-1, 1), got 1"));
    EXPECT_TRUE(failsAt([](json& j) { j["media"][0]["phase"]["g"] = -1.5; }, "media[0].phase.g", "got -1.5"));
}

TEST(ProjectLoad, RejectsMixWeightOutsideUnitInterval) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["media"][0]["phase"] = json{{"type", "mix"}, {"a", 1.2}};
        },
        "media[0].phase.a", "must be in [0, 1], got 1.2"));
}

TEST(ProjectLoad, RejectsEddingtonCoefficientAboveOne) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["media"][0]["phase"] = json{{"type", "eddington"}, {"b", -1.01}};
        },
        "media[0].phase.b", "must be in [-1, 1]"));
}

TEST(ProjectLoad, RejectsLegendreSeriesNotStartingWithOne) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["media"][0]["phase"] = json{{"type", "legendre"}, {"coefficients", {2, 0.5}}};
        },
        "media[0].phase.coefficients[0]", "a_0 must be 1"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["media"][0]["phase"] = json{{"type", "legendre"}};
        },
        "media[0].phase.coefficients", "needs coefficients"));
}

TEST(ProjectLoad, RejectsNegativeLegendreSeries) {
    // 1 - 1.5 P_2(x) is -0.5 at x = +-1.
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["media"][0]["phase"] = json{{"type", "legendre"}, {"coefficients", {1, 0, -1.5}}};
        },
        "media[0].phase.coefficients", "must be >= 0 for every cos in [-1, 1]"));
    // The truncated HG expansion a_n = (2n + 1) g^n with g = 0.9 dips below zero between the sample points' ends.
    std::vector<double> hg;
    for (int n = 0; n < 8; ++n)
        hg.push_back((2 * n + 1) * std::pow(0.9, n));
    EXPECT_TRUE(failsAt(
        [&](json& j) {
            j["media"][0]["phase"] = json{{"type", "legendre"}, {"coefficients", hg}};
        },
        "media[0].phase.coefficients", "must be >= 0"));
}

TEST(ProjectLoad, RejectsLegendreSeriesLongerThan32Terms) {
    std::vector<double> a(33, 0.0);
    a[0] = 1.0;
    EXPECT_TRUE(failsAt(
        [&](json& j) {
            j["media"][0]["phase"] = json{{"type", "legendre"}, {"coefficients", a}};
        },
        "media[0].phase.coefficients", "at most 32 coefficients, got 33"));
}

TEST(ProjectLoad, RejectsDegenerateBoxes) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["media"][0]["shape"] = "box";
            j["media"][0]["box"] = json{{"size", {1, 0, 1}}};
        },
        "media[0].box.size", "each component must be > 0, got [1, 0, 1]"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["particleMedia"][0]["generator"] = json{{"region", {{"size", {1, 1, -1}}}}};
        },
        "particleMedia[0].generator.region.size", "must be > 0"));
}

TEST(ProjectLoad, RejectsPolyhedraThatAreNotBoundedSolids) {
    const auto planes = [](std::vector<std::pair<Vec3, double>> list) {
        json array = json::array();
        for (const auto& [n, d] : list)
            array.push_back(json{{"normal", {n.x, n.y, n.z}}, {"offset", d}});
        return array;
    };
    EXPECT_TRUE(failsAt(
        [&](json& j) {
            j["media"][0]["shape"] = "polyhedron";
            j["media"][0]["planes"] = planes({{Vec3(1, 0, 0), 1}, {Vec3(-1, 0, 0), 1}, {Vec3(0, 1, 0), 1}});
        },
        "media[0].planes", "at least 4 planes, got 3"));
    // A slab bounded in x and y only.
    EXPECT_TRUE(failsAt(
        [&](json& j) {
            j["media"][0]["shape"] = "polyhedron";
            j["media"][0]["planes"] =
                planes({{Vec3(1, 0, 0), 1}, {Vec3(-1, 0, 0), 1}, {Vec3(0, 1, 0), 1}, {Vec3(0, -1, 0), 1}});
        },
        "media[0].planes", "do not bound"));
    // x <= -1 and x >= 1 cannot both hold.
    EXPECT_TRUE(failsAt(
        [&](json& j) {
            j["media"][0]["shape"] = "polyhedron";
            j["media"][0]["planes"] = planes({{Vec3(1, 0, 0), -1},
                                              {Vec3(-1, 0, 0), -1},
                                              {Vec3(0, 1, 0), 1},
                                              {Vec3(0, -1, 0), 1},
                                              {Vec3(0, 0, 1), 1},
                                              {Vec3(0, 0, -1), 1}});
        },
        "media[0].planes", "empty"));
    EXPECT_TRUE(failsAt(
        [&](json& j) {
            j["media"][0]["planes"] = planes({{Vec3(0, 0, 0), 1}});
        },
        "media[0].planes[0].normal", "must not be the zero vector"));
}

TEST(ProjectLoad, RejectsZeroAreaAreaLights) {
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][2]["vertices"] = json::parse("[[0, 3, 0], [1, 3, 0], [2, 3, 0]]"); },
                        "lights[2].vertices", "zero area"));
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][2]["vertices"] = json::parse("[[0, 3, 0], [1, 3, 0]]"); },
                        "lights[2].vertices", "at least 3 vertices"));
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][2].erase("vertices"); }, "lights[2].vertices", "is missing"));
}

TEST(ProjectLoad, RejectsNonPlanarAreaLights) {
    EXPECT_TRUE(failsAt(
        [](json& j) { j["lights"][2]["vertices"] = json::parse("[[-1, 3, -1], [1, 3, -1], [1, 3.5, 1], [-1, 3, 1]]"); },
        "lights[2].vertices", "not planar"));
}

TEST(ProjectLoad, RejectsNonConvexAreaLights) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][2]["vertices"] = json::parse("[[0, 3, 0], [2, 3, 0], [2, 3, 2], [1, 3, 0.5], [0, 3, 2]]");
        },
        "lights[2].vertices", "not convex"));
}

TEST(ProjectLoad, RejectsInvalidGobos) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][1]["gobo"] = json::parse("[[0, 5, 0], [2, 5, 0], [2, 5, 2], [1, 5, 0.5], [0, 5, 2]]");
        },
        "lights[1].gobo", "not convex"));
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][1]["gobo"] = json::parse("[[0, 5, 0], [1, 5, 0], [2, 5, 0]]"); },
                        "lights[1].gobo", "zero area"));
    // A gobo in a vertical plane, parallel to a beam pointing down.
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][1]["gobo"] = json::parse("[[0, 0, 0], [1, 0, 0], [1, 1, 0]]"); },
                        "lights[1].gobo", "contains the light direction"));
}

TEST(ProjectLoad, RejectsNegativeOrNonFiniteLightValues) {
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][2]["radiance"] = -1; }, "lights[2].radiance",
                        "each component must be in [0, 1e+15], got [-1, -1, -1]"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][1]["irradiance"] = json::array({1, -0.5, 1});
        },
        "lights[1].irradiance", "in [0, 1e+15]"));
    EXPECT_TRUE(
        failsAt([](json& j) { j["lights"][0]["intensity"] = "inf"; }, "lights[0].intensity", "got string \"inf\""));
}

TEST(ProjectLoad, RejectsNegativeLightDistribution) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][0]["distribution"] = json{{"type", "polynomial"}, {"coefficients", {0, 1}}};
        },
        "lights[0].distribution.coefficients", "it is -1 at cos = -1"));
    // 1 + 2 P_1 is -1 at cos = -1 as well.
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][0]["distribution"] = json{{"type", "legendre"}, {"coefficients", {1, 2}}};
        },
        "lights[0].distribution.coefficients", "it is -1 at cos = -1"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][0]["distribution"] = json{{"type", "polynomial"}};
        },
        "lights[0].distribution.coefficients", "at least one coefficient"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][0]["distribution"] = json{{"type", "spot"}, {"axis", {0, 0, 0}}};
        },
        "lights[0].distribution.axis", "must not be the zero vector"));
}

TEST(ProjectLoad, RejectsSpotExponentsThatAreNotIntegersUpTo256) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][0]["distribution"] = json{{"type", "spot"}, {"exponent", 2.5}};
        },
        "lights[0].distribution.exponent", "must be an integer in [0, 256], got 2.5"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["lights"][0]["distribution"] = json{{"type", "spot"}, {"exponent", 257}};
        },
        "lights[0].distribution.exponent", "got 257"));
}

TEST(ProjectLoad, RejectsDuplicateLightNames) {
    EXPECT_TRUE(failsAt([](json& j) { j["lights"][2]["name"] = "bulb"; }, "lights[2].name",
                        "duplicate light name 'bulb' (also lights[0])"));
}

TEST(ProjectLoad, RejectsDuplicateMediumNames) {
    EXPECT_TRUE(failsAt([](json& j) { j["particleMedia"][0]["name"] = "fog"; }, "particleMedia[0].name",
                        "duplicate medium name 'fog' (also media[0])"));
}

TEST(ProjectLoad, RejectsDuplicateMaterialMeshAndViewNames) {
    EXPECT_TRUE(
        failsAt([](json& j) { j["materials"][1]["name"] = "grey"; }, "materials[1].name", "duplicate material"));
    EXPECT_TRUE(failsAt([](json& j) { j["meshes"].push_back(j["meshes"][0]); }, "meshes[1].name", "duplicate mesh"));
    EXPECT_TRUE(failsAt([](json& j) { j["views"].push_back(j["views"][0]); }, "views[1].name", "duplicate view"));
}

TEST(ProjectLoad, RejectsMissingOrEmptyNames) {
    EXPECT_TRUE(failsAt([](json& j) { j["materials"][0].erase("name"); }, "materials[0].name", "is missing"));
    EXPECT_TRUE(failsAt([](json& j) { j["media"][0]["name"] = ""; }, "media[0].name", "must not be empty"));
}

TEST(ProjectLoad, RejectsMeshWithUnknownMaterialWithSuggestion) {
    EXPECT_TRUE(failsAt([](json& j) { j["meshes"][0]["material"] = "stel"; }, "meshes[0].material",
                        "unknown material 'stel'; did you mean 'steel'?"));
}

TEST(ProjectLoad, RejectsMissingObjFile) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["meshes"][0] = json{{"name", "m"}, {"shape", "obj"}, {"file", "nope.obj"}, {"material", "grey"}};
        },
        "meshes[0].file", "file not found: " + (testDir() / "nope.obj").string()));
    EXPECT_TRUE(failsAt([](json& j) { j["meshes"][0]["shape"] = "obj"; }, "meshes[0].file", "needs a file"));
}

TEST(ProjectLoad, RejectsMeshValuesOutOfRange) {
    EXPECT_TRUE(failsAt([](json& j) { j["meshes"][0]["subdivisions"] = 2; }, "meshes[0].subdivisions",
                        "must be an integer in [4, 1024], got 2"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["meshes"][0]["transform"] = json{{"scale", {1, 0, 1}}};
        },
        "meshes[0].transform.scale", "must be non-zero"));
}

TEST(ProjectLoad, RejectsMaterialValuesOutOfRange) {
    EXPECT_TRUE(failsAt([](json& j) { j["materials"][0]["albedo"] = 1.1; }, "materials[0].albedo", "[0, 1]"));
    EXPECT_TRUE(failsAt([](json& j) { j["materials"][1]["alpha"] = 0; }, "materials[1].alpha", "[0.001, 1]"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["materials"][1]["alpha"] = 0.2;
            j["materials"][1]["alphaX"] = 0.2;
        },
        "materials[1].alpha", "not both"));
}

TEST(ProjectLoad, RejectsAbsurdImageSizes) {
    EXPECT_TRUE(failsAt([](json& j) { j["camera"]["width"] = 0; }, "camera.width", "[1, 16384], got 0"));
    EXPECT_TRUE(failsAt([](json& j) { j["camera"]["height"] = 20000; }, "camera.height", "got 20000"));
}

TEST(ProjectLoad, RejectsFieldOfViewOutsideOpenRange) {
    EXPECT_TRUE(failsAt([](json& j) { j["camera"]["fovY"] = 180; }, "camera.fovY", "must be in (0, 180), got 180"));
    EXPECT_TRUE(failsAt([](json& j) { j["camera"]["fovY"] = 0; }, "camera.fovY", "got 0"));
}

TEST(ProjectLoad, RejectsCameraTargetAtItsPosition) {
    EXPECT_TRUE(failsAt([](json& j) { j["camera"]["target"] = j["camera"]["position"]; }, "camera.target",
                        "must differ from the position [0, 1, 5]"));
}

TEST(ProjectLoad, RejectsUpParallelToViewDirection) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["camera"]["up"] = json::array({0, 0, -3});
        },
        "camera.up", "must not be parallel to the view direction"));
    EXPECT_TRUE(failsAt([](json& j) { j["camera"]["up"] = json::array({0, 0, 0}); }, "camera.up", "zero vector"));
}

TEST(ProjectLoad, RejectsUnknownTechnique) {
    EXPECT_TRUE(failsAt([](json& j) { j["views"][0]["technique"] = "no-such-technique-xyz"; }, "views[0].technique",
                        "unknown technique 'no-such-technique-xyz'"));
    EXPECT_TRUE(failsAt([](json& j) { j["views"][0]["technique"] = "project-tst"; }, "views[0].technique",
                        "did you mean 'project-test'?"));
}

TEST(ProjectLoad, RejectsTechniqueParametersThatTheTechniqueRefuses) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["views"][0]["parameters"] = json{{"spp", 0}};
        },
        "views[0].parameters.spp", "an integer in [1, 65536]"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["views"][0]["parameters"] = json{{"sigm", 1}};
        },
        "views[0].parameters.sigm", "did you mean 'sigma'?"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["views"][0]["parameters"] = json{{"jitter", "yes"}};
        },
        "views[0].parameters.jitter", "true or false"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["views"][0]["parameters"] = json{{"sampling", "equiangular"}};
        },
        "views[0].parameters.sampling", "one of mis, light, phase"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["views"][0]["parameters"] = json{{"tint", {{"r", 1}}}};
        },
        "views[0].parameters.tint", "must be a number, true/false, a string or [r, g, b]"));
    EXPECT_TRUE(failsAt([](json& j) { j["views"][0]["parameters"] = 3; }, "views[0].parameters", "must be an object"));
}

TEST(ProjectLoad, RejectsViewPartsNamingUnknownLightsOrMedia) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["views"][0]["lights"] = {"sn"};
            j["views"][0]["media"] = json::array();
        },
        "views[0].lights[0]", "unknown light 'sn'; did you mean 'sun'?"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["views"][0]["lights"] = json::array();
            j["views"][0]["media"] = {"fog", "smok"};
        },
        "views[0].media[1]", "unknown medium 'smok'; did you mean 'smoke'?"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["views"][0]["lights"] = {"sun", "sun"};
            j["views"][0]["media"] = json::array();
        },
        "views[0].lights[1]", "listed twice"));
    EXPECT_TRUE(failsAt([](json& j) { j["views"][0]["lights"] = {"sun"}; }, "views[0].media", "give both"));
}

TEST(ProjectLoad, RejectsViewExposureOutOfRange) {
    EXPECT_TRUE(failsAt([](json& j) { j["views"][0]["exposure"] = 21; }, "views[0].exposure", "[-20, 20]"));
}

TEST(ProjectLoad, RejectsReferenceSettingsOutOfRange) {
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["reference"] = json{{"mode", "many"}};
        },
        "reference.mode", "allowed: single, multiple"));
    EXPECT_TRUE(failsAt([](json& j) { j["reference"] = json{{"maxDepth", 0}}; }, "reference.maxDepth", "[1, 1024]"));
    EXPECT_TRUE(failsAt([](json& j) { j["reference"] = json{{"spp", 2000000}}; }, "reference.spp", "[1, 1048576]"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["reference"] = json{{"seed", -1}};
        },
        "reference.seed", "non-negative integer"));
}

TEST(ProjectLoad, RejectsInvalidParticles) {
    EXPECT_TRUE(failsAt([](json& j) { j["particleMedia"][0]["particles"][0]["scale"] = 0; },
                        "particleMedia[0].particles[0].scale", "must be > 0, got 0"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["particleMedia"][0]["particles"][0]["orientation"] = {0, 0, 0, 0};
        },
        "particleMedia[0].particles[0].orientation", "non-zero quaternion"));
    EXPECT_TRUE(failsAt([](json& j) { j["particleMedia"][0]["albedo"] = 2; }, "particleMedia[0].albedo", "[0, 1]"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["particleMedia"][0]["generator"] = json{{"multiplierMin", 5}, {"multiplierMax", 4}};
        },
        "particleMedia[0].generator.multiplierMax", "must be in [5, 1e+06], got 4"));
    EXPECT_TRUE(failsAt(
        [](json& j) {
            j["particleMedia"][0]["generator"] = json{{"count", 2000000}};
        },
        "particleMedia[0].generator.count", "[0, 1000000]"));
}

// ---------------------------------------------------------------------------------------------------------------------
// Overrides

TEST(ProjectOverrides, SetExistingValues) {
    const Project p = parse(baseDocument(), {"camera.fovY=50", "media[0].sigma_s=[0.2,0.2,0.3]",
                                             "lights[1].irradiance = 4", "views[0].parameters.spp=64"});
    EXPECT_EQ(p.scene.camera.fovY, 50.0);
    EXPECT_EQ(p.scene.media[0].sigma_s, Rgb(0.2, 0.2, 0.3));
    EXPECT_EQ(p.scene.directionalLights[0].irradiance, Rgb(4.0));
    EXPECT_EQ(p.views[0].parameters["spp"], 64);
}

TEST(ProjectOverrides, SelectElementsByName) {
    const Project p = parse(baseDocument(), {"lights[sun].irradiance=3.5", "lights[bulb].position[1]=4"});
    EXPECT_EQ(p.scene.directionalLights[0].irradiance, Rgb(3.5));
    EXPECT_EQ(p.scene.pointLights[0].position, Vec3(0.0, 4.0, 0.0));
}

TEST(ProjectOverrides, CreateKeysThatTakeDefaults) {
    json document = baseDocument();
    document.erase("camera");
    const Project p = parse(
        document, {"reference.spp=16", "camera.fovY=30", "media[fog].phase.a=0.25", "materials[steel].alphaX=0.5"});
    EXPECT_EQ(p.reference.spp, 16);
    EXPECT_EQ(p.scene.camera.fovY, 30.0);
    EXPECT_EQ(p.scene.media[0].phase.a, 0.25);
    EXPECT_EQ(p.scene.materials[1].alphaX, 0.5);
}

TEST(ProjectOverrides, TakeValuesThatAreNotJsonAsStrings) {
    const Project p = parse(baseDocument(), {"name=my scene", "views[main].parameters.sampling=light"});
    EXPECT_EQ(p.name, "my scene");
    EXPECT_EQ(p.views[0].parameters["sampling"], "light");
}

TEST(ProjectOverrides, AreValidatedLikeTheFile) {
    EXPECT_TRUE(failsAt(baseDocument(), "camera.fovY", "must be in (0, 180), got 500", {"camera.fovY=500"}));
    EXPECT_TRUE(failsAt(baseDocument(), "media[0].sigma_s", "got string \"nan\"", {"media[0].sigma_s=nan"}));
}

TEST(ProjectOverrides, RejectUnknownKeysWithSuggestion) {
    EXPECT_TRUE(failsAt(baseDocument(), "--set camera.fovy", "unknown key 'fovy' in 'camera'; did you mean 'fovY'?",
                        {"camera.fovy=50"}));
    EXPECT_TRUE(failsAt(baseDocument(), "--set media[0].sigma_S", "did you mean 'sigma_s'?", {"media[0].sigma_S=1"}));
    EXPECT_TRUE(
        failsAt(baseDocument(), "--set lights[bulb].radiance", "unknown key 'radiance'", {"lights[bulb].radiance=1"}));
    EXPECT_TRUE(failsAt(baseDocument(), "--set views[0].parameters.sp", "unknown parameter 'sp'",
                        {"views[0].parameters.sp=3"}));
}

TEST(ProjectOverrides, RejectMissingElements) {
    EXPECT_TRUE(failsAt(baseDocument(), "--set lights[7].name", "index 7 is out of range: 'lights' has 3 elements",
                        {"lights[7].name=x"}));
    EXPECT_TRUE(failsAt(baseDocument(), "--set lights[sn].irradiance",
                        "no element of 'lights' is named 'sn'; did you mean 'sun'?", {"lights[sn].irradiance=3"}));
    json document = baseDocument();
    document.erase("views");
    EXPECT_TRUE(failsAt(document, "--set views[0].exposure", "'views' is not in the project", {"views[0].exposure=1"}));
    EXPECT_TRUE(failsAt(baseDocument(), "--set camera[0]", "'camera' is not an array", {"camera[0]=1"}));
}

TEST(ProjectOverrides, AppendElementsWithPlus) {
    json document = baseDocument();
    document.erase("views");
    const Project p = parse(document, {R"(lights[+]={"type": "point", "name": "fill", "position": [0, 2, 0]})",
                                       "lights[fill].intensity=2",
                                       R"(views[+]={"name": "fill only", "technique": "reference", "lights": ["fill"], "media": []})"});
    ASSERT_EQ(p.scene.pointLights.size(), 2u);
    EXPECT_EQ(p.scene.pointLights[1].name, "fill");
    EXPECT_EQ(p.scene.pointLights[1].intensity, Rgb(2.0));
    ASSERT_EQ(p.views.size(), 1u);
    EXPECT_EQ(p.views[0].name, "fill only");
    // The appended element is validated like one in the file.
    EXPECT_TRUE(failsAt(baseDocument(), "lights[3].position", "", {R"(lights[+]={"type": "point", "name": "x", "position": 1})"}));
    EXPECT_TRUE(failsAt(baseDocument(), "--set lights[+].name", "must end the path", {"lights[+].name=x"}));
    EXPECT_TRUE(failsAt(baseDocument(), "--set camera[+]", "'camera' is not an array", {"camera[+]=1"}));
}

TEST(ProjectOverrides, RejectIndicesTooLargeForAnyArray) {
    EXPECT_TRUE(failsAt(baseDocument(), "--set lights[99999999999999999999999].name", "is too large",
                        {"lights[99999999999999999999999].name=x"}));
    // Leading zeros do not count toward the digits.
    EXPECT_EQ(parse(baseDocument(), {"lights[0000000000000000000001].irradiance=4"}).scene.directionalLights[0].irradiance,
              Rgb(4.0));
}

TEST(ProjectOverrides, RejectMalformedOverrides) {
    EXPECT_TRUE(failsAt(baseDocument(), "--set camera.fovY", "expected path=value", {"camera.fovY"}));
    EXPECT_TRUE(failsAt(baseDocument(), "--set lights[0.name", "without a matching ']'", {"lights[0.name=x"}));
    EXPECT_TRUE(failsAt(baseDocument(), "--set camera..fovY", "empty key", {"camera..fovY=3"}));
    EXPECT_TRUE(failsAt(baseDocument(), "--set [0]", "must start with a key", {"[0]=3"}));
}

// ---------------------------------------------------------------------------------------------------------------------
// Saving

TEST(ProjectSave, RoundTripIsByteIdentical) {
    const fs::path dir = testDir();
    writeText(dir / "scene.json", kFullProject);
    saveProject(loadProject(techniqueCatalogue(), (dir / "scene.json").string()), (dir / "first.json").string());
    saveProject(loadProject(techniqueCatalogue(), (dir / "first.json").string()), (dir / "second.json").string());
    const std::string first = readText(dir / "first.json");
    EXPECT_EQ(first, readText(dir / "second.json"));
    EXPECT_EQ(first.rfind("{\n  \"tyndall\": 1,\n  \"name\": \"full\",\n  \"camera\": {", 0), 0u) << first;
}

TEST(ProjectSave, WritesLightsGroupedByType) {
    const Project p = parseProject(techniqueCatalogue(), kFullProject, projectPath());
    const json saved = projectToJson(p);
    std::vector<std::string> names;
    for (const json& light : saved["lights"])
        names.push_back(light["name"]);
    EXPECT_EQ(names, (std::vector<std::string>{"bulb", "spot", "lobe", "sun", "panel"}));
    EXPECT_EQ(projectToJson(projectFromJson(techniqueCatalogue(), saved, projectPath())), saved);
}

TEST(ProjectSave, RoundTripKeepsFieldsThatDoNotApplyToTheType) {
    Project p;
    p.name = "structural";
    HomogeneousMedium medium;
    medium.name = "m";
    medium.phase.g = 0.3;  // ignored by an isotropic phase function, but kept
    medium.box.size = Vec3(2.0, 3.0, 4.0);
    medium.planes = {HalfSpace{Vec3(0.0, 0.0, 1.0), 2.0}};
    p.scene.media.push_back(medium);
    PointLight light;
    light.name = "l";
    light.distribution.axis = Vec3(1.0, 0.0, 0.0);
    light.distribution.spotExponent = 3.0;
    p.scene.pointLights.push_back(light);
    Material material;
    material.name = "mat";
    material.f0 = Rgb(0.9);
    material.alphaX = 0.1;
    p.scene.materials.push_back(material);
    Mesh mesh;
    mesh.name = "mesh";
    mesh.material = "mat";
    mesh.subdivisions = 16;
    p.scene.meshes.push_back(mesh);
    View view;
    view.name = "v";
    view.technique = "project-test";
    view.parameters = json{{"sigma", 2.5}};
    view.part = ScenePart{{"l"}, {}};
    p.views.push_back(view);
    p.reference.seed = 0xFFFFFFFFFFFFFFFFull;

    const json saved = projectToJson(p);
    const Project loaded = projectFromJson(techniqueCatalogue(), saved, projectPath());
    EXPECT_EQ(projectToJson(loaded), saved);
    EXPECT_EQ(loaded.scene.media[0].phase.g, 0.3);
    EXPECT_EQ(loaded.scene.media[0].box.size, Vec3(2.0, 3.0, 4.0));
    EXPECT_EQ(loaded.scene.pointLights[0].distribution.spotExponent, 3.0);
    EXPECT_EQ(loaded.scene.materials[0].alphaY, 0.3);
    EXPECT_EQ(loaded.scene.meshes[0].subdivisions, 16);
    EXPECT_EQ(loaded.reference.seed, 0xFFFFFFFFFFFFFFFFull);
    EXPECT_FALSE(saved["media"][0]["phase"].contains("a")) << "defaults that do not apply are not written";
}

TEST(ProjectSave, DoublesRoundTripExactly) {
    Project p;
    HomogeneousMedium medium;
    medium.name = "m";
    medium.sigma_s = Rgb(0.1 + 0.2, 1e-300, 123456.789123456789);
    medium.sigma_a = Rgb(std::nextafter(1.0, 2.0), 5e-324, std::nextafter(1e6, 0.0));  // up to kMaxCoefficient
    p.scene.media.push_back(medium);
    const fs::path path = testDir() / "doubles.json";
    saveProject(p, path.string());
    const std::string text = readText(path);
    const Project loaded = loadProject(techniqueCatalogue(), path.string());
    EXPECT_EQ(loaded.scene.media[0].sigma_s, medium.sigma_s);
    EXPECT_EQ(loaded.scene.media[0].sigma_a, medium.sigma_a);
    saveProject(loaded, path.string());
    EXPECT_EQ(readText(path), text);
}

TEST(ProjectSave, ReplacesAnExistingFile) {
    const fs::path path = testDir() / "replace.json";
    writeText(path, "old");
    saveProject(parseProject(techniqueCatalogue(), R"({"tyndall": 1, "name": "new"})", path.string()), path.string());
    EXPECT_EQ(loadProject(techniqueCatalogue(), path.string()).name, "new");
}

TEST(ProjectSave, FailsIntoAMissingFolderAndLeavesNothing) {
    const fs::path dir = testDir() / "missing-folder";
    fs::remove_all(dir);
    const Project p = parseProject(techniqueCatalogue(), R"({"tyndall": 1})", "x.json");
    try {
        saveProject(p, (dir / "scene.json").string());
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().file, (dir / "scene.json").string());
        EXPECT_NE(e.message().find("cannot save"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir));
}

TEST(ProjectSave, FailsOntoAFolderAndRemovesTheTemporaryFile) {
    const fs::path dir = testDir() / "rename-fails";
    fs::remove_all(dir);
    fs::create_directories(dir / "scene.json");  // a folder where the file should go: rename fails
    EXPECT_THROW(
        saveProject(parseProject(techniqueCatalogue(), R"({"tyndall": 1})", "x.json"), (dir / "scene.json").string()),
        InputError);
    EXPECT_EQ(filesIn(dir), std::vector<std::string>{"scene.json"});
    EXPECT_TRUE(fs::is_directory(dir / "scene.json"));
}

TEST(ProjectSave, FailsIntoAReadOnlyFolderAndLeavesNothing) {
    if (::geteuid() == 0) GTEST_SKIP() << "root may write into read-only folders";
    const fs::path dir = testDir() / "read-only";
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_THROW(
        saveProject(parseProject(techniqueCatalogue(), R"({"tyndall": 1})", "x.json"), (dir / "scene.json").string()),
        InputError);
    fs::permissions(dir, fs::perms::owner_all);
    EXPECT_TRUE(filesIn(dir).empty());
}

// ---------------------------------------------------------------------------------------------------------------------
// Hash and parts

TEST(ProjectHash, IsStableAndChangesWithTheProject) {
    Project p = parseProject(techniqueCatalogue(), kFullProject, projectPath());
    const std::string hash = projectHash(p);
    EXPECT_EQ(hash.size(), 16u);
    EXPECT_EQ(hash.find_first_not_of("0123456789abcdef"), std::string::npos);
    EXPECT_EQ(projectHash(parseProject(techniqueCatalogue(), kFullProject, projectPath())), hash);
    p.scene.media[0].sigma_s.x += 1e-9;
    EXPECT_NE(projectHash(p), hash);
    EXPECT_EQ(projectHash(Project{}), "75e01861a580af2f") << "FNV-1a of the default project's JSON must not drift";
}

TEST(ProjectResolvePart, UsesTheViewsPartOrTheTechniquesDefault) {
    const Project p = parseProject(techniqueCatalogue(), kFullProject, projectPath());
    const ScenePart explicitPart = resolvePart(techniqueCatalogue(), p, p.views[1]);
    EXPECT_EQ(explicitPart.lights, std::vector<std::string>{"sun"});
    const ScenePart defaultPart = resolvePart(techniqueCatalogue(), p, p.views[0]);
    EXPECT_EQ(defaultPart.lights, (std::vector<std::string>{"bulb", "spot", "lobe", "sun", "panel"}));
    EXPECT_EQ(defaultPart.media, (std::vector<std::string>{"haze", "slab", "prism"})) << "no particle media";
}

// The default project's first screen is a comparison (issue 19): no view renders exactly what its reference renders
// (the same technique with the same parameters, seed and samples would show relMSE 0 and an infinite PSNR).
TEST(DefaultProject, NoViewIsItsOwnReference) {
    const std::string path = std::string(TYNDALL_SOURCE_DIR) + "/projects/default.json";
    const Project project = loadProject(techniqueCatalogue(), path);
    ASSERT_EQ(project.views.size(), 4u);
    for (const View& view : project.views) {
        SCOPED_TRACE(view.name);
        const RenderJob job = makeViewJob(project, path, view.name);
        const RenderJob reference = makeReferenceJob(project, path, view.name);
        // A request's spp 0 means the technique's default (the path tracer's 64, as the reference's here).
        const auto sppOf = [](const RenderJob& j) {
            return j.request.spp > 0 ? j.request.spp : j.technique->name() == "reference" ? ReferenceTechnique::kDefaultSpp : 0;
        };
        const bool same = job.technique->name() == reference.technique->name() &&
                          job.request.params.values() == reference.request.params.values() &&
                          job.request.seed == reference.request.seed && sppOf(job) == sppOf(reference);
        EXPECT_FALSE(same);
    }
}

}  // namespace
}  // namespace tyndall

// A few non-finite samples (a numerical corner) are a warning; more than kMaxNonFiniteFraction of the samples fail the
// render, so that an image whose samples overflowed is never written as if it were a render (issue 21, item 9).
TEST(RenderResultChecks, NonFiniteSamplesWarnOrFail) {
    tyndall::RenderResult result;
    result.image = tyndall::Image::rgb(100, 10);
    result.spp = 10;  // 10 000 samples
    EXPECT_EQ(tyndall::checkFiniteSamples(result), "");
    result.image.metadata["nonFiniteSamples"] = "0";
    EXPECT_EQ(tyndall::checkFiniteSamples(result), "");
    result.image.metadata["nonFiniteSamples"] = "10";  // exactly 0.1 %
    EXPECT_NE(tyndall::checkFiniteSamples(result).find("10 samples (0.1 %) were not finite"), std::string::npos);
    result.image.metadata["nonFiniteSamples"] = "11";
    EXPECT_THROW(tyndall::checkFiniteSamples(result), std::runtime_error);
    result.image.metadata["nonFiniteSamples"] = "10000";
    try {
        tyndall::checkFiniteSamples(result);
        FAIL() << "every sample non-finite must fail";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("nothing was written"), std::string::npos) << e.what();
    }
}
