// The Pegoraro technique end to end: its image of the example project against the reference in single-scattering
// mode, the GPU path against the CPU path, the closed form on the GPU against the CPU (the GPU framework's harness),
// and exact shadows against quadrature with a visibility test per sample.
#include "closed_form_cases.h"
#include "technique_gpu_test.h"

#include "pegoraro/pegoraro.h"
#include "pegoraro/prepared.h"
#include "tyndall/framework/shader_params.h"

#include "test_paths.h"
#include "tyndall/core/error.h"
#include "tyndall/gpu/context.h"
#include "tyndall/gpu/harness.h"
#include "tyndall/image/metrics.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <gtest/gtest.h>

namespace tyndall::pegoraro::test {
namespace {

const std::string kProject = tyndall::test::sourceDir() + "/projects/examples/pegoraro-street.json";

Project loadExample(int width, int height, const std::vector<std::string>& overrides = {}) {
    std::vector<std::string> all = {"camera.width=" + std::to_string(width), "camera.height=" + std::to_string(height)};
    all.insert(all.end(), overrides.begin(), overrides.end());
    return loadProject(techniqueCatalogue(), kProject, all);
}

RenderResult renderView(const Project& project, const std::string& view, std::optional<int> spp = std::nullopt) {
    JobOptions options;
    options.spp = spp;
    RenderJob job = makeViewJob(project, kProject, view, options);
    return runJob(job);
}

// Any validation error of the shared context fails the test that caused it.
using PegoraroGpu = tyndall::test::TechniqueGpuTest;

// relMSE of `image` against `reference` and the reference's own noise, mean(var / (r^2 + 0.01)), over every pixel.
// The pixels around the lights' projections count too: the reference jitters them about the projection
// (singular_pixel.h), so their noise is finite and their variance estimate meaningful (they used to be masked out).
struct ReferenceError {
    double relMSE = 0.0, noise = 0.0;
};

ReferenceError referenceError(const Image& image, const Image& reference) {
    const int varianceR = reference.channelIndex("variance.R");
    ReferenceError e;
    long terms = 0;
    for (int y = 0; y < image.height(); ++y) {
        for (int x = 0; x < image.width(); ++x) {
            for (int c = 0; c < 3; ++c) {
                const double r = reference.at(x, y, c), d = image.at(x, y, c) - r;
                e.relMSE += d * d / (r * r + 0.01);
                e.noise += reference.at(x, y, varianceR + c) / (r * r + 0.01);
                ++terms;
            }
        }
    }
    e.relMSE /= double(terms);
    e.noise /= double(terms);
    return e;
}

// The example project (three point lights with isotropic, spot and Legendre distributions, Rayleigh haze with
// chromatic coefficients, diffuse and anisotropic GGX surfaces, a sphere and a wall casting volumetric shadows) at
// 80 x 60.
//
// Tolerance. If the technique were exact, its error against the reference would be the reference's noise alone:
// E[relMSE] = mean(Var[r] / (r^2 + 0.01)), estimated from the reference's variance channels (the variance of each
// pixel's mean). The technique adds the error of integrating each pixel's footprint on a 16 x 16 grid (bounded by the
// relMSE between its 16 x 16 and 8 x 8 images, below), and over ~14,000 terms the noise estimate itself fluctuates by a
// few per cent. So: relMSE <= 1.5 x the reference's noise + the grid's error.
// Every pixel counts, the 3 x 3 around each light's projection too, where the radiance grows like 1/h (h the distance
// from the light to the ray): the technique integrates them with its singularity-cancelling rule and the reference
// jitters them about the projection (they were excluded before the reference could: 27 of 4800 pixels; with them,
// relMSE 1.97e-6 against a noise of 1.77e-6, without them 0.34e-6 against 0.52e-6).
// The same render without shadows (wrong by the volumetric shadows of the sphere and the wall) must exceed the bound
// by far, which shows the test can tell.
TEST(PegoraroTechnique, MatchesTheReferenceInSingleScattering) {
    const Project project =
        loadExample(80, 60,
                    {"views[closed form].parameters.device=cpu", "views[closed form].parameters.supersampling=16",
                     "views[closed form].parameters.precision=double"});
    JobOptions referenceOptions;
    referenceOptions.spp = 512;
    referenceOptions.seed = 7;
    RenderJob referenceJob = makeReferenceJob(project, kProject, "closed form", referenceOptions);
    const RenderResult reference = runJob(referenceJob);
    const RenderResult technique = renderView(project, "closed form");
    const ReferenceError e = referenceError(technique.image, reference.image);
    ASSERT_GT(e.noise, 0.0);
    // The grid's own error: at least halved from S = 8 to S = 16 (edges converge like 1/S, smooth parts faster), so
    // the S = 16 image is within |I16 - I8| of its pixel integrals.
    const Project coarse =
        loadExample(80, 60,
                    {"views[closed form].parameters.device=cpu", "views[closed form].parameters.supersampling=8",
                     "views[closed form].parameters.precision=double"});
    const double gridError =
        referenceError(technique.image, renderView(coarse, "closed form").image).relMSE;
    EXPECT_LE(e.relMSE, 1.5 * e.noise + gridError) << "reference noise " << e.noise << ", grid error " << gridError;
    RecordProperty("gridError", std::to_string(gridError * 1e6) + "e-6");
    EXPECT_EQ(technique.image.metadata.at("pegoraro:shadowOverflowPixels"), "0");
    RecordProperty("relMSE", std::to_string(e.relMSE * 1e6) + "e-6");
    RecordProperty("referenceNoise", std::to_string(e.noise * 1e6) + "e-6");

    const Project unshadowed =
        loadExample(80, 60,
                    {"views[closed form].parameters.device=cpu", "views[closed form].parameters.supersampling=8",
                     "views[closed form].parameters.shadows=false"});
    const ReferenceError wrong = referenceError(renderView(unshadowed, "closed form").image, reference.image);
    EXPECT_GT(wrong.relMSE, 4.0 * e.noise);
}

// The GPU path renders what the CPU path renders. Same shared code; differences come from the devices' float
// arithmetic in the geometry (rays, hits, lit intervals) and, in float, from lavapipe's log/atan (expint.md). Bound:
// relMSE <= 1e-8 and 99.5 % of pixels within 1e-4 relative (silhouette pixels may pick another triangle).
TEST_F(PegoraroGpu, GpuPathMatchesCpuPath) {
    // Double on the whole scene (order 12); float on the lamp alone (order 2, where float is accurate), unshadowed.
    for (const std::string view : {"closed form", "lamp only"}) {
        SCOPED_TRACE(view);
        const std::string precision = view == "closed form" ? "double" : "float";
        const std::string prefix = "views[" + view + "].parameters.";
        // The lamp renders without shadows, which the GPU compiles as its own variant.
        const std::string shadows = prefix + "shadows=" + (view == "closed form" ? "true" : "false");
        const Project gpuProject =
            loadExample(48, 36, {prefix + "device=gpu", prefix + "precision=" + precision, shadows});
        const Project cpuProject =
            loadExample(48, 36, {prefix + "device=cpu", prefix + "precision=" + precision, shadows});
        const RenderResult gpuResult = renderView(gpuProject, view);
        const RenderResult cpuResult = renderView(cpuProject, view);
        const Image& a = gpuResult.image;
        const Image& b = cpuResult.image;
        const Metrics m = computeMetrics(a, b);
        EXPECT_LE(m.relMSE, 1e-8);
        int far = 0;
        for (int y = 0; y < a.height(); ++y)
            for (int x = 0; x < a.width(); ++x)
                for (int c = 0; c < 3; ++c)
                    if (std::abs(a.at(x, y, c) - b.at(x, y, c)) > 1e-4 * std::abs(b.at(x, y, c)) + 1e-7) ++far;
        EXPECT_LE(far, int(0.005 * 3 * a.width() * a.height()));
        EXPECT_NE(a.metadata.at("device"), "cpu");
        // The street's camera hits come from the raster pass (framework/primary_hits.h), the CPU's from the BVH.
        EXPECT_EQ(a.metadata.at("primaryVisibility"), "raster");
    }
}

// The GPU compiles a variant per scene and renders in two passes: the closed form without the quadrature's code, then
// the samples where an evaluation needs the quadrature again with it, over a list. Each variant against the CPU path
// (same bounds as above): a grey medium (one closed form for the three channels) without meshes, the example with
// some evaluations falling back (their counts agree within 1 %: an evaluation whose error bound is within float
// roundoff of the tolerance may decide differently on the two devices), no fallback at all, and an isotropic phase
// function with the isotropic lamp (the one-term variant, whose series and ends skip the general loops).
TEST_F(PegoraroGpu, VariantsAndDeferredFallbacksMatchTheCpu) {
    const std::string view = "lamp only", prefix = "views[lamp only].parameters.";
    struct Variant {
        std::string name;
        std::vector<std::string> overrides;
        bool someFallbacks;
    };
    // In float, the lamp's closed form exceeds the default tolerance (1e-4) in part of the image.
    const std::vector<Variant> variants = {
        {"grey, no meshes", {"media[haze].sigma_s=[0.1,0.1,0.1]", "meshes=[]", prefix + "shadows=false"}, false},
        {"chromatic, meshes, shadows, deferred fallbacks", {}, true},
        {"no fallback", {prefix + "fallback=never"}, false},
        {"isotropic phase and light (one term)",
         {"media[haze].phase={\"type\":\"isotropic\"}", prefix + "fallback=never"},
         false}};
    for (const Variant& v : variants) {
        SCOPED_TRACE(v.name);
        std::vector<std::string> gpu = v.overrides, cpu = v.overrides;
        gpu.insert(gpu.end(), {prefix + "device=gpu", prefix + "precision=float"});
        cpu.insert(cpu.end(), {prefix + "device=cpu", prefix + "precision=float"});
        const RenderResult g = renderView(loadExample(40, 30, gpu), view);
        const RenderResult c = renderView(loadExample(40, 30, cpu), view);
        EXPECT_NE(g.image.metadata.at("device"), "cpu");
        EXPECT_LE(computeMetrics(g.image, c.image).relMSE, 1e-8);
        int far = 0;
        for (int y = 0; y < g.image.height(); ++y)
            for (int x = 0; x < g.image.width(); ++x)
                for (int ch = 0; ch < 3; ++ch)
                    if (std::abs(g.image.at(x, y, ch) - c.image.at(x, y, ch)) >
                        1e-4 * std::abs(c.image.at(x, y, ch)) + 1e-7)
                        ++far;
        EXPECT_LE(far, int(0.005 * 3 * g.image.width() * g.image.height()));
        const double gpuFallbacks = std::stod(g.image.metadata.at("pegoraro:fallbackEvaluations"));
        const double cpuFallbacks = std::stod(c.image.metadata.at("pegoraro:fallbackEvaluations"));
        std::printf("%s: fallback evaluations GPU %.0f, CPU %.0f\n", v.name.c_str(), gpuFallbacks, cpuFallbacks);
        EXPECT_NEAR(gpuFallbacks, cpuFallbacks, 0.01 * cpuFallbacks);
        if (v.someFallbacks) {
            EXPECT_GT(cpuFallbacks, 0.0);
            EXPECT_LT(std::stod(c.image.metadata.at("pegoraro:fallbackPixels")), 0.75 * 40 * 30);
        }
    }
}

// The closed form itself on the GPU against the CPU, through the GPU framework's harness: 2000 random configurations
// (H, ua, ub, del) with dc = 3/5 sqrt(1 - del^2) (a valid geometry), a Rayleigh-shaped phase function and a squared
// spot (order 4). Double: the same operations on both sides (double_math.h replaces libm). Float: lavapipe's float log
// and atan differ from glibc's by up to 3e-6 (expint.md) and the closed form amplifies that by its cancellation, which
// its error estimate measures: the two sides agree within the sum of their estimates.
const char* const kHarnessBody = R"(
    PegoraroPolynomial_REAL phase;
    PegoraroPolynomial_REAL light;
    phase.terms = 3;
    light.terms = 3;
    for (int k = 0; k < kPegoraroMaxTerms; ++k) { phase.c[k] = REAL(0); light.c[k] = REAL(0); }
    phase.c[0] = REAL(3) / REAL(16);
    phase.c[2] = phase.c[0];
    light.c[0] = REAL(1) / REAL(4); light.c[1] = REAL(1) / REAL(2); light.c[2] = REAL(1) / REAL(4);
    REAL del = REAL(x.w);
    REAL dc = REAL(3) / REAL(5) * sqrt(REAL(1) - del * del);
    PegoraroSeries_REAL s;
    pegoraroSeries(del, dc, phase, light, s);
    REAL bound;
    REAL value = pegoraroIntegral(s, REAL(x.x), REAL(x.y), REAL(x.z), bound);
    return VEC4(value, bound, 0, 0);
)";

template <typename Real>
glm::vec<4, Real> closedFormOnCpu(const glm::dvec4& x) {
    using Polynomial =
        std::conditional_t<std::is_same_v<Real, double>, sh::PegoraroPolynomial_double, sh::PegoraroPolynomial_float>;
    using Series =
        std::conditional_t<std::is_same_v<Real, double>, sh::PegoraroSeries_double, sh::PegoraroSeries_float>;
    Polynomial phase{}, light{};
    phase.terms = light.terms = 3;
    phase.c[0] = phase.c[2] = Real(3) / Real(16);
    light.c[0] = Real(0.25);
    light.c[1] = Real(0.5);
    light.c[2] = Real(0.25);
    const Real del = Real(x.w);
    const Real dc = Real(3) / Real(5) * std::sqrt(Real(1) - del * del);
    Series s;
    sh::pegoraroSeries(del, dc, phase, light, s);
    Real bound;
    const Real value = sh::pegoraroIntegral(s, Real(x.x), Real(x.y), Real(x.z), bound);
    return {value, bound, 0, 0};
}

std::string harnessBody(const std::string& real, const std::string& vec4) {
    std::string body = kHarnessBody;
    for (const auto& [from, to] : {std::pair<std::string, std::string>{"REAL", real}, {"VEC4", vec4}}) {
        for (std::size_t at = body.find(from); at != std::string::npos; at = body.find(from, at + to.size()))
            body.replace(at, from.size(), to);
    }
    return body;
}

TEST_F(PegoraroGpu, ClosedFormOnTheGpuMatchesTheCpu) {
    gpu::Context& context = *gpu::sharedContext();
    sh::Pcg32 rng = sh::pcg32Seed(99u, 4u);
    std::vector<glm::dvec4> inputs;
    for (int i = 0; i < 2000; ++i) {
        const auto u = [&] { return double(sh::pcg32NextFloat(rng)); };
        const double H = 1e-3 * std::pow(2e4, u());
        const double ua = 20.0 * u() - 10.0;
        const double ub = u() < 0.2 ? 1e30 : ua + 0.01 + 10.0 * u();
        inputs.push_back({H, ua, ub, 2.0 * u() - 1.0});
    }
    const std::string prelude = "#define TY_ENABLE_DOUBLE\n#include \"shared/pegoraro.h\"\n";
    if (context.device().shaderFloat64) {
        const std::vector<glm::dvec4> gpuOut =
            gpu::evaluateOnGpuDouble(context, prelude, harnessBody("double", "dvec4"), inputs);
        const gpu::HarnessReport report = gpu::compareWithCpu(inputs, gpuOut, closedFormOnCpu<double>, 1e-300);
        EXPECT_EQ(report.nonFiniteMismatches, 0u);
        // The same operations on both sides, so within the sum of both error estimates plus 1e-13 (the last bits of
        // division and exp; dc is written 3/5 because glslang folds double(0.6f) to the decimal 0.6, C++ to the float).
        for (std::size_t i = 0; i < inputs.size(); ++i) {
            const glm::dvec4 cpu = closedFormOnCpu<double>(inputs[i]);
            EXPECT_NEAR(gpuOut[i].x, cpu.x, gpuOut[i].y + cpu.y + 1e-13 * std::abs(cpu.x)) << "input " << i;
        }
    }
    std::vector<glm::vec4> inputsF;
    for (const glm::dvec4& x : inputs)
        inputsF.push_back(glm::vec4(x.x, x.y, std::min(x.z, 1e30), x.w));
    const std::vector<glm::vec4> gpuOutF =
        gpu::evaluateOnGpu(context, "#include \"shared/pegoraro.h\"\n", harnessBody("float", "vec4"), inputsF);
    const gpu::HarnessReport reportF = gpu::compareWithCpu(
        inputsF, gpuOutF, [](const glm::vec4& x) { return closedFormOnCpu<float>(glm::dvec4(x)); }, 1e-30);
    // Each side's value is within its own error estimate of the truth, so they agree within the sum of both.
    for (std::size_t i = 0; i < inputsF.size(); ++i) {
        const glm::vec4 cpu = closedFormOnCpu<float>(glm::dvec4(inputsF[i]));
        EXPECT_NEAR(gpuOutF[i].x, cpu.x, gpuOutF[i].y + cpu.y + 1e-6f * std::abs(cpu.x) + 1e-30f) << "input " << i;
    }
    EXPECT_EQ(reportF.nonFiniteMismatches, 0u);
}

sh::PegoraroPolynomial_double lightPolynomialOf(const sh::PegoraroLight& light) {
    return sh::pegoraroLoadPolynomial_double(light.firstCoefficient, light.terms);
}

// Exact shadows: the medium radiance of every light along random camera rays of the example project (a sphere and a
// wall cast shadows into the haze) against quadrature of Eq. 3 with a visibility test per sample. The quadrature is
// the midpoint rule with 40,000 nodes in the angle theta = atan((x - xh) / h), in which the integrand is bounded; each
// shadow boundary costs it at most one node's width (~4e-5 of the range) times the jump, so it is good to ~2e-4
// relative; the bound is 1e-3.
TEST(PegoraroTechnique, ShadowedIntervalsMatchQuadratureWithVisibility) {
    const Project project = loadExample(64, 48);
    const Settings settings = settingsFrom(createTechnique("pegoraro")->defaultParams());
    const PreparedScene scene =
        prepareScene(project.scene, settings, tyndall::test::sourceDir() + "/projects/examples");
    SceneScope scope(scene);
    const shader::PegoraroFrame& f = scene.frame;
    sh::Pcg32 rng = sh::pcg32Seed(8u, 8u);
    int tested = 0, shadowedRays = 0;
    for (int ray = 0; ray < 120; ++ray) {
        glm::vec3 origin, dir;
        sh::cameraRay(f.camera, 64.0f * sh::pcg32NextFloat(rng), 48.0f * sh::pcg32NextFloat(rng), origin, dir);
        sh::BvhHit hit;
        const bool hasHit = sh::bvhIntersect(origin, dir, 0.0f, sh::kInfinity, hit);
        const float tEnd = hasHit ? hit.t : sh::kInfinity;
        for (int l = 0; l < f.lightCount; ++l) {
            const sh::PegoraroLight light = sh::pegoraroLight(l);
            int fallbacks = 0, overflows = 0;
            const glm::vec3 closed = sh::pegoraroMediumRadiance_double(f, light, lightPolynomialOf(light), origin, dir,
                                                                       tEnd, fallbacks, overflows);
            ASSERT_EQ(overflows, 0);

            const glm::dvec3 o(origin), d(dir), pl(light.position), axis(light.axis);
            const double xh = glm::dot(pl - o, d);
            const double h = glm::length(o + xh * d - pl);
            const sh::PegoraroMedium medium = sh::pegoraroMedium(0);
            const sh::PegoraroPolynomial_double phase =
                sh::pegoraroLoadPolynomial_double(medium.firstCoefficient, medium.terms);
            const sh::PegoraroPolynomial_double lightPoly = lightPolynomialOf(light);
            const double thetaA = std::atan2(-xh, h);
            const double thetaB = hasHit ? std::atan2(double(tEnd) - xh, h) : 0.5 * 3.14159265358979323846;
            const int nodes = 40000;
            glm::dvec3 sum(0.0);
            int occludedNodes = 0;
            for (int i = 0; i < nodes; ++i) {
                const double theta = thetaA + (thetaB - thetaA) * (i + 0.5) / nodes;
                const double x = xh + h * std::tan(theta);
                const glm::dvec3 p = o + x * d;
                const glm::dvec3 fromLight = p - pl;
                const double dist = glm::length(fromLight);
                if (sh::bvhOccluded(glm::vec3(pl), glm::vec3(fromLight), 0.0f, 1.0f)) {
                    ++occludedNodes;
                    continue;
                }
                const glm::dvec3 w = fromLight / dist;
                const double value =
                    sh::pegoraroHorner(phase, glm::dot(w, -d)) * sh::pegoraroHorner(lightPoly, glm::dot(w, axis));
                sum += glm::exp(-glm::dvec3(f.sigmaT) * (x + dist)) * value;
            }
            const glm::dvec3 expected =
                glm::dvec3(medium.sigmaS) * glm::dvec3(light.intensity) * sum * (thetaB - thetaA) / double(nodes) / h;
            if (occludedNodes > 0) ++shadowedRays;
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(closed[c], expected[c], 1e-3 * expected[c] + 1e-9)
                    << "ray " << ray << ", light " << l << ", channel " << c << ", occluded nodes " << occludedNodes;
            ++tested;
        }
    }
    EXPECT_GT(shadowedRays, 10);  // the test must see shadows
    RecordProperty("shadowedRays", shadowedRays);
    RecordProperty("tested", tested);
}

// ---------------------------------------------------------------------------------------------------------------------
// The pixels around a light's projection

// A camera in an infinite haze, looking past a point light whose projection falls at a generic point of pixel (4, 3)
// of a 9 x 7 image, or, with nearEdge, 0.004 px from that pixel's left edge (a thin triangle of the split).
Scene singularScene(bool spot, bool nearEdge) {
    Scene scene;
    scene.camera.position = {0.0, 1.0, 4.0};
    scene.camera.target = {0.0, 1.0, 0.0};
    scene.camera.fovY = 10.0;
    scene.camera.width = 9;
    scene.camera.height = 7;
    HomogeneousMedium m;
    m.name = "haze";
    m.sigma_s = Rgb(0.2, 0.25, 0.3);
    m.sigma_a = Rgb(0.05);
    m.phase.kind = PhaseKind::Rayleigh;
    scene.media.push_back(m);
    PointLight l;
    l.name = "lamp";
    // One pixel spans 2 tan(5 deg) / 7 * 4 m = 0.1 m at the light's depth: the centre pixel's centre is at (0, 1).
    const double pixel = 2.0 * std::tan(5.0 * 3.14159265358979323846 / 180.0) / 7.0 * 4.0;
    l.position = {(nearEdge ? -0.496 : 0.137) * pixel, 1.0 + 0.291 * pixel, 0.0};
    l.intensity = Rgb(3.0);
    if (spot) {
        l.distribution.kind = AngularDistribution::Kind::Spot;
        l.distribution.spotExponent = 6.0;
        l.distribution.axis = glm::normalize(Vec3(0.3, -0.4, 0.6));
    }
    scene.pointLights.push_back(l);
    return scene;
}

// Gauss-Legendre nodes and weights of order n on [0, 1] (Newton on the Legendre recurrence).
std::vector<glm::dvec2> gaussLegendre(int n) {
    const double pi = 3.14159265358979323846;
    std::vector<glm::dvec2> nodes;
    for (int i = 1; i <= n; ++i) {
        double x = std::cos(pi * (i - 0.25) / (n + 0.5)), derivative = 1.0;
        for (int iteration = 0; iteration < 100; ++iteration) {
            double p0 = 1.0, p1 = x;
            for (int k = 2; k <= n; ++k) {
                const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            derivative = n * (x * p1 - p0) / (x * x - 1.0);
            const double step = p1 / derivative;
            x -= step;
            if (std::abs(step) < 1e-16) break;
        }
        nodes.push_back({0.5 + 0.5 * x, 1.0 / ((1.0 - x * x) * derivative * derivative)});
    }
    return nodes;
}

// The average of the pixel (px, py) of the radiance along the ray through each image point, in polar coordinates about
// the light's projection p (where the integrand times r is bounded): the angle split where the rays from p pass the
// pixel's corners, so that the interval [rIn, rOut] in which each ray crosses the pixel is smooth in the angle;
// Gauss-Legendre of order n in the angle and in r over that interval. Independent of the technique's rule (Duffy
// triangles with a sinh substitution, 8 nodes). An adaptive rule cannot be used: the rays' image coordinates are float,
// so the integrand is noisy at the 1e-7 level, which never lets adaptive refinement stop.
double accuratePixelAverage(const shader::PegoraroFrame& f, int px, int py, glm::dvec2 p, int channel, int n) {
    const double pi = 3.14159265358979323846;
    const std::vector<glm::dvec2> gl = gaussLegendre(n);
    std::vector<double> cuts;
    for (int k = 0; k < 4; ++k) {
        const glm::dvec2 corner(px + (k == 1 || k == 2), py + (k >= 2));
        double phi = std::atan2(corner.y - p.y, corner.x - p.x);
        if (phi < 0.0) phi += 2.0 * pi;
        cuts.push_back(phi);
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.push_back(cuts[0] + 2.0 * pi);
    double sum = 0.0;
    for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
        for (const glm::dvec2& a : gl) {
            const double phi = cuts[c] + (cuts[c + 1] - cuts[c]) * a.x;
            const glm::dvec2 dir(std::cos(phi), std::sin(phi));
            double rIn = 0.0, rOut = 1e30;
            for (int axis = 0; axis < 2; ++axis) {
                const double lo = axis == 0 ? px : py;
                if (std::abs(dir[axis]) < 1e-15) {
                    if (p[axis] < lo || p[axis] > lo + 1.0) rOut = -1.0;
                    continue;
                }
                const double t0 = (lo - p[axis]) / dir[axis], t1 = (lo + 1.0 - p[axis]) / dir[axis];
                rIn = std::max(rIn, std::min(t0, t1));
                rOut = std::min(rOut, std::max(t0, t1));
            }
            if (!(rOut > rIn)) continue;
            double inner = 0.0;
            for (const glm::dvec2& b : gl) {
                const double r = rIn + (rOut - rIn) * b.x;
                int overflows = 0;
                const glm::vec4 radiance =
                    sh::pegoraroRay_double(f, float(p.x + r * dir.x), float(p.y + r * dir.y), -1, overflows);
                inner += b.y * double(radiance[channel]) * r;
            }
            sum += a.y * (cuts[c + 1] - cuts[c]) * inner * (rOut - rIn);
        }
    }
    return sum;
}

// The pixel holding a light's projection and its eight neighbours against accuratePixelAverage, for an isotropic lamp
// and a spot (6th power, axis oblique to the view), the projection at a generic point and near a pixel edge, in double
// on the CPU. The regular grid (16 x 16, the largest supersampling) is off by up to ~2 % there (checked below, so the
// test can tell); the split rule of pegoraroSingularNode must be within 1e-4 relative (about 30 times below the grid's
// error 3 px away from the light's pixel, 1.2e-5 per pixel there times the 9 pixels' weight); the reference
// (accuratePixelAverage, order 64) agrees with itself at order 48 to 1e-5, checked for each pixel.
TEST(PegoraroTechnique, PixelsAroundALightMatchAnAccuratePixelAverage) {
    auto technique = createTechnique("pegoraro");
    for (bool spot : {false, true}) {
        for (bool nearEdge : {false, true}) {
            SCOPED_TRACE(std::string(spot ? "spot" : "isotropic") + (nearEdge ? ", near an edge" : ""));
            RenderRequest request;
            request.scene = singularScene(spot, nearEdge);
            request.params = technique->defaultParams();
            request.params.set("device", std::string("cpu"));
            request.params.set("precision", std::string("double"));
            request.params.set("supersampling", std::int64_t(16));
            const RenderResult result = technique->render(request, {});
            const Settings settings = settingsFrom(request.params);
            const PreparedScene scene = prepareScene(request.scene, settings, "");
            SceneScope scope(scene);
            glm::vec2 p;
            ASSERT_TRUE(sh::cameraProject(scene.frame.camera, scene.lights[0].position, p));
            ASSERT_EQ(int(std::floor(p.x)), 4);
            ASSERT_EQ(int(std::floor(p.y)), 3);
            double worstGrid = 0.0, worst = 0.0;
            for (int py = 2; py <= 4; ++py) {
                for (int px = 3; px <= 5; ++px) {
                    const int channel = (px + py) % 3;
                    const double expected = accuratePixelAverage(scene.frame, px, py, glm::dvec2(p), channel, 64);
                    // The reference's own accuracy: against order 48.
                    const double coarser = accuratePixelAverage(scene.frame, px, py, glm::dvec2(p), channel, 48);
                    ASSERT_NEAR(coarser, expected, 1e-5 * expected) << "pixel " << px << ", " << py;
                    const double value = result.image.at(px, py, channel);
                    double grid = 0.0;
                    for (int k = 0; k < 256; ++k) {
                        int overflows = 0;
                        grid += sh::pegoraroRay_double(scene.frame, px + (k % 16 + 0.5f) / 16.0f,
                                                       py + (k / 16 + 0.5f) / 16.0f, -1, overflows)[channel] /
                                256.0;
                    }
                    worstGrid = std::max(worstGrid, std::abs(grid / expected - 1.0));
                    worst = std::max(worst, std::abs(value / expected - 1.0));
                    EXPECT_NEAR(value, expected, 1e-4 * expected) << "pixel " << px << ", " << py;
                }
            }
            std::printf("%s%s: worst relative error %.2e (the 16 x 16 grid: %.2e)\n", spot ? "spot" : "isotropic",
                        nearEdge ? " near an edge" : "", worst, worstGrid);
            EXPECT_GT(worstGrid, 1e-3);
        }
    }
}

// The reference's jitter about a point light's image (singular_pixel.h) against the closed form's accurate pixel
// average, in the light's pixel and its eight neighbours: the reference is unbiased there, and its spread across seeds
// is small; uniform jitter, with the same samples, spreads the light's own pixel many times more (its variance is
// infinite). Eight seeds of 64 samples per configuration.
TEST(ReferenceAroundALight, MatchesTheClosedFormsPixelAverage) {
    auto reference = createTechnique("reference");
    const int seeds = 8;
    for (int config = 0; config < 3; ++config) {
        // An isotropic light inside its pixel and near its edge, where the peak's cancellation is what the spread
        // shows; a spot light, whose cos^6 profile across the rays' directions adds the distance samples' own spread.
        const bool spot = config == 2, nearEdge = config == 1;
        SCOPED_TRACE(std::string(spot ? "spot" : "isotropic") + (nearEdge ? ", near an edge" : ""));
        RenderRequest request;
        request.scene = singularScene(spot, nearEdge);
        request.spp = 64;
        request.params = reference->defaultParams();
        ParamSet closedForm = createTechnique("pegoraro")->defaultParams();
        closedForm.set("precision", std::string("double"));
        const Settings settings = settingsFrom(closedForm);
        const PreparedScene scene = prepareScene(request.scene, settings, "");
        SceneScope scope(scene);
        glm::vec2 p;
        ASSERT_TRUE(sh::cameraProject(scene.frame.camera, scene.lights[0].position, p));
        // mean and standard deviation across seeds per pixel of the 3 x 3 block (channel 1), for both jitters
        auto spread = [&](const std::string& jitter, std::vector<double>& mean, std::vector<double>& sd) {
            request.params.set("pixelJitter", jitter);
            std::vector<double> sum(9, 0.0), sumSquares(9, 0.0);
            for (int seed = 1; seed <= seeds; ++seed) {
                request.seed = std::uint64_t(seed);
                const Image image = reference->render(request, {}).image;
                for (int k = 0; k < 9; ++k) {
                    const double v = image.at(3 + k % 3, 2 + k / 3, 1);
                    sum[k] += v;
                    sumSquares[k] += v * v;
                }
            }
            mean.resize(9);
            sd.resize(9);
            for (int k = 0; k < 9; ++k) {
                mean[k] = sum[k] / seeds;
                sd[k] = std::sqrt(std::max(0.0, (sumSquares[k] - seeds * mean[k] * mean[k]) / (seeds - 1)));
            }
        };
        std::vector<double> mean, sd, uniformMean, uniformSd;
        spread("auto", mean, sd);
        spread("uniform", uniformMean, uniformSd);
        for (int k = 0; k < 9; ++k) {
            const int px = 3 + k % 3, py = 2 + k / 3;
            const double expected = accuratePixelAverage(scene.frame, px, py, glm::dvec2(p), 1, 64);
            std::printf("pixel %d, %d: closed form %.5f; auto %.5f +- %.5f; uniform %.5f +- %.5f\n", px, py, expected,
                        mean[k], sd[k], uniformMean[k], uniformSd[k]);
            // 5 standard errors of the mean of 8 seeds (Student's t with 7 degrees of freedom: p = 0.0016)
            EXPECT_NEAR(mean[k], expected, 5.0 * sd[k] / std::sqrt(double(seeds)) + 1e-4 * expected)
                << "pixel " << px << ", " << py;
            if (!spot) {
                EXPECT_LT(sd[k], 0.02 * expected) << "pixel " << px << ", " << py;
            }
        }
        if (!spot) {
            EXPECT_GT(uniformSd[4], 5.0 * sd[4]);  // the light's own pixel
        }
    }
}

// The GPU renders the pixels around a light's projection (a pass of its own over their nodes) as the CPU does.
TEST_F(PegoraroGpu, PixelsAroundALightMatchTheCpu) {
    auto technique = createTechnique("pegoraro");
    for (const std::string precision : {"float", "double"}) {
        SCOPED_TRACE(precision);
        RenderRequest request;
        request.scene = singularScene(true, false);
        request.params = technique->defaultParams();
        request.params.set("precision", precision);
        request.params.set("device", std::string("gpu"));
        const RenderResult g = technique->render(request, {});
        request.params.set("device", std::string("cpu"));
        const RenderResult c = technique->render(request, {});
        EXPECT_NE(g.image.metadata.at("device"), "cpu");
        for (int py = 2; py <= 4; ++py)
            for (int px = 3; px <= 5; ++px)
                for (int ch = 0; ch < 3; ++ch)
                    EXPECT_NEAR(g.image.at(px, py, ch), c.image.at(px, py, ch), 1e-4 * c.image.at(px, py, ch))
                        << "pixel " << px << ", " << py;
    }
}

// hgTerms up to 32 with fallback = never: each render is either accurate (within 1e-2 of the quadrature everywhere,
// fallback = always, good to 1e-6; 1e-2 is the error bound that makes never refuse) or refused with an InputError naming
// hgTerms. HG g = 0.7 in a haze lit by a spot, in double on the CPU; before, 24 terms rendered garbage silently.
TEST(PegoraroTechnique, HighOrdersAreAccurateOrRefused) {
    auto technique = createTechnique("pegoraro");
    int refused = 0, accepted = 0;
    for (int terms : {8, 12, 16, 20, 24, 32}) {
        SCOPED_TRACE("hgTerms " + std::to_string(terms));
        RenderRequest request;
        request.scene = singularScene(true, false);
        request.scene.camera.width = 12;
        request.scene.camera.height = 9;
        request.scene.camera.fovY = 40.0;
        request.scene.media[0].phase.kind = PhaseKind::HenyeyGreenstein;
        request.scene.media[0].phase.g = 0.7;
        request.params = technique->defaultParams();
        request.params.set("device", std::string("cpu"));
        request.params.set("precision", std::string("double"));
        request.params.set("supersampling", std::int64_t(1));
        request.params.set("hgTerms", std::int64_t(terms));
        request.params.set("fallback", std::string("always"));
        const RenderResult exact = technique->render(request, {});
        request.params.set("fallback", std::string("never"));
        try {
            const RenderResult r = technique->render(request, {});
            ++accepted;
            double worst = 0.0;
            for (int y = 0; y < 9; ++y)
                for (int x = 0; x < 12; ++x)
                    for (int c = 0; c < 3; ++c)
                        worst = std::max(worst, std::abs(r.image.at(x, y, c) / exact.image.at(x, y, c) - 1.0));
            std::printf("hgTerms %d, fallback = never: largest relative difference to the quadrature %.2e\n", terms,
                        worst);
            EXPECT_LE(worst, 1e-2);
        } catch (const InputError& e) {
            ++refused;
            std::printf("hgTerms %d, fallback = never: refused (%s)\n", terms, e.what());
            EXPECT_EQ(e.where().field, "hgTerms");
        }
    }
    EXPECT_GT(accepted, 0);
    EXPECT_GT(refused, 0);
}

}  // namespace
}  // namespace tyndall::pegoraro::test
