#include "wvds/prepared.h"

#include "tyndall/framework/shader_params.h"

#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"

#include <algorithm>

namespace tyndall::wvds {

// The std430 sizes the shader reads (glslangValidator -q: the last member's offset plus its size).
static_assert(sizeof(shader::WvdsFrame) == 276);
static_assert(sizeof(shader::WvdsLight) == 32);

namespace {

const PreparedScene& bound() {
    return BoundScene<PreparedScene>::get("WVDS");
}

glm::vec4 plane(const Vec3& normal, double offset) {
    const Vec3 n = glm::normalize(normal);
    return glm::vec4(glm::vec3(n), float(offset / glm::length(normal)));
}

}  // namespace

const std::vector<std::string>& estimatorNames() {
    static const std::vector<std::string> names = {"analytic", "mcwvds", "reds", "rees", "rm", "mcds"};
    return names;
}

int estimatorFromName(const std::string& name) {
    const auto& names = estimatorNames();
    auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end())
        throw InputError(InputLocation{"", 0, 0, "estimator"},
                         "unknown estimator '" + name + "'; allowed: analytic, mcwvds, reds, rees, rm, mcds");
    return int(it - names.begin());
}

Settings settingsFrom(const ParamSet& params) {
    Settings s;
    s.device = deviceFrom(params);
    s.estimator = estimatorFromName(params.getEnum("estimator"));
    s.samplesPerPixel = int(params.getInt("samplesPerPixel"));
    s.raySamples = int(params.getInt("raySamples"));
    s.shadows = params.getBool("shadows");
    s.lightSelection = params.getEnum("lightSelection") == "unoccluded";
    s.pdfScale = params.getFloat("pdfScale");
    s.denoise = params.getBool("denoise");
    return s;
}

PreparedScene prepareScene(const Scene& scene, const Settings& settings, std::uint64_t seed,
                           const std::string& projectDir) {
    PreparedScene p;
    shader::WvdsFrame& f = p.frame;
    f.camera = toCameraParams(scene.camera);

    if (scene.media.size() != 1 || !scene.particleMedia.empty())
        throw InputError(InputLocation{"", 0, 0, "media"},
                         "the WVDS technique integrates one bounded homogeneous medium; this view has " +
                             std::to_string(scene.media.size() + scene.particleMedia.size()) +
                             " media (give the view a part with one box or convex polyhedron)");
    const HomogeneousMedium& m = scene.media.front();
    const std::string field = "media[" + m.name + "]";
    if (m.shape == MediumShape::Infinite)
        throw InputError(InputLocation{"", 0, 0, field + ".shape"},
                         "the WVDS technique needs a bounded medium (box or convexPolyhedron); an infinite one "
                         "extinguishes collimated light completely");
    const std::vector<HalfSpace> halfSpaces = m.shape == MediumShape::Box ? boxHalfSpaces(m.box) : m.planes;
    if (int(halfSpaces.size()) > shader::kWvdsMaxPlanes)
        throw InputError(InputLocation{"", 0, 0, field + ".planes"},
                         "the WVDS technique takes convex media of at most " +
                             std::to_string(shader::kWvdsMaxPlanes) + " faces, got " +
                             std::to_string(halfSpaces.size()));
    for (const HalfSpace& h : halfSpaces)
        p.planes.push_back(plane(h.normal, h.offset));
    f.planeCount = int(p.planes.size());
    p.box = m.shape == MediumShape::Box;
    f.sigmaS = glm::vec3(m.sigma_s);
    f.sigmaT = glm::vec3(m.sigma_t());
    f.sigmaSample = (f.sigmaT.x + f.sigmaT.y + f.sigmaT.z) / 3.0f;
    f.phase = toPhaseParams(m.phase);

    if (int(scene.directionalLights.size()) > shader::kWvdsMaxLights)
        throw InputError(InputLocation{"", 0, 0, "lights"},
                         "the WVDS technique takes at most " + std::to_string(shader::kWvdsMaxLights) +
                             " collimated lights per view, got " + std::to_string(scene.directionalLights.size()));
    for (const DirectionalLight& l : scene.directionalLights) {
        shader::WvdsLight wl{};
        const Vec3 dir = glm::normalize(l.direction);
        wl.toLight = glm::vec3(-dir);
        wl.irradiance = glm::vec3(l.irradiance);
        wl.goboFirst = int(p.planes.size());
        if (!l.gobo.empty()) {
            // The beam: the prism of half-spaces through the gobo's edges, parallel to the direction (conventions.md).
            const Vec3 n = polygonNormal(l.gobo);
            if (std::abs(glm::dot(n, dir)) < 1e-6)
                throw InputError(InputLocation{"", 0, 0, "lights[" + l.name + "].gobo"},
                                 "the gobo's plane contains the light direction, so no light passes through it");
            if (int(l.gobo.size()) > shader::kWvdsMaxGoboPlanes)
                throw InputError(InputLocation{"", 0, 0, "lights[" + l.name + "].gobo"},
                                 "the WVDS technique takes gobos of at most " +
                                     std::to_string(shader::kWvdsMaxGoboPlanes) + " vertices, got " +
                                     std::to_string(l.gobo.size()));
            Vec3 centroid(0.0);
            for (const Vec3& v : l.gobo)
                centroid += v;
            centroid /= double(l.gobo.size());
            for (std::size_t i = 0; i < l.gobo.size(); ++i) {
                const Vec3& a = l.gobo[i];
                const Vec3& b = l.gobo[(i + 1) % l.gobo.size()];
                Vec3 pn = glm::normalize(glm::cross(b - a, dir));
                if (glm::dot(pn, centroid - a) > 0.0) pn = -pn;
                p.planes.push_back(plane(pn, glm::dot(pn, a)));
            }
        }
        wl.goboCount = int(p.planes.size()) - wl.goboFirst;
        p.lights.push_back(wl);
    }
    f.lightCount = int(p.lights.size());
    if (p.lights.empty()) p.lights.push_back(shader::WvdsLight{});  // no zero-sized buffers

    f.estimator = settings.estimator;
    f.raySamples = settings.raySamples;
    f.shadows = settings.shadows ? 1 : 0;
    f.lightSelection = settings.lightSelection ? 1 : 0;
    f.pdfScale = float(settings.pdfScale);
    f.seed = std::uint32_t(seed ^ (seed >> 32));

    p.surfaces = prepareGpuSurfaces(scene, projectDir);
    f.rayOffset = p.surfaces.rayOffset;
    return p;
}

}  // namespace tyndall::wvds

// The accessors of shaders/shared/wvds.h and wvds_scene.h over the scene bound to this thread.
namespace tyndall::shader {
vec4 wvdsPlane(int i) {
    return wvds::bound().planes[std::size_t(i)];
}
WvdsLight wvdsLight(int i) {
    return wvds::bound().lights[std::size_t(i)];
}
SurfaceTriangle wvdsTriangle(int id) {
    return wvds::bound().surfaces.triangles[std::size_t(id)];
}
MaterialParams wvdsMaterial(int i) {
    return wvds::bound().surfaces.materials[std::size_t(i)];
}
}  // namespace tyndall::shader
