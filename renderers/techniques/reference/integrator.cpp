#include "reference/integrator.h"

#include "tyndall/framework/shader_params.h"

#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tyndall::reference {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

vec3 toVec3(const Vec3& v) {
    return vec3(float(v.x), float(v.y), float(v.z));
}

float average(const vec3& v) {
    return (v.x + v.y + v.z) * (1.0f / 3.0f);
}
float maxComponent(const vec3& v) {
    return std::max(v.x, std::max(v.y, v.z));
}
bool isBlack(const vec3& v) {
    return v.x <= 0.0f && v.y <= 0.0f && v.z <= 0.0f;
}

vec3 expNeg(const vec3& tau) {
    return vec3(std::exp(-tau.x), std::exp(-tau.y), std::exp(-tau.z));
}

// A convex volume from half-spaces with unit normals.
ConvexVolume toConvexVolume(const std::vector<HalfSpace>& planes, const Vec3& lo, const Vec3& hi) {
    ConvexVolume volume;
    for (const HalfSpace& h : planes)
        volume.planes.emplace_back(toVec3(h.normal), float(h.offset));
    volume.boundsMin = toVec3(lo);
    volume.boundsMax = toVec3(hi);
    return volume;
}

ConvexVolume tetrahedronVolume(const std::array<Vec3, 4>& v) {
    static constexpr int kFaces[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};  // face + opposite
    ConvexVolume volume;
    for (const auto& f : kFaces) {
        Vec3 n = glm::normalize(glm::cross(v[f[1]] - v[f[0]], v[f[2]] - v[f[0]]));
        if (glm::dot(n, v[f[3]] - v[f[0]]) > 0.0) n = -n;  // outward
        volume.planes.emplace_back(toVec3(n), float(glm::dot(n, v[f[0]])));
    }
    Vec3 lo = glm::min(glm::min(v[0], v[1]), glm::min(v[2], v[3]));
    Vec3 hi = glm::max(glm::max(v[0], v[1]), glm::max(v[2], v[3]));
    volume.boundsMin = toVec3(lo);
    volume.boundsMax = toVec3(hi);
    return volume;
}

float polynomialValue(const std::vector<float>& c, float mu) {
    float value = 0.0f;
    for (size_t k = c.size(); k-- > 0;)
        value = value * mu + c[k];
    return value;
}

// Solid angles of the fan triangles (v0, vi, vi+1) of a convex polygon seen from x; returns their sum.
float fanSolidAngles(const PreparedAreaLight& light, const vec3& x, std::vector<float>& out) {
    vec3 a = glm::normalize(light.vertices[0] - x);
    float total = 0.0f;
    out.resize(light.vertices.size() - 2);
    for (size_t i = 1; i + 1 < light.vertices.size(); ++i) {
        vec3 b = glm::normalize(light.vertices[i] - x);
        vec3 c = glm::normalize(light.vertices[i + 1] - x);
        float omega = shader::sphericalTriangleSolidAngle(a, b, c);
        out[i - 1] = omega;
        total += omega;
    }
    return total;
}

// Whether 4 pi times the phase function's maximum over mu reaches kPeakedPhase (513 cosines, both ends included: the
// peaks of every kind Tyndall has are at mu = +-1 or spread wider than the spacing).
bool isPeaked(const PhaseParams& phase) {
    float peak = 0.0f;
    for (int i = 0; i <= 512; ++i)
        peak = std::max(peak, shader::phaseEval(phase, -1.0f + float(i) / 256.0f));
    return 4.0f * float(M_PI) * peak >= kPeakedPhase;
}

// gamma(n) = n eps / (1 - n eps) with eps = 2^-24, the unit roundoff of float: the relative error bound of n
// successive float operations (Higham; pbrt-v4, Sec. 6.8.1).
constexpr float floatGamma(int n) {
    constexpr float eps = 0.5f * std::numeric_limits<float>::epsilon();
    return float(n) * eps / (1.0f - float(n) * eps);
}

}  // namespace

// The hit point: the ray intersected in double with the plane of the (float) triangle Embree hit, rounded once to
// float. Embree's own t and barycentrics each carry an error of a few ulps of the triangle's size (3e-5 m on a 1 km
// ground: 1e-4 of the irradiance half a metre from a light); this point is off the exact intersection by half an ulp
// of its coordinates. Its error bound, for offsetting rays that leave it, adds gamma(7) sum |b_i p_i| (the bound of
// the barycentric sum in float, pbrt-v4 Sec. 6.8.5): a shadow ray's own test against this triangle in Embree rounds
// in proportion to the vertices' magnitudes, not to the point's, and the origin must clear that too.
SurfacePoint surfacePoint(const TriangleGeometry& mesh, const SurfaceHit& hit, const vec3& origin, const vec3& dir) {
    const glm::uvec3& tri = mesh.triangles[hit.triangle];
    const glm::dvec3 p0(mesh.positions[tri.x]), p1(mesh.positions[tri.y]), p2(mesh.positions[tri.z]);
    const double b1 = hit.u, b2 = hit.v, b0 = 1.0 - b1 - b2;
    const glm::dvec3 o(origin), d(dir);
    const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
    const double cosine = glm::dot(n, d);
    const glm::dvec3 p = cosine != 0.0 ? o + (glm::dot(n, p0 - o) / cosine) * d : b0 * p0 + b1 * p1 + b2 * p2;
    SurfacePoint sp;
    sp.p = vec3(p);
    sp.error = floatGamma(7) * vec3(glm::abs(b0 * p0) + glm::abs(b1 * p1) + glm::abs(b2 * p2)) +
               floatGamma(1) * glm::abs(sp.p);
    return sp;
}

// The origin of a ray leaving a surface point towards w: moved along the geometric normal to the face of the point's
// error box on w's side (the distance dot(|n|, error)), then each moved coordinate rounded one float further, so that
// the origin lies strictly on w's side of the true surface (pbrt-v4's OffsetRayOrigin, Sec. 6.8.6). Coordinates along
// which the normal has a component move by at least one float even when the error bound is zero (a plane at y = 0).
vec3 offsetRayOrigin(const SurfacePoint& sp, const vec3& ng, const vec3& w) {
    const float d = glm::dot(glm::abs(ng), sp.error);
    const vec3 n = glm::dot(w, ng) < 0.0f ? -ng : ng;
    vec3 po = sp.p + d * n;
    for (int i = 0; i < 3; ++i) {
        if (n[i] > 0.0f) po[i] = std::nextafter(po[i], kInf);
        else if (n[i] < 0.0f) po[i] = std::nextafter(po[i], -kInf);
    }
    return po;
}

// The near end of a shadow ray leaving a surface. The origin is already off the surface by the point's error bound,
// but Embree's own ray-triangle test rounds t relative to the coordinates' magnitude, and on the Pegoraro example's
// sphere and wall it still reported the surface itself at t ~ 0 (shadow acne: PegoraroTechnique.
// MatchesTheReferenceInSingleScattering failed at relMSE 4.2e-5 against a noise of 1e-6). 1e-5 of the point's largest
// coordinate (0.1 mm at 10 m, 1 cm at 1 km) is a visibility tolerance only: the light is still evaluated at the hit
// point, and occluders closer than that to the surface are the only ones missed.
namespace {
float embreeTnear(const vec3& p) {
    return 1e-5f * (1.0f + std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}));
}
}  // namespace

// ---------------------------------------------------------------------------------------------------------------------
// Scene preparation

std::unique_ptr<RenderScene> prepareScene(const Scene& scene, const std::string& projectDir) {
    auto rs = std::make_unique<RenderScene>();

    // Camera
    const Camera& cam = scene.camera;
    rs->camera = toCameraParams(cam);
    rs->width = cam.width;
    rs->height = cam.height;

    // Media
    std::vector<ConvexVolume> volumes;
    for (const HomogeneousMedium& m : scene.media) {
        PreparedMedium pm;
        pm.sigma_s = toVec3(m.sigma_s);
        pm.sigma_t = toVec3(m.sigma_t());
        pm.meanSigmaT = average(pm.sigma_t);
        pm.meanSigmaS = average(pm.sigma_s);
        pm.phase = toPhaseParams(m.phase);
        pm.peakedPhase = isPeaked(pm.phase);
        int index = int(rs->media.size());
        if (m.shape == MediumShape::Infinite) {
            pm.infinite = true;
            rs->infiniteMedia.push_back(index);
        } else {
            std::vector<HalfSpace> planes = m.shape == MediumShape::Box ? boxHalfSpaces(m.box) : m.planes;
            ConvexPolyhedron poly = makeConvexPolyhedron(planes);
            volumes.push_back(toConvexVolume(poly.planes, poly.boundsMin, poly.boundsMax));
            rs->elements.push_back(MediumElement{index, -1});
        }
        rs->media.push_back(pm);
    }
    for (const ParticleMedium& m : scene.particleMedia) {
        PreparedMedium pm;
        pm.sigma_s = toVec3(m.albedo);
        pm.phase = toPhaseParams(m.phase);
        pm.peakedPhase = isPeaked(pm.phase);
        pm.particles = true;
        int index = int(rs->media.size());
        rs->media.push_back(pm);
        for (const Particle& p : m.allParticles()) {
            double u = p.scale * p.falloff;
            PreparedParticle pp;
            pp.centre = toVec3(p.centre);
            pp.sigma = toVec3(m.extinction * p.extinctionMultiplier);
            pp.k = float(50.0 / (u * u));
            rs->elements.push_back(MediumElement{index, int(rs->particles.size())});
            rs->particles.push_back(pp);
            std::array<Vec3, 4> v = tetrahedronVertices(p);
            volumes.push_back(tetrahedronVolume(v));
        }
    }

    // Lights
    for (const PointLight& l : scene.pointLights) {
        PreparedPointLight p;
        p.position = toVec3(l.position);
        p.intensity = toVec3(l.intensity);
        p.axis = toVec3(glm::normalize(l.distribution.axis));
        for (double c : l.distribution.polynomial())
            p.polynomial.push_back(float(c));
        rs->pointLights.push_back(p);
    }
    for (const DirectionalLight& l : scene.directionalLights) {
        PreparedDirectionalLight p;
        Vec3 dir = glm::normalize(l.direction);
        p.direction = toVec3(dir);
        p.irradiance = toVec3(l.irradiance);
        if (!l.gobo.empty()) {
            p.hasGobo = true;
            Vec3 n = polygonNormal(l.gobo);
            if (std::abs(glm::dot(n, dir)) < 1e-6)
                throw InputError(InputLocation{"", 0, 0, "lights." + l.name + ".gobo"},
                                 "the gobo's plane contains the light direction, so no light passes through it");
            Vec3 centroid(0.0);
            for (const Vec3& v : l.gobo)
                centroid += v;
            centroid /= double(l.gobo.size());
            for (size_t i = 0; i < l.gobo.size(); ++i) {
                const Vec3& a = l.gobo[i];
                const Vec3& b = l.gobo[(i + 1) % l.gobo.size()];
                Vec3 pn = glm::normalize(glm::cross(b - a, dir));
                if (glm::dot(pn, centroid - a) > 0.0) pn = -pn;
                p.prism.planes.emplace_back(toVec3(pn), float(glm::dot(pn, a)));
            }
            p.prism.boundsMin = vec3(-kInf);
            p.prism.boundsMax = vec3(kInf);
        }
        rs->directionalLights.push_back(p);
    }
    for (const AreaLight& l : scene.areaLights) {
        PreparedAreaLight p;
        TY_CHECK(l.vertices.size() >= 3, "area lights have at least 3 vertices");
        Vec3 centroid(0.0);
        for (const Vec3& v : l.vertices) {
            p.vertices.push_back(toVec3(v));
            centroid += v;
        }
        p.centroid = toVec3(centroid / double(l.vertices.size()));
        p.normal = toVec3(polygonNormal(l.vertices));
        p.radiance = toVec3(l.radiance);
        p.twoSided = l.twoSided;
        Vec3 twiceArea(0.0);  // Newell: the sum of the edges' cross products is twice the area times the normal
        for (size_t i = 0; i < l.vertices.size(); ++i)
            twiceArea += glm::cross(l.vertices[i], l.vertices[(i + 1) % l.vertices.size()]);
        p.softening2 = float(0.5 * glm::length(twiceArea) / (4.0 * M_PI));
        rs->areaLights.push_back(p);
    }

    // Surfaces
    for (const Material& m : scene.materials) {
        rs->materials.push_back(toMaterialParams(m));
    }
    std::vector<TriangleGeometry> geometry;
    for (size_t i = 0; i < scene.meshes.size(); ++i) {
        const Mesh& mesh = scene.meshes[i];
        TriangleMesh tm = buildMesh(mesh, projectDir);
        TriangleGeometry g;
        g.positions = tm.positions;
        g.normals = tm.normals;
        g.triangles = tm.triangles;
        geometry.push_back(std::move(g));
        PreparedMesh pm;
        auto it = std::find_if(scene.materials.begin(), scene.materials.end(),
                               [&](const Material& m) { return m.name == mesh.material; });
        if (it == scene.materials.end())
            throw InputError(InputLocation{"", 0, 0, "meshes[" + std::to_string(i) + "].material"},
                             "unknown material '" + mesh.material + "'");
        pm.material = int(it - scene.materials.begin());
        pm.tangent = toVec3(mesh.tangent);
        rs->meshes.push_back(pm);
    }
    rs->embree = std::make_unique<EmbreeScene>(geometry, std::move(volumes));
    return rs;
}

// ---------------------------------------------------------------------------------------------------------------------
// Media along a ray

struct Span {
    float t0, t1;
    int medium;
    int particle;  // -1 for homogeneous media
};

struct Integrator::Segment {
    vec3 origin{0.0f}, dir{0.0f};
    float tMax = kInf;
    std::vector<Span> spans;
    float hullMin = kInf, hullMax = -kInf;  // the extent of all spans
    bool homogeneous = true;                // no particle span
    // The shaped equiangular tables of this segment, built on first use: per point light an index into `tables`, -1
    // when not built yet, -2 when the light takes plain equiangular on this segment.
    mutable std::vector<int> shaped;
    mutable std::vector<shader::ShapedEquiangular> tables;
};

void Integrator::buildSegment(const vec3& origin, const vec3& dir, float tMax, Segment& segment) const {
    segment.origin = origin;
    segment.dir = dir;
    segment.tMax = tMax;
    segment.spans.clear();
    for (int m : scene_.infiniteMedia)
        segment.spans.push_back(Span{0.0f, tMax, m, -1});
    thread_local std::vector<VolumeHit> hits;
    hits.clear();
    scene_.embree->volumeIntervals(origin, dir, 0.0f, tMax, hits);
    for (const VolumeHit& h : hits) {
        const MediumElement& e = scene_.elements[h.volume];
        segment.spans.push_back(Span{h.t0, h.t1, e.medium, e.particle});
    }
    segment.hullMin = kInf;
    segment.hullMax = -kInf;
    segment.homogeneous = true;
    for (const Span& s : segment.spans) {
        segment.hullMin = std::min(segment.hullMin, s.t0);
        segment.hullMax = std::max(segment.hullMax, s.t1);
        segment.homogeneous = segment.homogeneous && s.particle < 0;
    }
    segment.shaped.clear();
    segment.tables.clear();
}

// The extinction of one particle at x (ISV thesis (004), Eq. 9 written with the distance to the centre).
static vec3 particleExtinction(const PreparedParticle& p, const vec3& x) {
    vec3 d = x - p.centre;
    return p.sigma * std::exp(-p.k * glm::dot(d, d));
}

vec3 Integrator::sigmaT(const Segment& segment, float t) const {
    vec3 sum(0.0f);
    vec3 x = segment.origin + t * segment.dir;
    for (const Span& s : segment.spans) {
        if (t < s.t0 || t >= s.t1) continue;
        if (s.particle < 0)
            sum += scene_.media[s.medium].sigma_t;
        else
            sum += particleExtinction(scene_.particles[s.particle], x);
    }
    return sum;
}

// Integral of the Gaussian-faded extinction of a particle over [a, b] of the ray: with t_c the ray parameter closest to
// the centre and h its distance, sigma e^{-k h^2} sqrt(pi/k)/2 [erf(sqrt(k)(b - t_c)) - erf(sqrt(k)(a - t_c))]
// (ISV thesis (004), Eq. 10, derived in docs/reference.md), per channel.
static vec3 particleOpticalDepth(const PreparedParticle& p, const vec3& origin, const vec3& dir, double a, double b) {
    glm::dvec3 oc = glm::dvec3(p.centre) - glm::dvec3(origin);
    glm::dvec3 d(dir);
    double tc = glm::dot(oc, d);
    double h2 = std::max(0.0, glm::dot(oc, oc) - tc * tc);
    double sk = std::sqrt(double(p.k));
    double gauss = std::erf(sk * (b - tc)) - std::erf(sk * (a - tc));
    return p.sigma * float(std::exp(-double(p.k) * h2) * 0.5 * std::sqrt(M_PI) / sk * gauss);
}

vec3 Integrator::opticalDepth(const Segment& segment, float a, float b) const {
    vec3 tau(0.0f);
    for (const Span& s : segment.spans) {
        float lo = std::max(a, s.t0), hi = std::min(b, s.t1);
        if (lo >= hi) continue;
        if (s.particle < 0) {
            const vec3& st = scene_.media[s.medium].sigma_t;
            float length = hi - lo;
            for (int c = 0; c < 3; ++c)
                if (st[c] > 0.0f) tau[c] += st[c] * length;  // length may be infinite; 0 * inf must stay 0
        } else {
            tau += particleOpticalDepth(scene_.particles[s.particle], segment.origin, segment.dir, lo, hi);
        }
    }
    return tau;
}

vec3 Integrator::transmittance(const Segment& segment, float a, float b) const {
    if (!options_.transmittance) return vec3(1.0f);
    return expNeg(opticalDepth(segment, a, b));
}

// The density of a collision at t from delta tracking with a channel chosen uniformly: the one-sample MIS over the
// three channels, (1/3) sum_c sigma_t,c(t) T_c(0, t).
float Integrator::distancePdf(const Segment& segment, float t) const {
    if (!options_.transmittance || t >= segment.tMax) return 0.0f;
    vec3 st = sigmaT(segment, t);
    if (isBlack(st)) return 0.0f;
    return average(st * transmittance(segment, 0.0f, t));
}

// Delta tracking against the piecewise-constant majorant (the sum of each span's maximum: sigma_t for homogeneous
// media, the centre extinction for particles). In homogeneous media the majorant is exact and every tentative
// collision is real, so the first uniform number decides.
bool Integrator::sampleCollision(const Segment& segment, SampleStream& samples, float& tOut) const {
    if (segment.spans.empty()) return false;
    vec2 u = samples.next2D();
    int channel = std::min(2, int(u.x * 3.0f));

    struct Event {
        float t;
        float delta;
    };
    thread_local std::vector<Event> events;
    events.clear();
    for (const Span& s : segment.spans) {
        float majorant =
            s.particle < 0 ? scene_.media[s.medium].sigma_t[channel] : scene_.particles[s.particle].sigma[channel];
        if (majorant <= 0.0f) continue;
        events.push_back({s.t0, majorant});
        events.push_back({s.t1, -majorant});
    }
    if (events.empty()) return false;
    std::sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.t < b.t; });

    double tauTarget = -std::log(1.0 - double(u.y));
    double majorant = 0.0;
    float t = events.front().t;
    for (size_t i = 0; i < events.size();) {
        // Apply every event at this position.
        while (i < events.size() && events[i].t <= t)
            majorant += events[i++].delta;
        if (majorant < 1e-9) majorant = 0.0;
        float next = i < events.size() ? events[i].t : kInf;
        next = std::min(next, segment.tMax);
        if (majorant > 0.0) {
            for (;;) {
                double reach = majorant * (double(next) - double(t));
                if (reach < tauTarget) {
                    tauTarget -= reach;
                    break;
                }
                t += float(tauTarget / majorant);
                float real = sigmaT(segment, t)[channel];
                if (real >= majorant * 0.999999 || double(samples.extra()) * majorant < real) {
                    tOut = t;
                    return t < segment.tMax;
                }
                tauTarget = -std::log(1.0 - double(samples.extra()));
            }
        }
        if (next >= segment.tMax) return false;
        t = next;
    }
    return false;
}

// ---------------------------------------------------------------------------------------------------------------------
// Scattering in the media at a point

vec3 Integrator::inScattering(const Segment& segment, float t, float mu) const {
    vec3 sum(0.0f);
    vec3 x = segment.origin + t * segment.dir;
    for (const Span& s : segment.spans) {
        if (t < s.t0 || t >= s.t1) continue;
        const PreparedMedium& m = scene_.media[s.medium];
        float p = shader::phaseEval(m.phase, mu);
        if (s.particle < 0)
            sum += m.sigma_s * p;
        else
            sum += m.sigma_s * (particleExtinction(scene_.particles[s.particle], x) * p);
    }
    return sum;
}

// Chooses the medium that scatters in proportion to its mean scattering coefficient at t, then samples its phase
// function. The pdf is the mixture over the media present.
vec3 Integrator::sampleScatteringDirection(const Segment& segment, float t, const vec2& u, float& pdf) const {
    vec3 x = segment.origin + t * segment.dir;
    float total = 0.0f;
    thread_local std::vector<float> weights;
    weights.clear();
    for (const Span& s : segment.spans) {
        float w = 0.0f;
        if (t >= s.t0 && t < s.t1) {
            const PreparedMedium& m = scene_.media[s.medium];
            w = s.particle < 0 ? average(m.sigma_s)
                               : average(m.sigma_s * particleExtinction(scene_.particles[s.particle], x));
        }
        weights.push_back(w);
        total += w;
    }
    const int count = int(weights.size());
    pdf = 0.0f;
    if (total <= 0.0f) return vec3(0.0f);
    float target = u.x * total;
    int chosen = -1;
    float before = 0.0f;
    for (int i = 0; i < count; ++i) {
        if (weights[i] <= 0.0f) continue;
        chosen = i;
        if (target < before + weights[i]) break;
        before += weights[i];
    }
    if (chosen < 0) return vec3(0.0f);
    float reuse = std::min((target - before) / weights[chosen], shader::kOneMinusEpsilon);
    float lobePdf;
    vec3 wi = shader::phaseSample(scene_.media[segment.spans[chosen].medium].phase, segment.dir,
                                  vec2(std::max(0.0f, reuse), u.y), lobePdf);
    pdf = scatteringDirectionPdf(segment, t, glm::dot(segment.dir, wi));
    return wi;
}

float Integrator::scatteringDirectionPdf(const Segment& segment, float t, float mu) const {
    vec3 x = segment.origin + t * segment.dir;
    float total = 0.0f, weighted = 0.0f;
    for (const Span& s : segment.spans) {
        if (t < s.t0 || t >= s.t1) continue;
        const PreparedMedium& m = scene_.media[s.medium];
        float w = s.particle < 0 ? average(m.sigma_s)
                                 : average(m.sigma_s * particleExtinction(scene_.particles[s.particle], x));
        total += w;
        weighted += w * shader::phaseEval(m.phase, mu);
    }
    return total > 0.0f ? weighted / total : 0.0f;
}

// ---------------------------------------------------------------------------------------------------------------------
// Lights. Index order: point lights, directional lights, area lights.

struct Integrator::LightSample {
    vec3 wi{0.0f};
    float distance = 0.0f;
    vec3 Li{0.0f};     // incident radiance divided by the solid-angle pdf (area), or I/r^2 or E (delta lights)
    float pdf = 0.0f;  // solid-angle pdf of area lights; 0 for delta lights
};

int Integrator::lightCount() const {
    return int(scene_.pointLights.size() + scene_.directionalLights.size() + scene_.areaLights.size());
}

bool Integrator::isAreaLight(int light) const {
    return light >= int(scene_.pointLights.size() + scene_.directionalLights.size());
}

bool Integrator::sampleLight(int light, const vec3& x, const vec2& u, LightSample& ls) const {
    int nPoint = int(scene_.pointLights.size()), nDir = int(scene_.directionalLights.size());
    if (light < nPoint) {
        const PreparedPointLight& p = scene_.pointLights[light];
        vec3 d = p.position - x;
        float r2 = glm::dot(d, d);
        if (r2 <= 0.0f) return false;
        float r = std::sqrt(r2);
        ls.wi = d / r;
        ls.distance = r;
        float profile = std::max(0.0f, polynomialValue(p.polynomial, glm::dot(-ls.wi, p.axis)));
        ls.Li = p.intensity * (profile / r2);
        ls.pdf = 0.0f;
        return profile > 0.0f;
    }
    if (light < nPoint + nDir) {
        const PreparedDirectionalLight& p = scene_.directionalLights[light - nPoint];
        if (p.hasGobo) {
            for (const vec4& plane : p.prism.planes)
                if (glm::dot(vec3(plane), x) > plane.w) return false;
        }
        ls.wi = -p.direction;
        ls.distance = kInf;
        ls.Li = p.irradiance;
        ls.pdf = 0.0f;
        return true;
    }
    const PreparedAreaLight& a = scene_.areaLights[light - nPoint - nDir];
    float side = glm::dot(x - a.vertices[0], a.normal);
    if (side == 0.0f || (!a.twoSided && side < 0.0f)) return false;
    thread_local std::vector<float> omegas;
    float total = fanSolidAngles(a, x, omegas);
    if (total <= 1e-9f) return false;
    float target = u.x * total;
    size_t tri = 0;
    float before = 0.0f;
    size_t nTri = a.vertices.size() - 2;
    for (; tri + 1 < nTri; ++tri) {
        if (target < before + omegas[tri]) break;
        before += omegas[tri];
    }
    float ux = std::clamp((target - before) / std::max(omegas[tri], 1e-12f), 0.0f, shader::kOneMinusEpsilon);
    float omega;
    vec3 A = glm::normalize(a.vertices[0] - x), B = glm::normalize(a.vertices[tri + 1] - x),
         C = glm::normalize(a.vertices[tri + 2] - x);
    ls.wi = shader::sampleSphericalTriangle(A, B, C, vec2(ux, u.y), omega);
    if (omega <= 1e-7f) return false;  // a degenerate sliver (solid angle below 1e-7 sr): no usable direction
    float cosLight = glm::dot(ls.wi, a.normal);
    if (cosLight == 0.0f) return false;
    ls.distance = -side / cosLight;
    if (!(ls.distance > 0.0f)) return false;
    ls.pdf = 1.0f / total;
    ls.Li = a.radiance * total;
    return true;
}

// Solid-angle density with which sampleLight picks wi at x (0 for delta lights and directions that miss).
float Integrator::lightPdf(int light, const vec3& x, const vec3& wi) const {
    if (!isAreaLight(light)) return 0.0f;
    const PreparedAreaLight& a = scene_.areaLights[light - scene_.pointLights.size() - scene_.directionalLights.size()];
    float side = glm::dot(x - a.vertices[0], a.normal);
    if (side == 0.0f || (!a.twoSided && side < 0.0f)) return 0.0f;
    float cosLight = glm::dot(wi, a.normal);
    if (cosLight * side >= 0.0f) return 0.0f;  // moving away from the plane
    vec3 p = x + wi * (-side / cosLight);
    size_t n = a.vertices.size();
    for (size_t i = 0; i < n; ++i) {
        vec3 e = a.vertices[(i + 1) % n] - a.vertices[i];
        if (glm::dot(glm::cross(e, p - a.vertices[i]), a.normal) < 0.0f) return 0.0f;
    }
    thread_local std::vector<float> omegas;
    float total = fanSolidAngles(a, x, omegas);
    return total > 1e-9f ? 1.0f / total : 0.0f;
}

bool Integrator::hitAreaLight(const vec3& origin, const vec3& dir, float tMax, int& light, float& t) const {
    // Used per light by the caller: `light` is the area light to test (its global index); t receives the distance.
    const PreparedAreaLight& a = scene_.areaLights[light - scene_.pointLights.size() - scene_.directionalLights.size()];
    float side = glm::dot(origin - a.vertices[0], a.normal);
    if (side == 0.0f || (!a.twoSided && side < 0.0f)) return false;
    float cosLight = glm::dot(dir, a.normal);
    if (cosLight * side >= 0.0f) return false;
    t = -side / cosLight;
    if (!(t < tMax)) return false;
    vec3 p = origin + t * dir;
    size_t n = a.vertices.size();
    for (size_t i = 0; i < n; ++i) {
        vec3 e = a.vertices[(i + 1) % n] - a.vertices[i];
        if (glm::dot(glm::cross(e, p - a.vertices[i]), a.normal) < 0.0f) return false;
    }
    return true;
}

vec3 Integrator::shadowTransmittance(const vec3& x, const vec3& wi, float distance, float offset) const {
    float tEnd = std::isinf(distance) ? kInf : distance * (1.0f - 1e-5f);
    if (scene_.embree->occluded(x, wi, offset, tEnd)) return vec3(0.0f);
    if (!options_.transmittance) return vec3(1.0f);
    thread_local Segment shadow;  // its vectors keep their capacity from ray to ray
    buildSegment(x, wi, distance, shadow);
    return transmittance(shadow, 0.0f, distance);
}

// The light-targeted distance technique of a light on this segment: equiangular about point lights and the centroid of
// area lights; uniform over the part of the ray inside a directional light's beam. [a, b] is its support.
bool Integrator::lightTargetedTechnique(int light, const Segment& segment, float& a, float& b) const {
    a = std::max(0.0f, segment.hullMin);
    b = std::min(segment.tMax, segment.hullMax);
    if (!(a < b)) return false;
    int nPoint = int(scene_.pointLights.size()), nDir = int(scene_.directionalLights.size());
    if (light >= nPoint && light < nPoint + nDir) {
        const PreparedDirectionalLight& p = scene_.directionalLights[light - nPoint];
        if (p.hasGobo && !EmbreeScene::clip(p.prism, segment.origin, segment.dir, a, b)) return false;
        return std::isfinite(b - a);
    }
    return true;
}

static vec3 lightTargetPoint(const RenderScene& scene, int light) {
    int nPoint = int(scene.pointLights.size());
    if (light < nPoint) return scene.pointLights[light].position;
    return scene.areaLights[light - nPoint - scene.directionalLights.size()].centroid;
}

// The equiangular density about a point light, or about an area light's centroid, there softened by the light's size
// when `soften` (the shaped distances: docs/reference.md, "Shaped equiangular distances").
static shader::Equiangular lightEquiangular(const RenderScene& scene, int light, const vec3& origin, const vec3& dir,
                                            float a, float b, bool soften) {
    const int nPoint = int(scene.pointLights.size());
    const float softening2 =
        light < nPoint || !soften ? 0.0f : scene.areaLights[light - nPoint - scene.directionalLights.size()].softening2;
    return shader::equiangularSetupSoftened(origin, dir, lightTargetPoint(scene, light), a,
                                            std::isinf(b) ? shader::kInfinity : b, softening2);
}

// The shaped equiangular table of a point light on a segment through homogeneous media (nullptr elsewhere: area and
// directional lights, particles, the `shapedEquiangular` option off). Each node's weight is what equiangular leaves
// of the single-scattering integrand (shared/shaped_equiangular.h), estimated cheaply: the camera leg's optical depth
// from the spans, the light leg's as the local extinction times the distance (exact in a fog that holds the light),
// the media's scattering times their phase functions towards the light, and a spot's profile; channels averaged. The
// estimate only shapes the density: the sample is weighted by the exact integrand over the exact pdf. Area lights take
// the softened equiangular density instead (lightEquiangular): on fog-quad such a table towards the centroid (with or
// without a cosine at the light) gave no lower error per sample, so its cost was a loss (docs/reference.md).
const shader::ShapedEquiangular* Integrator::shapedTable(int light, const Segment& segment, float a, float b) const {
    if (!options_.shapedEquiangular || !options_.transmittance || !segment.homogeneous ||
        light >= int(scene_.pointLights.size()))
        return nullptr;
    if (segment.shaped.empty()) segment.shaped.assign(scene_.pointLights.size(), -1);
    int& slot = segment.shaped[std::size_t(light)];
    if (slot == -1) {
        const PreparedPointLight& point = scene_.pointLights[std::size_t(light)];
        const shader::Equiangular e = shader::equiangularSetup(segment.origin, segment.dir, point.position, a,
                                                               std::isinf(b) ? shader::kInfinity : b);
        // A ray within 1e-5 (relative) of the light: its angles lie within float resolution of +/- pi/2, where the
        // nodes' positions lose their precision (a table built there gave 30x outliers at h ~ 1e-7 |t0|). The pixel
        // jitter about a light's image sends a few samples in a thousand there; they take plain equiangular.
        if (e.h < 1e-5f * std::max(std::abs(e.t0), 1.0f)) {
            slot = -2;
            return nullptr;
        }
        slot = int(segment.tables.size());
        shader::ShapedEquiangular& table = segment.tables.emplace_back();
        table.e = e;
        shader::ShapedNodes nodes;
        shader::shapedNodeGeometry(table.e, nodes);
        const bool profile = point.polynomial.size() > 1;
        for (int k = 0; k <= TY_SHAPED_BINS; ++k) {
            // The end nodes lie on the ends of [a, b] up to rounding, which may put them just outside the media:
            // clamp them in, and count a medium's ends as inside it.
            const float t = std::clamp(nodes.t[k], a, b);
            float depth = 0.0f, local = 0.0f, scattering = 0.0f;
            for (const Span& sp : segment.spans) {
                const PreparedMedium& m = scene_.media[std::size_t(sp.medium)];
                depth += m.meanSigmaT * std::max(0.0f, std::min(t, sp.t1) - sp.t0);
                if (t >= sp.t0 && t <= sp.t1) {
                    local += m.meanSigmaT;
                    scattering += m.meanSigmaS * shader::phaseEval(m.phase, nodes.mu[k]);
                }
            }
            float w = scattering > 0.0f ? scattering * std::exp(-(depth + local * nodes.r[k])) : 0.0f;
            if (w > 0.0f && profile) {
                const vec3 fromLight = (segment.origin + t * segment.dir - point.position) / nodes.r[k];
                w *= std::max(0.0f, polynomialValue(point.polynomial, glm::dot(fromLight, point.axis)));
            }
            table.w[k] = w;
        }
        shader::shapedFinish(table);
    }
    return slot >= 0 ? &segment.tables[std::size_t(slot)] : nullptr;
}

float Integrator::lightTargetedSample(int light, const Segment& segment, float u, float& pdf) const {
    float a, b;
    lightTargetedTechnique(light, segment, a, b);
    int nPoint = int(scene_.pointLights.size()), nDir = int(scene_.directionalLights.size());
    if (light >= nPoint && light < nPoint + nDir) {
        pdf = 1.0f / (b - a);
        return a + u * (b - a);
    }
    if (const shader::ShapedEquiangular* table = shapedTable(light, segment, a, b))
        return std::clamp(shader::shapedSample(*table, u, pdf), a, b);
    shader::Equiangular e =
        lightEquiangular(scene_, light, segment.origin, segment.dir, a, b, options_.shapedEquiangular);
    float t = shader::equiangularSample(e, u, pdf);
    return std::clamp(t, a, b);
}

float Integrator::lightTargetedPdf(int light, const Segment& segment, float t) const {
    float a, b;
    if (!lightTargetedTechnique(light, segment, a, b) || t < a || t > b) return 0.0f;
    int nPoint = int(scene_.pointLights.size()), nDir = int(scene_.directionalLights.size());
    if (light >= nPoint && light < nPoint + nDir) return 1.0f / (b - a);
    if (const shader::ShapedEquiangular* table = shapedTable(light, segment, a, b)) return shader::shapedPdf(*table, t);
    shader::Equiangular e =
        lightEquiangular(scene_, light, segment.origin, segment.dir, a, b, options_.shapedEquiangular);
    return shader::equiangularPdf(e, t);
}

// ---------------------------------------------------------------------------------------------------------------------
// The estimator. Per ray segment and light, scattering distances come from up to three techniques combined with the
// balance heuristic (docs/reference.md):
//   T1  t by delta tracking, direction by light sampling;
//   T2  t by the light-targeted technique, direction by light sampling;
//   T3  t by delta tracking, direction by phase sampling, counted when it reaches an area light.
// Under the balance heuristic each technique's sample contributes f / (sum of the enabled techniques' pdfs). Surfaces
// combine light sampling with BSDF sampling the same way. The delta-tracking collision doubles as the path's next
// vertex in multiple-scattering mode.

vec3 Integrator::radiance(const vec3& cameraOrigin, const vec3& cameraDir, SampleStream& samples) const {
    const int nLights = lightCount();
    const bool distanceOn = options_.distance != DistanceStrategy::LightTargeted;
    const bool targetedOn = options_.distance != DistanceStrategy::Distance;
    const bool areaNee = options_.light != LightStrategy::PhaseSampling;
    const bool areaPhase = options_.light != LightStrategy::LightSampling;
    const bool autoLight = options_.light == LightStrategy::Auto;
    // Whether directions sampled from the phase function (T3) or the BSDF may reach area lights here. `auto` samples
    // them only where light sampling alone is weak (docs/reference.md): in media with a peaked phase function and on
    // glossy surfaces.
    auto phaseSamplingOn = [&](const Segment& seg) {
        if (scene_.areaLights.empty() || !areaPhase) return false;
        if (!autoLight) return true;
        return std::any_of(seg.spans.begin(), seg.spans.end(),
                           [&](const Span& sp) { return scene_.media[sp.medium].peakedPhase; });
    };
    auto bsdfSamplingOn = [&](const MaterialParams& material) {
        if (scene_.areaLights.empty() || !areaPhase) return false;
        return !autoLight || material.kind != shader::kMaterialDiffuse;
    };

    // Per segment and light: which techniques of the table above are enabled. Auto keeps delta tracking where it
    // pays (measured in docs/reference.md): for directional lights, whose light-targeted technique is uniform in the
    // beam, and on segments through particle media, whose extinction varies; point and area lights in homogeneous
    // media take equiangular distances alone.
    bool particlesOnSegment = false;
    auto t1Enabled = [&](int l, bool targetedAvailable) {
        if (!options_.transmittance) return false;
        if (isAreaLight(l) && !areaNee) return false;
        if (options_.distance == DistanceStrategy::Auto)
            return !targetedAvailable || particlesOnSegment ||
                   (l >= int(scene_.pointLights.size()) && !isAreaLight(l));
        return distanceOn || !targetedAvailable;
    };
    auto t2Enabled = [&](int l, bool targetedAvailable) {
        if (isAreaLight(l) && !areaNee) return false;
        return targetedOn && targetedAvailable;
    };

    // The 2-D sample of a light sample: delta lights take none, so that no Sobol pair is drawn for nothing.
    auto lightSample = [&](int l) { return isAreaLight(l) ? samples.next2D() : vec2(0.0f); };

    // The state a phase- or BSDF-sampled direction carries to the next segment, to weight the area lights it reaches.
    struct Pending {
        bool active = false;
        bool medium = false;
        vec3 x{0.0f};
        float pDistance = 0.0f;        // medium: delta-tracking pdf of the vertex (0 when T1 was off)
        float pDirection = 0.0f;       // pdf of the sampled direction (phase mixture or BSDF)
        std::vector<float> pTargeted;  // medium: light-targeted pdfs of the vertex per area light (0 when T2 was off)
        std::vector<char> t1;          // medium: whether T1 was on per area light
    } pending;
    pending.pTargeted.resize(scene_.areaLights.size());
    pending.t1.resize(scene_.areaLights.size());
    // The balance-heuristic weight of the direction sampled at the previous vertex, reaching area light l.
    auto pendingLightWeight = [&](const Pending& from, int l, const vec3& wi) {
        const int area = l - int(scene_.pointLights.size() + scene_.directionalLights.size());
        float pLight = areaNee ? lightPdf(l, from.x, wi) : 0.0f;
        float mine = from.medium ? from.pDistance * from.pDirection : from.pDirection;
        float others = from.medium ? (from.t1[area] ? from.pDistance * pLight : 0.0f) + from.pTargeted[area] * pLight
                                   : pLight;
        return mine / (mine + others);
    };

    vec3 L(0.0f), beta(1.0f);
    vec3 origin = cameraOrigin, dir = cameraDir;
    float tNear = 0.0f;
    int events = 0;
    thread_local Segment segment;  // its vectors keep their capacity from ray to ray

    for (;;) {
        // After the last event, the sampled direction only serves to find the area lights it reaches: test the
        // lights' polygons first and trace only towards those it hits (in single scattering the phase- and
        // BSDF-sampled rays mostly miss a small light; tracing each one as a segment cost 8 % more per sample on
        // fog-quad). A light counts when nothing blocks the ray before it, as on a traced segment below.
        if (pending.active && events >= options_.maxDepth) {
            int firstArea = int(scene_.pointLights.size() + scene_.directionalLights.size());
            for (int l = firstArea; l < nLights; ++l) {
                float tl;
                if (!hitAreaLight(origin, dir, kInf, l, tl)) continue;
                if (scene_.embree->occluded(origin, dir, tNear, tl * (1.0f - 1e-5f))) continue;
                buildSegment(origin, dir, tl, segment);
                L += beta * pendingLightWeight(pending, l, dir) * scene_.areaLights[l - firstArea].radiance *
                     transmittance(segment, 0.0f, tl);
            }
            break;
        }
        SurfaceHit hit;
        bool hasHit = scene_.embree->intersect(origin, dir, tNear, kInf, hit);
        buildSegment(origin, dir, hasHit ? hit.t : kInf, segment);
        particlesOnSegment = std::any_of(segment.spans.begin(), segment.spans.end(),
                                         [](const Span& s) { return s.particle >= 0; });
        const bool phaseHere = phaseSamplingOn(segment);
        // Per light: whether its light-targeted technique has a support on this segment (T2, and the T1 rule).
        thread_local std::vector<char> targeted;
        targeted.assign(std::size_t(nLights), 0);
        for (int l = 0; l < nLights; ++l) {
            float a, b;
            targeted[std::size_t(l)] = lightTargetedTechnique(l, segment, a, b);
        }

        // Area lights reached by the direction sampled at the previous vertex (T3 and surface BSDF sampling).
        if (pending.active) {
            int firstArea = int(scene_.pointLights.size() + scene_.directionalLights.size());
            for (int l = firstArea; l < nLights; ++l) {
                float tl;
                // The light counts when no surface is in front of it: tl (1 - 1e-5) < t_max, the rule of the
                // terminal test above and of the shadow rays of light sampling.
                if (!hitAreaLight(origin, dir, segment.tMax / (1.0f - 1e-5f), l, tl)) continue;
                L += beta * pendingLightWeight(pending, l, dir) * scene_.areaLights[l - firstArea].radiance *
                     transmittance(segment, 0.0f, tl);
            }
            pending.active = false;
        }
        if (events >= options_.maxDepth) break;

        // T2: one light-targeted distance per light.
        for (int l = 0; l < nLights; ++l) {
            const bool available = targeted[std::size_t(l)];
            if (!t2Enabled(l, available)) continue;
            vec2 u = samples.next2D();
            float pT;
            float t = lightTargetedSample(l, segment, u.x, pT);
            LightSample ls;
            if (!(pT > 0.0f) || !sampleLight(l, segment.origin + t * dir, lightSample(l), ls)) continue;
            float mu = glm::dot(dir, ls.wi);
            vec3 S = inScattering(segment, t, mu);
            if (isBlack(S)) continue;
            vec3 f = transmittance(segment, 0.0f, t) * S * ls.Li;
            vec3 x = origin + t * dir;
            f *= shadowTransmittance(x, ls.wi, ls.distance, 0.0f);
            if (isBlack(f)) continue;
            float denom = pT + (t1Enabled(l, available) ? distancePdf(segment, t) : 0.0f);
            if (isAreaLight(l) && phaseHere && ls.pdf > 0.0f)
                denom += distancePdf(segment, t) * scatteringDirectionPdf(segment, t, mu) / ls.pdf;
            L += beta * f / denom;
        }

        // T1: delta tracking; the collision is also the next vertex of the path. It is not drawn when nothing would
        // use it (single scattering from point lights under `auto`: 13 % of the time per sample on fog-point).
        bool collisionUsed = events + 1 < options_.maxDepth || phaseHere;
        for (int l = 0; l < nLights && !collisionUsed; ++l)
            collisionUsed = t1Enabled(l, targeted[std::size_t(l)]);
        float tc = 0.0f;
        bool collided = options_.transmittance && collisionUsed && sampleCollision(segment, samples, tc);
        if (collided) {
            vec3 x = origin + tc * dir;
            float pD = distancePdf(segment, tc);
            vec3 Tc = transmittance(segment, 0.0f, tc);
            for (int l = 0; l < nLights; ++l) {
                const bool available = targeted[std::size_t(l)];
                if (!t1Enabled(l, available)) continue;
                LightSample ls;
                if (!sampleLight(l, x, lightSample(l), ls)) continue;
                float mu = glm::dot(dir, ls.wi);
                vec3 S = inScattering(segment, tc, mu);
                if (isBlack(S)) continue;
                vec3 f = Tc * S * ls.Li * shadowTransmittance(x, ls.wi, ls.distance, 0.0f);
                if (isBlack(f)) continue;
                float denom = pD + (t2Enabled(l, available) ? lightTargetedPdf(l, segment, tc) : 0.0f);
                if (isAreaLight(l) && phaseHere && ls.pdf > 0.0f)
                    denom += pD * scatteringDirectionPdf(segment, tc, mu) / ls.pdf;
                L += beta * f / denom;
            }
        }

        // Direct light at the surface, weighted by the exact transmittance in front of it.
        SurfaceHit surface = hit;
        SurfacePoint sp;
        vec3 n(0.0f), ng(0.0f), tangent(0.0f), bitangent(0.0f), xs(0.0f);
        MaterialParams material{};
        vec3 woLocal(0.0f);
        bool bsdfHere = false;
        if (hasHit) {
            const TriangleGeometry& mesh = scene_.embree->meshes()[surface.mesh];
            const glm::uvec3& tri = mesh.triangles[surface.triangle];
            sp = surfacePoint(mesh, surface, origin, dir);
            xs = sp.p;
            ng = surface.geometricNormal;
            if (glm::dot(ng, dir) > 0.0f) ng = -ng;
            n = ng;
            if (!mesh.normals.empty()) {
                vec3 ns = glm::normalize((1.0f - surface.u - surface.v) * mesh.normals[tri.x] +
                                         surface.u * mesh.normals[tri.y] + surface.v * mesh.normals[tri.z]);
                if (glm::dot(ns, ng) < 0.0f) ns = -ns;
                n = ns;
            }
            const PreparedMesh& pm = scene_.meshes[surface.mesh];
            material = scene_.materials[pm.material];
            bsdfHere = bsdfSamplingOn(material);
            tangent = pm.tangent - glm::dot(pm.tangent, n) * n;
            if (glm::dot(tangent, tangent) < 1e-8f) shader::buildFrame(n, tangent, bitangent);
            tangent = glm::normalize(tangent);
            bitangent = glm::cross(n, tangent);
            auto toLocal = [&](const vec3& v) {
                return vec3(glm::dot(v, tangent), glm::dot(v, bitangent), glm::dot(v, n));
            };
            woLocal = toLocal(-dir);
            vec3 Ts = transmittance(segment, 0.0f, surface.t);
            if (!isBlack(Ts)) {
                // The light is sampled and evaluated at the hit point itself; only the shadow ray starts off the surface.
                for (int l = 0; l < nLights; ++l) {
                    if (isAreaLight(l) && !areaNee) continue;
                    LightSample ls;
                    if (!sampleLight(l, xs, lightSample(l), ls)) continue;
                    vec3 wiLocal = toLocal(ls.wi);
                    if (wiLocal.z <= 0.0f || glm::dot(ls.wi, ng) <= 0.0f) continue;
                    vec3 f = shader::bsdfEval(material, woLocal, wiLocal) * wiLocal.z * ls.Li;
                    if (isBlack(f)) continue;
                    f *= shadowTransmittance(offsetRayOrigin(sp, ng, ls.wi), ls.wi, ls.distance, embreeTnear(xs));
                    float weight = 1.0f;
                    if (isAreaLight(l) && bsdfHere && ls.pdf > 0.0f) {
                        float pB = shader::bsdfPdf(material, woLocal, wiLocal);
                        weight = ls.pdf / (ls.pdf + pB);
                    }
                    L += beta * Ts * f * weight;
                }
            }
        }

        // Continue the path: from the collision, or from the surface when delta tracking passed it.
        const bool needDirection = events + 1 < options_.maxDepth || (collided ? phaseHere : hasHit && bsdfHere);
        if (!needDirection) break;
        // Russian roulette after three events keeps long paths affordable without bias: everything that follows is
        // scaled by beta, so it is decided before the next direction is drawn.
        if (events >= 3) {
            float q = std::min(1.0f, maxComponent(beta));
            if (samples.extra() >= q) break;
            beta /= q;
        }
        if (collided) {
            vec3 x = origin + tc * dir;
            float pD = distancePdf(segment, tc);
            float pPhase;
            vec3 wi = sampleScatteringDirection(segment, tc, samples.next2D(), pPhase);
            if (!(pPhase > 0.0f) || !(pD > 0.0f)) break;
            float mu = glm::dot(dir, wi);
            beta *= transmittance(segment, 0.0f, tc) * inScattering(segment, tc, mu) / (pD * pPhase);
            pending.active = phaseHere;
            pending.medium = true;
            pending.x = x;
            pending.pDistance = pD;
            pending.pDirection = pPhase;
            int firstArea = int(scene_.pointLights.size() + scene_.directionalLights.size());
            for (int l = firstArea; l < nLights; ++l) {
                const bool available = targeted[std::size_t(l)];
                pending.t1[l - firstArea] = t1Enabled(l, available);
                pending.pTargeted[l - firstArea] = t2Enabled(l, available) ? lightTargetedPdf(l, segment, tc) : 0.0f;
            }
            origin = x;
            dir = wi;
            tNear = 0.0f;
        } else if (hasHit) {
            // Reaching the surface had probability (1/3) sum_c T_c when delta tracking ran; weight by T / that. When
            // no collision was drawn (nothing used one) the surface is reached with probability 1.
            vec3 Ts = transmittance(segment, 0.0f, surface.t);
            float pReach = options_.transmittance && collisionUsed && !segment.spans.empty() ? average(Ts) : 1.0f;
            if (!(pReach > 0.0f)) break;
            float pB;
            vec3 wiLocal = shader::bsdfSample(material, woLocal, samples.next2D(), pB);
            if (!(pB > 0.0f) || wiLocal.z <= 0.0f) break;
            vec3 wi = wiLocal.x * tangent + wiLocal.y * bitangent + wiLocal.z * n;
            if (glm::dot(wi, ng) <= 0.0f) break;
            beta *= (Ts / pReach) * shader::bsdfEval(material, woLocal, wiLocal) * (wiLocal.z / pB);
            pending.active = bsdfHere;
            pending.medium = false;
            pending.pDistance = 0.0f;
            pending.x = xs;
            pending.pDirection = pB;
            origin = offsetRayOrigin(sp, ng, wi);
            dir = wi;
            tNear = 0.0f;
        } else {
            break;
        }
        ++events;
        if (isBlack(beta)) break;
    }
    return L;
}

}  // namespace tyndall::reference
