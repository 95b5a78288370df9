// The scene model: everything the techniques and the reference render, as plain data with SI units.
// Conventions (units, colour space, angles, what single scattering includes) are in docs/conventions.md.
// Numbers are doubles so that a project file round-trips exactly; renderers convert to float where they need to.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tyndall {

using Vec3 = glm::dvec3;
using Rgb = glm::dvec3;  // linear Rec.709 RGB

// ---------------------------------------------------------------------------------------------------------------------
// Camera

struct Camera {
    Vec3 position{0.0, 1.0, 5.0};  // m, world space
    Vec3 target{0.0, 1.0, 0.0};    // m, the point the camera looks at
    Vec3 up{0.0, 1.0, 0.0};        // world up hint; need not be orthogonal to the view direction
    double fovY = 45.0;            // degrees, vertical field of view, in (0, 180)
    int width = 512;               // pixels, [1, 16384]
    int height = 512;              // pixels, [1, 16384]
};

// ---------------------------------------------------------------------------------------------------------------------
// Transforms: translate * rotate (Euler XYZ, degrees, applied X first) * scale.

struct Transform {
    Vec3 translate{0.0};  // m
    Vec3 rotate{0.0};     // degrees about x, y, z, applied in that order
    Vec3 scale{1.0};      // unitless, each component non-zero

    glm::dmat4 worldFromLocal() const;
    glm::dmat3 rotation() const;  // the rotation part alone
};

// ---------------------------------------------------------------------------------------------------------------------
// Phase functions. The angle theta is between the direction light travels before and after scattering:
// cos(theta) = +1 is forward scattering, and g > 0 favours it.

enum class PhaseKind {
    Isotropic,         // 1 / (4 pi)
    HenyeyGreenstein,  // g in (-1, 1)
    IsoHgMix,          // (1 - a) / (4 pi) + a * HG(g); a in [0, 1] (ISV thesis, Sec. 3.3)
    Rayleigh,          // 3 / (16 pi) * (1 + cos^2)
    Eddington,         // linear anisotropic: (1 + b cos) / (4 pi), b in [-1, 1]
    Legendre,          // sum_n a_n P_n(cos) / (4 pi), a_0 = 1, non-negative over [-1, 1]
    HazyMie,           // (1/2 + 9/2 ((1 + cos) / 2)^8) / (4 pi)    (Nishita et al. 1987)
    MurkyMie,          // (1/2 + 33/2 ((1 + cos) / 2)^32) / (4 pi)
};

struct PhaseFunction {
    PhaseKind kind = PhaseKind::Isotropic;
    double g = 0.0;                // HenyeyGreenstein and IsoHgMix: asymmetry, in (-1, 1)
    double a = 1.0;                // IsoHgMix: weight of the HG lobe (the thesis' "anisotropy"), in [0, 1]
    double b = 0.0;                // Eddington: linear coefficient, in [-1, 1]
    std::vector<double> legendre;  // Legendre: a_0 .. a_{N-1}, N <= kMaxLegendreTerms

    static constexpr int kMaxLegendreTerms = 32;
};

const char* toString(PhaseKind kind);

// The monomial coefficients c_k of sum_n a[n] P_n(mu) = sum_k c_k mu^k (Eq. 13 of the Pegoraro paper (003) without its
// 1 / (4 pi)), so that Legendre-form phase functions and light distributions become polynomials in the cosine.
std::vector<double> legendreToMonomial(const std::vector<double>& a);

// ---------------------------------------------------------------------------------------------------------------------
// Media. Extinction coefficients add where media overlap.

enum class MediumShape {
    Infinite,          // fills all space
    Box,               // an oriented box: `box` below
    ConvexPolyhedron,  // the intersection of the half-spaces in `planes`
};

struct OrientedBox {
    Vec3 centre{0.0};  // m
    Vec3 size{1.0};    // m, full edge lengths, each > 0
    Vec3 rotate{0.0};  // degrees, Euler XYZ like Transform::rotate

    glm::dmat3 worldFromBoxRotation() const;
};

// The half-space { x : dot(normal, x) <= offset }. Normals need not be unit length in the file; they are normalised
// when loaded.
struct HalfSpace {
    Vec3 normal{0.0, 1.0, 0.0};
    double offset = 0.0;  // m
};

struct HomogeneousMedium {
    std::string name;  // unique among media
    Rgb sigma_s{0.1};  // 1/m, scattering coefficient, >= 0
    Rgb sigma_a{0.0};  // 1/m, absorption coefficient, >= 0
    PhaseFunction phase;
    MediumShape shape = MediumShape::Infinite;
    OrientedBox box;                // when shape == Box
    std::vector<HalfSpace> planes;  // when shape == ConvexPolyhedron: at least 4, bounded, non-empty

    Rgb sigma_t() const { return sigma_s + sigma_a; }
};

// One tetrahedral particle of an ISV particle medium (ISV thesis, Sec. 3.8 and 3.16). The tetrahedron is regular, its
// vertices at distance `scale` from the centre. Inside it the extinction is
//   sigma_t(x) = medium.extinction * extinctionMultiplier * exp(-50 |x - centre|^2 / u^2),  u = scale * falloff,
// per channel (a chromatic extinction colours what the medium transmits, and so its shadows),
// (Eq. 9 of the thesis, written with the distance to the centre), and zero outside.
struct Particle {
    Vec3 centre{0.0};                            // m
    double scale = 1.0;                          // m, centre-to-vertex distance, > 0
    glm::dquat orientation{1.0, 0.0, 0.0, 0.0};  // unit quaternion (w, x, y, z)
    double extinctionMultiplier = 1.0;           // unitless, >= 0
    double falloff = 1.6;                        // unitless f, > 0; u = scale * f
};

// Deterministic particle placement, so that projects need not list thousands of particles.
struct ParticleGenerator {
    int count = 0;  // number of particles, [0, 1'000'000]
    std::uint64_t seed = 1;
    OrientedBox region;          // centres are uniform in this box
    double scale = 0.25;         // m, every particle's scale
    double falloff = 1.6;        // every particle's falloff f
    double multiplierMin = 5.0;  // extinction multipliers are uniform in [min, max] (thesis: [5, 10])
    double multiplierMax = 10.0;
};

// A push on the particles near a point (ISV thesis Sec. 3.14: "an impulse to any particles that are close to the mouse
// cursor"), at the start of one step of the simulation.
struct ParticleImpulse {
    int step = 0;        // the step it is applied at, [0, steps)
    Vec3 position{0.0};  // m, where it pushes from
    double radius = 0.5;  // m, > 0: particles closer than this are pushed away
    double speed = 1.0;   // m/s, >= 0: the velocity given to a particle at the centre, falling linearly to 0 at radius
};

// The particle simulation of ISV thesis Sec. 3.14, deterministic so that a frame of the animation is a scene every
// renderer (the reference too) renders alike. Each particle starts at rest at its place (explicit or generated) and is
// drawn towards its target, that place moved with the region by `offset`, by a spring of `stiffness`; `viscosity`
// damps its velocity. Semi-implicit Euler in double precision, particles in order.
struct ParticleSimulation {
    int steps = 0;                 // steps simulated, [0, 100000]
    double timeStep = 1.0 / 60.0;  // s, (0, 1]
    double stiffness = 30.0;       // 1/s^2, >= 0: acceleration per metre away from the target
    double viscosity = 4.0;        // 1/s, >= 0: the velocity's damping rate
    Vec3 offset{0.0};              // m: how far the region of targets has moved
    std::vector<ParticleImpulse> impulses;
};

// The particles after `simulation`'s steps (the ISV thesis' animation), in the same order.
std::vector<Particle> simulateParticles(std::vector<Particle> particles, const ParticleSimulation& simulation);

// When a particle at rest on its target, given a velocity by an impulse, is farthest from the target, in seconds: the
// first maximum of the damped spring x'' = -stiffness x - viscosity x' with x(0) = 0 (docs/isv.md, "Impulses"). When
// the spring has no stiffness the particle coasts to a stop and never comes back: the time it takes to cover 95 % of
// its way (3 / viscosity), or `limit` without viscosity either. At most `limit`.
double impulsePeakSeconds(const ParticleSimulation& simulation, double limit = 1.0);

struct ParticleMedium {
    std::string name;         // unique among media
    Rgb extinction{1.0};      // 1/m, base extinction sigma per channel (one number: grey), each >= 0
    Rgb albedo{0.8};          // single-scattering albedo rho, each in [0, 1]
    PhaseFunction phase;
    std::vector<Particle> particles;             // explicit particles ...
    std::optional<ParticleGenerator> generator;  // ... and/or generated ones (appended after the explicit ones)
    std::optional<ParticleSimulation> simulation;  // when set, every particle is where the simulation has taken it

    // Explicit particles followed by the generated ones, simulated when the medium has a simulation.
    std::vector<Particle> allParticles() const;
};

// ---------------------------------------------------------------------------------------------------------------------
// Lights. Lights are not seen directly by the camera (docs/conventions.md).

// Angular distribution of a point light about `axis`, as a polynomial in mu = cos(angle to axis):
//   I(mu) = intensity * sum_k coefficients[k] * mu^k         (Polynomial), or
//   I(mu) = intensity * sum_k coefficients[k] * P_k(mu)      (Legendre, P_k the Legendre polynomials).
// Must be >= 0 for every mu in [-1, 1].
struct AngularDistribution {
    enum class Kind { Isotropic, Spot, Polynomial, Legendre };
    Kind kind = Kind::Isotropic;
    Vec3 axis{0.0, -1.0, 0.0};         // direction of the lobe, normalised when loaded
    Vec3 axisAsWritten{0.0};           // the axis as the project gives it (written back so; 0: as `axis`)
    double spotExponent = 1.0;         // Spot: ((1 + mu) / 2)^n, n in [0, 256]
    std::vector<double> coefficients;  // Polynomial or Legendre: c_0 .. c_{N-1}, N <= 32

    // The polynomial coefficients for every kind (the spot preset expanded with the binomial theorem).
    std::vector<double> polynomial() const;
};

struct PointLight {
    std::string name;
    Vec3 position{0.0, 2.0, 0.0};  // m
    Rgb intensity{1.0};            // W/sr, >= 0; on the axis for Spot (the polynomial's value scales it)
    AngularDistribution distribution;
};

// A collimated beam: parallel rays travelling along `direction` carrying `irradiance` across a plane perpendicular to
// it. With a gobo the beam is the infinite prism swept by the convex aperture polygon along `direction`; without one it
// fills all space. Its radiance arrives from infinity, so it is attenuated by every medium along the way.
struct DirectionalLight {
    std::string name;
    Vec3 direction{0.0, -1.0, 0.0};  // the direction light travels, normalised when loaded
    // The direction as the project gives it: a project is written back with the user's numbers (a one-value edit is
    // a one-line diff), while every renderer uses `direction`. 0: as `direction`.
    Vec3 directionAsWritten{0.0};
    Rgb irradiance{1.0};             // W/m^2, >= 0, on a plane perpendicular to direction
    std::vector<Vec3> gobo;          // optional convex planar aperture polygon, m; empty for none
};

// A planar convex polygon that emits `radiance` from its front side (counter-clockwise vertices seen from the front,
// i.e. normal = right-hand rule), or from both sides when twoSided.
struct AreaLight {
    std::string name;
    std::vector<Vec3> vertices;  // m, >= 3, planar, convex, non-zero area
    Rgb radiance{1.0};           // W/(m^2 sr), >= 0
    bool twoSided = false;
};

// ---------------------------------------------------------------------------------------------------------------------
// Surfaces

struct Material {
    enum class Kind { Diffuse, GGX };
    std::string name;
    Kind kind = Kind::Diffuse;
    Rgb albedo{0.5};      // Diffuse: Lambertian reflectance, each in [0, 1]
    Rgb f0{0.04};         // GGX: Fresnel reflectance at normal incidence (Schlick), each in [0, 1]
    double alphaX = 0.3;  // GGX: roughness (width) along the tangent, [1e-3, 1]
    double alphaY = 0.3;  // GGX: roughness along the bitangent, [1e-3, 1]; equal to alphaX when isotropic
};

struct Mesh {
    enum class Source { Plane, Box, Sphere, Obj };
    std::string name;
    Source source = Source::Plane;
    std::string file;       // Obj: path, relative to the project file's folder
    int subdivisions = 32;  // Sphere: segments around the equator, [4, 1024]
    Transform transform;
    std::string material;         // name of a material in Scene::materials
    Vec3 tangent{1.0, 0.0, 0.0};  // world direction projected onto the surface for anisotropic GGX
};

// Geometry of a mesh in world space, ready to render.
struct TriangleMesh {
    std::vector<glm::vec3> positions;  // m, world space
    std::vector<glm::vec3> normals;    // per vertex, unit length (may be empty: face normals are used)
    std::vector<glm::uvec3> triangles;
};

// ---------------------------------------------------------------------------------------------------------------------

struct Scene {
    Camera camera;
    std::vector<HomogeneousMedium> media;
    std::vector<ParticleMedium> particleMedia;
    std::vector<PointLight> pointLights;
    std::vector<DirectionalLight> directionalLights;
    std::vector<AreaLight> areaLights;
    std::vector<Material> materials;
    std::vector<Mesh> meshes;
};

// What a view renders: a subset of the scene's lights and media, by name. Surfaces are always part of it, because
// they occlude. Comparisons render the same part with the reference.
struct ScenePart {
    std::vector<std::string> lights;  // names from pointLights, directionalLights and areaLights
    std::vector<std::string> media;   // names from media and particleMedia

    // A scene holding only the selected lights and media (plus camera, materials and meshes).
    Scene apply(const Scene& scene) const;
    // Every light and medium of the scene.
    static ScenePart everything(const Scene& scene);
};

}  // namespace tyndall
