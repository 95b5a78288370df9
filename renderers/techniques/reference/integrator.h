// The reference's light transport: an unbiased estimator of the radiance arriving along a camera ray, in single- or
// multiple-scattering mode as docs/conventions.md defines them. Written for clarity first; see docs/reference.md for
// the estimators and their MIS weights.
#pragma once

#include "reference/embree_scene.h"

#include "shared/bsdf.h"
#include "shared/camera.h"
#include "shared/phase.h"
#include "shared/rng.h"
#include "shared/shaped_equiangular.h"
#include "tyndall/core/scene.h"

#include <memory>
#include <string>
#include <vector>

namespace tyndall::reference {

using glm::vec2;
using shader::MaterialParams;
using shader::PhaseParams;

// ---------------------------------------------------------------------------------------------------------------------
// The scene prepared for rendering: float data, world space.

struct MediumElement {
    int medium = 0;        // index into RenderScene::media
    int particle = -1;     // index into RenderScene::particles, or -1 for a homogeneous medium
};

struct PreparedMedium {
    vec3 sigma_s{0.0f};    // 1/m; for particle media: the albedo (sigma_s = albedo * sigma_t(x))
    vec3 sigma_t{0.0f};    // 1/m; unused for particle media
    PhaseParams phase{};
    float meanSigmaT = 0.0f, meanSigmaS = 0.0f;  // channel means (homogeneous media), for the shaped equiangular table
    bool particles = false;
    bool infinite = false;
    bool peakedPhase = false;  // 4 pi max p >= kPeakedPhase: light sampling alone is weak near an area light
};

// The phase function's peak, relative to isotropic, above which `auto` light sampling adds phase sampling. HG reaches
// it at |g| = 0.848: on fog-quad (a 1 m^2 light in fog, 128 x 128) light sampling alone was 1.30 and 1.12 times as
// efficient as MIS at g = 0.6 and 0.8, and 0.86 times at g = 0.9 (docs/reference.md).
constexpr float kPeakedPhase = 80.0f;

struct PreparedParticle {
    vec3 centre{0.0f};
    vec3 sigma{0.0f};      // 1/m at the centre, per channel: extinction * multiplier
    float k = 0.0f;        // 50 / u^2, 1/m^2 (ISV thesis, Eq. 9)
};

struct PreparedPointLight {
    vec3 position{0.0f};
    vec3 intensity{0.0f};
    vec3 axis{0.0f, -1.0f, 0.0f};
    std::vector<float> polynomial;  // I(mu) = intensity * sum c_k mu^k
};

struct PreparedDirectionalLight {
    vec3 direction{0.0f, -1.0f, 0.0f};  // direction of travel
    vec3 irradiance{0.0f};
    bool hasGobo = false;
    ConvexVolume prism;                  // the beam: half-spaces through the gobo's edges, parallel to direction
};

struct PreparedAreaLight {
    std::vector<vec3> vertices;
    vec3 normal{0.0f};     // right-hand rule
    vec3 centroid{0.0f};
    vec3 radiance{0.0f};
    bool twoSided = false;
    float softening2 = 0.0f;  // m^2: the shaped light-targeted density's softening, area / (4 pi)
};

struct PreparedMesh {
    int material = 0;
    vec3 tangent{1.0f, 0.0f, 0.0f};
};

struct RenderScene {
    // camera
    shader::CameraParams camera{};
    int width = 1, height = 1;

    std::vector<PreparedMedium> media;
    std::vector<MediumElement> elements;   // one per Embree volume, in the same order
    std::vector<int> infiniteMedia;        // indices into media of unbounded homogeneous media
    std::vector<PreparedParticle> particles;
    std::vector<PreparedPointLight> pointLights;
    std::vector<PreparedDirectionalLight> directionalLights;
    std::vector<PreparedAreaLight> areaLights;
    std::vector<MaterialParams> materials;
    std::vector<PreparedMesh> meshes;
    std::unique_ptr<EmbreeScene> embree;
};

// A point on a triangle with a bound on the absolute rounding error of each coordinate (m).
struct SurfacePoint {
    vec3 p{0.0f};
    vec3 error{0.0f};
};
// Where the ray (origin, dir) meets the triangle of `hit` (docs/reference.md, Surfaces).
SurfacePoint surfacePoint(const TriangleGeometry& mesh, const SurfaceHit& hit, const vec3& origin, const vec3& dir);
// The origin for a ray leaving sp towards w (either side of the geometric normal ng): strictly on w's side of the
// surface, by no more than the point's error bound and one float.
vec3 offsetRayOrigin(const SurfacePoint& sp, const vec3& ng, const vec3& w);

// Throws InputError for scene content that cannot be prepared (e.g. a missing OBJ file).
std::unique_ptr<RenderScene> prepareScene(const Scene& scene, const std::string& projectDir);


// ---------------------------------------------------------------------------------------------------------------------

// How scattering distances are chosen along a ray: both techniques, delta tracking only, light-targeted only, or
// light-targeted alone for point and area lights in homogeneous media and both elsewhere (Auto, docs/reference.md).
enum class DistanceStrategy { Mis, Distance, LightTargeted, Auto };
// How directions to area lights are chosen: MIS of light sampling and phase/BSDF sampling everywhere, light sampling
// only, phase/BSDF sampling only, or Auto: MIS in media whose phase function is peaked (PreparedMedium::peakedPhase)
// and on glossy surfaces, light sampling alone elsewhere.
enum class LightStrategy { Mis, LightSampling, PhaseSampling, Auto };

struct IntegratorOptions {
    bool multipleScattering = false;
    int maxDepth = 1;                  // scattering events at most (1 in single-scattering mode)
    DistanceStrategy distance = DistanceStrategy::Mis;
    LightStrategy light = LightStrategy::Mis;
    bool transmittance = true;         // test hook: false makes every transmittance 1 (and disables distance sampling)
    // Light-targeted distances: for point lights on segments through homogeneous media, equiangular shaped by both
    // transmittances, the phase function and the light's profile (shared/shaped_equiangular.h); for area lights,
    // equiangular about the centroid softened by the light's size. Or plain equiangular for both.
    bool shapedEquiangular = true;
};

// Random numbers for one camera sample: padded Owen-scrambled Sobol pairs for the structured dimensions, and a PCG
// stream for the variable-length ones (rejections in delta tracking).
class SampleStream {
public:
    SampleStream(uint32_t pixelSeed, uint32_t index) : pixelSeed_(pixelSeed), index_(index) {
        pcg_ = shader::pcg32Seed(pixelSeed ^ 0x5bd1e995u, index);
    }
    vec2 next2D() { return shader::sobolSample2D(pixelSeed_, index_, pair_++); }
    float next1D() { return next2D().x; }
    float extra() { return shader::pcg32NextFloat(pcg_); }

private:
    uint32_t pixelSeed_, index_, pair_ = 0;
    shader::Pcg32 pcg_;
};

class Integrator {
public:
    Integrator(const RenderScene& scene, IntegratorOptions options) : scene_(scene), options_(options) {}

    // Radiance (W/(m^2 sr)) arriving at `origin` along -dir, one sample.
    vec3 radiance(const vec3& origin, const vec3& dir, SampleStream& samples) const;

    // The renderer's shadow query: 0 when a surface blocks [offset, distance) of the ray, else the transmittance
    // through the media along it (distance may be infinite). Public for benchmarks.
    vec3 shadowTransmittance(const vec3& x, const vec3& wi, float distance, float offset) const;

private:
    struct Segment;
    void buildSegment(const vec3& origin, const vec3& dir, float tMax, Segment& segment) const;
    vec3 opticalDepth(const Segment& segment, float a, float b) const;
    vec3 transmittance(const Segment& segment, float a, float b) const;
    vec3 sigmaT(const Segment& segment, float t) const;
    float distancePdf(const Segment& segment, float t) const;
    bool sampleCollision(const Segment& segment, SampleStream& samples, float& t) const;

    struct LightSample;
    bool sampleLight(int light, const vec3& x, const vec2& u, LightSample& ls) const;
    float lightPdf(int light, const vec3& x, const vec3& wi) const;
    bool lightTargetedTechnique(int light, const Segment& segment, float& a, float& b) const;
    float lightTargetedSample(int light, const Segment& segment, float u, float& pdf) const;
    float lightTargetedPdf(int light, const Segment& segment, float t) const;
    const shader::ShapedEquiangular* shapedTable(int light, const Segment& segment, float a, float b) const;

    vec3 inScattering(const Segment& segment, float t, float mu) const;
    vec3 sampleScatteringDirection(const Segment& segment, float t, const vec2& u, float& pdf) const;
    float scatteringDirectionPdf(const Segment& segment, float t, float mu) const;
    int lightCount() const;
    bool isAreaLight(int light) const;
    bool hitAreaLight(const vec3& origin, const vec3& dir, float tMax, int& light, float& t) const;

    const RenderScene& scene_;
    IntegratorOptions options_;
};

}  // namespace tyndall::reference
