// The WVDS technique: the analytic unoccluded integral against adaptive quadrature, whole-volume distance sampling and
// distance sampling against their pdfs (chi-square), every estimator against the reference in single scattering (and
// a biased variant that must fail the same test), and the GPU path against the CPU path.
#include "stats.h"
#include "technique_gpu_test.h"

#include "wvds/prepared.h"
#include "wvds/wvds.h"

#include "test_paths.h"
#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"
#include "tyndall/gpu/context.h"
#include "tyndall/image/metrics.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <gtest/gtest.h>

#include <random>

namespace tyndall::wvds::test {
namespace {

using tyndall::test::chiSquareTest;
using tyndall::test::integrate;

const std::string kProject = tyndall::test::sourceDir() + "/projects/examples/wvds-box.json";
const std::string kDefaultProject = tyndall::test::sourceDir() + "/projects/default.json";

// A medium of planes bound for the shared accessors, without surfaces.
struct BoundPlanes {
    PreparedScene scene;
    std::unique_ptr<SceneScope> scope;
    explicit BoundPlanes(const std::vector<HalfSpace>& halfSpaces) {
        for (const HalfSpace& h : halfSpaces) {
            const glm::dvec3 n = glm::normalize(h.normal);
            scene.planes.push_back(glm::vec4(glm::vec3(n), float(h.offset / glm::length(h.normal))));
        }
        scene.lights.push_back(shader::WvdsLight{});
        scene.surfaces.bvh = gpu::buildBvh(std::vector<glm::vec3>{}, std::vector<glm::uvec3>{});
        scope = std::make_unique<SceneScope>(scene);
    }
    int count() const { return int(scene.planes.size()); }
};

// ---------------------------------------------------------------------------------------------------------------------
// The brute-force side of the quadrature test: everything pointwise in double from the (float) planes, without the
// envelope of the technique.

struct RayInMedium {
    double tIn = 0.0, tOut = 0.0;
    bool hit = false;
};

RayInMedium clipBrute(const std::vector<glm::vec4>& planes, const glm::dvec3& o, const glm::dvec3& d) {
    RayInMedium r;
    double a = 0.0, b = 1e300;
    for (const glm::vec4& p : planes) {
        const glm::dvec3 n(p);
        const double nd = glm::dot(n, d), room = double(p.w) - glm::dot(n, o);
        if (nd > 0.0) b = std::min(b, room / nd);
        else if (nd < 0.0) a = std::max(a, room / nd);
        else if (room < 0.0) b = -1.0;
    }
    r.tIn = a;
    r.tOut = b;
    r.hit = a < b;
    return r;
}

double exitBrute(const std::vector<glm::vec4>& planes, const glm::dvec3& x, const glm::dvec3& l) {
    double m = 1e300;
    for (const glm::vec4& p : planes) {
        const glm::dvec3 n(p);
        const double nl = glm::dot(n, l);
        if (nl > 0.0) m = std::min(m, (double(p.w) - glm::dot(n, x)) / nl);
    }
    return std::max(m, 0.0);
}

// A random unit vector.
glm::dvec3 randomDirection(std::mt19937_64& rng) {
    std::normal_distribution<double> g;
    glm::dvec3 v;
    do {
        v = glm::dvec3(g(rng), g(rng), g(rng));
    } while (glm::length(v) < 1e-6);
    return glm::normalize(v);
}

enum class Case { Outside, Inside, Parallel, AntiParallel, NearParallel, Edge, Corner, Surface };

// The analytic integral (Eq. 6 summed over the segments, Eq. 7-8 in the parallel cases) against adaptive quadrature
// of e^{-sigma P(t)} with d_m by brute force, over 1600 random oriented boxes, cameras and lights: the camera outside
// and inside the box, light and view exactly and nearly parallel (both ways), rays grazing an edge or a corner, and
// rays clamped by a surface inside the box. Double precision (the core is instantiated in double for this); the
// quadrature is split into 64 pieces so that the kinks at the corners cost it nothing. Tolerance 1e-6 relative (the
// issue's); the measured worst is printed. Both envelopes: the general walk and the box variant's closed form.
TEST(WvdsIntegral, MatchesQuadratureOnRandomConfigurations) {
    std::mt19937_64 rng(20261201);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    double worst = 0.0, worstBox = 0.0;
    int configurations = 0, multiSegment = 0, negativeSlope = 0;
    const Case cases[] = {Case::Outside,      Case::Inside, Case::Parallel, Case::AntiParallel,
                          Case::NearParallel, Case::Edge,   Case::Corner,   Case::Surface};
    for (int i = 0; i < 1600; ++i) {
        const Case kind = cases[i % 8];
        OrientedBox box;
        box.centre = glm::dvec3(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5) * 2.0;
        box.size = glm::dvec3(0.3 + 3.0 * U(rng), 0.3 + 3.0 * U(rng), 0.3 + 3.0 * U(rng));
        box.rotate = glm::dvec3(U(rng), U(rng), U(rng)) * 360.0;
        const BoundPlanes bound(boxHalfSpaces(box));
        const std::vector<glm::vec4>& planes = bound.scene.planes;
        const glm::dmat3 R = box.worldFromBoxRotation();
        auto boxPoint = [&](double sx, double sy, double sz) {  // s in [-1, 1]^3
            return box.centre + R * (0.5 * box.size * glm::dvec3(sx, sy, sz));
        };
        glm::dvec3 o, target;
        if (kind == Case::Inside) {
            o = boxPoint(1.8 * U(rng) - 0.9, 1.8 * U(rng) - 0.9, 1.8 * U(rng) - 0.9);
            target = o + randomDirection(rng);
        } else {
            o = box.centre + randomDirection(rng) * (3.0 + 4.0 * U(rng));
            target = boxPoint(2.0 * U(rng) - 1.0, 2.0 * U(rng) - 1.0, 2.0 * U(rng) - 1.0);
            if (kind == Case::Edge) target = boxPoint(1.0, 1.0, 2.0 * U(rng) - 1.0);
            if (kind == Case::Corner) target = boxPoint(1.0, -1.0, 1.0);
        }
        const glm::dvec3 d = glm::normalize(target - o);
        glm::dvec3 l = randomDirection(rng);
        if (kind == Case::Parallel) l = d;
        if (kind == Case::AntiParallel) l = -d;
        if (kind == Case::NearParallel)
            l = glm::normalize((U(rng) < 0.5 ? d : -d) + randomDirection(rng) * std::pow(10.0, -7.0 + 5.0 * U(rng)));
        const double sigma = std::pow(10.0, -1.0 + 2.5 * U(rng));  // 0.1 .. 30 1/m

        const RayInMedium r = clipBrute(planes, o, d);
        if (!r.hit || r.tOut - r.tIn < 1e-9) continue;
        double b = r.tOut;
        if (kind == Case::Surface) b = r.tIn + (0.1 + 0.8 * U(rng)) * (r.tOut - r.tIn);
        shader::WvdsPieces_double pieces;
        shader::wvdsPieces_double(0, bound.count(), o, d, l, r.tIn, r.tIn, b, pieces);
        const double analytic = shader::wvdsTotal_double(pieces, sigma);

        const auto integrand = [&](double t) {
            const glm::dvec3 x = o + t * d;
            return std::exp(-sigma * (t - r.tIn + exitBrute(planes, x, l)));
        };
        double quadrature = 0.0;
        const int parts = 64;
        for (int k = 0; k < parts; ++k) {
            const double t0 = r.tIn + (b - r.tIn) * k / parts, t1 = r.tIn + (b - r.tIn) * (k + 1) / parts;
            quadrature += integrate(integrand, t0, t1, 1e-16, 1e-11);
        }
        ASSERT_GT(quadrature, 0.0);
        const double error = std::abs(analytic - quadrature) / quadrature;
        worst = std::max(worst, error);
        ++configurations;
        if (pieces.count > 1) ++multiSegment;
        for (int k = 0; k < pieces.count; ++k)
            if (pieces.c[k] < 0.0) ++negativeSlope;
        ASSERT_LE(error, 1e-6) << "configuration " << i << " (case " << int(kind) << "): analytic " << analytic
                               << ", quadrature " << quadrature << ", " << pieces.count << " segments";

        // The closed-form envelope of the box variant: the same integral, three ordered pieces covering [tIn, b]
        // (some possibly empty), and the same path length P(t) everywhere.
        shader::WvdsPieces_double boxPieces;
        ASSERT_EQ(shader::wvdsBoxPieces_double(0, o, d, l, r.tIn, r.tIn, b, boxPieces), 3);
        const double boxError = std::abs(shader::wvdsTotal_double(boxPieces, sigma) - quadrature) / quadrature;
        worstBox = std::max(worstBox, boxError);
        ASSERT_LE(boxError, 1e-6) << "configuration " << i << " (case " << int(kind) << "), box envelope";
        EXPECT_EQ(boxPieces.t0[0], r.tIn);
        for (int k = 0; k < 3; ++k) {
            EXPECT_GE(boxPieces.len[k], 0.0) << "configuration " << i;
            const double end = k < 2 ? boxPieces.t0[k + 1] : b;
            EXPECT_NEAR(boxPieces.t0[k] + boxPieces.len[k], end, 1e-12 * (1.0 + std::abs(end))) << "configuration " << i;
        }
        for (int j = 0; j < 16; ++j) {
            const double t = r.tIn + (b - r.tIn) * (j + 0.5) / 16.0;
            const double P = shader::wvdsPathLength_double(pieces, t);
            EXPECT_NEAR(shader::wvdsPathLength_double(boxPieces, t), P, 1e-9 * (1.0 + P)) << "configuration " << i;
        }
    }
    std::printf("WVDS integral: %d configurations (%d with several segments, %d segments of negative slope), worst "
                "relative error %.3g (box envelope %.3g)\n",
                configurations, multiSegment, negativeSlope, worst, worstBox);
    EXPECT_GE(configurations, 1000);
    EXPECT_GE(multiSegment, 300);
    EXPECT_GE(negativeSlope, 50);
}

// The float instantiation (what the GPU and the CPU renderer run) is good to 1e-4 relative on the same kind of
// configurations (float geometry and exponentials: about 100 units of roundoff at these depths).
TEST(WvdsIntegral, FloatAgreesWithDouble) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    for (int i = 0; i < 500; ++i) {
        OrientedBox box;
        box.size = glm::dvec3(0.5 + 3.0 * U(rng), 0.5 + 3.0 * U(rng), 0.5 + 3.0 * U(rng));
        box.rotate = glm::dvec3(U(rng), U(rng), U(rng)) * 360.0;
        const BoundPlanes bound(boxHalfSpaces(box));
        const glm::vec3 o = glm::vec3(randomDirection(rng) * 6.0);
        const glm::vec3 d = glm::normalize(glm::vec3(randomDirection(rng) * 0.3) - o);
        const glm::vec3 l = glm::vec3(randomDirection(rng));
        const float sigma = float(0.1 + 3.0 * U(rng));
        float a = 0.0f, b = shader::kInfinity;
        if (!shader::wvdsClip_float(0, bound.count(), o, d, a, b)) continue;
        shader::WvdsPieces_float pf;
        shader::wvdsPieces_float(0, bound.count(), o, d, l, a, a, b, pf);
        shader::WvdsPieces_double pd;
        shader::wvdsPieces_double(0, bound.count(), glm::dvec3(o), glm::dvec3(d), glm::dvec3(l), a, a, b, pd);
        const double reference = shader::wvdsTotal_double(pd, sigma);
        EXPECT_NEAR(shader::wvdsTotal_float(pf, sigma), reference, 1e-4 * reference) << "configuration " << i;
        shader::WvdsPieces_float boxPieces;
        shader::wvdsBoxPieces_float(0, o, d, l, a, a, b, boxPieces);
        EXPECT_NEAR(shader::wvdsTotal_float(boxPieces, sigma), reference, 1e-4 * reference) << "configuration " << i;
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Samplers

struct SamplerCase {
    const char* name;
    OrientedBox box;
    glm::dvec3 origin, target, toLight;
    double sigma;
};

std::vector<SamplerCase> samplerCases() {
    std::vector<SamplerCase> cases;
    OrientedBox unit;
    unit.size = glm::dvec3(2.0);
    // Light and view exit through the same face: one segment (the paper's Fig. 4).
    cases.push_back({"one segment", unit, {0.0, 0.0, 4.0}, {0.0, 0.0, 0.0}, glm::normalize(glm::dvec3(0.1, 0.2, 1.0)),
                     1.5});
    // Oblique light: two or three segments (Fig. 5), one with negative slope.
    cases.push_back({"oblique", unit, {0.0, 0.2, 4.0}, {0.1, 0.0, 0.0}, glm::normalize(glm::dvec3(1.0, 0.3, -0.4)),
                     2.0});
    OrientedBox turned;
    turned.size = glm::dvec3(3.0, 1.0, 2.0);
    turned.rotate = glm::dvec3(20.0, 35.0, 10.0);
    cases.push_back({"rotated box, camera inside", turned, {0.2, 0.1, 0.0}, {2.0, -0.3, 1.0},
                     glm::normalize(glm::dvec3(-0.5, 1.0, 0.6)), 3.0});
    cases.push_back({"light towards the camera", turned, {0.0, 0.0, 5.0}, {0.0, 0.0, 0.0},
                     glm::normalize(glm::dvec3(0.05, 0.1, 1.0)), 0.8});
    // Three segments (the most a box has): the first of a seeded search over cameras inside a rotated box.
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int i = 0; i < 100000; ++i) {
        SamplerCase c{"three segments", turned, glm::dvec3(U(rng), U(rng), U(rng)) * 0.4,
                      glm::dvec3(U(rng), U(rng), U(rng)) * 3.0, randomDirection(rng), 1.2};
        const BoundPlanes bound(boxHalfSpaces(c.box));
        const glm::vec3 o(c.origin), d(glm::normalize(c.target - c.origin));
        float a = 0.0f, b = shader::kInfinity;
        if (!shader::wvdsClip_float(0, bound.count(), o, d, a, b)) continue;
        shader::WvdsPieces_float p;
        shader::wvdsPieces_float(0, bound.count(), o, d, glm::vec3(c.toLight), a, a, b, p);
        bool substantial = p.count == 3;
        for (int k = 0; k < p.count; ++k)
            substantial = substantial && p.len[k] > 0.15f * (b - a);
        if (substantial) {
            cases.push_back(c);
            break;
        }
    }
    return cases;
}

// Whole-volume distance sampling (Eq. 9-10) against its pdf (Eq. 11), in float as the renderers run it: the pdf
// integrates to one, and 10^6 samples in 256 bins pass a chi-square test at the 1e-4 level against the bins' expected
// counts (the double pdf integrated over each bin). The segments of every case are listed on failure.
TEST(WvdsSampling, WholeVolumeSamplesMatchTheirPdf) {
    int segmentsSeen = 0;
    for (const SamplerCase& c : samplerCases()) {
        SCOPED_TRACE(c.name);
        const BoundPlanes bound(boxHalfSpaces(c.box));
        const glm::vec3 o(c.origin), d(glm::normalize(c.target - c.origin)), l(c.toLight);
        float a = 0.0f, b = shader::kInfinity;
        ASSERT_TRUE(shader::wvdsClip_float(0, bound.count(), o, d, a, b));
        shader::WvdsPieces_float pf;
        shader::wvdsPieces_float(0, bound.count(), o, d, l, a, a, b, pf);
        shader::WvdsPieces_double pd;
        shader::wvdsPieces_double(0, bound.count(), glm::dvec3(o), glm::dvec3(d), glm::dvec3(l), a, a, b, pd);
        segmentsSeen = std::max(segmentsSeen, pf.count);
        const auto pdf = [&](double t) { return shader::wvdsPdf_double(pd, c.sigma, t); };
        EXPECT_NEAR(integrate(pdf, a, b, 1e-12, 1e-10), 1.0, 1e-7);

        constexpr int kBins = 256, kSamples = 1000000;
        std::vector<double> observed(kBins, 0.0), expected(kBins, 0.0);
        const double width = double(b - a) / kBins;
        for (int i = 0; i < kBins; ++i)
            expected[i] = kSamples * integrate(pdf, a + i * width, a + (i + 1) * width, 1e-14, 1e-10);
        shader::Pcg32 rng = shader::pcg32Seed(11u, 3u);
        for (int k = 0; k < kSamples; ++k) {
            float samplePdf, path;
            const float t = shader::wvdsSample_float(pf, float(c.sigma), shader::pcg32NextFloat(rng), samplePdf, path);
            ASSERT_GE(t, a);
            ASSERT_LE(t, b);
            // The pdf it returns is Eq. 11 at the sample, and the path length is P(t).
            ASSERT_NEAR(samplePdf, shader::wvdsPdf_float(pf, float(c.sigma), t), 1e-4 * samplePdf);
            ASSERT_NEAR(path, shader::wvdsPathLength_float(pf, t), 1e-5f * (1.0f + path));
            observed[std::min(kBins - 1, int((t - a) / width))] += 1.0;
        }
        const auto chi = chiSquareTest(observed, expected);
        EXPECT_GT(chi.pValue, 1e-4) << chi.describe() << " (" << pf.count << " segments)";
    }
    EXPECT_GE(segmentsSeen, 3);
}

// Distance sampling truncated to the interval (REDS, MCDS) against its pdf, the same way.
TEST(WvdsSampling, DistanceSamplesMatchTheirPdf) {
    for (double sigma : {0.05, 1.0, 12.0}) {
        const double a = 0.5, b = 3.5;
        const auto pdf = [&](double t) { return shader::wvdsDistancePdf_double(sigma, a, b, t); };
        EXPECT_NEAR(integrate(pdf, a, b, 1e-12, 1e-10), 1.0, 1e-7);
        constexpr int kBins = 256, kSamples = 1000000;
        std::vector<double> observed(kBins, 0.0), expected(kBins, 0.0);
        const double width = (b - a) / kBins;
        for (int i = 0; i < kBins; ++i)
            expected[i] = kSamples * integrate(pdf, a + i * width, a + (i + 1) * width, 1e-14, 1e-10);
        shader::Pcg32 rng = shader::pcg32Seed(5u, 9u);
        for (int k = 0; k < kSamples; ++k) {
            float samplePdf;
            const float t =
                shader::wvdsDistanceSample_float(float(sigma), float(a), float(b), shader::pcg32NextFloat(rng), samplePdf);
            ASSERT_GE(t, a);
            ASSERT_LE(t, b);
            observed[std::min(kBins - 1, int((t - a) / width))] += 1.0;
        }
        const auto chi = chiSquareTest(observed, expected);
        EXPECT_GT(chi.pValue, 1e-4) << "sigma " << sigma << ": " << chi.describe();
    }
}

// The segment sampler at slopes where its closed forms switch (tiny, moderate, huge, negative) stays inside the
// segment and is monotonic in u, so stratification survives it.
TEST(WvdsSampling, SegmentSamplerIsMonotonicAtEverySlope) {
    for (double x : {-800.0, -30.0, -1.0, -1e-3, -1e-9, 0.0, 1e-9, 1e-3, 0.4, 0.6, 1.0, 30.0, 800.0}) {
        double previous = -1.0;
        for (int i = 0; i <= 1000; ++i) {
            const double u = i / 1000.0;
            const double s = shader::wvdsPieceSample_double(1.0, x, 1.0, u);
            ASSERT_GE(s, 0.0) << "x " << x;
            ASSERT_LE(s, 1.0) << "x " << x;
            ASSERT_GE(s, previous) << "x " << x << ", u " << u;
            previous = s;
        }
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// The technique against the reference

Project loadExample(const std::string& path, int width, int height, const std::vector<std::string>& overrides = {}) {
    std::vector<std::string> all = {"camera.width=" + std::to_string(width), "camera.height=" + std::to_string(height)};
    all.insert(all.end(), overrides.begin(), overrides.end());
    return loadProject(techniqueCatalogue(), path, all);
}

RenderResult renderView(const Project& project, const std::string& path, const std::string& view, int spp,
                        std::uint64_t seed) {
    JobOptions options;
    options.spp = spp;
    options.seed = seed;
    RenderJob job = makeViewJob(project, path, view, options);
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

struct Comparison {
    double relMSE = 0.0, bound = 0.0;
};

// Tolerance. Two independent unbiased (or consistent) estimates of the same pixel integrals differ by their noise
// alone: E[relMSE] = mean((Var_t + Var_r) / (r^2 + 0.01)), with both variances from the images' variance channels
// (each the squared difference of two half-images over four, an unbiased estimate of the variance of the pixel mean).
// Over the 3 x 64 x 48 terms the estimate fluctuates by a few per cent, and the variance estimate itself has a heavy
// tail per pixel, so the test allows 1.5 x. A biased estimator adds bias^2 / (r^2 + 0.01) per pixel, which at 2 %
// and these radiances is several times the bound.
Comparison compare(const RenderResult& technique, const RenderResult& reference) {
    Comparison c;
    c.relMSE = computeMetrics(technique.image, reference.image).relMSE;
    c.bound = 1.5 * (noiseOf(technique.image, reference.image) + noiseOf(reference.image, reference.image));
    return c;
}

class WvdsAgainstReference : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        project_ = std::make_unique<Project>(loadExample(kProject, 64, 48, cpuEverywhere()));
        JobOptions options;
        options.spp = 2048;
        options.seed = 7;
        RenderJob job = makeReferenceJob(*project_, kProject, "mcwvds", options);
        reference_ = std::make_unique<RenderResult>(runJob(job));
    }
    static void TearDownTestSuite() {
        project_.reset();
        reference_.reset();
    }
    static std::vector<std::string> cpuEverywhere() {
        std::vector<std::string> o;
        for (const char* v : {"mcwvds", "reds", "rees", "rm", "mcds", "analytic", "two lights", "polyhedron"})
            o.push_back(std::string("views[") + v + "].parameters.device=cpu");
        return o;
    }
    static std::unique_ptr<Project> project_;
    static std::unique_ptr<RenderResult> reference_;
};
std::unique_ptr<Project> WvdsAgainstReference::project_;
std::unique_ptr<RenderResult> WvdsAgainstReference::reference_;

// Every unbiased or consistent estimator of the Fig. 6 project at 1024 spp against the reference's single scattering
// at 2048 spp.
TEST_F(WvdsAgainstReference, EveryEstimatorConverges) {
    for (const char* estimator : {"mcwvds", "reds", "rees", "rm", "mcds"}) {
        const RenderResult image = renderView(*project_, kProject, estimator, 1024, 3);
        const Comparison c = compare(image, *reference_);
        std::printf("%-7s relMSE %.3g, bound %.3g\n", estimator, c.relMSE, c.bound);
        EXPECT_LE(c.relMSE, c.bound) << estimator;
        EXPECT_GT(c.bound, 0.0);
    }
}

// The same test fails for a 2 % scaled pdf (and a 2 % scaled analytic term of a ratio estimator), and for the
// unoccluded image: the test can tell.
TEST_F(WvdsAgainstReference, BiasedVariantsFail) {
    for (const char* estimator : {"mcwvds", "reds"}) {
        Project biased = *project_;
        const std::string field = std::string("views[") + estimator + "].parameters.pdfScale=1.02";
        biased = loadExample(kProject, 64, 48, {field, std::string("views[") + estimator + "].parameters.device=cpu"});
        const RenderResult image = renderView(biased, kProject, estimator, 1024, 3);
        const Comparison c = compare(image, *reference_);
        std::printf("%-7s with pdfScale 1.02: relMSE %.3g, bound %.3g\n", estimator, c.relMSE, c.bound);
        EXPECT_GT(c.relMSE, 2.0 * c.bound) << estimator;
    }
    const RenderResult unoccluded = renderView(*project_, kProject, "analytic", 64, 3);
    const Comparison c = compare(unoccluded, *reference_);
    EXPECT_GT(c.relMSE, 10.0 * c.bound);
}

// Beyond the single box and light: two lights, one with a gobo, with light selection by unoccluded radiance; and a
// convex polyhedral medium (a hexagonal prism).
TEST_F(WvdsAgainstReference, SeveralLightsAGoboAndAPolyhedron) {
    for (const char* view : {"two lights", "polyhedron"}) {
        JobOptions options;
        options.spp = 2048;
        options.seed = 7;
        RenderJob job = makeReferenceJob(*project_, kProject, view, options);
        const RenderResult reference = runJob(job);
        const RenderResult image = renderView(*project_, kProject, view, 1024, 3);
        const Comparison c = compare(image, reference);
        std::printf("%-10s relMSE %.3g, bound %.3g\n", view, c.relMSE, c.bound);
        EXPECT_LE(c.relMSE, c.bound) << view;
    }
}

// The default project's light shaft, rendered by WVDS: the camera inside the box, the window's gobo, chromatic
// extinction (the samplers then use the channels' mean), the room's walls occluding.
TEST(WvdsTechnique, RendersTheDefaultProjectsLightShaft) {
    const Project project = loadExample(kDefaultProject, 48, 36, {"views[light shaft].parameters.device=cpu"});
    JobOptions options;
    options.spp = 1024;
    options.seed = 5;
    RenderJob referenceJob = makeReferenceJob(project, kDefaultProject, "light shaft", options);
    const RenderResult reference = runJob(referenceJob);
    const RenderResult image = renderView(project, kDefaultProject, "light shaft", 1024, 3);
    EXPECT_EQ(image.image.metadata.at("technique"), "wvds");
    const Comparison c = compare(image, reference);
    std::printf("light shaft relMSE %.3g, bound %.3g\n", c.relMSE, c.bound);
    EXPECT_LE(c.relMSE, c.bound);
}

// The `denoise` option of the ratio estimators: each light's numerator and denominator denoised separately (with the
// same weights) before the ratio. At 4 spp the denoised REDS image is closer to a converged REDS image (512 spp) than
// the raw one. Over the whole image most of the error at 4 spp is the pixel jitter at the box's and the floor's edges
// (in the surface and analytic terms, which the option leaves alone), so the test measures the region of the sphere's
// shadow in the medium, where the ratio's noise is; over the whole image it only asks for no loss.
TEST(WvdsTechnique, DenoisedRatioIsCloserToConvergedAtLowSpp) {
    const Project raw = loadExample(kProject, 64, 48, {"views[reds].parameters.device=cpu"});
    const Project denoised = loadExample(
        kProject, 64, 48, {"views[reds].parameters.device=cpu", "views[reds].parameters.denoise=true"});
    const RenderResult converged = renderView(raw, kProject, "reds", 512, 11);
    const RenderResult noisy = renderView(raw, kProject, "reds", 4, 3);
    const RenderResult filtered = renderView(denoised, kProject, "reds", 4, 3);
    EXPECT_EQ(filtered.image.metadata.count("wvds:denoise"), 1u);
    EXPECT_EQ(noisy.image.metadata.count("wvds:denoise"), 0u);
    const Region shadow{32, 16, 16, 16};
    const double eRaw = computeMetrics(noisy.image, converged.image, 0.0, shadow).relMSE;
    const double eDenoised = computeMetrics(filtered.image, converged.image, 0.0, shadow).relMSE;
    const double allRaw = computeMetrics(noisy.image, converged.image).relMSE;
    const double allDenoised = computeMetrics(filtered.image, converged.image).relMSE;
    std::printf("reds at 4 spp against 512 spp, relMSE in the shadow: raw %.3g, denoised %.3g (%.1fx); whole image: "
                "raw %.3g, denoised %.3g\n",
                eRaw, eDenoised, eRaw / eDenoised, allRaw, allDenoised);
    // Measured: 4.2x in the shadow, 1.4x over the whole image. Bounds 3x and 1.2x.
    EXPECT_LT(eDenoised, eRaw / 3.0);
    EXPECT_LT(allDenoised, allRaw / 1.2);
    for (std::size_t i = 0; i < filtered.image.size(); ++i) ASSERT_TRUE(std::isfinite(filtered.image.data()[i]));
}

// Progressive rendering: an intermediate image at each pass, spp reported, and cancellation.
TEST(WvdsTechnique, RendersProgressivelyAndCancels) {
    const Project project = loadExample(kProject, 32, 24, {"views[reds].parameters.device=cpu"});
    JobOptions options;
    options.spp = 16;
    RenderJob job = makeViewJob(project, kProject, "reds", options);
    std::vector<int> passes;
    RenderCallbacks callbacks;
    callbacks.intermediate = [&](const Image&, int spp) { passes.push_back(spp); };
    const RenderResult result = runJob(job, callbacks);
    EXPECT_EQ(result.spp, 16);
    EXPECT_EQ(passes, (std::vector<int>{1, 2, 4, 8}));

    std::atomic<bool> cancel{true};
    RenderCallbacks cancelled;
    cancelled.cancel = &cancel;
    RenderJob again = makeViewJob(project, kProject, "reds", options);
    EXPECT_THROW(runJob(again, cancelled), Cancelled);
}

// What the technique cannot render is refused with a reason, not rendered black.
TEST(WvdsTechnique, RefusesWhatItCannotRender) {
    WvdsTechnique t;
    HomogeneousMedium infinite;
    infinite.name = "haze";
    EXPECT_FALSE(t.supports(infinite).supported);
    EXPECT_NE(t.supports(infinite).reason.find("haze"), std::string::npos);
    PointLight point;
    point.name = "bulb";
    EXPECT_FALSE(t.supports(point).supported);
    // Two media in one view.
    Project project = loadExample(kProject, 16, 12);
    RenderRequest request;
    request.scene = project.scene;
    request.params = t.defaultParams();
    request.scene.directionalLights.resize(1);
    EXPECT_THROW(t.render(request, {}), InputError);
}

// The probe behind the studio's PDF panel: at a pixel whose ray crosses the lit box, three sample histograms with their
// pdfs, and each histogram matches its pdf (the largest bin difference is a few standard deviations of a bin).
TEST(WvdsTechnique, DistanceProbeShowsHistogramsAndPdfs) {
    const Project project = loadExample(kProject, 64, 48, {"views[mcwvds].parameters.device=cpu"});
    JobOptions options;
    RenderJob job = makeViewJob(project, kProject, "mcwvds", options);
    const ProbeResult r = job.technique->probe(job.request, "distances", 30, 20);
    ASSERT_EQ(r.series.size(), 6u) << r.title;
    for (std::size_t s = 0; s < 6; s += 2) {
        const ProbeSeries& samples = r.series[s];
        const ProbeSeries& pdf = r.series[s + 1];
        ASSERT_EQ(samples.x.size(), 256u);
        double worst = 0.0, mass = 0.0;
        const double width = samples.x[1] - samples.x[0];
        for (std::size_t i = 0; i < 256; ++i) {
            worst = std::max(worst, std::abs(samples.y[i] - pdf.y[i]) / std::max(pdf.y[i], 1e-6));
            mass += samples.y[i] * width;
        }
        EXPECT_NEAR(mass, 1.0, 1e-3) << samples.label;
        EXPECT_LT(worst, 0.1) << samples.label;  // stratified samples: bins hold 256 +- a few each
    }
    EXPECT_THROW(job.technique->probe(job.request, "distances", 64, 0), InputError);
}

// ---------------------------------------------------------------------------------------------------------------------
// GPU against CPU

using WvdsGpu = tyndall::test::TechniqueGpuTest;

// The same samples on both paths: the shared code in float, so the images agree to float roundoff except where a
// shadow ray grazes an edge and the two sides decide differently (a handful of pixels). Bound: relMSE <= 1e-8 and
// 99 % of the pixels within 1e-4 relative, for every estimator and with two lights. The GPU compiles a variant per
// scene (the box's closed-form envelope, grey or chromatic extinction, with or without meshes), so the views cover
// each: the Fig. 6 box is grey, the polyhedron takes the general envelope; a chromatic medium and a scene without
// meshes are overrides.
TEST_F(WvdsGpu, GpuAgreesWithCpu) {
    struct Variant {
        const char* view;
        std::vector<std::string> overrides;
    };
    const std::vector<Variant> variants = {
        {"mcwvds", {}}, {"reds", {}}, {"rees", {}}, {"rm", {}}, {"mcds", {}}, {"analytic", {}}, {"two lights", {}},
        {"polyhedron", {}},
        {"analytic", {"media[0].sigma_a=[0.05,0.15,0.3]"}}, {"reds", {"media[0].sigma_a=[0.05,0.15,0.3]"}},
        {"analytic", {"meshes=[]"}}, {"mcwvds", {"meshes=[]"}}};
    for (const Variant& variant : variants) {
        const char* view = variant.view;
        const std::string device = std::string("views[") + view + "].parameters.device=";
        std::vector<std::string> gpuOverrides = variant.overrides, cpuOverrides = variant.overrides;
        gpuOverrides.push_back(device + "gpu");
        cpuOverrides.push_back(device + "cpu");
        const Project gpuProject = loadExample(kProject, 48, 36, gpuOverrides);
        const Project cpuProject = loadExample(kProject, 48, 36, cpuOverrides);
        const RenderResult g = renderView(gpuProject, kProject, view, 4, 9);
        const RenderResult c = renderView(cpuProject, kProject, view, 4, 9);
        EXPECT_NE(g.image.metadata.at("device"), "cpu");
        const double relMSE = computeMetrics(g.image, c.image).relMSE;
        int close = 0;
        for (int y = 0; y < 36; ++y)
            for (int x = 0; x < 48; ++x) {
                bool same = true;
                for (int ch = 0; ch < 3; ++ch)
                    same &= std::abs(g.image.at(x, y, ch) - c.image.at(x, y, ch)) <=
                            1e-4 * std::max(1e-3f, std::abs(c.image.at(x, y, ch)));
                close += same;
            }
        const std::string label = std::string(view) + (variant.overrides.empty() ? "" : " " + variant.overrides[0]);
        EXPECT_LE(relMSE, 1e-8) << label;
        EXPECT_GE(close, int(0.99 * 48 * 36)) << label;
    }
}

// The GPU renderer keeps its accumulators (and its slice size) from one render to the next, and zeroes them in place:
// a second render with another seed equals a first render with that seed. Left unzeroed, it would average both seeds'
// samples.
TEST_F(WvdsGpu, ARenderAgainStartsFromZero) {
    const std::vector<std::string> overrides = {"views[mcwvds].parameters.device=gpu"};
    const Project project = loadExample(kProject, 48, 36, overrides);
    JobOptions options;
    options.spp = 2;
    options.seed = 1;
    RenderJob reused = makeViewJob(project, kProject, "mcwvds", options);
    runJob(reused);
    reused.request.seed = 2;
    const RenderResult again = runJob(reused);
    const RenderResult fresh = renderView(project, kProject, "mcwvds", 2, 2);
    EXPECT_EQ(again.image.metadata.at("device"), fresh.image.metadata.at("device"));
    double largest = 0.0;
    for (int y = 0; y < 36; ++y)
        for (int x = 0; x < 48; ++x)
            for (int c = 0; c < 6; ++c)
                largest = std::max(largest, double(std::abs(again.image.at(x, y, c) - fresh.image.at(x, y, c))));
    EXPECT_EQ(largest, 0.0);
}

}  // namespace
}  // namespace tyndall::wvds::test
