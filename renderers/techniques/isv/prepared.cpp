#include "isv/prepared.h"

#include "tyndall/framework/shader_params.h"

#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"
#include "tyndall/framework/row_loop.h"
#include "tyndall/gpu/bvh.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>

namespace tyndall::isv {

// The std430 sizes the GLSL side sees (shaders/shared/isv.h).
static_assert(sizeof(shader::IsvParticle) == 80);
static_assert(sizeof(shader::IsvMedium) == 192);
static_assert(sizeof(shader::IsvLightSpace) == 80);
static_assert(sizeof(shader::IsvFrame) == 240 + 2 * 80 + 4 * 192);

namespace {

thread_local const std::vector<float>* gVsm = nullptr;
thread_local const std::vector<float>* gShadow = nullptr;

int indexOf(const std::vector<std::string>& names, const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    TY_CHECK(it != names.end(), "ParamSet validated the enum");
    return int(it - names.begin());
}

// A square grid over the extents [lo, hi] of the particles' grid coordinates (orthographic: m; perspective: tangents)
// and depths, with one empty texel of margin on each side, so that bilinear lookups fade to zero outside the
// particles.
shader::IsvLightSpace makeGrid(const glm::vec3& origin, const glm::vec3& right, const glm::vec3& up,
                               const glm::vec3& forward, bool perspective, const glm::vec3& lo, const glm::vec3& hi,
                               int size, int slices) {
    shader::IsvLightSpace g{};
    const float side = std::max({hi.x - lo.x, hi.y - lo.y, 1e-4f});
    g.size = size;
    g.texel = side / float(size - 2);
    g.origin = origin;
    g.right = right;
    g.up = up;
    g.forward = forward;
    g.perspective = perspective ? 1 : 0;
    g.corner = glm::vec2(lo.x - g.texel, lo.y - g.texel);
    g.depthOrigin = lo.z;
    g.slices = slices;
    g.depthStep = std::max(hi.z - lo.z, 1e-4f) / float(std::max(slices - 1, 1));
    return g;
}

// Grid-plane coordinates and depth of x seen from `origin` (orthographic: m; perspective: tangents, depth in m).
glm::vec3 toLight(const glm::vec3& origin, const glm::vec3& right, const glm::vec3& up, const glm::vec3& forward,
                  bool perspective, const glm::vec3& x) {
    const glm::vec3 r = x - origin;
    const float z = glm::dot(r, forward);
    glm::vec2 plane(glm::dot(r, right), glm::dot(r, up));
    if (perspective) plane /= z;
    return {plane, z};
}

// The texel-centre range [first, last] whose centres (i + 1/2) texel lie in [lo, hi] (grid coordinates in m).
glm::ivec2 centreRange(float lo, float hi, float texel, int size) {
    const int first = std::max(0, int(std::ceil(lo / texel - 0.5f)));
    const int last = std::min(size - 1, int(std::floor(hi / texel - 0.5f)));
    return {first, last};
}

}  // namespace

const std::vector<std::string>& integrationNames() {
    static const std::vector<std::string> names = {"analytic", "taylor", "simpson", "wasted-pixels"};
    return names;
}

Settings settingsFrom(const ParamSet& params) {
    Settings s;
    s.device = deviceFrom(params);
    const std::string& proxies = params.getEnum("proxies");
    s.proxies = proxies == "mesh" ? Proxies::Mesh : proxies == "geometry" ? Proxies::Geometry : Proxies::Auto;
    s.integration = indexOf(integrationNames(), params.getEnum("integration"));
    s.steps = int(params.getInt("steps"));
    s.fading = params.getBool("fading");
    s.threshold = float(params.getFloat("threshold"));
    s.multiScatter = float(params.getFloat("multiScatter"));
    s.selfShadowing = params.getBool("selfShadowing");
    s.vsmResolution = int(params.getInt("vsmResolution"));
    s.vsmSlices = int(params.getInt("vsmSlices"));
    s.opaqueShadows = params.getBool("opaqueShadows");
    s.shadowMapResolution = int(params.getInt("shadowMapResolution"));
    s.pcfRadius = int(params.getInt("pcfRadius"));
    s.supersampling = int(params.getInt("supersampling"));
    s.nearPlane = float(params.getFloat("nearPlane"));
    return s;
}

int lightCount(const Scene& scene) {
    return int(scene.directionalLights.size() + scene.pointLights.size());
}

PreparedScene prepareScene(const Scene& scene, const Settings& settings, const std::string& projectDir) {
    PreparedScene p;
    shader::IsvFrame& f = p.frame;
    f.integration = settings.integration;
    f.steps = settings.steps;
    f.threshold = settings.threshold;
    f.multiScatter = settings.multiScatter;
    f.fading = settings.fading ? 1 : 0;
    f.pcfRadius = settings.pcfRadius;

    if (int(scene.particleMedia.size()) > shader::kIsvMaxMedia)
        throw InputError(InputLocation{"", 0, 0, "particleMedia"}, "ISV renders at most " +
                                                                       std::to_string(shader::kIsvMaxMedia) +
                                                                       " particle media in one view; this view has " +
                                                                       std::to_string(scene.particleMedia.size()));

    f.mediumCount = int(scene.particleMedia.size());
    for (std::size_t m = 0; m < scene.particleMedia.size(); ++m) {
        const ParticleMedium& medium = scene.particleMedia[m];
        f.media[m].albedo = glm::vec3(medium.albedo);
        f.media[m].phase = toPhaseParams(medium.phase);
        // The particles carry the largest channel, the medium the ratio of each channel to it (coloured shadows).
        const Rgb& e = medium.extinction;
        const double largest = std::max({e.x, e.y, e.z});
        f.media[m].tint = largest > 0.0 ? glm::vec3(e / largest) : glm::vec3(1.0f);
        // Generated (and simulated) once: allParticles() does the work on every call.
        const std::vector<Particle> particles = medium.allParticles();
        // The RGB variant (and dual-source blending) only for a chromatic medium that has particles.
        if (f.media[m].tint != glm::vec3(1.0f) && !particles.empty()) p.chromatic = true;
        for (const Particle& particle : particles) {
            const std::array<Vec3, 4> v = tetrahedronVertices(particle);
            shader::IsvParticle q{};
            q.v0 = glm::vec3(v[0]);
            q.v1 = glm::vec3(v[1]);
            q.v2 = glm::vec3(v[2]);
            q.v3 = glm::vec3(v[3]);
            q.centre = glm::vec3(particle.centre);
            q.sigma = float(largest * particle.extinctionMultiplier);
            const double u = particle.scale * particle.falloff;
            q.k = float(50.0 / (u * u));
            q.medium = int(m);
            p.particles.push_back(q);
        }
    }

    p.surfaces = prepareGpuSurfaces(scene, projectDir);
    p.supersampling = settings.supersampling;
    p.nearPlane = settings.nearPlane;
    p.width = scene.camera.width * settings.supersampling;
    p.height = scene.camera.height * settings.supersampling;
    Camera camera = scene.camera;
    camera.width = p.width;
    camera.height = p.height;
    p.camera = toCameraParams(camera);

    // Every light is checked (its perspective maps must hold the particles), then the first one is set.
    for (int light = lightCount(scene) - 1; light >= 0; --light)
        lightScene(p, scene, settings, light);
    if (lightCount(scene) == 0) lightScene(p, scene, settings, -1);
    return p;
}

void lightScene(PreparedScene& p, const Scene& scene, const Settings& settings, int light) {
    shader::IsvFrame& f = p.frame;
    const int directionalCount = int(scene.directionalLights.size());
    const DirectionalLight* directional =
        light >= 0 && light < directionalCount ? &scene.directionalLights[std::size_t(light)] : nullptr;
    const PointLight* point = light >= directionalCount && light < lightCount(scene)
                                  ? &scene.pointLights[std::size_t(light - directionalCount)]
                                  : nullptr;
    TY_CHECK(light == -1 || directional || point, "lightScene: light index out of range");
    // Without a light the frame holds a black directional one.
    f.lightType = shader::kIsvDirectional;
    f.lightDirection = glm::vec3(0.0f, -1.0f, 0.0f);
    f.irradiance = glm::vec3(0.0f);
    f.lightPosition = glm::vec3(0.0f);
    f.lightAxis = glm::vec3(0.0f);
    f.distributionTerms = 0;
    f.spotExponent = 0.0f;
    std::fill(std::begin(f.distribution), std::end(f.distribution), 0.0f);
    f.hasVsm = 0;
    f.vsm = shader::IsvLightSpace{};
    f.hasShadowMap = 0;
    f.shadowMap = shader::IsvLightSpace{};
    f.shadowBias = 0.0f;
    if (directional) {
        f.lightDirection = glm::normalize(glm::vec3(directional->direction));
        f.irradiance = glm::vec3(directional->irradiance);
    }
    if (point) {
        f.lightType = shader::kIsvPoint;
        f.lightPosition = glm::vec3(point->position);
        f.irradiance = glm::vec3(point->intensity);
        f.lightAxis = glm::normalize(glm::vec3(point->distribution.axis));
        if (point->distribution.kind == AngularDistribution::Kind::Spot) {
            f.distributionTerms = -1;
            f.spotExponent = float(point->distribution.spotExponent);
        } else if (point->distribution.kind != AngularDistribution::Kind::Isotropic) {
            const std::vector<double> c = point->distribution.polynomial();
            TY_CHECK(c.size() <= std::size_t(shader::kIsvMaxDistributionTerms), "the loader limits the terms");
            f.distributionTerms = int(c.size());
            for (std::size_t k = 0; k < c.size(); ++k)
                f.distribution[k] = float(c[k]);
        }
    }

    std::vector<glm::vec3> vertices;
    vertices.reserve(p.particles.size() * 4);
    for (const shader::IsvParticle& q : p.particles)
        for (const glm::vec3& v : {q.v0, q.v1, q.v2, q.v3})
            vertices.push_back(v);

    // The light's view of the particles: orthographic along a directional light, or the frustum from a point light
    // towards the particles' bounding box, which must lie in front of the light.
    glm::vec3 gridOrigin(0.0f), forward = f.lightDirection;
    if (point && !vertices.empty()) {
        glm::vec3 bmin(std::numeric_limits<float>::max()), bmax(-std::numeric_limits<float>::max());
        for (const glm::vec3& v : vertices) {
            bmin = glm::min(bmin, v);
            bmax = glm::max(bmax, v);
        }
        gridOrigin = f.lightPosition;
        forward = 0.5f * (bmin + bmax) - gridOrigin;
        const float distance = glm::length(forward);
        if (!(distance > 0.0f))
            throw InputError(InputLocation{"", 0, 0, "lights[" + point->name + "].position"},
                             "the point light is at the particles' centre; ISV's perspective shadow maps need the "
                             "particles in front of the light");
        forward /= distance;
    }
    glm::vec3 right, up;
    shader::buildFrame(forward, right, up);
    const bool perspective = point != nullptr;
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const glm::vec3& v : vertices) {
        const glm::vec3 l = toLight(gridOrigin, right, up, forward, perspective, v);
        if (perspective && !(l.z > 1e-3f))
            throw InputError(InputLocation{"", 0, 0, "lights[" + point->name + "].position"},
                             "the point light is inside or beside the particle cloud: ISV's perspective shadow maps "
                             "need every particle in front of the light (a cube map would be needed)");
        lo = glm::min(lo, l);
        hi = glm::max(hi, l);
    }
    if (perspective && !vertices.empty() &&
        std::max({std::abs(lo.x), std::abs(lo.y), std::abs(hi.x), std::abs(hi.y)}) > 5.7f)  // tan 80 degrees
        throw InputError(InputLocation{"", 0, 0, "lights[" + point->name + "].position"},
                         "the particle cloud spans more than 160 degrees seen from the point light; ISV's perspective "
                         "shadow maps cover less (move the light away from the cloud)");

    const bool lit = directional || point;
    p.vsm = lit && settings.selfShadowing && !p.particles.empty();
    if (p.vsm) {
        f.hasVsm = 1;
        f.vsm = makeGrid(gridOrigin, right, up, forward, perspective, lo, hi, settings.vsmResolution,
                         settings.vsmSlices);
    }
    if (perspective) {
        // Surfaces take shadow rays; the map gives Vis inside the medium, over the particles' frustum.
        f.hasShadowMap = lit && settings.opaqueShadows && p.surfaces.triangleCount > 0 ? 1 : 0;
        p.shadowMap = f.hasShadowMap != 0 && !p.particles.empty();
        if (p.shadowMap) {
            f.shadowMap = makeGrid(gridOrigin, right, up, forward, true, lo, hi, settings.shadowMapResolution, 2);
            f.shadowBias = 2.0f * f.shadowMap.texel;  // relative to the distance: two texels of slope
        }
    } else {
        p.shadowMap = lit && settings.opaqueShadows && p.surfaces.triangleCount > 0;
        if (p.shadowMap) {
            // Over the particles and every surface, starting in front of all of them so that each occluder is seen.
            glm::vec3 slo = lo, shi = hi;
            for (int c = 0; c < 8; ++c) {
                const glm::vec3 corner((c & 1) ? p.surfaces.boundsMax.x : p.surfaces.boundsMin.x,
                                       (c & 2) ? p.surfaces.boundsMax.y : p.surfaces.boundsMin.y,
                                       (c & 4) ? p.surfaces.boundsMax.z : p.surfaces.boundsMin.z);
                const glm::vec3 l = toLight(gridOrigin, right, up, forward, false, corner);
                slo = glm::min(slo, l);
                shi = glm::max(shi, l);
            }
            slo.z -= 1e-3f * std::max(shi.z - slo.z, 1.0f);
            f.hasShadowMap = 1;
            f.shadowMap = makeGrid(gridOrigin, right, up, forward, false, slo, shi, settings.shadowMapResolution, 2);
            // Two texels of slope: a surface lit at up to ~63 degrees from its normal does not shadow itself.
            f.shadowBias = 2.0f * f.shadowMap.texel;
        }
    }
}

bool inFrontOfNearPlane(const PreparedScene& scene, const shader::IsvParticle& p) {
    const glm::vec3 vertices[4] = {p.v0, p.v1, p.v2, p.v3};
    for (const glm::vec3& v : vertices)
        if (glm::dot(v - scene.camera.position, scene.camera.forward) < scene.nearPlane) return false;
    return true;
}

std::uint32_t sortKey(const PreparedScene& scene, const shader::IsvParticle& p) {
    return std::bit_cast<std::uint32_t>(glm::length(p.centre - scene.camera.position));
}

std::vector<std::uint32_t> backToFront(const PreparedScene& scene) {
    std::vector<std::uint32_t> order(scene.particles.size());
    std::iota(order.begin(), order.end(), 0u);
    std::vector<std::uint32_t> keys(order.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        keys[i] = sortKey(scene, scene.particles[i]);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return keys[a] != keys[b] ? keys[a] > keys[b] : a < b;
    });
    return order;
}

MapScope::MapScope(const std::vector<float>* vsm, const std::vector<float>* shadow)
    : previousVsm_(gVsm), previousShadow_(gShadow) {
    gVsm = vsm;
    gShadow = shadow;
}

MapScope::~MapScope() {
    gVsm = previousVsm_;
    gShadow = previousShadow_;
}

std::vector<float> shadowMapCpu(const PreparedScene& scene, int threads, const std::atomic<bool>* cancel) {
    const shader::IsvLightSpace& g = scene.frame.shadowMap;
    std::vector<float> depth(std::size_t(g.size) * g.size, shader::kInfinity);
    RowLoop(g.size, threads, cancel).grain(4).forEachChunk([&](int y0, int y1) {
        gpu::BvhScope bvh(scene.surfaces.bvh);
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < g.size; ++x) {
                glm::vec3 o, d;
                float cosine;
                shader::isvGridRay(g, float(x) + 0.5f, float(y) + 0.5f, o, d, cosine);
                shader::BvhHit hit;
                if (shader::bvhIntersect(o, d, 0.0f, shader::kInfinity, hit))
                    depth[std::size_t(y) * g.size + x] = hit.t;
            }
    });
    return depth;
}

std::vector<float> vsmSlabsCpu(const PreparedScene& scene, int threads, const std::atomic<bool>* cancel) {
    const shader::IsvLightSpace& g = scene.frame.vsm;
    const int slabs = g.slices - 1;
    const std::size_t plane = std::size_t(g.size) * g.size;
    std::vector<float> out(plane * slabs * kVsmChannels, 0.0f);
    // Per particle its texel ranges and slab range, in grid coordinates.
    struct Footprint {
        glm::ivec2 xs, ys, slabs;
    };
    std::vector<Footprint> footprints(scene.particles.size());
    for (std::size_t i = 0; i < scene.particles.size(); ++i) {
        const shader::IsvParticle& p = scene.particles[i];
        glm::vec3 lo(shader::kInfinity), hi(-shader::kInfinity);
        for (const glm::vec3& v : {p.v0, p.v1, p.v2, p.v3}) {
            const glm::vec3 l = shader::isvGridPoint(g, v);
            lo = glm::min(lo, l);
            hi = glm::max(hi, l);
        }
        footprints[i].xs = centreRange(lo.x, hi.x, 1.0f, g.size);
        footprints[i].ys = centreRange(lo.y, hi.y, 1.0f, g.size);
        footprints[i].slabs = glm::ivec2(std::clamp(int(std::floor(lo.z / g.depthStep)), 0, slabs - 1),
                                         std::clamp(int(std::floor(hi.z / g.depthStep)), 0, slabs - 1));
    }
    RowLoop(g.size, threads, cancel).grain(2).forEachChunk([&](int y0, int y1) {
        for (std::size_t i = 0; i < scene.particles.size(); ++i) {
            const Footprint& fp = footprints[i];
            const shader::IsvParticle& p = scene.particles[i];
            for (int y = std::max(y0, fp.ys.x); y < std::min(y1, fp.ys.y + 1); ++y)
                for (int x = fp.xs.x; x <= fp.xs.y; ++x) {
                    glm::vec3 o, d;
                    float cosine;
                    shader::isvGridRay(g, float(x) + 0.5f, float(y) + 0.5f, o, d, cosine);
                    const glm::vec2 t = shader::isvRayTetrahedron(p, o, d);
                    if (!(t.x < t.y)) continue;
                    const glm::vec3 tint = scene.frame.media[p.medium].tint;
                    for (int j = fp.slabs.x; j <= fp.slabs.y; ++j) {
                        const float tau = shader::isvSlabDepth(
                            p, o, d, t.x, t.y, shader::isvRayDistance(g, float(j) * g.depthStep, cosine),
                            shader::isvRayDistance(g, float(j + 1) * g.depthStep, cosine), scene.frame.fading);
                        float* texel = &out[(std::size_t(j) * plane + std::size_t(y) * g.size + x) * kVsmChannels];
                        for (int c = 0; c < 3; ++c)
                            texel[c] += tau * tint[c];
                    }
                }
        }
    });
    return out;
}

std::vector<float> slicesFromSlabs(const std::vector<float>& slabs, const shader::IsvLightSpace& g) {
    const std::size_t plane = std::size_t(g.size) * g.size * kVsmChannels;
    std::vector<float> slices(plane * g.slices, 0.0f);
    for (int s = 1; s < g.slices; ++s)
        for (std::size_t i = 0; i < plane; ++i)
            slices[std::size_t(s) * plane + i] = slices[std::size_t(s - 1) * plane + i] + slabs[std::size_t(s - 1) * plane + i];
    return slices;
}

std::vector<glm::vec4> surfacesCpu(const PreparedScene& scene, const std::vector<float>& vsm,
                                   const std::vector<float>& shadow, int threads, const std::atomic<bool>* cancel) {
    std::vector<glm::vec4> out(std::size_t(scene.width) * scene.height, glm::vec4(0.0f, 0.0f, 0.0f, shader::kInfinity));
    if (scene.surfaces.triangleCount == 0) return out;
    RowLoop(scene.height, threads, cancel).grain(4).forEachChunk([&](int y0, int y1) {
        gpu::BvhScope bvh(scene.surfaces.bvh);
        MapScope maps(&vsm, &shadow);
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < scene.width; ++x) {
                glm::vec3 o, d;
                shader::cameraRay(scene.camera, float(x) + 0.5f, float(y) + 0.5f, o, d);
                shader::BvhHit hit;
                if (!shader::bvhIntersect(o, d, 0.0f, shader::kInfinity, hit)) continue;
                const shader::SurfaceTriangle& st = scene.surfaces.triangles[hit.id];
                const shader::SurfaceFrame sf = shader::surfaceFrame(st, hit.uv, d);
                const glm::vec3 point = o + hit.t * d;
                const float vis = shader::isvSurfaceVisibility(scene.frame, point, sf.ng, scene.surfaces.rayOffset);
                const glm::vec3 radiance = shader::isvSurfaceRadiance(
                    scene.frame, scene.surfaces.materials[std::size_t(st.material)], sf, point, -d, vis);
                out[std::size_t(y) * scene.width + x] = glm::vec4(radiance, hit.t);
            }
    });
    return out;
}

std::vector<glm::vec4> compositeCpu(const PreparedScene& scene, const std::vector<glm::vec4>& background,
                                    const std::vector<float>& vsm, const std::vector<float>& shadow,
                                    const std::vector<std::uint32_t>& order, int threads,
                                    const std::atomic<bool>* cancel) {
    const int w = scene.width, h = scene.height;
    std::vector<glm::vec4> out(background.size());
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = glm::vec4(glm::vec3(background[i]), 1.0f);
    // Per particle its pixel-centre ranges (empty for culled ones).
    const shader::CameraParams& cam = scene.camera;
    std::vector<glm::ivec4> boxes(scene.particles.size(), glm::ivec4(0, -1, 0, -1));
    for (std::size_t i = 0; i < scene.particles.size(); ++i) {
        const shader::IsvParticle& p = scene.particles[i];
        if (!inFrontOfNearPlane(scene, p)) continue;
        glm::vec2 lo(shader::kInfinity), hi(-shader::kInfinity);
        for (const glm::vec3& v : {p.v0, p.v1, p.v2, p.v3}) {
            const glm::vec3 r = v - cam.position;
            const float z = glm::dot(r, cam.forward);
            const glm::vec2 s((glm::dot(r, cam.right) / (z * cam.tanHalfFovY * cam.aspect) + 1.0f) * 0.5f * float(w),
                              (1.0f - glm::dot(r, cam.up) / (z * cam.tanHalfFovY)) * 0.5f * float(h));
            lo = glm::min(lo, s);
            hi = glm::max(hi, s);
        }
        const glm::ivec2 xs = centreRange(lo.x, hi.x, 1.0f, w), ys = centreRange(lo.y, hi.y, 1.0f, h);
        boxes[i] = glm::ivec4(xs.x, xs.y, ys.x, ys.y);
    }
    RowLoop(h, threads, cancel).grain(2).forEachChunk([&](int y0, int y1) {
        MapScope maps(&vsm, &shadow);
        for (std::uint32_t index : order) {
            const glm::ivec4 box = boxes[index];
            const shader::IsvParticle& p = scene.particles[index];
            for (int y = std::max(y0, box.z); y < std::min(y1, box.w + 1); ++y)
                for (int x = box.x; x <= box.y; ++x) {
                    glm::vec3 o, d;
                    shader::cameraRay(cam, float(x) + 0.5f, float(y) + 0.5f, o, d);
                    const glm::vec2 t = shader::isvRayTetrahedron(p, o, d);
                    const std::size_t pixel = std::size_t(y) * w + x;
                    const float surface = background[pixel].w;
                    if (!(t.x < t.y) || t.x >= surface) continue;
                    glm::vec3 a;
                    const glm::vec3 c = shader::isvShade(scene.frame, p, o, d, t.x, std::min(t.y, surface), a);
                    // The blend of particle.frag.glsl: per channel, and alpha by the mean transmittance.
                    out[pixel] = glm::vec4(c + a * glm::vec3(out[pixel]), shader::isvMeanChannel(a) * out[pixel].w);
                }
        }
    });
    return out;
}

}  // namespace tyndall::isv

// The accessors of shaders/shared/isv.h over the maps bound to this thread.
namespace tyndall::shader {
vec3 isvVsmTexel(int i) {
    TY_CHECK(tyndall::isv::gVsm != nullptr, "isvVsmTexel needs an isv::MapScope on this thread");
    const float* texel = &(*tyndall::isv::gVsm)[std::size_t(i) * tyndall::isv::kVsmChannels];
    return vec3(texel[0], texel[1], texel[2]);
}
float isvShadowTexel(int i) {
    TY_CHECK(tyndall::isv::gShadow != nullptr, "isvShadowTexel needs an isv::MapScope on this thread");
    return (*tyndall::isv::gShadow)[std::size_t(i)];
}
}  // namespace tyndall::shader
