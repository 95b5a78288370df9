#include "volume_ris/prepared.h"

#include "tyndall/framework/shader_params.h"

#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"

#include <algorithm>

namespace tyndall::volume_ris {

// The std430 sizes the shader reads (shared/volume_ris.h).
static_assert(sizeof(shader::RisFrame) == 276);
static_assert(sizeof(shader::RisLight) == 64);

namespace {

const PreparedScene& bound() {
    return BoundScene<PreparedScene>::get("Volume-RIS");
}

// Light power up to the common factor pi: area x mean radiance x the number of sides that emit.
double lightPower(const AreaLight& l) {
    return polygonArea(l.vertices) * (l.radiance.x + l.radiance.y + l.radiance.z) / 3.0 * (l.twoSided ? 2.0 : 1.0);
}

}  // namespace

Settings settingsFrom(const ParamSet& params) {
    Settings s;
    s.device = deviceFrom(params);
    s.candidates = int(params.getInt("candidates"));
    s.samplesPerPixel = int(params.getInt("samplesPerPixel"));
    s.distanceSampling =
        params.getEnum("distanceSampling") == "equiangular" ? shader::kRisEquiangular : shader::kRisTransmittance;
    s.lightSampling = params.getEnum("lightSampling") == "area" ? shader::kRisArea : shader::kRisSolidAngle;
    s.shadows = params.getBool("shadows");
    return s;
}

PreparedScene prepareScene(const Scene& scene, const Settings& settings, std::uint64_t seed,
                           const std::string& projectDir) {
    PreparedScene p;
    shader::RisFrame& f = p.frame;
    f.camera = toCameraParams(scene.camera);

    if (scene.media.size() > 1 || !scene.particleMedia.empty())
        throw InputError(InputLocation{"", 0, 0, "media"},
                         "the Volume-RIS technique renders at most one homogeneous medium; this view has " +
                             std::to_string(scene.media.size() + scene.particleMedia.size()) +
                             " media (give the view a part with one medium)");
    f.mediumKind = shader::kRisMediumNone;
    if (!scene.media.empty()) {
        const HomogeneousMedium& m = scene.media.front();
        if (m.shape == MediumShape::Infinite) {
            f.mediumKind = shader::kRisMediumInfinite;
        } else {
            const std::vector<HalfSpace> halfSpaces = m.shape == MediumShape::Box ? boxHalfSpaces(m.box) : m.planes;
            if (int(halfSpaces.size()) > shader::kRisMaxPlanes)
                throw InputError(InputLocation{"", 0, 0, "media[" + m.name + "].planes"},
                                 "the Volume-RIS technique takes convex media of at most " +
                                     std::to_string(shader::kRisMaxPlanes) + " faces, got " +
                                     std::to_string(halfSpaces.size()));
            for (const HalfSpace& h : halfSpaces) {
                const Vec3 n = glm::normalize(h.normal);
                p.planes.push_back(glm::vec4(glm::vec3(n), float(h.offset / glm::length(h.normal))));
            }
            f.mediumKind = shader::kRisMediumPlanes;
        }
        f.sigmaS = glm::vec3(m.sigma_s);
        f.sigmaT = glm::vec3(m.sigma_t());
        f.phase = toPhaseParams(m.phase);
    } else {
        f.phase = toPhaseParams(PhaseFunction{});
    }
    f.planeCount = int(p.planes.size());
    if (p.planes.empty()) p.planes.push_back(glm::vec4(0.0f));  // no zero-sized buffers
    f.sigmaSample = (f.sigmaT.x + f.sigmaT.y + f.sigmaT.z) / 3.0f;
    p.grey = f.sigmaT.y == f.sigmaT.x && f.sigmaT.z == f.sigmaT.x;

    if (int(scene.areaLights.size()) > shader::kRisMaxLights)
        throw InputError(InputLocation{"", 0, 0, "lights"},
                         "the Volume-RIS technique takes at most " + std::to_string(shader::kRisMaxLights) +
                             " area lights per view, got " + std::to_string(scene.areaLights.size()));
    double totalPower = 0.0;
    for (const AreaLight& l : scene.areaLights)
        totalPower += lightPower(l);
    double start = 0.0;
    for (const AreaLight& l : scene.areaLights) {
        if (int(l.vertices.size()) > shader::kRisMaxVertices)
            throw InputError(InputLocation{"", 0, 0, "lights[" + l.name + "].vertices"},
                             "the Volume-RIS technique takes polygons of at most " +
                                 std::to_string(shader::kRisMaxVertices) + " vertices, got " +
                                 std::to_string(l.vertices.size()));
        shader::RisLight rl{};
        rl.normal = glm::vec3(polygonNormal(l.vertices));
        rl.radiance = glm::vec3(l.radiance);
        rl.vertexFirst = int(p.vertices.size());
        rl.vertexCount = int(l.vertices.size());
        rl.twoSided = l.twoSided ? 1 : 0;
        Vec3 centre(0.0);
        for (const Vec3& v : l.vertices)
            centre += v;
        rl.centre = glm::vec3(centre / double(l.vertices.size()));
        // The fan (v0, v_k-1, v_k) and its cumulative areas, in double.
        std::vector<double> cumulative(l.vertices.size(), 0.0);
        for (std::size_t k = 2; k < l.vertices.size(); ++k)
            cumulative[k] = cumulative[k - 1] + 0.5 * glm::length(glm::cross(l.vertices[k - 1] - l.vertices[0],
                                                                                l.vertices[k] - l.vertices[0]));
        const double area = cumulative.back();
        rl.area = float(area);
        for (std::size_t k = 0; k < l.vertices.size(); ++k)
            p.vertices.push_back(glm::vec4(glm::vec3(l.vertices[k]), k >= 2 && area > 0.0 ? float(cumulative[k] / area) : 0.0f));
        const double power = lightPower(l);
        rl.selectStart = float(start);
        rl.selectPdf = totalPower > 0.0 && area > 0.0 ? float(power / totalPower) : 0.0f;
        start += totalPower > 0.0 ? power / totalPower : 0.0;
        p.lights.push_back(rl);
    }
    // A light whose power is 0 is never chosen; the others' selection probabilities sum to 1.
    f.lightCount = totalPower > 0.0 ? int(p.lights.size()) : 0;
    if (p.lights.empty()) p.lights.push_back(shader::RisLight{});
    if (p.vertices.empty()) p.vertices.push_back(glm::vec4(0.0f));

    f.candidates = settings.candidates;
    f.distanceSampling = settings.distanceSampling;
    f.lightSampling = settings.lightSampling;
    f.shadows = settings.shadows ? 1 : 0;
    f.seed = std::uint32_t(seed ^ (seed >> 32));

    p.surfaces = prepareGpuSurfaces(scene, projectDir);
    f.rayOffset = p.surfaces.rayOffset;
    return p;
}

}  // namespace tyndall::volume_ris

// The accessors of shaders/shared/volume_ris.h over the scene bound to this thread.
namespace tyndall::shader {
vec4 risPlane(int i) {
    return volume_ris::bound().planes[std::size_t(i)];
}
RisLight risLight(int i) {
    return volume_ris::bound().lights[std::size_t(i)];
}
vec4 risVertex(int i) {
    return volume_ris::bound().vertices[std::size_t(i)];
}
SurfaceTriangle risTriangle(int id) {
    return volume_ris::bound().surfaces.triangles[std::size_t(id)];
}
MaterialParams risMaterial(int i) {
    return volume_ris::bound().surfaces.materials[std::size_t(i)];
}
}  // namespace tyndall::shader
