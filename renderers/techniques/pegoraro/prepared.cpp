#include "pegoraro/prepared.h"

#include "pegoraro/pegoraro.h"
#include "tyndall/framework/gpu_surfaces.h"
#include "tyndall/framework/shader_params.h"

#include "shared/rng.h"

#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <type_traits>

namespace tyndall::pegoraro {

// The std430 sizes the shader reads (glslangValidator -q: the last member's offset plus its size).
static_assert(sizeof(shader::PegoraroFrame) == 144);
static_assert(sizeof(shader::PegoraroLight) == 48);

namespace {

const PreparedScene& bound() {
    return BoundScene<PreparedScene>::get("Pegoraro");
}

// A double as a pair of floats whose sum carries about 48 bits: the double closed form on the GPU reads both.
glm::vec2 split(double x) {
    const float hi = float(x);
    return {hi, float(x - double(hi))};
}

int appendCoefficients(std::vector<glm::vec2>& out, const std::vector<double>& c) {
    const int first = int(out.size());
    for (double x : c)
        out.push_back(split(x));
    return first;
}

}  // namespace

Settings settingsFrom(const ParamSet& params) {
    Settings s;
    s.device = deviceFrom(params);
    const std::string& precision = params.getEnum("precision");
    s.precision = precision == "double" ? Precision::Double : precision == "float" ? Precision::Float : Precision::Auto;
    s.supersampling = int(params.getInt("supersampling"));
    s.shadows = params.getBool("shadows");
    s.hg.terms = int(params.getInt("hgTerms"));
    s.hg.expansion = params.getEnum("hgExpansion") == "taylor" ? HgExpansion::Taylor : HgExpansion::Legendre;
    s.hg.taylorCentre = params.getFloat("hgTaylorCentre");
    s.hg.tolerance = params.getFloat("hgTolerance");
    const std::string& fallback = params.getEnum("fallback");
    s.fallbackMode = fallback == "never"    ? shader::kPegoraroFallbackNever
                     : fallback == "always" ? shader::kPegoraroFallbackAlways
                                            : shader::kPegoraroFallbackAuto;
    s.fallbackTolerance = params.getFloat("fallbackTolerance");
    s.quadratureTolerance = params.getFloat("quadratureTolerance");
    return s;
}

PreparedScene prepareScene(const Scene& scene, const Settings& settings, const std::string& projectDir) {
    PreparedScene p;
    shader::PegoraroFrame& f = p.frame;
    f.camera = toCameraParams(scene.camera);
    f.supersampling = settings.supersampling;
    f.shadows = settings.shadows ? 1 : 0;
    f.fallbackMode = settings.fallbackMode;
    f.fallbackTolerance = float(settings.fallbackTolerance);
    f.quadratureTolerance = float(settings.quadratureTolerance);

    // Media: every infinite homogeneous medium, each with its own phase polynomial; extinction adds up.
    glm::dvec3 sigmaT(0.0);
    int maxPhaseTerms = 0;
    for (const HomogeneousMedium& m : scene.media) {
        PhasePolynomial phase = phasePolynomial(m.phase, settings.hg);
        shader::PegoraroMedium pm{};
        pm.sigmaS = glm::vec3(m.sigma_s);
        pm.firstCoefficient = appendCoefficients(p.coefficients, phase.c);
        pm.terms = int(phase.c.size());
        maxPhaseTerms = std::max(maxPhaseTerms, pm.terms);
        p.media.push_back(pm);
        p.phases.push_back(std::move(phase));
        sigmaT += m.sigma_t();
    }
    f.sigmaT = glm::vec3(sigmaT);
    f.mediumCount = int(p.media.size());

    int maxLightTerms = 0;
    for (const PointLight& l : scene.pointLights) {
        const std::vector<double> c = l.distribution.polynomial();
        if (int(c.size()) > PegoraroTechnique::kMaxLightTerms)
            throw InputError(
                InputLocation{"", 0, 0, "lights[" + l.name + "].distribution"},
                "the Pegoraro technique takes light distributions of at most " +
                    std::to_string(PegoraroTechnique::kMaxLightTerms) + " terms (a spot exponent of at most " +
                    std::to_string(PegoraroTechnique::kMaxLightTerms - 1) + "), got " + std::to_string(c.size()));
        shader::PegoraroLight pl{};
        pl.position = glm::vec3(l.position);
        pl.axis = glm::vec3(glm::normalize(l.distribution.axis));
        pl.intensity = glm::vec3(l.intensity);
        pl.firstCoefficient = appendCoefficients(p.coefficients, c);
        pl.terms = int(c.size());
        maxLightTerms = std::max(maxLightTerms, pl.terms);
        p.lights.push_back(pl);
    }
    f.lightCount = int(p.lights.size());
    p.maxTerms = std::max(1, maxPhaseTerms + maxLightTerms - 1);
    if (p.maxTerms > shader::kPegoraroMaxTerms)
        throw InputError(InputLocation{"", 0, 0, "lights"},
                         "a phase function of " + std::to_string(maxPhaseTerms) +
                             " terms and a light distribution of " + std::to_string(maxLightTerms) +
                             " make a closed form of " + std::to_string(p.maxTerms) +
                             " terms; the Pegoraro technique takes at most " +
                             std::to_string(shader::kPegoraroMaxTerms) + " (lower hgTerms or the spot exponent)");
    if (p.coefficients.empty()) p.coefficients.push_back(glm::vec2(0.0f));  // no zero-sized buffers

    // Surfaces.
    GpuSurfaces surfaces = prepareGpuSurfaces(scene, projectDir);
    p.triangleCount = surfaces.triangleCount;
    p.triangles = std::move(surfaces.triangles);
    p.materials = std::move(surfaces.materials);
    p.bvh = std::move(surfaces.bvh);
    f.boundsMin = surfaces.boundsMin;
    f.boundsMax = surfaces.boundsMax;
    f.rayOffset = surfaces.rayOffset;
    return p;
}

namespace {

template <typename Series, typename Polynomial>
double closedFormErrorEstimateIn(const Polynomial& phase, const Polynomial& light) {
    using R = decltype(phase.c[0]);
    using Real = std::remove_cv_t<std::remove_reference_t<R>>;
    shader::Pcg32 rng = shader::pcg32Seed(16u, 3u);
    const auto uniform = [&] { return double(shader::pcg32NextFloat(rng)); };
    const auto unit = [&] {
        const double z = 2.0 * uniform() - 1.0, phi = 2.0 * 3.14159265358979323846 * uniform();
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        return glm::dvec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    // The error is measured against the brightest the evaluation could be (the isotropic integral times the largest
    // values of the phase function and the light distribution): relative to the value itself it would be huge wherever
    // a lobe makes the value nearly zero, which does not show in an image.
    Real maxPhase = 0, maxLight = 0;
    for (int k = 0; k <= 256; ++k) {
        const Real mu = Real(-1.0 + k / 128.0);
        maxPhase = std::max(maxPhase, std::abs(shader::pegoraroHorner(phase, mu)));
        maxLight = std::max(maxLight, std::abs(shader::pegoraroHorner(light, mu)));
    }
    Polynomial one{};
    one.terms = 1;
    one.c[0] = Real(1);
    double worst = 0.0;
    for (int i = 0; i < 64; ++i) {
        // A ray direction, the light's axis and the direction from the light to the foot (perpendicular to the ray).
        const glm::dvec3 dir = unit(), axis = unit();
        const glm::dvec3 foot = glm::normalize(glm::cross(dir, unit()));
        const Real del = Real(glm::dot(dir, axis)), dc = Real(glm::dot(foot, axis));
        const Real H = Real(1e-2 * std::pow(2000.0, uniform()));
        const Real ua = Real(10.0 * uniform() - 5.0);
        const Real ub = uniform() < 0.3 ? Real(shader::kInfinity) : ua + Real(0.01 + 5.0 * uniform());
        Series s, isotropic;
        Real bound = 0, unused = 0;
        shader::pegoraroSeries(del, dc, one, one, isotropic);
        const double brightest =
            double(shader::pegoraroIntegral(isotropic, H, ua, ub, unused)) * double(maxPhase) * double(maxLight);
        shader::pegoraroSeries(del, dc, phase, light, s);
        shader::pegoraroSeriesRefine(del, dc, phase, light, s);
        shader::pegoraroIntegral(s, H, ua, ub, bound);
        if (brightest > 1e-30) worst = std::max(worst, double(bound) / brightest);
    }
    return worst;
}

}  // namespace

double closedFormErrorEstimate(const PreparedScene& scene, int m, int l, bool useDouble) {
    const shader::PegoraroMedium& medium = scene.media[std::size_t(m)];
    const shader::PegoraroLight& light = scene.lights[std::size_t(l)];
    if (useDouble)
        return closedFormErrorEstimateIn<shader::PegoraroSeries_double>(
            shader::pegoraroLoadPolynomial_double(medium.firstCoefficient, medium.terms),
            shader::pegoraroLoadPolynomial_double(light.firstCoefficient, light.terms));
    return closedFormErrorEstimateIn<shader::PegoraroSeries_float>(
        shader::pegoraroLoadPolynomial_float(medium.firstCoefficient, medium.terms),
        shader::pegoraroLoadPolynomial_float(light.firstCoefficient, light.terms));
}

void checkClosedFormRange(const PreparedScene& scene, const Settings& settings, bool useDouble) {
    if (settings.fallbackMode != shader::kPegoraroFallbackNever) return;
    SceneScope scope(scene);
    for (std::size_t m = 0; m < scene.media.size(); ++m) {
        for (std::size_t l = 0; l < scene.lights.size(); ++l) {
            const double estimate = closedFormErrorEstimate(scene, int(m), int(l), useDouble);
            if (estimate <= kNeverMaxError) continue;
            char text[512];
            std::snprintf(text, sizeof(text),
                          "with fallback = never the closed form of %d terms (phase function %d, light distribution "
                          "%d) in %s would be off by up to %.2g relative (allowed: %g): lower hgTerms (or raise "
                          "hgTolerance), use fallback = auto%s",
                          scene.media[m].terms + scene.lights[l].terms - 1, scene.media[m].terms, scene.lights[l].terms,
                          useDouble ? "double" : "float", estimate, kNeverMaxError,
                          useDouble ? "" : ", or precision = double");
            throw InputError(InputLocation{"", 0, 0, "hgTerms"}, text);
        }
    }
}

}  // namespace tyndall::pegoraro

// The accessors of shaders/shared/pegoraro_scene.h over the scene bound to this thread.
namespace tyndall::shader {
PegoraroLight pegoraroLight(int i) {
    return pegoraro::bound().lights[std::size_t(i)];
}
PegoraroMedium pegoraroMedium(int i) {
    return pegoraro::bound().media[std::size_t(i)];
}
vec2 pegoraroCoefficient(int i) {
    return pegoraro::bound().coefficients[std::size_t(i)];
}
SurfaceTriangle surfaceTriangle(int id) {
    return pegoraro::bound().triangles[std::size_t(id)];
}
MaterialParams surfaceMaterial(int i) {
    return pegoraro::bound().materials[std::size_t(i)];
}
}  // namespace tyndall::shader
