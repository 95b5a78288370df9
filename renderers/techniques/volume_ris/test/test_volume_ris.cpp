// The Volume-RIS technique: its distance sampler and light-point sampler against their pdfs (chi-square), the
// technique against the reference in single scattering (and the unshadowed variant, which must fail the same test),
// the GPU path against the CPU path, and what it refuses.
#include "stats.h"
#include "technique_gpu_test.h"

#include "volume_ris/prepared.h"
#include "volume_ris/volume_ris.h"

#include "test_paths.h"
#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"
#include "tyndall/image/metrics.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

namespace tyndall::volume_ris::test {
namespace {

using tyndall::test::chiSquareTest;
using tyndall::test::integrate;

const std::string kProject = tyndall::test::sourceDir() + "/projects/examples/volume-ris-shaft.json";

Project loadShaft(int width, int height, const std::vector<std::string>& overrides = {}) {
    std::vector<std::string> all = {"camera.width=" + std::to_string(width), "camera.height=" + std::to_string(height)};
    all.insert(all.end(), overrides.begin(), overrides.end());
    return loadProject(techniqueCatalogue(), kProject, all);
}

// ---------------------------------------------------------------------------------------------------------------------
// Samplers

// The transmittance-proportional distance sampler: its pdf integrates to 1 over finite and infinite segments (and the
// near-uniform limit), and 2^17 samples fall into 64 bins as the pdf says (chi-square, p > 1e-3).
TEST(VolumeRisSampling, DistanceSamplesMatchTheirPdf) {
    struct Case {
        float sigma, a, b;
    };
    const float inf = shader::kInfinity;
    for (const Case c : {Case{0.6f, 1.0f, 4.0f}, Case{3.0f, 0.2f, 5.0f}, Case{0.5f, 2.0f, inf}, Case{1e-6f, 0.0f, 2.0f},
                         Case{40.0f, 0.0f, 1.0f}}) {
        const double end = c.b < inf ? c.b : c.a + 40.0 / c.sigma;  // beyond: e^-40 of the mass
        const double mass = integrate([&](double t) { return shader::risDistancePdf(c.sigma, c.a, c.b, float(t)); },
                                      c.a, end, 1e-9, 1e-7);
        EXPECT_NEAR(mass, 1.0, 1e-4) << c.sigma << " " << c.a << " " << c.b;
        constexpr int kBins = 64, kSamples = 1 << 17;
        std::vector<double> observed(kBins, 0.0), expected(kBins, 0.0);
        const double width = (end - c.a) / kBins;
        for (int i = 0; i < kBins; ++i)
            expected[std::size_t(i)] =
                kSamples * integrate([&](double t) { return shader::risDistancePdf(c.sigma, c.a, c.b, float(t)); },
                                     c.a + i * width, c.a + (i + 1) * width, 1e-12, 1e-8);
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> uniform(0.0f, shader::kOneMinusEpsilon);
        int outside = 0;
        for (int k = 0; k < kSamples; ++k) {
            float pdf;
            const float t = shader::risDistanceSample(c.sigma, c.a, c.b, uniform(rng), pdf);
            EXPECT_NEAR(pdf, shader::risDistancePdf(c.sigma, c.a, c.b, t), 1e-4f * pdf + 1e-6f);
            const int bin = int((t - c.a) / width);
            if (bin >= 0 && bin < kBins) observed[std::size_t(bin)] += 1.0;
            else ++outside;
        }
        EXPECT_LE(outside, 2);
        const auto r = chiSquareTest(observed, expected);
        EXPECT_GT(r.pValue, 1e-3) << r.describe() << " sigma " << c.sigma;
    }
}

// Light points: chosen by power between two lights (a quad and a two-sided pentagon) and uniform on each polygon's
// area. The selection frequencies match the power fractions (to 4 standard errors), and the points on the pentagon
// fall into an 8 x 8 grid over its bounding box as its area says (chi-square; each cell's share of the polygon by a
// 256 x 256 midpoint count, accurate to ~1e-3 of a boundary cell, far below the counts' noise).
TEST(VolumeRisSampling, LightPointsAreChosenByPowerAndUniformOnTheArea) {
    const Project project = loadShaft(16, 16);
    RenderJob job = makeViewJob(project, kProject, "two lights", {});
    const PreparedScene scene = prepareScene(job.request.scene, settingsFrom(job.request.params), 1, "");
    SceneScope scope(scene);
    ASSERT_EQ(scene.frame.lightCount, 2);
    shader::RisFrame frame = scene.frame;
    frame.lightSampling = shader::kRisArea;
    const AreaLight& pentagon = job.request.scene.areaLights[1];
    ASSERT_EQ(pentagon.vertices.size(), 5u);
    // The pentagon lies in x = -1.3: grid over its (y, z) bounding box.
    double y0 = 1e9, y1 = -1e9, z0 = 1e9, z1 = -1e9;
    for (const Vec3& v : pentagon.vertices) {
        y0 = std::min(y0, v.y), y1 = std::max(y1, v.y), z0 = std::min(z0, v.z), z1 = std::max(z1, v.z);
    }
    auto inside = [&](double y, double z) {
        const std::size_t n = pentagon.vertices.size();
        const Vec3 normal = polygonNormal(pentagon.vertices);
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3 a = pentagon.vertices[i], b = pentagon.vertices[(i + 1) % n];
            if (glm::dot(glm::cross(b - a, Vec3(-1.3, y, z) - a), normal) < 0.0) return false;
        }
        return true;
    };
    constexpr int kGrid = 8, kSub = 256, kSamples = 1 << 18;
    std::vector<double> share(kGrid * kGrid, 0.0);
    double total = 0.0;
    for (int i = 0; i < kGrid * kSub; ++i)
        for (int j = 0; j < kGrid * kSub; ++j) {
            const double y = y0 + (i + 0.5) / (kGrid * kSub) * (y1 - y0), z = z0 + (j + 0.5) / (kGrid * kSub) * (z1 - z0);
            if (inside(y, z)) {
                share[std::size_t((i / kSub) * kGrid + j / kSub)] += 1.0;
                total += 1.0;
            }
        }
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uniform(0.0f, shader::kOneMinusEpsilon);
    std::vector<double> observed(kGrid * kGrid, 0.0);
    int chosen[2] = {0, 0};
    for (int k = 0; k < kSamples; ++k) {
        int light;
        float pdfArea;
        const glm::vec3 p = shader::risSampleLightPoint(frame, glm::vec3(0.0f),
                                                        glm::vec3(uniform(rng), uniform(rng), uniform(rng)), light,
                                                        pdfArea);
        ASSERT_TRUE(light == 0 || light == 1);
        ++chosen[light];
        EXPECT_FLOAT_EQ(pdfArea, scene.lights[std::size_t(light)].selectPdf / scene.lights[std::size_t(light)].area);
        if (light != 1) continue;
        EXPECT_NEAR(p.x, -1.3f, 1e-5f);
        const int i = std::clamp(int((p.y - y0) / (y1 - y0) * kGrid), 0, kGrid - 1);
        const int j = std::clamp(int((p.z - z0) / (z1 - z0) * kGrid), 0, kGrid - 1);
        observed[std::size_t(i * kGrid + j)] += 1.0;
    }
    // Selection by power: area x mean radiance x sides.
    const AreaLight& quad = job.request.scene.areaLights[0];
    auto power = [](const AreaLight& l) {
        return polygonArea(l.vertices) * (l.radiance.x + l.radiance.y + l.radiance.z) * (l.twoSided ? 2.0 : 1.0);
    };
    const double p1 = power(pentagon) / (power(quad) + power(pentagon));
    EXPECT_NEAR(scene.lights[1].selectPdf, p1, 1e-6);
    EXPECT_NEAR(scene.lights[1].area, polygonArea(pentagon.vertices), 1e-6);
    EXPECT_NEAR(chosen[1], p1 * kSamples, 4.0 * std::sqrt(kSamples * p1 * (1.0 - p1)));
    std::vector<double> expected(share.size());
    for (std::size_t c = 0; c < share.size(); ++c)
        expected[c] = share[c] / total * chosen[1];
    const auto r = chiSquareTest(observed, expected);
    EXPECT_GT(r.pValue, 1e-3) << r.describe();
}

// Solid-angle sampling of a light point, seen from shading points near, far, oblique and behind the lights: every point
// lies on its polygon, and the density in area measure is right: the mean of 1 / pdf estimates the light's area (the
// integral of 1 dA), and the mean of |y - c|^2 / pdf its second moment about the centre c, against the same integrals
// by 2-D quadrature over the fan triangles, to 4 standard errors. Behind the one-sided quad nothing is sampled.
TEST(VolumeRisSampling, SolidAngleDensityIntegratesOverThePolygon) {
    const Project project = loadShaft(16, 16);
    RenderJob job = makeViewJob(project, kProject, "two lights", {});
    const PreparedScene scene = prepareScene(job.request.scene, settingsFrom(job.request.params), 1, "");
    SceneScope scope(scene);
    ASSERT_EQ(scene.frame.lightSampling, shader::kRisSolidAngle);
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> uniform(0.0f, shader::kOneMinusEpsilon);
    for (int k = 0; k < 2; ++k) {
        const AreaLight& light = job.request.scene.areaLights[std::size_t(k)];
        const shader::RisLight& rl = scene.lights[std::size_t(k)];
        const Vec3 c = glm::dvec3(rl.centre);
        // The exact integrals over the polygon of 1 and |y - c|^2, by quadrature over each fan triangle (v0, vi-1, vi)
        // in barycentric coordinates (y = v0 + s e1 + s t e2 ... the Duffy map s in [0, 1], t in [0, 1]).
        double area = 0.0, moment = 0.0;
        for (std::size_t i = 2; i < light.vertices.size(); ++i) {
            const Vec3 v0 = light.vertices[0], e1 = light.vertices[i - 1] - v0, e2 = light.vertices[i] - v0;
            const double twice = glm::length(glm::cross(e1, e2));
            area += 0.5 * twice;
            moment += twice * tyndall::test::integrate2D(
                                  [&](double a, double b) {
                                      const Vec3 y = v0 + a * (1.0 - b) * e1 + a * b * e2;
                                      return glm::dot(y - c, y - c) * a;  // the Duffy map's Jacobian a
                                  },
                                  0.0, 1.0, 0.0, 1.0, 1e-12, 1e-9);
        }
        for (const glm::vec3 x : {glm::vec3(0.1f, 2.2f, 0.05f), glm::vec3(0.0f, 1.0f, 3.0f), glm::vec3(1.5f, 2.35f, 1.2f),
                                  glm::vec3(-1.0f, 1.1f, -0.2f), glm::vec3(-1.6f, 1.0f, -0.3f), glm::vec3(0.0f, 2.6f, 0.0f)}) {
            const double side = glm::dot(glm::dvec3(x) - light.vertices[0], polygonNormal(light.vertices));
            const bool visible = light.twoSided ? side != 0.0 : side > 0.0;
            constexpr int kSamples = 1 << 16;
            double sumArea = 0.0, sumArea2 = 0.0, sumMoment = 0.0, sumMoment2 = 0.0;
            int zero = 0;
            for (int n = 0; n < kSamples; ++n) {
                float pdf;
                const glm::vec3 y = shader::risSampleSolidAngle(rl, x, uniform(rng), glm::vec2(uniform(rng), uniform(rng)), pdf);
                if (!(pdf > 0.0f)) {
                    ++zero;
                    continue;
                }
                // On the polygon's plane and inside it.
                const Vec3 yd(y), normal = polygonNormal(light.vertices);
                ASSERT_NEAR(glm::dot(yd - light.vertices[0], normal), 0.0, 1e-4);
                for (std::size_t i = 0; i < light.vertices.size(); ++i) {
                    const Vec3 a = light.vertices[i], b = light.vertices[(i + 1) % light.vertices.size()];
                    ASSERT_GE(glm::dot(glm::cross(b - a, yd - a), normal), -1e-4);
                }
                const double w = 1.0 / pdf, m = glm::dot(yd - c, yd - c) / pdf;
                sumArea += w, sumArea2 += w * w, sumMoment += m, sumMoment2 += m * m;
            }
            if (!visible) {
                EXPECT_EQ(zero, kSamples) << "light " << k << " behind";
                continue;
            }
            EXPECT_EQ(zero, 0) << "light " << k;
            auto check = [&](double sum, double sum2, double exact, const char* what) {
                const double mean = sum / kSamples, se = std::sqrt(std::max(sum2 / kSamples - mean * mean, 0.0) / kSamples);
                EXPECT_NEAR(mean, exact, 4.0 * se + 1e-4 * exact)
                    << what << " of light " << k << " from (" << x.x << ", " << x.y << ", " << x.z << ")";
            };
            check(sumArea, sumArea2, area, "area");
            check(sumMoment, sumMoment2, moment, "second moment");
        }
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// The technique against the reference

RenderResult renderView(const Project& project, const std::string& view, int spp, std::uint64_t seed) {
    JobOptions options;
    options.spp = spp;
    options.seed = seed;
    RenderJob job = makeViewJob(project, kProject, view, options);
    return runJob(job);
}

// The noise of an image's pixel means, mean(Var / (r^2 + 0.01)) over R, G, B, from its variance channels.
double noiseOf(const Image& image, const Image& reference) {
    const int v = image.channelIndex("variance.R");
    EXPECT_GE(v, 0);
    double sum = 0.0;
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            for (int c = 0; c < 3; ++c) {
                const double r = reference.at(x, y, c);
                sum += image.at(x, y, v + c) / (r * r + 0.01);
            }
    return sum / (3.0 * image.width() * image.height());
}

// Tolerance, as WvdsAgainstReference states it: two independent unbiased estimates of the same pixel integrals differ
// by their noise alone, E[relMSE] = mean((Var_t + Var_r) / (r^2 + 0.01)), both variances from the images' variance
// channels; the test allows 1.5 x for the fluctuation of that estimate over 3 x 32 x 32 terms and the heavy tail of
// per-pixel variance estimates. A bias adds bias^2 / (r^2 + 0.01) per pixel: the unshadowed image is far above it.
struct Comparison {
    double relMSE = 0.0, bound = 0.0;
};
Comparison compare(const RenderResult& technique, const RenderResult& reference) {
    Comparison c;
    c.relMSE = computeMetrics(technique.image, reference.image).relMSE;
    c.bound = 1.5 * (noiseOf(technique.image, reference.image) + noiseOf(reference.image, reference.image));
    return c;
}

std::vector<std::string> onCpu(const std::vector<std::string>& views) {
    std::vector<std::string> o;
    for (const std::string& v : views)
        o.push_back("views[" + v + "].parameters.device=cpu");
    return o;
}

// 32 x 32 pixels: the box of fog, the quad light, the plate's shadow shaft, the diffuse ground and the GGX ball; then
// two lights (one a two-sided pentagon), equiangular distances, an infinite chromatic haze, and a hexagonal prism
// (a convex polyhedron, chromatic, back-scattering) with both lights, the side light inside it. The shaft at the
// default M = 32, the others at M = 8 (unbiased for any M; cheaper), each at 256 spp against the reference's single
// scattering at 1024 spp, with light points sampled in the solid angle (the default); then uniform area sampling.
// TYNDALL_TEST_SEED changes the seeds (default 3; 3, 4 and 5 pass).
TEST(VolumeRisAgainstReference, MatchesWithinNoise) {
    const std::vector<std::string> views = {"shaft", "equiangular", "two lights", "haze", "prism", "unshadowed"};
    std::vector<std::string> overrides = onCpu(views);
    for (const char* v : {"equiangular", "two lights", "haze", "prism", "unshadowed"})
        overrides.push_back(std::string("views[") + v + "].parameters.candidates=8");
    const Project project = loadShaft(32, 32, overrides);
    const std::uint64_t seed = std::getenv("TYNDALL_TEST_SEED") ? std::stoull(std::getenv("TYNDALL_TEST_SEED")) : 3;
    for (const std::string& view :
         {std::string("shaft"), std::string("two lights"), std::string("haze"), std::string("prism")}) {
        JobOptions options;
        options.spp = 1024;
        options.seed = seed + 4;
        RenderJob job = makeReferenceJob(project, kProject, view, options);
        const RenderResult reference = runJob(job);
        std::vector<std::string> compared = {view};
        if (view == "shaft") compared.push_back("equiangular");
        for (const std::string& v : compared) {
            const RenderResult image = renderView(project, v, 256, seed);
            EXPECT_EQ(image.image.metadata.at("technique"), "volume-ris");
            const Comparison c = compare(image, reference);
            std::printf("%-12s relMSE %.3g, bound %.3g (%.1f s; reference %.1f s)\n", v.c_str(), c.relMSE, c.bound,
                        image.seconds, reference.seconds);
            EXPECT_LE(c.relMSE, c.bound) << v;
            EXPECT_GT(c.bound, 0.0);
        }
        if (view == "shaft") {
            // Without the shadow ray the plate's shadow in the fog and on the ground is missing: the same test must see
            // it, by a margin.
            const RenderResult unshadowed = renderView(project, "unshadowed", 256, seed);
            const Comparison c = compare(unshadowed, reference);
            std::printf("%-12s relMSE %.3g, bound %.3g\n", "unshadowed", c.relMSE, c.bound);
            EXPECT_GT(c.relMSE, 3.0 * c.bound);
        }
    }

    // Uniform area sampling of the light point. Where camera rays pass close to a light inside the medium its weights
    // G / p ~ 1 / r^2 are not square-integrable (infinite variance): the variance channels of a finite render cannot
    // bound its error there (measured: 1.2 x the bound at one seed in three). With the fog's top 0.4 m below the light
    // the weights are bounded and the test applies.
    std::vector<std::string> below = onCpu({"shaft", "equiangular"});
    for (const char* v : {"shaft", "equiangular"})
        below.push_back(std::string("views[") + v + "].parameters.lightSampling=area");
    below.push_back("media[fog].box.centre=[0.0,1.0,0.0]");
    below.push_back("media[fog].box.size=[3.0,2.0,3.0]");
    const Project areaProject = loadShaft(32, 32, below);
    JobOptions options;
    options.spp = 1024;
    options.seed = seed + 4;
    RenderJob job = makeReferenceJob(areaProject, kProject, "shaft", options);
    const RenderResult reference = runJob(job);
    for (const char* v : {"shaft", "equiangular"}) {
        const RenderResult image = renderView(areaProject, v, 256, seed);
        const Comparison c = compare(image, reference);
        std::printf("%-12s area sampling, fog below the light: relMSE %.3g, bound %.3g\n", v, c.relMSE, c.bound);
        EXPECT_LE(c.relMSE, c.bound) << v << " with area sampling";
    }
}

// Progressive rendering: an intermediate image at each pass, spp reported, and cancellation.
TEST(VolumeRisTechnique, RendersProgressivelyAndCancels) {
    const Project project = loadShaft(16, 16, onCpu({"shaft"}));
    JobOptions options;
    options.spp = 16;
    RenderJob job = makeViewJob(project, kProject, "shaft", options);
    std::vector<int> passes;
    RenderCallbacks callbacks;
    callbacks.intermediate = [&](const Image&, int spp) { passes.push_back(spp); };
    const RenderResult result = runJob(job, callbacks);
    EXPECT_EQ(result.spp, 16);
    EXPECT_EQ(passes, (std::vector<int>{1, 2, 4, 8}));
    EXPECT_EQ(result.image.metadata.at("nonFiniteSamples"), "0");
    // The medium's and the surface's parts add up to R, G, B, and each has light somewhere.
    const Image& image = result.image;
    const int medium = image.channelIndex("medium.R"), surface = image.channelIndex("surface.R");
    ASSERT_GE(medium, 0);
    ASSERT_GE(surface, 0);
    double mediumSum = 0.0, surfaceSum = 0.0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
            for (int c = 0; c < 3; ++c) {
                const float m = image.at(x, y, medium + c), su = image.at(x, y, surface + c);
                EXPECT_NEAR(image.at(x, y, c), m + su, 1e-6f * (std::abs(image.at(x, y, c)) + 1e-6f));
                mediumSum += m;
                surfaceSum += su;
            }
    EXPECT_GT(mediumSum, 0.0);
    EXPECT_GT(surfaceSum, 0.0);

    std::atomic<bool> cancel{true};
    RenderCallbacks cancelled;
    cancelled.cancel = &cancel;
    RenderJob again = makeViewJob(project, kProject, "shaft", options);
    EXPECT_THROW(runJob(again, cancelled), Cancelled);
}

// What the technique cannot render is refused with a reason naming it, not rendered black.
TEST(VolumeRisTechnique, RefusesWhatItCannotRender) {
    VolumeRisTechnique t;
    PointLight point;
    point.name = "bulb";
    EXPECT_FALSE(t.supports(point).supported);
    EXPECT_NE(t.supports(point).reason.find("bulb"), std::string::npos);
    DirectionalLight sun;
    sun.name = "sun";
    EXPECT_FALSE(t.supports(sun).supported);
    EXPECT_NE(t.supports(sun).reason.find("sun"), std::string::npos);
    ParticleMedium particles;
    particles.name = "smoke";
    EXPECT_FALSE(t.supports(particles).supported);
    EXPECT_NE(t.supports(particles).reason.find("smoke"), std::string::npos);
    HomogeneousMedium infinite;
    EXPECT_TRUE(t.supports(infinite).supported);
    AreaLight big;
    big.name = "disc";
    for (int i = 0; i < shader::kRisMaxVertices + 1; ++i) {
        const double a = 2.0 * 3.14159265358979 * i / (shader::kRisMaxVertices + 1);
        big.vertices.push_back(Vec3(std::cos(a), 2.0, std::sin(a)));
    }
    EXPECT_FALSE(t.supports(big).supported);

    // A view with a point light is refused by the render, with the reason.
    Project project = loadShaft(16, 16, onCpu({"shaft"}));
    RenderJob job = makeViewJob(project, kProject, "shaft", {});
    job.request.scene.pointLights.push_back(point);
    try {
        job.technique->render(job.request, {});
        ADD_FAILURE() << "a point light was rendered";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("bulb"), std::string::npos) << e.what();
    }
    // Two media in one view.
    RenderJob two = makeViewJob(project, kProject, "shaft", {});
    two.request.scene.media.push_back(two.request.scene.media.front());
    EXPECT_THROW(two.technique->render(two.request, {}), InputError);
}

// ---------------------------------------------------------------------------------------------------------------------
// GPU against CPU

using VolumeRisGpu = tyndall::test::TechniqueGpuTest;

// The same samples on both paths, the shared code in float. Solid-angle sampling (the default) goes through acos,
// atan, sin and cos in Arvo's sampler, which Vulkan lets a device compute with far less precision than glibc (GLSL.std.450
// allows errors around 2^-11 for sin and cos): each candidate's light point moves by ~1e-4 relative, and the pixels differ
// by that much (measured over R, G, B and the medium and surface parts: median 1e-4, 99th percentile 2e-3 .. 5e-3).
// Bound for those variants: 98 % of the pixels
// within 5e-3 relative and a mean relative difference <= 2e-3. With uniform area sampling (no such functions) the two
// agree to float roundoff: 98 % of the pixels within 1e-4 and the mean <= 1e-3. In both, a pixel may differ a lot where
// a reservoir's choice (u * sum < w) or a grazing shadow ray flips (another valid sample; measured max 0.5 in one
// pixel). The variants: a box (planes), two lights, equiangular distances, an infinite chromatic medium, no meshes, a
// polyhedron (8 planes), unshadowed; the first three also with area sampling.
TEST_F(VolumeRisGpu, GpuAgreesWithCpu) {
    struct Variant {
        const char* view;
        std::vector<std::string> overrides;
    };
    const std::vector<Variant> variants = {{"shaft", {}},
                                           {"two lights", {}},
                                           {"equiangular", {}},
                                           {"haze", {}},
                                           {"shaft", {"meshes=[]"}},
                                           {"prism", {}},
                                           {"unshadowed", {}},
                                           {"shaft", {"views[shaft].parameters.lightSampling=area"}},
                                           {"two lights", {"views[two lights].parameters.lightSampling=area"}},
                                           {"equiangular", {"views[equiangular].parameters.lightSampling=area"}}};
    for (const Variant& variant : variants) {
        const std::string device = std::string("views[") + variant.view + "].parameters.device=";
        std::vector<std::string> gpuOverrides = variant.overrides, cpuOverrides = variant.overrides;
        gpuOverrides.push_back(device + "gpu");
        cpuOverrides.push_back(device + "cpu");
        const Project gpuProject = loadShaft(32, 32, gpuOverrides);
        const Project cpuProject = loadShaft(32, 32, cpuOverrides);
        const RenderResult g = renderView(gpuProject, variant.view, 4, 9);
        const RenderResult c = renderView(cpuProject, variant.view, 4, 9);
        EXPECT_NE(g.image.metadata.at("device"), "cpu");
        const bool area = !variant.overrides.empty() && variant.overrides[0].find("=area") != std::string::npos;
        const double closeTo = area ? 1e-4 : 5e-3, meanBound = area ? 1e-3 : 2e-3;
        int close = 0;
        double meanRelative = 0.0;
        std::vector<double> worstPerPixel;
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) {
                bool same = true;
                double worst = 0.0;
                for (const int ch : {0, 1, 2, 6, 7, 8, 9, 10, 11}) {  // R, G, B, medium.*, surface.*
                    const double d = std::abs(g.image.at(x, y, ch) - c.image.at(x, y, ch)) /
                                     std::max(1e-3f, std::abs(c.image.at(x, y, ch)));
                    same &= d <= closeTo;
                    meanRelative += d / (9.0 * 32 * 32);
                    worst = std::max(worst, d);
                }
                worstPerPixel.push_back(worst);
                close += same;
            }
        const std::string label = std::string(variant.view) + (variant.overrides.empty() ? "" : " " + variant.overrides[0]);
        std::sort(worstPerPixel.begin(), worstPerPixel.end());
        std::printf("%-20s %d of 1024 pixels within %.0e, mean relative difference %.3g, percentiles 50 %.2g 90 %.2g "
                    "99 %.2g max %.2g\n",
                    label.c_str(), close, closeTo, meanRelative, worstPerPixel[512], worstPerPixel[921], worstPerPixel[1013],
                    worstPerPixel[1023]);
        EXPECT_GE(close, int(0.98 * 32 * 32)) << label;
        EXPECT_LE(meanRelative, meanBound) << label;
    }
}

}  // namespace
}  // namespace tyndall::volume_ris::test
