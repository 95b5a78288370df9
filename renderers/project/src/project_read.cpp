// projectFromJson: reads and validates a project's JSON. Every rule is a small named function that fails at the field
// it checks, with the value found and what is allowed (docs/project-format.md lists the same rules).
#include "project_internal.h"

#include "tyndall/core/geometry.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>

namespace tyndall {

namespace {

using K = ObjectKind;

constexpr double kUnitLengthTolerance = 1e-12;
constexpr std::size_t kMaxPolynomialTerms = 32;
constexpr int kMaxSpotExponent = 256;
constexpr int kMaxImageSize = 16384;
constexpr int kMaxParticleCount = 1'000'000;         // per generator
constexpr int kMaxSimulationSteps = 100'000;
constexpr int kMaxSimulationImpulses = 1000;
constexpr double kMaxSimulationSpeed = 1000.0;       // m/s
constexpr double kMaxSimulationWork = 2e8;           // steps times particles
constexpr std::size_t kMaxTotalParticles = 2'000'000;  // in all particle media together
constexpr double kMaxExposure = 20.0;  // EV stops either way
constexpr double kMinRoughness = 1e-3;
constexpr double kNonNegativeTolerance = 1e-9;  // relative to the sum of |coefficients|
constexpr double kParallelTolerance = 1e-6;     // |sin| of the angle between two directions
constexpr double kMinCameraDistance = 1e-6;     // m, and relative to the camera's distance from the origin

struct ReadContext {
    std::string file;
    std::filesystem::path projectDir;
};

template <typename F>
void forEachElement(const JsonField& array, F&& read) {
    if (!array.present()) return;
    const std::size_t n = array.arraySize();
    for (std::size_t i = 0; i < n; ++i)
        read(array[i]);
}

// ---------------------------------------------------------------------------------------------------------------------
// Generic rules

std::string readName(const JsonField& object) {
    const JsonField field = object["name"];
    const std::string& name = field.string();
    if (name.empty()) field.fail("must not be empty");
    return name;
}

// Unit length, without touching vectors that are unit length to within rounding: re-normalising a normalised vector
// may change its last bits, and then loading and saving a file would not be a fixed point.
double lengthToNormalise(const JsonField& field, const Vec3& v) {
    requireNonZero(field, v);
    const double length = glm::length(v);
    if (!std::isfinite(length)) field.fail("is too long to normalise: " + formatVec3(v));
    return std::abs(length - 1.0) <= kUnitLengthTolerance ? 1.0 : length;
}

Vec3 readDirection(const JsonField& field, const Vec3& fallback) {
    const Vec3 v = field.vec3Or(fallback);
    return v / lengthToNormalise(field, v);
}

// A position in world space, within +-kMaxWorldCoordinate (geometry.h) so that every renderer stays in finite numbers.
void requireInWorld(const JsonField& field, const Vec3& p, double radius = 0.0) {
    const double extent = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) + radius;
    if (!(extent <= kMaxWorldCoordinate)) {
        field.fail("reaches " + formatNumber(extent) + " m from the origin along an axis; world coordinates are limited to +-" +
                   formatNumber(kMaxWorldCoordinate) + " m");
    }
}

Vec3 readPoint(const JsonField& field, const Vec3& fallback) {
    const Vec3 p = field.vec3Or(fallback);
    requireInWorld(field, p);
    return p;
}

std::vector<std::string> readStringList(const JsonField& field) {
    std::vector<std::string> strings;
    forEachElement(field, [&](const JsonField& element) { strings.push_back(element.string()); });
    return strings;
}

// Names must be unique within a group (lights; media and particle media; materials; meshes; views).
class UniqueNames {
public:
    UniqueNames(const char* singular, const char* plural) : singular_(singular), plural_(plural) {}

    void add(const JsonField& object, const std::string& name) {
        const auto [it, inserted] = paths_.emplace(name, object.path());
        if (!inserted) {
            object["name"].fail(std::string("duplicate ") + singular_ + " name '" + clipForMessage(name) + "' (also " + it->second +
                                ")");
        }
        names_.push_back(name);
    }
    bool contains(const std::string& name) const { return paths_.count(name) != 0; }
    const std::vector<std::string>& names() const { return names_; }
    const char* singular() const { return singular_; }
    const char* plural() const { return plural_; }

private:
    const char* singular_;
    const char* plural_;
    std::map<std::string, std::string> paths_;
    std::vector<std::string> names_;
};

void requireKnownName(const JsonField& field, const std::string& name, const UniqueNames& known) {
    if (known.contains(name)) return;
    std::string message = std::string("unknown ") + known.singular() + " '" + clipForMessage(name) + "'";
    const std::string nearest = nearestName(name, known.names());
    if (!nearest.empty()) {
        message += "; did you mean '" + nearest + "'?";
    } else if (known.names().empty()) {
        message += std::string("; the project has no ") + known.plural();
    }
    field.fail(message);
}

// ---------------------------------------------------------------------------------------------------------------------
// Functions of cos(theta) on [-1, 1] that must not be negative

struct Minimum {
    double value = 0.0;
    double at = 0.0;
};

// 4097 uniform points and 1024 Chebyshev nodes, which crowd towards +-1 where high-order terms swing most.
const std::vector<double>& unitIntervalSamples() {
    static const std::vector<double> samples = [] {
        constexpr int kUniform = 4097, kChebyshev = 1024;
        std::vector<double> x;
        for (int i = 0; i < kUniform; ++i)
            x.push_back(-1.0 + 2.0 * i / (kUniform - 1));
        for (int k = 0; k < kChebyshev; ++k)
            x.push_back(std::cos((2.0 * k + 1.0) * std::numbers::pi / (2.0 * kChebyshev)));
        return x;
    }();
    return samples;
}

template <typename F>
Minimum minimumOverUnitInterval(F&& f) {
    Minimum m{f(-1.0), -1.0};
    for (double x : unitIntervalSamples()) {
        const double y = f(x);
        if (y < m.value) m = {y, x};
    }
    return m;
}

double polynomialAt(const std::vector<double>& c, double mu) {
    double sum = 0.0;
    for (auto it = c.rbegin(); it != c.rend(); ++it)
        sum = sum * mu + *it;
    return sum;
}

// sum_n a_n P_n(x), with Bonnet's recursion (n + 1) P_{n+1} = (2n + 1) x P_n - n P_{n-1}.
double legendreSeriesAt(const std::vector<double>& a, double x) {
    double previous = 1.0, current = x, sum = a.empty() ? 0.0 : a[0];
    for (std::size_t n = 1; n < a.size(); ++n) {
        sum += a[n] * current;
        const double next = ((2.0 * n + 1.0) * x * current - n * previous) / (n + 1.0);
        previous = current;
        current = next;
    }
    return sum;
}

double absoluteSum(const std::vector<double>& c) {
    double sum = 0.0;
    for (double x : c)
        sum += std::abs(x);
    return sum;
}

void requireNonNegativeOnUnitInterval(const JsonField& field, const Minimum& m, double scale, const char* what) {
    if (m.value >= -kNonNegativeTolerance * scale) return;
    field.fail(std::string(what) + " must be >= 0 for every cos in [-1, 1]; it is " + formatNumber(m.value) +
               " at cos = " + formatNumber(m.at));
}

void requireAtMostTerms(const JsonField& field, const std::vector<double>& c) {
    if (c.size() > kMaxPolynomialTerms) {
        field.fail("at most " + std::to_string(kMaxPolynomialTerms) + " coefficients, got " + std::to_string(c.size()));
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Media

void requireValidLegendre(const JsonField& field, const std::vector<double>& a) {
    if (a.empty()) field.fail("a legendre phase function needs coefficients, starting with a_0 = 1");
    if (a[0] != 1.0) field[0].fail("a_0 must be 1 (the normalisation), got " + formatNumber(a[0]));
    const Minimum m = minimumOverUnitInterval([&](double x) { return legendreSeriesAt(a, x); });
    requireNonNegativeOnUnitInterval(field, m, absoluteSum(a), "the phase function");
}

PhaseFunction readPhase(const JsonField& f) {
    PhaseFunction phase;
    if (!f.present()) return phase;
    f.expectObject(keyNames(K::Phase));
    if (f["type"].present()) phase.kind = readEnum(f["type"], kPhaseKindNames);
    phase.g = f["g"].numberOr(phase.g);
    requireInOpenRange(f["g"], phase.g, -1.0, 1.0);
    phase.a = f["a"].numberOr(phase.a);
    requireInRange(f["a"], phase.a, 0.0, 1.0);
    phase.b = f["b"].numberOr(phase.b);
    requireInRange(f["b"], phase.b, -1.0, 1.0);
    phase.legendre = f["coefficients"].numbersOr({});
    requireAtMostTerms(f["coefficients"], phase.legendre);
    if (phase.kind == PhaseKind::Legendre) requireValidLegendre(f["coefficients"], phase.legendre);
    return phase;
}

OrientedBox readBox(const JsonField& f) {
    OrientedBox box;
    if (!f.present()) return box;
    f.expectObject(keyNames(K::Box));
    box.centre = readPoint(f["centre"], box.centre);
    box.size = f["size"].vec3Or(box.size);
    requireEachAbove(f["size"], box.size, 0.0);
    requireInWorld(f["size"], box.centre, 0.5 * glm::length(box.size));  // the box's corners, however rotated
    box.rotate = f["rotate"].vec3Or(box.rotate);
    return box;
}

HalfSpace readPlane(const JsonField& f) {
    f.expectObject(keyNames(K::Plane));
    HalfSpace plane;
    const Vec3 normal = f["normal"].vec3Or(plane.normal);
    const double length = lengthToNormalise(f["normal"], normal);
    plane.normal = normal / length;
    plane.offset = f["offset"].numberOr(plane.offset) / length;
    return plane;
}

void requireBoundedPolyhedron(const JsonField& field, const std::vector<HalfSpace>& planes) {
    if (planes.size() < 4) {
        field.fail("a polyhedron needs at least 4 planes, got " + std::to_string(planes.size()));
    }
    try {
        makeConvexPolyhedron(planes);
    } catch (const InputError& e) {
        field.fail(e.message());
    }
}

// Either sigma_s and sigma_a, or albedo and extinction (sigma_s = albedo * extinction, sigma_a = extinction - sigma_s).
void readCoefficients(const JsonField& f, HomogeneousMedium& medium) {
    const JsonField albedo = f["albedo"], extinction = f["extinction"];
    const bool albedoForm = albedo.present() || extinction.present();
    if (!albedoForm) {
        medium.sigma_s = f["sigma_s"].rgbOr(medium.sigma_s);
        requireEachInRange(f["sigma_s"], medium.sigma_s, 0.0, kMaxCoefficient);
        medium.sigma_a = f["sigma_a"].rgbOr(medium.sigma_a);
        requireEachInRange(f["sigma_a"], medium.sigma_a, 0.0, kMaxCoefficient);
        return;
    }
    const JsonField& given = albedo.present() ? albedo : extinction;
    if (f["sigma_s"].present() || f["sigma_a"].present()) {
        given.fail("give either 'sigma_s' and 'sigma_a', or 'albedo' and 'extinction', not both forms");
    }
    if (!albedo.present()) albedo.fail("is required together with 'extinction'");
    if (!extinction.present()) extinction.fail("is required together with 'albedo'");
    const Rgb rho = albedo.rgb(), sigma_t = extinction.rgb();
    requireEachInRange(albedo, rho, 0.0, 1.0);
    requireEachInRange(extinction, sigma_t, 0.0, kMaxCoefficient);
    medium.sigma_s = rho * sigma_t;
    medium.sigma_a = sigma_t - medium.sigma_s;
}

HomogeneousMedium readMedium(const JsonField& f) {
    f.expectObject(keyNames(K::Medium));
    HomogeneousMedium medium;
    medium.name = readName(f);
    readCoefficients(f, medium);
    medium.phase = readPhase(f["phase"]);
    if (f["shape"].present()) medium.shape = readEnum(f["shape"], kMediumShapeNames);
    medium.box = readBox(f["box"]);
    forEachElement(f["planes"], [&](const JsonField& plane) { medium.planes.push_back(readPlane(plane)); });
    if (medium.shape == MediumShape::ConvexPolyhedron) requireBoundedPolyhedron(f["planes"], medium.planes);
    // A box is a polyhedron of six planes to every renderer: what they would refuse is refused here, by its field.
    if (medium.shape == MediumShape::Box) {
        if (glm::length(medium.box.size) < kMinPolygonSize)
            f["box"]["size"].fail("the box is " + formatNumber(glm::length(medium.box.size)) +
                                  " m across (its diagonal); the smallest allowed is " + formatNumber(kMinPolygonSize) +
                                  " m");
        try {
            makeConvexPolyhedron(boxHalfSpaces(medium.box));
        } catch (const InputError& e) {
            f["box"].fail(e.message());
        }
    }
    return medium;
}

glm::dquat readOrientation(const JsonField& field, const glm::dquat& fallback) {
    if (!field.present()) return fallback;
    const std::vector<double> wxyz = field.numbers();
    if (wxyz.size() != 4) field.fail("must be a quaternion [w, x, y, z], got " + describeJson(field.json()));
    const glm::dquat q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
    const double length = glm::length(q);
    if (length == 0.0 || !std::isfinite(length)) field.fail("must be a non-zero quaternion");
    return std::abs(length - 1.0) <= kUnitLengthTolerance ? q : q / length;
}

Particle readParticle(const JsonField& f) {
    f.expectObject(keyNames(K::Particle));
    Particle p;
    p.centre = readPoint(f["centre"], p.centre);
    p.scale = f["scale"].numberOr(p.scale);
    requireAbove(f["scale"], p.scale, 0.0);
    requireInWorld(f["scale"], p.centre, p.scale);
    p.orientation = readOrientation(f["orientation"], p.orientation);
    p.extinctionMultiplier = f["extinctionMultiplier"].numberOr(p.extinctionMultiplier);
    requireInRange(f["extinctionMultiplier"], p.extinctionMultiplier, 0.0, kMaxCoefficient);
    p.falloff = f["falloff"].numberOr(p.falloff);
    requireAbove(f["falloff"], p.falloff, 0.0);
    return p;
}

ParticleGenerator readGenerator(const JsonField& f) {
    f.expectObject(keyNames(K::Generator));
    ParticleGenerator g;
    g.count = f["count"].intInRangeOr(g.count, 0, kMaxParticleCount);
    g.seed = f["seed"].unsignedIntegerOr(g.seed);
    g.region = readBox(f["region"]);
    if (std::min({g.region.size.x, g.region.size.y, g.region.size.z}) < kMinPolygonSize)
        f["region"]["size"].fail("each side must be at least " + formatNumber(kMinPolygonSize) +
                                 " m (the smallest size the format allows, as for polygons), got " +
                                 formatVec3(g.region.size));
    g.scale = f["scale"].numberOr(g.scale);
    requireAbove(f["scale"], g.scale, 0.0);
    requireInWorld(f["scale"], g.region.centre, 0.5 * glm::length(g.region.size) + g.scale);
    g.falloff = f["falloff"].numberOr(g.falloff);
    requireAbove(f["falloff"], g.falloff, 0.0);
    g.multiplierMin = f["multiplierMin"].numberOr(g.multiplierMin);
    requireAtLeast(f["multiplierMin"], g.multiplierMin, 0.0);
    g.multiplierMax = f["multiplierMax"].numberOr(g.multiplierMax);
    requireInRange(f["multiplierMax"], g.multiplierMax, g.multiplierMin, kMaxCoefficient);
    return g;
}

ParticleImpulse readImpulse(const JsonField& f, int steps) {
    f.expectObject(keyNames(K::Impulse));
    ParticleImpulse impulse;
    impulse.step = f["step"].intInRangeOr(impulse.step, 0, std::max(steps - 1, 0));
    impulse.position = readPoint(f["position"], impulse.position);
    impulse.radius = f["radius"].numberOr(impulse.radius);
    requireAbove(f["radius"], impulse.radius, 0.0);
    requireInWorld(f["radius"], impulse.position, impulse.radius);
    impulse.speed = f["speed"].numberOr(impulse.speed);
    requireAtLeast(f["speed"], impulse.speed, 0.0);
    if (impulse.speed > kMaxSimulationSpeed)
        f["speed"].fail("must be at most " + formatNumber(kMaxSimulationSpeed) + " m/s, got " + formatNumber(impulse.speed));
    return impulse;
}

ParticleSimulation readSimulation(const JsonField& f) {
    f.expectObject(keyNames(K::Simulation));
    ParticleSimulation sim;
    sim.steps = f["steps"].intInRangeOr(sim.steps, 0, kMaxSimulationSteps);
    sim.timeStep = f["timeStep"].numberOr(sim.timeStep);
    requireAbove(f["timeStep"], sim.timeStep, 0.0);
    if (sim.timeStep > 1.0) f["timeStep"].fail("must be in (0, 1] s, got " + formatNumber(sim.timeStep));
    sim.stiffness = f["stiffness"].numberOr(sim.stiffness);
    requireAtLeast(f["stiffness"], sim.stiffness, 0.0);
    sim.viscosity = f["viscosity"].numberOr(sim.viscosity);
    requireAtLeast(f["viscosity"], sim.viscosity, 0.0);
    // Semi-implicit Euler stays bounded for a damped spring while (stiffness dt^2 + 2 viscosity dt) <= 4.
    if (sim.stiffness * sim.timeStep * sim.timeStep + 2.0 * sim.viscosity * sim.timeStep > 4.0)
        f["timeStep"].fail("is too long for this stiffness and viscosity: stiffness * timeStep^2 + 2 * viscosity * "
                           "timeStep must be at most 4 (the simulation would blow up), got " +
                           formatNumber(sim.stiffness * sim.timeStep * sim.timeStep + 2.0 * sim.viscosity * sim.timeStep));
    sim.offset = f["offset"].vec3Or(sim.offset);
    requireInWorld(f["offset"], sim.offset, 0.0);
    forEachElement(f["impulses"], [&](const JsonField& i) { sim.impulses.push_back(readImpulse(i, sim.steps)); });
    if (sim.impulses.size() > std::size_t(kMaxSimulationImpulses))
        f["impulses"].fail("at most " + std::to_string(kMaxSimulationImpulses) + " impulses, got " +
                           std::to_string(sim.impulses.size()));
    return sim;
}

ParticleMedium readParticleMedium(const JsonField& f) {
    f.expectObject(keyNames(K::ParticleMedium));
    ParticleMedium medium;
    medium.name = readName(f);
    medium.extinction = f["extinction"].rgbOr(medium.extinction);
    requireEachInRange(f["extinction"], medium.extinction, 0.0, kMaxCoefficient);
    medium.albedo = f["albedo"].rgbOr(medium.albedo);
    requireEachInRange(f["albedo"], medium.albedo, 0.0, 1.0);
    medium.phase = readPhase(f["phase"]);
    forEachElement(f["particles"], [&](const JsonField& p) { medium.particles.push_back(readParticle(p)); });
    if (f["generator"].present()) medium.generator = readGenerator(f["generator"]);
    if (f["simulation"].present()) {
        medium.simulation = readSimulation(f["simulation"]);
        const double work = double(medium.simulation->steps) *
                            double(medium.particles.size() + (medium.generator ? medium.generator->count : 0));
        if (work > kMaxSimulationWork)
            f["simulation"]["steps"].fail("steps times particles must be at most " + formatNumber(kMaxSimulationWork) +
                                          " (the simulation runs before every render), got " + formatNumber(work));
    }
    return medium;
}

// ---------------------------------------------------------------------------------------------------------------------
// Lights

void requireSpotExponent(const JsonField& field, double n) {
    if (n >= 0.0 && n <= kMaxSpotExponent && n == std::floor(n)) return;
    field.fail("must be an integer in [0, " + std::to_string(kMaxSpotExponent) + "], got " + formatNumber(n));
}

void requireValidPolynomial(const JsonField& field, const std::vector<double>& c) {
    if (c.empty()) field.fail("a polynomial distribution needs at least one coefficient");
    const Minimum m = minimumOverUnitInterval([&](double mu) { return polynomialAt(c, mu); });
    requireNonNegativeOnUnitInterval(field, m, absoluteSum(c), "the distribution");
}

AngularDistribution readDistribution(const JsonField& f) {
    AngularDistribution d;
    if (!f.present()) return d;
    f.expectObject(keyNames(K::Distribution));
    if (f["type"].present()) d.kind = readEnum(f["type"], kDistributionNames);
    d.axisAsWritten = f["axis"].vec3Or(d.axis);
    d.axis = readDirection(f["axis"], d.axis);
    d.spotExponent = f["exponent"].numberOr(d.spotExponent);
    requireSpotExponent(f["exponent"], d.spotExponent);
    d.coefficients = f["coefficients"].numbersOr({});
    requireAtMostTerms(f["coefficients"], d.coefficients);
    for (std::size_t k = 0; k < d.coefficients.size(); ++k)
        requireInRange(f["coefficients"][k], d.coefficients[k], -kMaxRadiometric, kMaxRadiometric);
    if (d.kind == AngularDistribution::Kind::Polynomial) requireValidPolynomial(f["coefficients"], d.coefficients);
    if (d.kind == AngularDistribution::Kind::Legendre)
        requireValidPolynomial(f["coefficients"], legendreToMonomial(d.coefficients));
    return d;
}

void requireValidPolygon(const JsonField& field, const std::vector<Vec3>& vertices) {
    const std::string problem = polygonProblem(vertices);
    if (!problem.empty()) field.fail(problem);
}

PointLight readPointLight(const JsonField& f) {
    PointLight light;
    light.name = readName(f);
    light.position = readPoint(f["position"], light.position);
    light.intensity = f["intensity"].rgbOr(light.intensity);
    requireEachInRange(f["intensity"], light.intensity, 0.0, kMaxRadiometric);
    light.distribution = readDistribution(f["distribution"]);
    // The radiometric limit holds for the light's brightest direction: its intensity times the distribution's peak,
    // so that every renderer (in float on the GPU) stays finite.
    const std::vector<double> c = light.distribution.polynomial();
    const Minimum lowestNegated = minimumOverUnitInterval([&](double mu) { return -polynomialAt(c, mu); });
    const double peak = -lowestNegated.value;
    const double brightest = std::max({light.intensity.r, light.intensity.g, light.intensity.b}) * peak;
    if (!(brightest <= kMaxRadiometric)) {
        f["distribution"]["coefficients"].fail(
            "the light's peak intensity (its intensity times the distribution's largest value, " + formatNumber(peak) +
            " at cos = " + formatNumber(lowestNegated.at) + ") must be at most " + formatNumber(kMaxRadiometric) +
            " W/sr, got " + formatNumber(brightest));
    }
    return light;
}

// The beam is the prism swept by the gobo along the direction, so the gobo's plane must not contain the direction.
void requireGoboAcrossBeam(const JsonField& field, const std::vector<Vec3>& gobo, const Vec3& direction) {
    if (std::abs(glm::dot(polygonNormal(gobo), direction)) <= kParallelTolerance) {
        field.fail("the gobo's plane contains the light direction " + formatVec3(direction) + ", so the beam is empty");
    }
}

DirectionalLight readDirectionalLight(const JsonField& f) {
    DirectionalLight light;
    light.name = readName(f);
    light.directionAsWritten = f["direction"].vec3Or(light.direction);
    light.direction = readDirection(f["direction"], light.direction);
    light.irradiance = f["irradiance"].rgbOr(light.irradiance);
    requireEachInRange(f["irradiance"], light.irradiance, 0.0, kMaxRadiometric);
    if (f["gobo"].present()) {
        light.gobo = f["gobo"].vec3s();
        requireValidPolygon(f["gobo"], light.gobo);
        requireGoboAcrossBeam(f["gobo"], light.gobo, light.direction);
    }
    return light;
}

AreaLight readAreaLight(const JsonField& f) {
    AreaLight light;
    light.name = readName(f);
    light.vertices = f["vertices"].vec3s();
    requireValidPolygon(f["vertices"], light.vertices);
    light.radiance = f["radiance"].rgbOr(light.radiance);
    requireEachInRange(f["radiance"], light.radiance, 0.0, kMaxRadiometric);
    light.twoSided = f["twoSided"].booleanOr(light.twoSided);
    return light;
}

// A key that belongs to another type of light gets a clearer message than "unknown key".
void requireKeysOfLightType(const JsonField& f, ObjectKind kind, const std::string& type) {
    const std::vector<std::string> allowed = keyNames(kind);
    for (const auto& [key, value] : f.json().items()) {
        if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
            f[key].fail("'" + key + "' does not apply to a " + type + " light");
        }
    }
}

void readLight(const JsonField& f, Scene& scene) {
    f.expectObject(keyNames(K::Light));
    const std::string type = requireOneOf(f["type"], {std::begin(kLightTypes), std::end(kLightTypes)});
    const ObjectKind kind = lightKind(f.json());
    requireKeysOfLightType(f, kind, type);
    if (kind == K::PointLight) scene.pointLights.push_back(readPointLight(f));
    if (kind == K::DirectionalLight) scene.directionalLights.push_back(readDirectionalLight(f));
    if (kind == K::AreaLight) scene.areaLights.push_back(readAreaLight(f));
}

// ---------------------------------------------------------------------------------------------------------------------
// Surfaces

void readRoughness(const JsonField& f, Material& material) {
    const JsonField alpha = f["alpha"];
    if (alpha.present() && (f["alphaX"].present() || f["alphaY"].present())) {
        alpha.fail("give 'alpha' (isotropic) or 'alphaX' and 'alphaY', not both");
    }
    if (alpha.present()) {
        material.alphaX = material.alphaY = alpha.number();
        requireInRange(alpha, material.alphaX, kMinRoughness, 1.0);
        return;
    }
    material.alphaX = f["alphaX"].numberOr(material.alphaX);
    requireInRange(f["alphaX"], material.alphaX, kMinRoughness, 1.0);
    material.alphaY = f["alphaY"].numberOr(material.alphaY);
    requireInRange(f["alphaY"], material.alphaY, kMinRoughness, 1.0);
}

Material readMaterial(const JsonField& f) {
    f.expectObject(keyNames(K::Material));
    Material material;
    material.name = readName(f);
    if (f["type"].present()) material.kind = readEnum(f["type"], kMaterialKindNames);
    material.albedo = f["albedo"].rgbOr(material.albedo);
    requireEachInRange(f["albedo"], material.albedo, 0.0, 1.0);
    material.f0 = f["f0"].rgbOr(material.f0);
    requireEachInRange(f["f0"], material.f0, 0.0, 1.0);
    readRoughness(f, material);
    return material;
}

Transform readTransform(const JsonField& f) {
    Transform t;
    if (!f.present()) return t;
    f.expectObject(keyNames(K::Transform));
    t.translate = readPoint(f["translate"], t.translate);
    t.rotate = f["rotate"].vec3Or(t.rotate);
    t.scale = f["scale"].vec3Or(t.scale);
    if (t.scale.x == 0.0 || t.scale.y == 0.0 || t.scale.z == 0.0) {
        f["scale"].fail("each component must be non-zero, got " + formatVec3(t.scale));
    }
    return t;
}

void requireObjFileExists(const JsonField& field, const std::string& file, const std::filesystem::path& projectDir) {
    if (file.empty()) field.fail("an obj mesh needs a file");
    std::filesystem::path path(file);
    if (path.is_relative()) path = projectDir / path;
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error)) field.fail("file not found: " + path.string());
}

Mesh readMesh(const JsonField& f, const ReadContext& context) {
    f.expectObject(keyNames(K::Mesh));
    Mesh mesh;
    mesh.name = readName(f);
    if (f["shape"].present()) mesh.source = readEnum(f["shape"], kMeshSourceNames);
    mesh.file = f["file"].stringOr(mesh.file);
    if (mesh.source == Mesh::Source::Obj) requireObjFileExists(f["file"], mesh.file, context.projectDir);
    mesh.subdivisions = f["subdivisions"].intInRangeOr(mesh.subdivisions, 4, 1024);
    mesh.transform = readTransform(f["transform"]);
    mesh.material = f["material"].string();
    mesh.tangent = f["tangent"].vec3Or(mesh.tangent);
    requireNonZero(f["tangent"], mesh.tangent);
    return mesh;
}

// ---------------------------------------------------------------------------------------------------------------------
// Camera, views and reference

void requireUpAcrossView(const JsonField& field, const Vec3& up, const Vec3& view) {
    if (!(glm::length(glm::cross(glm::normalize(up), glm::normalize(view))) > kParallelTolerance)) {
        field.fail("must not be parallel to the view direction (target - position = " + formatVec3(view) + "), got " +
                   formatVec3(up));
    }
}

Camera readCamera(const JsonField& f) {
    Camera camera;
    if (!f.present()) return camera;
    f.expectObject(keyNames(K::Camera));
    camera.position = readPoint(f["position"], camera.position);
    camera.target = readPoint(f["target"], camera.target);
    if (camera.target == camera.position) {
        f["target"].fail("must differ from the position " + formatVec3(camera.position));
    }
    // Far enough from the position that the view direction is well defined in float as well as in double.
    const double minDistance =
        kMinCameraDistance * std::max({1.0, glm::length(camera.position), glm::length(camera.target)});
    if (!(glm::distance(camera.target, camera.position) >= minDistance)) {
        f["target"].fail("must be at least " + formatNumber(minDistance) + " m from the position " +
                         formatVec3(camera.position) + " (1e-6 of the larger distance from the origin, at least 1e-6 m)");
    }
    camera.up = f["up"].vec3Or(camera.up);
    requireNonZero(f["up"], camera.up);
    requireUpAcrossView(f["up"], camera.up, camera.target - camera.position);
    camera.fovY = f["fovY"].numberOr(camera.fovY);
    requireInOpenRange(f["fovY"], camera.fovY, 0.0, 180.0);
    camera.width = f["width"].intInRangeOr(camera.width, 1, kMaxImageSize);
    camera.height = f["height"].intInRangeOr(camera.height, 1, kMaxImageSize);
    return camera;
}

void requireKnownTechnique(const TechniqueCatalogue& techniques, const JsonField& field, const std::string& name) {
    if (techniques.parameters(name)) return;
    const std::vector<std::string> known = techniques.names();
    std::string message = "unknown technique '" + clipForMessage(name) + "'";
    const std::string nearest = nearestName(name, known);
    if (!nearest.empty()) message += "; did you mean '" + nearest + "'?";
    std::string list;
    for (const std::string& n : known)
        list += (list.empty() ? "" : ", ") + n;
    field.fail(message + "; known techniques: " + list);
}

void requireValidParameters(const TechniqueCatalogue& techniques, const JsonField& field,
                            const std::string& technique) {
    if (!field.json().is_object()) field.fail("must be an object, got " + describeJson(field.json()));
    ParamSet params(*techniques.parameters(technique));
    for (const auto& [name, value] : field.json().items()) {
        const JsonField parameter = field[name];
        try {
            params.set(name, paramValueFromJson(parameter));
        } catch (const InputError& e) {
            parameter.fail(e.message());
        }
    }
}

std::vector<std::string> readPartNames(const JsonField& field, const UniqueNames& known) {
    const std::vector<std::string> names = readStringList(field);
    for (std::size_t i = 0; i < names.size(); ++i) {
        requireKnownName(field[i], names[i], known);
        if (std::find(names.begin(), names.begin() + i, names[i]) != names.begin() + i) {
            field[i].fail("'" + clipForMessage(names[i]) + "' is listed twice");
        }
    }
    return names;
}

View readView(const TechniqueCatalogue& techniques, const JsonField& f, const UniqueNames& lights,
              const UniqueNames& media) {
    f.expectObject(keyNames(K::View));
    View view;
    view.name = readName(f);
    view.technique = f["technique"].string();
    requireKnownTechnique(techniques, f["technique"], view.technique);
    if (f["parameters"].present()) {
        requireValidParameters(techniques, f["parameters"], view.technique);
        view.parameters = f["parameters"].json();
    }
    const JsonField lightList = f["lights"], mediaList = f["media"];
    if (lightList.present() != mediaList.present()) {
        (lightList.present() ? mediaList : lightList)
            .fail("give both 'lights' and 'media' (the part the view renders), or neither for the technique's default");
    }
    if (lightList.present()) {
        view.part = ScenePart{readPartNames(lightList, lights), readPartNames(mediaList, media)};
    }
    view.exposure = f["exposure"].numberOr(view.exposure);
    requireInRange(f["exposure"], view.exposure, -kMaxExposure, kMaxExposure);
    return view;
}

ReferenceSettings readReference(const JsonField& f) {
    ReferenceSettings reference;
    if (!f.present()) return reference;
    f.expectObject(keyNames(K::Reference));
    if (f["mode"].present()) reference.mode = readEnum(f["mode"], kReferenceModeNames);
    reference.maxDepth = f["maxDepth"].intInRangeOr(reference.maxDepth, 1, 1024);
    reference.spp = f["spp"].intInRangeOr(reference.spp, 1, 1 << 20);
    reference.seed = f["seed"].unsignedIntegerOr(reference.seed);
    return reference;
}

void requireSupportedVersion(const JsonField& field) {
    if (!field.present()) {
        field.fail("is missing: a Tyndall project starts with {\"tyndall\": " + std::to_string(kProjectFormatVersion) +
                   ", ...}");
    }
    const std::int64_t version = field.integer();
    if (version != kProjectFormatVersion) {
        field.fail("unsupported project format version " + std::to_string(version) + "; this build reads version " +
                   std::to_string(kProjectFormatVersion));
    }
}

// ---------------------------------------------------------------------------------------------------------------------

// Registers the name of an element that failed to read, when it has a valid one (a view naming it then adds nothing).
void keepName(const JsonField& f, UniqueNames& names) {
    try {
        names.add(f, readName(f));
    } catch (const InputError&) {
    }
}

// Every error of a project, not only its first: each section and each element of the top-level arrays is read on
// its own, and the errors (up to kMaxReportedErrors) are thrown together at the end, the first one's location first.
// An element that failed still registers its name when it has one, so that later references to it add no errors.
class ErrorList {
public:
    template <typename F>
    void attempt(F&& read) {
        try {
            read();
        } catch (const InputError& e) {
            errors_.push_back(e);
        }
    }
    // An element of a named kind: `read` reads it and registers its name; when it fails, its name is registered
    // anyway if it has a valid one.
    template <typename F>
    void attemptElement(const JsonField& f, UniqueNames& names, F&& read) {
        attempt([&] {
            try {
                read();
            } catch (const InputError&) {
                keepName(f, names);
                throw;
            }
        });
    }
    void throwIfAny() const {
        if (errors_.empty()) return;
        if (errors_.size() == 1) throw errors_.front();
        std::string message = errors_.front().message();
        const std::size_t shown = std::min(errors_.size(), kMaxReportedErrors);
        for (std::size_t i = 1; i < shown; ++i)
            message += "\n" + std::string(errors_[i].what());
        if (errors_.size() > shown)
            message += "\n... and " + std::to_string(errors_.size() - shown) + " more errors (fix these first)";
        else
            message += "\n(" + std::to_string(errors_.size()) + " errors)";
        throw InputError(errors_.front().where(), message);
    }

private:
    static constexpr std::size_t kMaxReportedErrors = 20;
    std::vector<InputError> errors_;
};

Scene readScene(const JsonField& root, const ReadContext& context, UniqueNames& lightNames, UniqueNames& mediumNames,
                ErrorList& errors) {
    Scene scene;
    errors.attempt([&] { scene.camera = readCamera(root["camera"]); });
    forEachElement(root["media"], [&](const JsonField& f) {
        errors.attemptElement(f, mediumNames, [&] {
            scene.media.push_back(readMedium(f));
            mediumNames.add(f, scene.media.back().name);
        });
    });
    std::size_t particleCount = 0;
    forEachElement(root["particleMedia"], [&](const JsonField& f) {
        errors.attemptElement(f, mediumNames, [&] {
            scene.particleMedia.push_back(readParticleMedium(f));
            mediumNames.add(f, scene.particleMedia.back().name);
            const ParticleMedium& m = scene.particleMedia.back();
            particleCount += m.particles.size() + (m.generator ? std::size_t(m.generator->count) : 0);
            if (particleCount > kMaxTotalParticles) {
                f.fail("the project's particle media hold " + std::to_string(particleCount) +
                       " particles up to here; at most " + std::to_string(kMaxTotalParticles) +
                       " in all (each costs memory in every renderer)");
            }
        });
    });
    forEachElement(root["lights"], [&](const JsonField& f) {
        errors.attemptElement(f, lightNames, [&] {
            readLight(f, scene);
            lightNames.add(f, readName(f));
        });
    });
    UniqueNames materialNames("material", "materials");
    forEachElement(root["materials"], [&](const JsonField& f) {
        errors.attemptElement(f, materialNames, [&] {
            scene.materials.push_back(readMaterial(f));
            materialNames.add(f, scene.materials.back().name);
        });
    });
    UniqueNames meshNames("mesh", "meshes");
    forEachElement(root["meshes"], [&](const JsonField& f) {
        errors.attempt([&] {
            scene.meshes.push_back(readMesh(f, context));
            meshNames.add(f, scene.meshes.back().name);
            requireKnownName(f["material"], scene.meshes.back().material, materialNames);
        });
    });
    return scene;
}

}  // namespace

Project projectFromJson(const TechniqueCatalogue& techniques, const nlohmann::json& json,
                        const std::string& pathForErrors) {
    const ReadContext context{pathForErrors, std::filesystem::path(pathForErrors).parent_path()};
    const JsonField root(&json, "", context.file);
    if (!json.is_object()) root.fail("a project must be a JSON object, got " + describeJson(json));
    requireSupportedVersion(root["tyndall"]);
    root.expectObject(keyNames(K::Project));

    Project project;
    project.name = root["name"].stringOr("");
    UniqueNames lightNames("light", "lights"), mediumNames("medium", "media");
    ErrorList errors;
    project.scene = readScene(root, context, lightNames, mediumNames, errors);
    UniqueNames viewNames("view", "views");
    forEachElement(root["views"], [&](const JsonField& f) {
        errors.attempt([&] {
            project.views.push_back(readView(techniques, f, lightNames, mediumNames));
            viewNames.add(f, project.views.back().name);
        });
    });
    errors.attempt([&] { project.reference = readReference(root["reference"]); });
    errors.throwIfAny();
    return project;
}

}  // namespace tyndall
