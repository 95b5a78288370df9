#include "tyndall/core/scene.h"

#include "tyndall/core/error.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace tyndall {

namespace {

// Euler XYZ in degrees, X applied first: R = Rz * Ry * Rx. glm matrices are built from columns.
glm::dmat3 eulerXyzRotation(const Vec3& degrees) {
    const Vec3 r = glm::radians(degrees);
    const double cx = std::cos(r.x), sx = std::sin(r.x);
    const double cy = std::cos(r.y), sy = std::sin(r.y);
    const double cz = std::cos(r.z), sz = std::sin(r.z);
    const glm::dmat3 rx(Vec3(1.0, 0.0, 0.0), Vec3(0.0, cx, sx), Vec3(0.0, -sx, cx));
    const glm::dmat3 ry(Vec3(cy, 0.0, -sy), Vec3(0.0, 1.0, 0.0), Vec3(sy, 0.0, cy));
    const glm::dmat3 rz(Vec3(cz, sz, 0.0), Vec3(-sz, cz, 0.0), Vec3(0.0, 0.0, 1.0));
    return rz * ry * rx;
}

// SplitMix64 (Steele, Lea and Flood 2014): small, fast, and good enough to scatter particles reproducibly.
class SplitMix64 {
public:
    explicit SplitMix64(std::uint64_t seed) : state_(seed) {}

    std::uint64_t next() {
        state_ += 0x9E3779B97F4A7C15ull;
        std::uint64_t z = state_;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }

    // Uniform in [0, 1) with 53 random bits.
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

private:
    std::uint64_t state_;
};

// A uniformly distributed rotation (Shoemake, "Uniform random rotations", Graphics Gems III, 1992).
glm::dquat uniformRotation(double u1, double u2, double u3) {
    const double twoPi = glm::two_pi<double>();
    const double r1 = std::sqrt(1.0 - u1), r2 = std::sqrt(u1);
    const double x = r1 * std::sin(twoPi * u2), y = r1 * std::cos(twoPi * u2);
    const double z = r2 * std::sin(twoPi * u3), w = r2 * std::cos(twoPi * u3);
    return glm::dquat(w, x, y, z);
}

// Per particle, in this order: 3 numbers for the centre, 3 for the orientation, 1 for the extinction multiplier.
std::vector<Particle> generateParticles(const ParticleGenerator& generator) {
    TY_CHECK(generator.count >= 0, "particle count must be non-negative");
    SplitMix64 rng(generator.seed);
    const glm::dmat3 worldFromBox = generator.region.worldFromBoxRotation();
    std::vector<Particle> particles;
    particles.reserve(static_cast<std::size_t>(generator.count));
    for (int i = 0; i < generator.count; ++i) {
        Particle p;
        const Vec3 inBox(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
        p.centre = generator.region.centre + worldFromBox * (inBox * generator.region.size);
        const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
        p.orientation = uniformRotation(u1, u2, u3);
        p.extinctionMultiplier =
            generator.multiplierMin + rng.uniform() * (generator.multiplierMax - generator.multiplierMin);
        p.scale = generator.scale;
        p.falloff = generator.falloff;
        particles.push_back(p);
    }
    return particles;
}

template <typename Light>
void appendNames(const std::vector<Light>& items, std::vector<std::string>& names) {
    for (const Light& item : items)
        names.push_back(item.name);
}

template <typename T>
std::vector<T> selectByName(const std::vector<T>& items, const std::vector<std::string>& names) {
    std::vector<T> selected;
    for (const T& item : items) {
        if (std::find(names.begin(), names.end(), item.name) != names.end()) selected.push_back(item);
    }
    return selected;
}

}  // namespace

glm::dmat3 Transform::rotation() const {
    return eulerXyzRotation(rotate);
}

glm::dmat4 Transform::worldFromLocal() const {
    const glm::dmat3 rotateScale = rotation() * glm::dmat3(scale.x, 0.0, 0.0, 0.0, scale.y, 0.0, 0.0, 0.0, scale.z);
    glm::dmat4 m(rotateScale);
    m[3] = glm::dvec4(translate, 1.0);
    return m;
}

glm::dmat3 OrientedBox::worldFromBoxRotation() const {
    return eulerXyzRotation(rotate);
}

const char* toString(PhaseKind kind) {
    switch (kind) {
        case PhaseKind::Isotropic:
            return "isotropic";
        case PhaseKind::HenyeyGreenstein:
            return "hg";
        case PhaseKind::IsoHgMix:
            return "mix";
        case PhaseKind::Rayleigh:
            return "rayleigh";
        case PhaseKind::Eddington:
            return "eddington";
        case PhaseKind::Legendre:
            return "legendre";
        case PhaseKind::HazyMie:
            return "hazy-mie";
        case PhaseKind::MurkyMie:
            return "murky-mie";
    }
    return "unknown";
}

std::vector<Particle> ParticleMedium::allParticles() const {
    std::vector<Particle> all = particles;
    if (generator) {
        const std::vector<Particle> generated = generateParticles(*generator);
        all.insert(all.end(), generated.begin(), generated.end());
    }
    if (simulation) all = simulateParticles(std::move(all), *simulation);
    return all;
}

std::vector<Particle> simulateParticles(std::vector<Particle> particles, const ParticleSimulation& sim) {
    std::vector<Vec3> targets(particles.size()), velocities(particles.size(), Vec3(0.0));
    for (std::size_t i = 0; i < particles.size(); ++i)
        targets[i] = particles[i].centre + sim.offset;
    const double dt = sim.timeStep;
    for (int step = 0; step < sim.steps; ++step) {
        for (const ParticleImpulse& impulse : sim.impulses) {
            if (impulse.step != step) continue;
            for (std::size_t i = 0; i < particles.size(); ++i) {
                const Vec3 away = particles[i].centre - impulse.position;
                const double d = glm::length(away);
                if (d >= impulse.radius || d == 0.0) continue;
                velocities[i] += (impulse.speed * (1.0 - d / impulse.radius) / d) * away;
            }
        }
        for (std::size_t i = 0; i < particles.size(); ++i) {
            // Semi-implicit Euler: the velocity first, then the position with the new velocity.
            velocities[i] += dt * (sim.stiffness * (targets[i] - particles[i].centre) - sim.viscosity * velocities[i]);
            particles[i].centre += dt * velocities[i];
        }
    }
    return particles;
}

double impulsePeakSeconds(const ParticleSimulation& sim, double limit) {
    const double k = sim.stiffness, c = sim.viscosity;
    if (k <= 0.0) return c > 0.0 ? std::min(limit, 3.0 / c) : limit;
    // x(t) for x(0) = 0, x'(0) = v: the roots of r^2 + c r + k = 0 decide its shape; x'(t) = 0 at the peak.
    const double omega0 = std::sqrt(k), zeta = c / (2.0 * omega0);
    double t;
    if (zeta < 1.0) {
        // Underdamped: x = v e^{-zeta w0 t} sin(wd t) / wd, x' = 0 where tan(wd t) = wd / (zeta w0).
        const double omegaD = omega0 * std::sqrt(1.0 - zeta * zeta);
        t = std::atan2(omegaD, zeta * omega0) / omegaD;
    } else if (zeta == 1.0) {
        t = 1.0 / omega0;  // critically damped: x = v t e^{-w0 t}
    } else {
        // Overdamped: x = v (e^{r1 t} - e^{r2 t}) / (r1 - r2), r2 < r1 < 0; x' = 0 where r1 e^{r1 t} = r2 e^{r2 t}.
        const double root = omega0 * std::sqrt(zeta * zeta - 1.0);
        const double r1 = -zeta * omega0 + root, r2 = -zeta * omega0 - root;
        t = std::log(r2 / r1) / (r1 - r2);
    }
    return std::min(limit, t);
}

std::vector<double> legendreToMonomial(const std::vector<double>& a) {
    // The monomial coefficients of P_n by Bonnet's recurrence (n + 1) P_{n+1} = (2n + 1) mu P_n - n P_{n-1}: the same
    // numbers as Eq. 13's explicit sum, without its large factorials.
    const std::size_t terms = a.size();
    std::vector<double> c(terms, 0.0);
    if (terms == 0) return c;
    // P_1 has two coefficients, so the rows hold at least two even for a single term.
    const std::size_t rowSize = std::max<std::size_t>(terms, 1) + 1;
    std::vector<double> previous(rowSize, 0.0), current(rowSize, 0.0), next(rowSize, 0.0);
    previous[0] = 1.0;  // P_0
    current[1] = 1.0;   // P_1
    for (std::size_t n = 0; n < terms; ++n) {
        const std::vector<double>& pn = n == 0 ? previous : current;
        for (std::size_t k = 0; k <= n; ++k)
            c[k] += a[n] * pn[k];
        if (n == 0) continue;
        const double dn = double(n);
        std::fill(next.begin(), next.end(), 0.0);
        for (std::size_t k = 0; k + 1 <= n + 1 && k < terms; ++k) {
            next[k + 1] += (2.0 * dn + 1.0) * current[k] / (dn + 1.0);
            next[k] -= dn * previous[k] / (dn + 1.0);
        }
        std::swap(previous, current);
        std::swap(current, next);
    }
    return c;
}

std::vector<double> AngularDistribution::polynomial() const {
    switch (kind) {
        case Kind::Isotropic:
            return {1.0};
        case Kind::Polynomial:
            return coefficients;
        case Kind::Legendre:
            return legendreToMonomial(coefficients);
        case Kind::Spot:
            break;
    }
    // ((1 + mu) / 2)^n = 2^-n sum_k C(n, k) mu^k, with C(n, k + 1) = C(n, k) (n - k) / (k + 1).
    TY_CHECK(spotExponent >= 0.0 && spotExponent <= 256.0 && spotExponent == std::floor(spotExponent),
             "spot exponent must be an integer in [0, 256]");
    const int n = static_cast<int>(spotExponent);
    std::vector<double> c(static_cast<std::size_t>(n) + 1);
    c[0] = std::ldexp(1.0, -n);
    for (int k = 0; k < n; ++k)
        c[k + 1] = c[k] * (n - k) / (k + 1);
    return c;
}

Scene ScenePart::apply(const Scene& scene) const {
    Scene part;
    part.camera = scene.camera;
    part.materials = scene.materials;
    part.meshes = scene.meshes;
    part.media = selectByName(scene.media, media);
    part.particleMedia = selectByName(scene.particleMedia, media);
    part.pointLights = selectByName(scene.pointLights, lights);
    part.directionalLights = selectByName(scene.directionalLights, lights);
    part.areaLights = selectByName(scene.areaLights, lights);
    return part;
}

ScenePart ScenePart::everything(const Scene& scene) {
    ScenePart part;
    appendNames(scene.pointLights, part.lights);
    appendNames(scene.directionalLights, part.lights);
    appendNames(scene.areaLights, part.lights);
    appendNames(scene.media, part.media);
    appendNames(scene.particleMedia, part.media);
    return part;
}

}  // namespace tyndall
