// The ISV technique (Jandhyala 2025; ../shared/papers/004) piece by piece: the interval-shading proxies against exact
// ray-tetrahedron intersection, each integration mode against quadrature of Eq. 7 with the Eq. 9 falloff, the
// volumetric shadow map against the optical depth it stores, back-to-front compositing against the analytic
// composite; then whole against the reference, the GPU against the CPU model, and what it refuses.
#include "technique_gpu_test.h"

#include "isv/gpu_renderer.h"
#include "isv/isv.h"
#include "isv/prepared.h"

#include "test_paths.h"
#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"
#include "tyndall/framework/shader_params.h"
#include "tyndall/image/metrics.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace tyndall::isv::test {
namespace {

using shader::IsvFrame;
using shader::IsvParticle;

Particle particleAt(const Vec3& centre, double scale, std::mt19937& rng, double multiplier = 1.0) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Particle p;
    p.centre = centre;
    p.scale = scale;
    p.orientation = glm::normalize(glm::dquat(u(rng), u(rng), u(rng), u(rng)));
    p.extinctionMultiplier = multiplier;
    return p;
}

IsvParticle toIsv(const Particle& particle, double sigma) {
    const std::array<Vec3, 4> v = tetrahedronVertices(particle);
    IsvParticle q{};
    q.v0 = glm::vec3(v[0]);
    q.v1 = glm::vec3(v[1]);
    q.v2 = glm::vec3(v[2]);
    q.v3 = glm::vec3(v[3]);
    q.centre = glm::vec3(particle.centre);
    q.sigma = float(sigma * particle.extinctionMultiplier);
    const double u = particle.scale * particle.falloff;
    q.k = float(50.0 / (u * u));
    return q;
}

// The particle's optical depth over [a, b] of a ray, in double (the reference's formula).
double exactDepth(const IsvParticle& p, const glm::dvec3& o, const glm::dvec3& d, double a, double b) {
    if (b <= a) return 0.0;
    // The float ray direction is unit to 1e-7 only; with t_c^2 ~ 10 m^2 that alone would move h^2 by 1e-6 m^2.
    const glm::dvec3 oc = glm::dvec3(p.centre) - o, u = glm::normalize(d);
    const double tc = glm::dot(oc, u), h2 = std::max(0.0, glm::dot(oc, oc) - tc * tc), sk = std::sqrt(double(p.k));
    const double scale = glm::length(d);  // a and b are in units of |d|
    return double(p.sigma) * std::exp(-double(p.k) * h2) * 0.5 * std::sqrt(M_PI) / sk *
           (std::erf(sk * (b * scale - tc)) - std::erf(sk * (a * scale - tc)));
}

shader::CameraParams cameraLookingAt(const glm::vec3& position, const glm::vec3& target, int w, int h) {
    Camera c;
    c.position = Vec3(position);
    c.target = Vec3(target);
    c.fovY = 40.0;
    c.width = w;
    c.height = h;
    return toCameraParams(c);
}

// Pixel coordinates of x for the camera (the projection compositeCpu and the geometry shader use).
glm::vec2 project(const shader::CameraParams& c, const glm::vec3& x) {
    const glm::vec3 r = x - c.position;
    const float z = glm::dot(r, c.forward);
    return {(glm::dot(r, c.right) / (z * c.tanHalfFovY * c.aspect) + 1.0f) * 0.5f * c.width,
            (1.0f - glm::dot(r, c.up) / (z * c.tanHalfFovY)) * 0.5f * c.height};
}

// -------------------------------------------------------------------------------------------------------------------
// Proxies (Sec. 2.3)

TEST(IsvProxy, InterpolatedDepthsEqualTheRayTetrahedronInterval) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    int covered = 0, case1 = 0, case2 = 0;
    double worst = 0.0;
    for (int trial = 0; trial < 200; ++trial) {
        const IsvParticle p = toIsv(particleAt(Vec3(u(rng), u(rng), u(rng)), 0.3 + 0.5 * std::abs(u(rng)), rng), 1.0);
        const glm::vec3 eye = p.centre + glm::normalize(glm::vec3(u(rng), u(rng), u(rng))) * (1.5f + 2.0f * std::abs(u(rng)));
        const shader::CameraParams cam = cameraLookingAt(eye, p.centre + 0.2f * glm::vec3(u(rng), u(rng), u(rng)), 64, 48);
        const glm::vec3 v[4] = {p.v0, p.v1, p.v2, p.v3};
        glm::vec2 s[4];
        glm::vec4 q;
        for (int i = 0; i < 4; ++i) {
            s[i] = project(cam, v[i]);
            q[i] = 1.0f / glm::dot(v[i] - cam.position, cam.forward);
        }
        const shader::IsvProxy proxy = shader::isvProxy(s[0], s[1], s[2], s[3], q);
        ASSERT_TRUE(proxy.silhouette == 3 || proxy.silhouette == 4);
        (proxy.silhouette == 3 ? case1 : case2)++;
        for (int py = 0; py < 48; ++py)
            for (int px = 0; px < 64; ++px) {
                const glm::vec2 pixel(float(px) + 0.5f, float(py) + 0.5f);
                glm::vec3 o, d;
                shader::cameraRay(cam, pixel.x, pixel.y, o, d);
                const glm::vec2 t = shader::isvRayTetrahedron(p, o, d);
                int inside = -1;
                glm::vec3 l(0.0f);
                float margin = 1.0f;
                for (int i = 0; i < proxy.silhouette && inside < 0; ++i) {
                    l = shader::isvBarycentric(pixel, proxy.p[i], proxy.p[(i + 1) % proxy.silhouette],
                                               proxy.p[proxy.silhouette]);
                    if (l.x >= 0.0f && l.y >= 0.0f && l.z >= 0.0f) inside = i;
                    margin = std::min(margin, std::min({std::abs(l.x), std::abs(l.y), std::abs(l.z)}));
                }
                const float chord = t.y - t.x;
                if (inside < 0) {
                    if (margin > 1e-3f) {
                        EXPECT_FALSE(chord > 1e-3f) << "uncovered pixel inside the tetrahedron";
                    }
                    continue;
                }
                ++covered;
                const int i = inside;
                const glm::vec2 qi = l.x * proxy.q[i] + l.y * proxy.q[(i + 1) % proxy.silhouette] +
                                     l.z * proxy.q[proxy.silhouette];
                const float cosine = glm::dot(d, cam.forward);
                const float ta = 1.0f / qi.x / cosine, tb = 1.0f / qi.y / cosine;
                ASSERT_TRUE(t.x <= t.y + 1e-4f) << "a covered pixel misses the tetrahedron";
                const double err = std::max(std::abs(std::min(ta, tb) - t.x), std::abs(std::max(ta, tb) - t.y));
                worst = std::max(worst, err);
                EXPECT_LT(err, 2e-4) << "trial " << trial << " pixel " << px << "," << py;
            }
    }
    EXPECT_GT(covered, 5000);
    EXPECT_GT(case1, 10);
    EXPECT_GT(case2, 10);
    std::printf("proxies: %d covered pixel centres, %d case-1 and %d case-2 tetrahedra, worst depth error %.2g m\n",
                covered, case1, case2, worst);
}

// -------------------------------------------------------------------------------------------------------------------
// Integration (Sec. 3.7-3.10)

std::vector<float> gradientVsm;  // slice 0: 0, slice 1: c everywhere (see frameWithGradient), kVsmChannels per texel
std::vector<float> noShadow;

// A frame lit from above (light travelling along -y) through a volumetric shadow map whose optical depth grows
// linearly with depth below y = 2: tau_L(x) = c_rgb (2 - x.y) / 2 over the region |x|, |z| < 15, c_rgb = c channel.
// The medium's extinction is the particle's sigma times `tint` per channel.
IsvFrame frameWithGradient(float c, int integration, int steps, const glm::vec3& tint = glm::vec3(1.0f),
                           const glm::vec3& channel = glm::vec3(1.0f)) {
    IsvFrame f{};
    f.lightDirection = glm::vec3(0.0f, -1.0f, 0.0f);
    f.irradiance = glm::vec3(1.0f);
    f.integration = integration;
    f.steps = steps;
    f.threshold = 0.0f;
    f.fading = 1;
    f.mediumCount = 1;
    f.media[0].albedo = glm::vec3(1.0f);
    f.media[0].tint = tint;
    f.media[0].phase.kind = shader::kPhaseIsotropic;
    f.hasVsm = c > 0.0f ? 1 : 0;
    shader::IsvLightSpace& g = f.vsm;
    g.forward = glm::vec3(0.0f, -1.0f, 0.0f);
    shader::buildFrame(g.forward, g.right, g.up);
    g.size = 4;
    g.texel = 10.0f;
    g.slices = 2;
    g.depthStep = 2.0f;
    g.origin = glm::vec3(0.0f, 2.0f, 0.0f) - 20.0f * (g.right + g.up);
    gradientVsm.assign(32 * kVsmChannels, 0.0f);
    for (int i = 16; i < 32; ++i)
        for (int k = 0; k < 3; ++k)
            gradientVsm[std::size_t(i * kVsmChannels + k)] = c * channel[k];
    return f;
}

// Quadrature of Eq. 7 without K for the frame's exact fields: sigma_t T_V T_L with tau_L = c (2 - y) / 2.
double quadratureEq7(const IsvParticle& p, const glm::dvec3& o, const glm::dvec3& d, double t0, double t1, double c) {
    const int n = 20000;
    const double h = (t1 - t0) / n;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const double t = t0 + (i + 0.5) * h;
        const glm::dvec3 x = o + t * d, r = x - glm::dvec3(p.centre);
        const double sigma = double(p.sigma) * std::exp(-double(p.k) * glm::dot(r, r));
        sum += sigma * std::exp(-exactDepth(p, o, d, t0, t) - c * (2.0 - x.y) / 2.0) * h;
    }
    return sum;
}

// Of `count` rays from o towards points about p's centre, those that cross p over more than 5 cm: the ray's index, its
// direction and its interval through p.
struct CrossingRay {
    int k;
    glm::vec3 d;
    glm::vec2 t;
};
std::vector<CrossingRay> raysThrough(const IsvParticle& p, const glm::vec3& o, int count) {
    std::vector<CrossingRay> rays;
    for (int k = 0; k < count; ++k) {
        const glm::vec3 target = p.centre + 0.25f * glm::vec3(std::sin(k * 1.3f), std::cos(k * 0.7f), std::sin(k * 2.1f));
        const glm::vec3 d = glm::normalize(target - o);
        const glm::vec2 t = shader::isvRayTetrahedron(p, o, d);
        if (t.y - t.x > 0.05f) rays.push_back({k, d, t});
    }
    return rays;
}

TEST(IsvShade, IntegrationModesAgainstQuadratureOfEq7) {
    std::mt19937 rng(5);
    Particle particle = particleAt(Vec3(0.1, 1.0, -0.2), 0.6, rng, 6.0);
    const IsvParticle p = toIsv(particle, 1.0);
    MapScope maps(&gradientVsm, &noShadow);
    const glm::vec3 o(-2.0f, 1.3f, 2.5f);
    struct Row {
        const char* name;
        int integration, steps;
        double bound;
    };
    // Bounds at 1.3-2x the worst relative error measured over these rays (printed): one Simpson step, the thesis'
    // default, is off by up to 58 % on a ray through a dense particle's edge; ten steps agree with the quadrature.
    const Row rows[] = {{"simpson 1", shader::kIsvSimpson, 1, 0.8}, {"simpson 2", shader::kIsvSimpson, 2, 0.1},
                        {"simpson 10", shader::kIsvSimpson, 10, 3e-5}, {"taylor", shader::kIsvTaylor, 1, 2.6}};
    for (const Row& row : rows) {
        double worst = 0.0;
        for (const auto& [k, d, t] : raysThrough(p, o, 40)) {
            for (float c : {0.0f, 1.5f}) {
                const IsvFrame f = frameWithGradient(c, row.integration, row.steps);
                glm::vec3 a;
                const glm::vec3 s = shader::isvShade(f, p, o, d, t.x, t.y, a);
                const double expected = quadratureEq7(p, o, d, t.x, t.y, c) * shader::kInvFourPi;
                const double rel = std::abs(s.x - expected) / expected;
                worst = std::max(worst, rel);
                EXPECT_LT(rel, row.bound) << row.name << " ray " << k << " c " << c;
                EXPECT_NEAR(a.x, std::exp(-exactDepth(p, o, d, t.x, t.y)), 2e-6) << "A = T_V(z_min, z_max)";
                EXPECT_EQ(s.x, s.y) << "a grey medium";
                EXPECT_EQ(a.x, a.z) << "a grey medium";
            }
        }
        std::printf("%-10s worst relative error against quadrature of Eq. 7: %.3g\n", row.name, worst);
    }
}

// Coloured shadows: with a chromatic extinction each channel has its own particle extinction (sigma times the tint)
// and its own light optical depth; each is the grey integral of that channel's particle, against quadrature.
TEST(IsvShade, ChromaticExtinctionIntegratesEachChannelOnItsOwn) {
    std::mt19937 rng(5);
    const IsvParticle p = toIsv(particleAt(Vec3(0.1, 1.0, -0.2), 0.6, rng, 6.0), 1.0);
    MapScope maps(&gradientVsm, &noShadow);
    const glm::vec3 o(-2.0f, 1.3f, 2.5f), tint(0.25f, 1.0f, 0.6f), channel(2.0f, 0.5f, 1.0f);
    const float c = 1.5f;
    const std::vector<CrossingRay> rays = raysThrough(p, o, 20);
    for (const auto& [k, d, t] : rays) {
        const IsvFrame f = frameWithGradient(c, shader::kIsvSimpson, 10, tint, channel);
        glm::vec3 a;
        const glm::vec3 s = shader::isvShade(f, p, o, d, t.x, t.y, a);
        for (int ch = 0; ch < 3; ++ch) {
            IsvParticle q = p;
            q.sigma = p.sigma * tint[ch];
            const double expected = quadratureEq7(q, o, d, t.x, t.y, c * channel[ch]) * shader::kInvFourPi;
            EXPECT_NEAR(s[ch], expected, 3e-5 * expected) << "ray " << k << " channel " << ch;
            EXPECT_NEAR(a[ch], std::exp(-exactDepth(q, o, d, t.x, t.y)), 2e-6) << "ray " << k << " channel " << ch;
        }
        EXPECT_GT(a.x, a.y) << "the red channel is the least attenuated";
    }
    EXPECT_GT(rays.size(), 10u);
}

TEST(IsvShade, AnalyticModeIsExactForConstantExtinction) {
    std::mt19937 rng(6);
    const IsvParticle p = toIsv(particleAt(Vec3(0.0, 1.0, 0.0), 0.5, rng, 3.0), 1.0);
    MapScope maps(&gradientVsm, &noShadow);
    const glm::vec3 o(0.3f, 1.1f, 3.0f), d = glm::normalize(p.centre - o);
    const glm::vec2 t = shader::isvRayTetrahedron(p, o, d);
    for (float c : {0.0f, 0.7f, 3.0f}) {
        IsvFrame f = frameWithGradient(c, shader::kIsvAnalytic, 1);
        glm::vec3 a;
        const glm::vec3 s = shader::isvShade(f, p, o, d, t.x, t.y, a);
        // sigma int_0^L e^(-sigma s) e^(-tau_L(s)) ds with tau_L linear along the ray, by quadrature.
        const double sigma = p.sigma, L = t.y - t.x;
        const double tau0 = c * (2.0 - (o.y + t.x * d.y)) / 2.0, tau1 = c * (2.0 - (o.y + t.y * d.y)) / 2.0;
        double sum = 0.0;
        const int n = 100000;
        for (int i = 0; i < n; ++i) {
            const double s0 = (i + 0.5) * L / n;
            sum += sigma * std::exp(-sigma * s0 - (tau0 + (tau1 - tau0) * s0 / L)) * L / n;
        }
        EXPECT_NEAR(s.x / shader::kInvFourPi, sum, 2e-5 * sum) << "c " << c;
        EXPECT_NEAR(a.x, std::exp(-sigma * L), 1e-6);
    }
}

TEST(IsvShade, EarlyOutSkipsThinFragmentsAndWastedPixelsShowThem) {
    std::mt19937 rng(7);
    const IsvParticle p = toIsv(particleAt(Vec3(0.0, 1.0, 0.0), 0.5, rng, 1.0), 1.0);
    MapScope maps(&gradientVsm, &noShadow);
    const glm::vec3 o(0.0f, 1.0f, 3.0f), d(0.0f, 0.0f, -1.0f);
    const glm::vec2 t = shader::isvRayTetrahedron(p, o, d);
    // The threshold applies to the thickest channel: blue here.
    IsvFrame f = frameWithGradient(0.0f, shader::kIsvSimpson, 1, glm::vec3(0.5f, 0.25f, 1.0f));
    glm::vec3 a;
    shader::isvShade(f, p, o, d, t.x, t.y, a);
    const float tau = -std::log(a.z);
    EXPECT_NEAR(-std::log(a.x), 0.5f * tau, 1e-5f * tau);
    f.threshold = 1.01f * tau;
    EXPECT_EQ(shader::isvShade(f, p, o, d, t.x, t.y, a), glm::vec3(0.0f));
    EXPECT_EQ(a, glm::vec3(1.0f));
    f.integration = shader::kIsvWasted;
    EXPECT_EQ(shader::isvShade(f, p, o, d, t.x, t.y, a), glm::vec3(1.0f, 0.0f, 0.0f));
    f.threshold = 0.99f * tau;
    EXPECT_EQ(shader::isvShade(f, p, o, d, t.x, t.y, a), glm::vec3(0.0f, 1.0f, 0.0f));
    f.integration = shader::kIsvSimpson;
    EXPECT_NE(shader::isvShade(f, p, o, d, t.x, t.y, a), glm::vec3(0.0f)) << "blue alone is above the threshold";
}

// -------------------------------------------------------------------------------------------------------------------
// The scene: a small particle cloud under a directional light, optionally over a floor.

// The cloud lit by a spot light above and to the side instead of the sun (beyond the thesis: a perspective shadow map).
Scene spotScene(Scene s) {
    s.directionalLights.clear();
    PointLight spot;
    spot.name = "spot";
    spot.position = Vec3(1.3, 2.9, 1.0);
    spot.intensity = Rgb(9.0, 8.5, 8.0);
    spot.distribution.kind = AngularDistribution::Kind::Spot;
    spot.distribution.axis = glm::normalize(Vec3(0.0, 0.9, 0.0) - spot.position);
    spot.distribution.spotExponent = 4.0;
    s.pointLights.push_back(spot);
    return s;
}

Scene cloudScene(int count, bool floor, int width = 48, int height = 36);

// The cloud lit by its sun, a bluish moon from the other side and the spot light of spotScene: three passes, two
// light types.
Scene threeLightScene(Scene s) {
    DirectionalLight moon = s.directionalLights.front();
    moon.name = "moon";
    moon.direction = glm::normalize(Vec3(-0.6, -0.8, 0.4));
    moon.irradiance = Rgb(0.8, 0.9, 1.2);
    s.directionalLights.push_back(moon);
    s.pointLights = spotScene(s).pointLights;
    return s;
}

// The scene lit by its light `light` alone (ISV's order: directional lights, then point lights).
Scene onlyLight(const Scene& s, std::size_t light) {
    Scene one = s;
    one.directionalLights.clear();
    one.pointLights.clear();
    if (light < s.directionalLights.size())
        one.directionalLights.push_back(s.directionalLights[light]);
    else
        one.pointLights.push_back(s.pointLights[light - s.directionalLights.size()]);
    return one;
}

Scene cloudScene(int count, bool floor, int width, int height) {
    Scene s;
    s.camera.position = Vec3(0.0, 1.2, 3.2);
    s.camera.target = Vec3(0.0, 0.9, 0.0);
    s.camera.fovY = 40.0;
    s.camera.width = width;
    s.camera.height = height;
    ParticleMedium m;
    m.name = "smoke";
    m.extinction = Rgb(1.5);
    m.albedo = Rgb(0.9, 0.85, 0.8);
    m.phase.kind = PhaseKind::IsoHgMix;
    m.phase.a = 0.7;
    m.phase.g = 0.5;
    ParticleGenerator g;
    g.count = count;
    g.seed = 3;
    g.region.centre = Vec3(0.0, 0.9, 0.0);
    g.region.size = Vec3(1.2, 0.8, 1.0);
    g.scale = 0.3;
    m.generator = g;
    s.particleMedia.push_back(m);
    DirectionalLight sun;
    sun.name = "sun";
    sun.direction = glm::normalize(Vec3(0.4, -1.0, -0.3));
    sun.irradiance = Rgb(3.0, 2.9, 2.7);
    s.directionalLights.push_back(sun);
    if (floor) {
        Material grey;
        grey.name = "grey";
        grey.albedo = Rgb(0.5);
        s.materials.push_back(grey);
        Mesh plane;
        plane.name = "floor";
        plane.transform.scale = Vec3(6.0, 1.0, 6.0);
        plane.material = "grey";
        s.meshes.push_back(plane);
        Mesh box;
        box.name = "occluder";
        box.source = Mesh::Source::Box;
        box.transform.translate = Vec3(-0.3, 1.9, 0.2);
        box.transform.scale = Vec3(0.4, 0.1, 0.4);
        box.material = "grey";
        s.meshes.push_back(box);
    }
    return s;
}

TEST(IsvVsm, SlicesHoldTheOpticalDepthFromTheLightToEachSlice) {
  for (const bool point : {false, true}) {
    Scene scene = cloudScene(40, false);
    scene.particleMedia[0].extinction = Rgb(0.75, 1.5, 0.3);  // per channel: coloured shadows
    if (point) {  // a perspective map from a spot light above and to the side
        scene.directionalLights.clear();
        PointLight spot;
        spot.name = "spot";
        spot.position = Vec3(1.5, 3.0, 1.0);
        scene.pointLights.push_back(spot);
    }
    Settings settings;
    settings.vsmResolution = 32;
    settings.vsmSlices = 8;
    const PreparedScene p = prepareScene(scene, settings, "");
    ASSERT_TRUE(p.vsm);
    ASSERT_TRUE(p.chromatic);
    const glm::vec3 tint(0.5f, 1.0f, 0.2f);
    EXPECT_EQ(p.frame.media[0].tint, tint);
    const shader::IsvLightSpace& g = p.frame.vsm;
    const std::vector<float> slices = slicesFromSlabs(vsmSlabsCpu(p, 0, nullptr), g);
    double worst = 0.0, largest = 0.0;
    for (int y = 0; y < g.size; y += 3)
        for (int x = 0; x < g.size; x += 3) {
            glm::vec3 o, d;
            float cosine;
            shader::isvGridRay(g, float(x) + 0.5f, float(y) + 0.5f, o, d, cosine);
            for (int s = 0; s < g.slices; ++s) {
                double tau = 0.0;
                for (const IsvParticle& q : p.particles) {
                    const glm::vec2 t = shader::isvRayTetrahedron(q, o, d);
                    if (t.x < t.y)
                        tau += exactDepth(q, glm::dvec3(o), glm::dvec3(d), t.x,
                                          std::min<double>(t.y, shader::isvRayDistance(g, s * g.depthStep, cosine)));
                }
                const float* stored = &slices[((std::size_t(s) * g.size + y) * g.size + x) * kVsmChannels];
                worst = std::max(worst, std::abs(stored[1] - tau));
                largest = std::max(largest, tau);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(stored[c], tau * tint[c], 1e-4 + 1e-4 * tau)
                        << "texel " << x << "," << y << " slice " << s << " channel " << c;
            }
        }
    EXPECT_GT(largest, 0.5) << "the cloud should be optically thick somewhere";
    EXPECT_EQ(g.perspective, point ? 1 : 0);
  }
}

// -------------------------------------------------------------------------------------------------------------------
// Compositing (Sec. 3.2)

TEST(IsvComposite, OverlappingParticlesBlendBackToFrontAndAReversedOrderFails) {
    for (int count : {2, 3}) {
        Scene scene = cloudScene(0, false, 16, 16);
        std::mt19937 rng(9);
        // One medium per particle, each of its own colour: blending is then not commutative.
        // The media's extinctions differ per channel too (coloured shadows): each channel is blended by its own A.
        const Rgb albedos[3] = {Rgb(0.9, 0.2, 0.2), Rgb(0.2, 0.2, 0.9), Rgb(0.2, 0.9, 0.2)};
        const Rgb extinctions[3] = {Rgb(1.5), Rgb(0.4, 1.0, 2.0), Rgb(2.0, 0.8, 0.6)};
        scene.particleMedia.resize(std::size_t(count), scene.particleMedia[0]);
        for (int i = 0; i < count; ++i) {
            ParticleMedium& m = scene.particleMedia[std::size_t(i)];
            m.name = "medium " + std::to_string(i);
            m.albedo = albedos[i];
            m.extinction = extinctions[i];
            m.particles.push_back(particleAt(Vec3(0.05 * i, 0.9, -0.35 * i), 0.5, rng, 4.0));
        }
        Settings settings;
        const PreparedScene p = prepareScene(scene, settings, "");
        const std::vector<float> vsm = slicesFromSlabs(vsmSlabsCpu(p, 0, nullptr), p.frame.vsm);
        const std::vector<glm::vec4> background(std::size_t(p.width) * p.height, glm::vec4(0.2f, 0.3f, 0.4f, shader::kInfinity));
        const std::vector<std::uint32_t> order = backToFront(p);
        ASSERT_EQ(order.front(), std::uint32_t(count - 1)) << "the farthest particle comes first";
        const std::vector<glm::vec4> image = compositeCpu(p, background, vsm, noShadow, order, 0, nullptr);
        std::vector<std::uint32_t> reversed(order.rbegin(), order.rend());
        const std::vector<glm::vec4> wrong = compositeCpu(p, background, vsm, noShadow, reversed, 0, nullptr);

        // The centre pixel by hand: C = s_0 + A_0 (s_1 + A_1 (... + A_n background)), nearest first.
        MapScope maps(&vsm, &noShadow);
        glm::vec3 o, d;
        shader::cameraRay(p.camera, 8.5f, 8.5f, o, d);
        glm::vec3 c(0.2f, 0.3f, 0.4f);
        float a = 1.0f;
        int hits = 0;
        for (int i = count - 1; i >= 0; --i) {  // farthest first
            const glm::vec2 t = shader::isvRayTetrahedron(p.particles[std::size_t(i)], o, d);
            if (!(t.x < t.y)) continue;
            ++hits;
            glm::vec3 transmittance;
            const glm::vec3 s = shader::isvShade(p.frame, p.particles[std::size_t(i)], o, d, t.x, t.y, transmittance);
            c = s + transmittance * c;
            a *= shader::isvMeanChannel(transmittance);
            if (i > 0) {
                EXPECT_NE(transmittance.x, transmittance.z) << "a chromatic particle";
            }
        }
        ASSERT_EQ(hits, count) << "the centre ray crosses every particle";
        const glm::vec4 got = image[8 * 16 + 8], bad = wrong[8 * 16 + 8];
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(got[k], c[k], 1e-6f + 1e-5f * c[k]);
        EXPECT_NEAR(got.w, a, 1e-6f);
        EXPECT_GT(glm::length(glm::vec3(bad) - c), 0.02f * glm::length(c)) << "the order must matter here";
    }
}

// -------------------------------------------------------------------------------------------------------------------
// Animation (Sec. 3.14)

TEST(IsvAnimation, TheSimulationIsDeterministicSettlesOnMovedTargetsAndImpulsesPushAway) {
    const Scene scene = cloudScene(200, false);
    const std::vector<Particle> rest = scene.particleMedia[0].allParticles();
    ParticleSimulation sim;
    EXPECT_EQ(simulateParticles(rest, sim).front().centre, rest.front().centre) << "zero steps move nothing";

    // The region moved by 0.5 m: after 10 s (critically damped enough) every particle is within 1 mm of its target.
    sim.steps = 600;
    sim.offset = Vec3(0.5, 0.0, -0.2);
    const std::vector<Particle> settled = simulateParticles(rest, sim);
    double worst = 0.0;
    for (std::size_t i = 0; i < rest.size(); ++i)
        worst = std::max(worst, glm::length(settled[i].centre - (rest[i].centre + sim.offset)));
    EXPECT_LT(worst, 1e-3);

    // An impulse at the cloud's centre: near particles move away from it, far ones stay; bit-identical reruns.
    ParticleSimulation push;
    push.steps = 10;
    push.impulses.push_back({2, Vec3(0.0, 0.9, 0.0), 0.4, 2.0});
    const std::vector<Particle> a = simulateParticles(rest, push), b = simulateParticles(rest, push);
    int pushed = 0;
    for (std::size_t i = 0; i < rest.size(); ++i) {
        EXPECT_EQ(a[i].centre, b[i].centre);
        const double before = glm::length(rest[i].centre - push.impulses[0].position);
        const double after = glm::length(a[i].centre - push.impulses[0].position);
        if (before < 0.4) {
            EXPECT_GT(after, before) << "particle " << i;
            ++pushed;
        } else {
            EXPECT_EQ(a[i].centre, rest[i].centre) << "particle " << i;
        }
    }
    EXPECT_GT(pushed, 5);
}

// impulsePeakSeconds against the simulation itself: one particle pushed at step 0, stepped finely (dt = 0.1 ms, where
// semi-implicit Euler follows the exact spring to well within a step), is farthest from its target at the formula's
// time, within two steps, in each regime of the spring; without stiffness it has covered 95 % of its way by then.
TEST(IsvAnimation, ImpulsePeakTimeIsWhenThePushedParticleIsFarthest) {
    struct Spring {
        double stiffness, viscosity;
        const char* regime;
    };
    for (const Spring& spring : {Spring{30.0, 4.0, "underdamped (the default)"}, Spring{25.0, 10.0, "critical"},
                                 Spring{4.0, 10.0, "overdamped"}, Spring{400.0, 0.0, "undamped"}}) {
        ParticleSimulation sim;
        sim.timeStep = 1e-4;
        sim.stiffness = spring.stiffness;
        sim.viscosity = spring.viscosity;
        const double peak = impulsePeakSeconds(sim, 10.0);
        // The particle sits 1 m from the impulse, inside its radius: pushed along +x at 0.5 m/s.
        sim.impulses.push_back({0, Vec3(-1.0, 0.0, 0.0), 2.0, 1.0});
        std::vector<Particle> particle(1);
        particle[0].centre = Vec3(0.0);
        particle[0].scale = 0.1;
        int farthest = 0;
        double best = -1.0;
        for (int steps = 1; steps <= int(std::ceil(1.5 * peak / sim.timeStep)); steps += 1) {
            if (std::abs(steps * sim.timeStep - peak) > 0.05 * peak + 10 * sim.timeStep) continue;  // near the peak
            sim.steps = steps;
            const double x = simulateParticles(particle, sim)[0].centre.x;
            if (x > best) best = x, farthest = steps;
        }
        EXPECT_NEAR(farthest * sim.timeStep, peak, 2.0 * sim.timeStep) << spring.regime;
    }
    ParticleSimulation coast;
    coast.stiffness = 0.0;
    coast.viscosity = 2.0;
    EXPECT_DOUBLE_EQ(impulsePeakSeconds(coast, 10.0), 1.5);  // 1 - e^{-3} = 95 % of v / c
    EXPECT_DOUBLE_EQ(impulsePeakSeconds(coast), 1.0) << "at most the limit";
    coast.viscosity = 0.0;
    EXPECT_DOUBLE_EQ(impulsePeakSeconds(coast, 0.5), 0.5) << "a particle that never stops: the limit";
}

TEST(IsvAnimation, ProjectsStoreTheSimulationAndRefuseAnUnstableOne) {
    const std::string base = tyndall::test::sourceDir() + "/projects/isv/smoke.json";
    const Project p = loadProject(techniqueCatalogue(), base,
                                  {"particleMedia[0].simulation={\"steps\": 30, \"offset\": [0.2, 0, 0], "
                                   "\"impulses\": [{\"step\": 3, \"position\": [0, 1, 0]}]}"});
    ASSERT_TRUE(p.scene.particleMedia[0].simulation.has_value());
    EXPECT_EQ(p.scene.particleMedia[0].simulation->impulses.size(), 1u);
    const std::string saved = ::testing::TempDir() + "/isv-simulation.json";
    saveProject(p, saved);
    const Project again = loadProject(techniqueCatalogue(), saved);
    EXPECT_EQ(projectHash(again), projectHash(p));
    EXPECT_NE(projectHash(again), projectHash(loadProject(techniqueCatalogue(), base)));
    try {
        (void)loadProject(techniqueCatalogue(), base,
                          {"particleMedia[0].simulation={\"timeStep\": 0.9, \"stiffness\": 30}"});
        ADD_FAILURE() << "an unstable time step must be refused";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("simulation.timeStep"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("blow up"), std::string::npos) << e.what();
    }
}

// -------------------------------------------------------------------------------------------------------------------
// The technique

RenderResult renderIsv(const Scene& scene, const std::map<std::string, ParamValue>& values) {
    IsvTechnique technique;
    RenderRequest request;
    request.scene = scene;
    request.params = technique.defaultParams();
    for (const auto& [name, value] : values)
        request.params.set(name, value);
    return technique.render(request, {});
}

TEST(IsvTechnique, RefusesWhatItCannotRender) {
    IsvTechnique t;
    HomogeneousMedium fog;
    fog.name = "fog";
    EXPECT_FALSE(t.supports(fog).supported);
    PointLight point;
    point.name = "bulb";
    EXPECT_TRUE(t.supports(point).supported) << "point and spot lights, through a perspective shadow map";
    AreaLight area;
    area.name = "panel";
    EXPECT_FALSE(t.supports(area).supported);
    DirectionalLight gobo;
    gobo.name = "beam";
    gobo.gobo = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
    EXPECT_FALSE(t.supports(gobo).supported);
    ParticleMedium tinted;
    tinted.name = "smoke";
    EXPECT_TRUE(t.supports(tinted).supported);
    tinted.extinction = Rgb(1.5, 1.0, 0.5);
    EXPECT_TRUE(t.supports(tinted).supported) << "coloured shadows";

    // A point light inside the cloud: its perspective maps cannot hold the particles. Named, also beside other lights.
    Scene inside = cloudScene(4, false);
    PointLight bulb;
    bulb.name = "bulb";
    bulb.position = Vec3(0.0, 0.9, 0.0);
    inside.pointLights.push_back(bulb);
    RenderRequest request;
    request.scene = inside;
    request.params = t.defaultParams();
    try {
        t.check(request);
        ADD_FAILURE() << "a point light inside the cloud must be refused";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().field, "lights[bulb].position") << e.what();
    }
}

// A reduced stage of the studio's progressive resolution (1/16 of the image in each axis) reduces the shadow maps in
// proportion, down to their floors, and drops supersampling; a value already below a floor stays; full resolution
// reduces nothing. The reduced image still resembles the full one (the same cloud, lit and shadowed).
TEST(IsvTechnique, APreviewReducesTheShadowMapsWithinFloors) {
    IsvTechnique t;
    ParamSet params = t.defaultParams();
    params.set("supersampling", std::int64_t(2));
    EXPECT_EQ(t.reduceForPreview(params, 1), "");
    EXPECT_EQ(params.getInt("shadowMapResolution"), 1024);
    EXPECT_EQ(t.reduceForPreview(params, 16), "coarser shadow maps");
    EXPECT_EQ(params.getInt("shadowMapResolution"), 64);
    EXPECT_EQ(params.getInt("vsmResolution"), 16);
    EXPECT_EQ(params.getInt("vsmSlices"), 4);
    EXPECT_EQ(params.getInt("supersampling"), 1);
    ParamSet half = t.defaultParams();
    half.set("vsmResolution", std::int64_t(8));
    EXPECT_EQ(t.reduceForPreview(half, 2), "coarser shadow maps");
    EXPECT_EQ(half.getInt("shadowMapResolution"), 512);
    EXPECT_EQ(half.getInt("vsmResolution"), 8);
    EXPECT_EQ(half.getInt("vsmSlices"), 8);

    RenderRequest request;
    request.scene = cloudScene(60, true);
    request.scene.camera.width = request.scene.camera.height = 32;
    request.params = t.defaultParams();
    const Image full = t.render(request, {}).image;
    ASSERT_EQ(t.reduceForPreview(request.params, 4), "coarser shadow maps");
    const Image reduced = t.render(request, {}).image;
    const Metrics m = computeMetrics(reduced, full);
    std::printf("a preview's coarser shadow maps: energy %+.2f %%, relMSE %.3g against the full maps\n", m.energyBias,
                m.relMSE);
    EXPECT_LT(std::abs(m.energyBias), 3.0) << "measured -0.83 %: coarser maps change the shadows' edges, not the image";
}

Image renderReference(const Scene& scene) {
    std::unique_ptr<Technique> reference = createTechnique("reference");
    RenderRequest request;
    request.scene = scene;
    request.params = reference->defaultParams();
    request.params.set("mode", std::string("single"));
    request.spp = 1024;
    request.seed = 5;
    return reference->render(request, {}).image;
}

const Image& referenceImage() {
    static const Image image = [] {
        std::unique_ptr<Technique> reference = createTechnique("reference");
        RenderRequest request;
        request.scene = cloudScene(60, true);
        request.params = reference->defaultParams();
        request.params.set("mode", std::string("single"));
        request.spp = 1024;
        request.seed = 5;
        return reference->render(request, {}).image;
    }();
    return image;
}

// ISV against the path-traced reference (single scattering) on a cloud of 60 particles over a floor with an occluder:
// the energy bias and relMSE per integration mode. ISV is biased by design; the bounds sit at about 1.3x what was
// measured (printed), so that a regression in any pass fails while the thesis' own approximations pass.
TEST(IsvTechnique, AgainstTheReferencePerIntegrationMode) {
    const Image& ref = referenceImage();
    struct Row {
        const char* name;
        std::string integration;
        int steps;
        double maxBias, maxRelMse;
    };
    const Row rows[] = {{"simpson 1", "simpson", 1, 2.0, 0.017},
                        {"simpson 4", "simpson", 4, 1.5, 0.0095},
                        {"taylor", "taylor", 1, 6.0, 0.082},
                        {"analytic", "analytic", 1, 2.0, 0.1}};
    for (const Row& row : rows) {
        const RenderResult r = renderIsv(cloudScene(60, true), {{"device", std::string("cpu")},
                                                              {"integration", row.integration},
                                                              {"steps", std::int64_t(row.steps)},
                                                              {"supersampling", std::int64_t(2)},
                                                              {"vsmResolution", std::int64_t(64)}});
        const Metrics m = computeMetrics(r.image, ref);
        std::printf("%-10s energy bias %+.2f %%, relMSE %.4g, reference noise %.3g\n", row.name, m.energyBias,
                    m.relMSE, m.referenceNoiseRelMSE.value_or(0.0));
        EXPECT_LT(std::abs(m.energyBias), row.maxBias) << row.name;
        EXPECT_LT(m.relMSE, row.maxRelMse) << row.name;
    }
}

// A spot light (beyond the thesis): the perspective volumetric shadow map, 1/r^2 and the spot's lobe varying along each
// fragment, shadow rays for the surfaces. Bounds at about 1.3x what was measured (printed).
TEST(IsvTechnique, SpotLightAgainstTheReference) {
    const Scene scene = spotScene(cloudScene(60, true));
    const Image ref = renderReference(scene);
    const RenderResult r = renderIsv(scene, {{"device", std::string("cpu")},
                                             {"steps", std::int64_t(4)},
                                             {"supersampling", std::int64_t(2)},
                                             {"vsmResolution", std::int64_t(64)}});
    const Metrics m = computeMetrics(r.image, ref);
    std::printf("spot light, simpson 4: energy bias %+.2f %%, relMSE %.4g, reference noise %.3g\n", m.energyBias,
                m.relMSE, m.referenceNoiseRelMSE.value_or(0.0));
    EXPECT_LT(std::abs(m.energyBias), 2.6);
    EXPECT_LT(m.relMSE, 0.0013);
}

// Several lights (beyond the thesis, which draws one): one pass per light, summed. Each light alone and all three
// together: the sum of the single-light images equals the three-light image to float rounding, transmittance included,
// and each light adds a visible share (a pass that ignored its light would fail both).
TEST(IsvTechnique, SeveralLightsSumTheirSingleLightImages) {
    const Scene all = threeLightScene(cloudScene(60, true));
    const std::map<std::string, ParamValue> settings{{"device", std::string("cpu")},
                                                     {"steps", std::int64_t(2)},
                                                     {"supersampling", std::int64_t(2)},
                                                     {"vsmResolution", std::int64_t(48)}};
    const RenderResult together = renderIsv(all, settings);
    EXPECT_EQ(together.image.metadata.at("isv:lights"), "3");
    const int w = together.image.width(), h = together.image.height();
    std::vector<double> sum(std::size_t(w) * h * 3, 0.0);
    double total = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                total += together.image.at(x, y, c);
    for (std::size_t light = 0; light < 3; ++light) {
        const RenderResult alone = renderIsv(onlyLight(all, light), settings);
        double share = 0.0, worstAlpha = 0.0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                for (int c = 0; c < 3; ++c) {
                    sum[(std::size_t(y) * w + x) * 3 + c] += alone.image.at(x, y, c);
                    share += alone.image.at(x, y, c);
                }
                worstAlpha =
                    std::max(worstAlpha, double(std::abs(alone.image.at(x, y, 3) - together.image.at(x, y, 3))));
            }
        std::printf("light %zu alone: %.1f %% of the three-light image's energy\n", light, 100.0 * share / total);
        EXPECT_GT(share, 0.1 * total) << "light " << light;
        EXPECT_EQ(worstAlpha, 0.0) << "light " << light << ": the transmittance does not depend on the light";
    }
    double peak = 0.0, worst = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                const double v = together.image.at(x, y, c);
                peak = std::max(peak, v);
                worst = std::max(worst, std::abs(v - sum[(std::size_t(y) * w + x) * 3 + c]));
            }
    std::printf("three lights against the sum of each alone: worst difference %.3g of the peak %.3g\n", worst, peak);
    EXPECT_LT(worst, 1e-5 * peak);
}

// Each light alone, two lights (the sun and the spot) and three (with the moon) against the reference, which samples
// every light: bounds at about 1.3x what was measured (printed), as for one light. The errors are the single lights'
// (the sun's self-shadowed cloud as in AgainstTheReferencePerIntegrationMode, the moon's back light through it).
TEST(IsvTechnique, SeveralLightsAgainstTheReference) {
    const Scene three = threeLightScene(cloudScene(60, true));
    Scene two = three;
    two.directionalLights.pop_back();  // the sun and the spot
    struct Case {
        std::string name;
        Scene scene;
        int lights;
        double maxBias, maxRelMse;
    };
    // Measured (energy bias, relMSE): sun -0.30 %, 7.2e-3; moon +0.73 %, 1.4e-3; spot +1.93 %, 1.0e-3; two lights
    // +0.03 %, 8.6e-3; three lights +0.17 %, 1.2e-2. The lights' errors add per pixel, and relMSE's denominator
    // (ref^2 + 0.01) is absolute, so in the many dim pixels (ref ~ 0.1) the brighter multi-light image weighs them more
    // than each light's own image does; energy biases of opposite sign cancel. Bias bounds of at least 0.5 %.
    const Case cases[] = {{"sun alone", onlyLight(three, 0), 1, 0.5, 0.0095},
                          {"moon alone", onlyLight(three, 1), 1, 1.0, 0.0018},
                          {"spot alone", onlyLight(three, 2), 1, 2.6, 0.0013},
                          {"two lights", two, 2, 0.5, 0.011},
                          {"three lights", three, 3, 0.5, 0.016}};
    for (const Case& c : cases) {
        const Image ref = renderReference(c.scene);
        const RenderResult r = renderIsv(c.scene, {{"device", std::string("cpu")},
                                                   {"steps", std::int64_t(4)},
                                                   {"supersampling", std::int64_t(2)},
                                                   {"vsmResolution", std::int64_t(64)}});
        EXPECT_EQ(r.image.metadata.at("isv:lights"), std::to_string(c.lights));
        const Metrics m = computeMetrics(r.image, ref);
        std::printf("%-12s simpson 4: energy bias %+.2f %%, relMSE %.4g, reference noise %.3g\n", c.name.c_str(),
                    m.energyBias, m.relMSE, m.referenceNoiseRelMSE.value_or(0.0));
        EXPECT_LT(std::abs(m.energyBias), c.maxBias) << c.name;
        EXPECT_LT(m.relMSE, c.maxRelMse) << c.name;
    }
}

// The mean of each channel over the image.
glm::dvec3 channelMeans(const Image& image) {
    glm::dvec3 sum(0.0);
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            for (int c = 0; c < 3; ++c)
                sum[c] += image.at(x, y, c);
    return sum / double(image.width() * image.height());
}

// A smoke whose extinction is chromatic (beyond the thesis, whose shadows are grey, Fig. 23): it lets red through and
// stops blue, so its shadow on the floor is red and its self-shadowed core reddens. Against the reference per channel;
// bounds at about 1.3x what was measured (printed). A grey ISV render of the same scene must miss the colour.
TEST(IsvTechnique, ColouredShadowsAgainstTheReference) {
    Scene scene = cloudScene(60, true);
    scene.particleMedia[0].extinction = Rgb(0.6, 1.5, 3.0);
    const Image ref = renderReference(scene);
    const std::map<std::string, ParamValue> settings{{"device", std::string("cpu")},
                                                     {"steps", std::int64_t(4)},
                                                     {"supersampling", std::int64_t(2)},
                                                     {"vsmResolution", std::int64_t(64)}};
    const RenderResult r = renderIsv(scene, settings);
    const Metrics m = computeMetrics(r.image, ref);
    const glm::dvec3 isv = channelMeans(r.image), truth = channelMeans(ref);
    std::printf("coloured shadows, simpson 4: energy bias %+.2f %%, relMSE %.4g, reference noise %.3g; channel means "
                "ISV %.4f %.4f %.4f, reference %.4f %.4f %.4f\n",
                m.energyBias, m.relMSE, m.referenceNoiseRelMSE.value_or(0.0), isv.x, isv.y, isv.z, truth.x, truth.y,
                truth.z);
    EXPECT_LT(std::abs(m.energyBias), 1.0);
    EXPECT_LT(m.relMSE, 0.0098);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(isv[c], truth[c], 0.02 * truth[c]) << "channel " << c;
    // The red-to-blue balance, which grey shadows get wrong: the same scene with the green channel's extinction in
    // every channel.
    Scene grey = scene;
    grey.particleMedia[0].extinction = Rgb(1.5);
    const glm::dvec3 wrong = channelMeans(renderIsv(grey, settings).image);
    const double balance = isv.x / isv.z, truthBalance = truth.x / truth.z, greyBalance = wrong.x / wrong.z;
    std::printf("red / blue: ISV %.4f, reference %.4f, grey extinction %.4f\n", balance, truthBalance, greyBalance);
    EXPECT_NEAR(balance, truthBalance, 0.012 * truthBalance);
    EXPECT_GT(std::abs(greyBalance - truthBalance), 5.0 * std::abs(balance - truthBalance));
}

// -------------------------------------------------------------------------------------------------------------------
// The GPU passes against the CPU model

class IsvGpu : public tyndall::test::TechniqueGpuTest {};

// Per pixel the sum of chord lengths through the (not culled) particles: the GPU's proxies, rasterised and blended
// additively, against exact ray-tetrahedron intersection at each pixel centre. Coverage must agree (a pixel centre
// on a proxy's edge may go either way); the chords within `relTol`.
void expectChordsMatch(const Scene& scene, float nearPlane, int minCulled, double relTol) {
    Settings settings;
    settings.nearPlane = nearPlane;
    settings.selfShadowing = false;
    PreparedScene p = prepareScene(scene, settings, "");
    p.frame.integration = shader::kIsvChord;
    int culled = 0;
    for (const IsvParticle& q : p.particles)
        culled += inFrontOfNearPlane(p, q) ? 0 : 1;
    EXPECT_GE(culled, minCulled);
    GpuRenderer gpu;
    const GpuOutput out = gpu.render(p, {});
    const std::vector<glm::vec4> background(out.pixels.size(), glm::vec4(0.0f, 0.0f, 0.0f, shader::kInfinity));
    const std::vector<glm::vec4> cpu = compositeCpu(p, background, {}, {}, backToFront(p), 0, nullptr);
    int coverage = 0, chords = 0, lit = 0;
    double worst = 0.0;
    for (std::size_t i = 0; i < cpu.size(); ++i) {
        const float g = out.pixels[i].x, c = cpu[i].x;
        lit += c > 0.0f ? 1 : 0;
        if ((g > 0.0f) != (c > 0.0f)) ++coverage;
        const double rel = std::abs(g - c) / std::max(c, 0.01f);
        worst = std::max(worst, rel);
        if (rel > relTol) ++chords;
    }
    std::printf("chords: %d pixels with medium, %d culled particles; coverage differs at %d pixels, chords beyond %g "
                "at %d, worst relative difference %.2g\n",
                lit, culled, coverage, relTol, chords, worst);
    EXPECT_GT(lit, int(cpu.size() / 8));
    EXPECT_LE(coverage, 2);
    EXPECT_EQ(chords, 0);
}

// The rasteriser snaps proxy vertices to 1/256 pixel (lavapipe's subpixel precision). A face seen nearly edge-on has
// a steep 1/z gradient in screen space, so the snap moves its interpolated depth: 1e-3 of the chord at most (1.5e-4 m)
// for a cloud 1.5-3 m away, and up to 3 cm (1.3 % of the sum of chords) for tetrahedra 8-30 cm from the camera.
TEST_F(IsvGpu, ProxyChordsEqualExactChordsOutsideTheCloud) {
    expectChordsMatch(cloudScene(80, false, 64, 48), 0.05f, 0, 2e-3);
}

// Near-plane handling (thesis Sec. 2.3.4: culled): with the camera inside the cloud, both paths drop the same
// particles and agree on the rest.
TEST_F(IsvGpu, CameraInsideTheCloudCullsTheSameParticles) {
    Scene scene = cloudScene(300, false, 64, 48);
    scene.camera.position = Vec3(0.1, 0.9, 0.2);
    scene.camera.target = Vec3(0.0, 0.8, -1.0);
    expectChordsMatch(scene, 0.05f, 3, 0.02);
}

// The proxies' producer is selectable: the mesh shader where the device has VK_EXT_mesh_shader, else a clear refusal
// of `proxies = mesh`; auto takes what the device has and the image says which ran.
TEST_F(IsvGpu, ProxiesProducerFollowsTheDevice) {
    const bool hasMesh = gpu::sharedContext()->device().meshShader;
    const Scene scene = cloudScene(20, false, 16, 12);
    const RenderResult automatic = renderIsv(scene, {{"device", std::string("gpu")}});
    EXPECT_EQ(automatic.image.metadata.at("isv:proxies"), hasMesh ? "mesh" : "geometry");
    EXPECT_EQ(renderIsv(scene, {{"device", std::string("gpu")}, {"proxies", std::string("geometry")}})
                  .image.metadata.at("isv:proxies"),
              "geometry");
    if (hasMesh) {
        EXPECT_EQ(renderIsv(scene, {{"device", std::string("gpu")}, {"proxies", std::string("mesh")}})
                      .image.metadata.at("isv:proxies"),
                  "mesh");
        return;
    }
    try {
        renderIsv(scene, {{"device", std::string("gpu")}, {"proxies", std::string("mesh")}});
        ADD_FAILURE() << "proxies = mesh must be refused on a device without mesh shaders";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().field, "proxies");
        EXPECT_NE(std::string(e.what()).find("VK_EXT_mesh_shader"), std::string::npos) << e.what();
    }
}

// A scene beyond the device's limits is refused before anything is allocated, naming the field to change: the
// particles, the maps, the rendering resolution, coloured shadows without dual-source blending. Checked against
// shrunken limits (the real device takes the test scene).
TEST(IsvLimits, WhatTheDeviceCannotHoldIsRefusedNamingTheField) {
    Scene scene = cloudScene(40, true, 48, 36);
    Settings settings;
    settings.vsmResolution = 64;
    settings.vsmSlices = 16;
    settings.shadowMapResolution = 256;
    const PreparedScene p = prepareScene(scene, settings, "");
    gpu::DeviceInfo device;
    device.name = "small";
    device.dualSrcBlend = true;
    device.maxStorageBufferRange = 1u << 30;
    device.maxImageDimension2D = device.maxFramebufferWidth = device.maxFramebufferHeight = 4096;
    device.maxImageArrayLayers = 256;
    EXPECT_FALSE(deviceLimitProblem(p, device).has_value());
    auto fieldOf = [&](const gpu::DeviceInfo& d, const PreparedScene& q) {
        const std::optional<InputError> e = deviceLimitProblem(q, d);
        if (!e) return std::string("none");
        EXPECT_NE(e->message().find("'small'"), std::string::npos) << e->message();
        return e->where().field;
    };
    gpu::DeviceInfo small = device;
    small.maxStorageBufferRange = 40 * sizeof(shader::IsvParticle) - 1;
    EXPECT_EQ(fieldOf(small, p), "particleMedia");
    small.maxStorageBufferRange = 64 * 64 * 16 * 4 - 1;  // the particles fit, the shadow map's slices do not
    EXPECT_EQ(fieldOf(small, p), "vsmResolution");
    small = device;
    small.maxImageArrayLayers = 8;
    EXPECT_EQ(fieldOf(small, p), "vsmSlices");
    small = device;
    small.maxImageDimension2D = 40;
    EXPECT_EQ(fieldOf(small, p), "supersampling");
    Scene coloured = scene;
    coloured.particleMedia[0].extinction = Rgb(0.5, 1.0, 2.0);
    const PreparedScene c = prepareScene(coloured, settings, "");
    small = device;
    small.dualSrcBlend = false;
    EXPECT_EQ(fieldOf(small, c), "device");
    EXPECT_EQ(fieldOf(small, p), "none") << "grey particles need no dual-source blending";
    small.maxStorageBufferRange = 64 * 64 * 16 * 4;  // the grey map fits; the RGBA one would not
    small.dualSrcBlend = true;
    EXPECT_EQ(fieldOf(small, p), "none");
    EXPECT_EQ(fieldOf(small, c), "vsmResolution");
}

// The device's limits are checked for every light's pass, and for a view without a light too (its one pass lights
// nothing but still allocates): a rendering resolution beyond the device's images is refused under device = gpu,
// naming the field, and under auto the view falls back to the CPU model, with no light as with two.
TEST_F(IsvGpu, EveryPassIsCheckedAgainstTheDevice) {
    const std::uint32_t side = gpu::sharedContext()->device().maxImageDimension2D;
    for (int lights : {0, 2}) {
        Scene scene = cloudScene(10, false, int(side / 8 + 8), 2);  // the sun
        if (lights == 0)
            scene.directionalLights.clear();
        else
            scene.pointLights = spotScene(scene).pointLights;  // the sun and the spot
        try {
            renderIsv(scene, {{"device", std::string("gpu")}, {"supersampling", std::int64_t(8)}});
            ADD_FAILURE() << lights << " lights: a rendering resolution beyond the device must be refused";
        } catch (const InputError& e) {
            EXPECT_EQ(e.where().field, "supersampling") << e.what();
        }
        const RenderResult r = renderIsv(scene, {{"device", std::string("auto")}, {"supersampling", std::int64_t(8)}});
        EXPECT_EQ(r.image.metadata.at("device"), "cpu") << lights << " lights";
        ASSERT_EQ(r.image.metadata.count("isv:fallback"), 1u) << lights << " lights";
        EXPECT_EQ(r.image.metadata.at("isv:fallback").rfind("supersampling", 0), 0u) << lights << " lights";
    }
}

// Where both producers can run, they draw the same proxies: the same chords, and the same image in both passes (the
// volumetric shadow map's slabs and the camera's sorted particles, whose order blending depends on).
TEST_F(IsvGpu, MeshAndGeometryProducersAgree) {
    if (!gpu::sharedContext()->device().meshShader) GTEST_SKIP() << "the device has no mesh shaders";
    Settings settings;
    settings.selfShadowing = false;
    PreparedScene chords = prepareScene(cloudScene(300, false, 64, 48), settings, "");
    chords.frame.integration = shader::kIsvChord;
    GpuRenderer gpu;
    const GpuOutput a = gpu.render(chords, {}, Proxies::Geometry), b = gpu.render(chords, {}, Proxies::Mesh);
    ASSERT_TRUE(b.meshProxies);
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
        ASSERT_NEAR(a.pixels[i].x, b.pixels[i].x, 1e-5f * std::max(1.0f, a.pixels[i].x)) << "pixel " << i;
    const Scene scene = cloudScene(300, true, 64, 48);
    const RenderResult geometry = renderIsv(scene, {{"device", std::string("gpu")}, {"proxies", std::string("geometry")}});
    const RenderResult mesh = renderIsv(scene, {{"device", std::string("gpu")}, {"proxies", std::string("mesh")}});
    const Metrics m = computeMetrics(mesh.image, geometry.image);
    EXPECT_LT(m.relMSE, 1e-10);
}

TEST_F(IsvGpu, GpuMatchesTheCpuModel) {
    for (const char* integration :
         {"simpson", "analytic", "taylor", "two media", "spot light", "coloured", "three lights"}) {
        Scene scene = cloudScene(60, true, 40, 30);
        if (std::string(integration) == "spot light") {
            scene = spotScene(scene);
            integration = "simpson";
        }
        if (std::string(integration) == "three lights") {
            scene = threeLightScene(scene);
            integration = "simpson";
        }
        const bool coloured = std::string(integration) == "coloured";
        if (coloured) {
            // Coloured shadows: the RGB volumetric shadow map and dual-source blending, with a grey and a chromatic
            // medium in one view.
            if (!gpu::sharedContext()->device().dualSrcBlend) continue;
            scene.particleMedia[0].extinction = Rgb(0.6, 1.5, 3.0);
            integration = "two media";
        }
        if (std::string(integration) == "two media") {
            // A second medium of another colour and phase function: the media array's layout and the run-time
            // phase kind.
            ParticleMedium second = scene.particleMedia[0];
            second.name = "dust";
            second.albedo = Rgb(0.2, 0.5, 0.9);
            second.phase = PhaseFunction{};
            second.generator->seed = 8;
            second.generator->region.centre = Vec3(0.5, 1.2, -0.3);
            if (coloured) second.extinction = Rgb(2.0);
            scene.particleMedia.push_back(second);
            integration = coloured ? "coloured" : "simpson";
        }
        const std::map<std::string, ParamValue> common{{"integration", std::string(coloured ? "simpson" : integration)},
                                                       {"steps", std::int64_t(2)},
                                                       {"vsmResolution", std::int64_t(48)},
                                                       {"shadowMapResolution", std::int64_t(256)},
                                                       {"pcfRadius", std::int64_t(1)}};
        auto withDevice = [&](const char* device) {
            std::map<std::string, ParamValue> v = common;
            v["device"] = std::string(device);
            return renderIsv(scene, v);
        };
        const RenderResult gpu = withDevice("gpu"), cpu = withDevice("cpu");
        ASSERT_NE(gpu.image.metadata.at("device"), "cpu");
        const Metrics m = computeMetrics(gpu.image, cpu.image);
        // The transmittance channel (alpha: the product of the fragments' mean transmittance), which metrics skip.
        double alphaDifference = 0.0;
        int alphaBeyond = 0;
        for (int y = 0; y < gpu.image.height(); ++y)
            for (int x = 0; x < gpu.image.width(); ++x) {
                const double d = std::abs(gpu.image.at(x, y, 3) - cpu.image.at(x, y, 3));
                alphaDifference = std::max(alphaDifference, d);
                if (d > 1e-4) ++alphaBeyond;
            }
        std::printf("%-8s GPU against CPU: relMSE %.3g, energy bias %+.4f %%, transmittance differs by more than 1e-4 "
                    "at %d pixels (at most %.2g)\n",
                    integration, m.relMSE, m.energyBias, alphaBeyond, alphaDifference);
        // A pixel centre on a proxy's edge may be covered by one path only.
        EXPECT_LE(alphaBeyond, 2) << integration;
        // Float rounding differs (FMA, exp); a pixel centre on a proxy's edge may be shaded by one path only.
        EXPECT_LT(m.relMSE, 1e-4) << integration;
        EXPECT_LT(std::abs(m.energyBias), 0.1) << integration;
    }
}

}  // namespace
}  // namespace tyndall::isv::test
