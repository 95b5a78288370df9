#include "ltsd/prepared.h"

#include "tyndall/framework/shader_params.h"

#include "tyndall/core/error.h"
#include "tyndall/core/geometry.h"
#include "tyndall/tables/ltc_table.h"
#include "tyndall/tables/ltsd_table.h"

#include <algorithm>
#include <cmath>

namespace tyndall::ltsd {

// The std430 sizes the shader reads (glslangValidator -q: the last member's offset plus its size).
static_assert(sizeof(shader::LtsdFrame) == 296);
static_assert(sizeof(shader::LtsdLight) == 176);

namespace {

const PreparedScene& bound() {
    return BoundScene<PreparedScene>::get("LTSD");
}

int indexOf(const std::vector<std::string>& names, const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    TY_CHECK(it != names.end(), "ParamSet validated the enum");
    return int(it - names.begin());
}

// A light's polygon with its normal; the scene loader has checked that it is planar, convex and of non-zero area.
shader::LtsdLight toLight(const AreaLight& a) {
    shader::LtsdLight l{};
    const std::size_t n = a.vertices.size();
    glm::dvec3 normal(0.0), centroid(0.0);
    for (std::size_t i = 0; i < n; ++i) {
        normal += glm::cross(a.vertices[i], a.vertices[(i + 1) % n]);  // Newell: twice the vector area
        centroid += a.vertices[i];
        l.vertices[i] = glm::vec4(glm::vec3(a.vertices[i]), 0.0f);
    }
    l.vertexCount = int(n);
    l.normal = glm::vec3(glm::normalize(normal));
    l.radius2 = float(0.5 * glm::length(normal) / M_PI);  // area / pi
    l.radiance = glm::vec3(a.radiance);
    l.twoSided = a.twoSided ? 1 : 0;
    l.centre = glm::vec3(centroid / double(n));
    return l;
}

}  // namespace

const std::vector<std::string>& placementNames() {
    static const std::vector<std::string> names{"midpoint", "transmittance", "equiangular"};
    return names;
}

const std::vector<std::string>& transmittanceNames() {
    static const std::vector<std::string> names{"min-distance", "polygon"};
    return names;
}

const std::vector<std::string>& shadowNames() {
    static const std::vector<std::string> names{"off", "ratio", "ratio-denoised"};
    return names;
}

const std::vector<std::string>& sMethodNames() {
    static const std::vector<std::string> names{"paper", "accurate"};
    return names;
}

Settings settingsFrom(const ParamSet& params) {
    Settings s;
    s.device = deviceFrom(params);
    s.nodes = int(params.getInt("nodes"));
    s.placement = indexOf(placementNames(), params.getEnum("placement"));
    s.transmittance = indexOf(transmittanceNames(), params.getEnum("transmittance"));
    s.supersampling = int(params.getInt("supersampling"));
    s.shadows = indexOf(shadowNames(), params.getEnum("shadows"));
    s.ratioSamples = int(params.getInt("ratioSamples"));
    s.sMethod = indexOf(sMethodNames(), params.getEnum("sMethod"));
    return s;
}

LtsdPhase ltsdPhaseOf(const HomogeneousMedium& medium) {
    const std::string type = toString(medium.phase.kind);
    const std::string refusal = ltsdPhaseRefusal(type);
    if (!refusal.empty())
        throw InputError(InputLocation{"", 0, 0, "media[" + medium.name + "].phase"},
                         "the LTSD technique cannot render the medium '" + medium.name + "' with the phase function " +
                             type + ": " + refusal);
    return LtsdPhase{type, medium.phase.g, medium.phase.a, medium.phase.b};
}

PreparedScene prepareScene(const Scene& scene, const Settings& settings, const std::string& projectDir) {
    PreparedScene p;
    shader::LtsdFrame& f = p.frame;
    f.camera = toCameraParams(scene.camera);
    f.nodes = settings.nodes;
    f.placement = settings.placement;
    f.transmittance = settings.transmittance;
    f.supersampling = settings.supersampling;
    f.sMethod = settings.sMethod;

    if (scene.media.size() > 1 || !scene.particleMedia.empty())
        throw InputError(InputLocation{"", 0, 0, "media"},
                         "the LTSD technique renders one homogeneous medium; this view has " +
                             std::to_string(scene.media.size() + scene.particleMedia.size()) +
                             " media (give the view a part with one)");
    if (!scene.pointLights.empty() || !scene.directionalLights.empty())
        throw InputError(InputLocation{"", 0, 0, "lights"},
                         "the LTSD technique integrates over area lights' polygons; leave point and directional lights "
                         "out of the view's part");
    if (int(scene.areaLights.size()) > shader::kLtsdMaxLights)
        throw InputError(InputLocation{"", 0, 0, "lights"},
                         "the LTSD technique takes at most " + std::to_string(shader::kLtsdMaxLights) +
                             " area lights per view, got " + std::to_string(scene.areaLights.size()));
    for (const AreaLight& a : scene.areaLights) {
        if (int(a.vertices.size()) > shader::kLtsdLightMaxVertices)
            throw InputError(InputLocation{"", 0, 0, "lights[" + a.name + "].vertices"},
                             "the LTSD technique takes area lights of at most " +
                                 std::to_string(shader::kLtsdLightMaxVertices) + " vertices, got " +
                                 std::to_string(a.vertices.size()));
        p.lights.push_back(toLight(a));
        p.anyTwoSided = p.anyTwoSided || a.twoSided;
    }
    f.lightCount = int(p.lights.size());
    if (p.lights.empty()) p.lights.push_back(shader::LtsdLight{});

    if (!scene.media.empty()) {
        const HomogeneousMedium& m = scene.media.front();
        const std::string field = "media[" + m.name + "]";
        const LtsdPhase phase = ltsdPhaseOf(m);
        p.g = phase.g;
        f.g = float(p.g);
        f.phaseKind = toPhaseParams(m.phase).kind;
        f.phaseA = float(phase.a);
        f.phaseB = float(phase.b);
        f.hasMedium = 1;
        f.sigmaS = glm::vec3(m.sigma_s);
        f.sigmaT = glm::vec3(m.sigma_t());
        const float sigmaMin = std::min({f.sigmaT.x, f.sigmaT.y, f.sigmaT.z});
        f.tailDistance = sigmaMin > 0.0f ? 9.2f / sigmaMin : 1e30f;
        if (m.shape != MediumShape::Infinite) {
            const std::vector<HalfSpace> halfSpaces = m.shape == MediumShape::Box ? boxHalfSpaces(m.box) : m.planes;
            if (int(halfSpaces.size()) > shader::kLtsdMaxPlanes)
                throw InputError(InputLocation{"", 0, 0, field + ".planes"},
                                 "the LTSD technique takes convex media of at most " +
                                     std::to_string(shader::kLtsdMaxPlanes) + " faces, got " +
                                     std::to_string(halfSpaces.size()));
            for (const HalfSpace& h : halfSpaces) {
                const glm::dvec3 n = glm::normalize(h.normal);
                p.planes.emplace_back(glm::vec3(n), float(h.offset / glm::length(h.normal)));
            }
        }
        if (settings.sMethod == shader::kLtsdSMethodAccurate) {
            // The boundary form needs no table.
            const LtsdBoundaryTerms terms = ltsdBoundaryTerms(phase);
            f.sLobe = terms.lobe;
            f.sLobeWeight = terms.lobeWeight;
            f.phaseIsotropic = terms.isotropic;
            f.phaseLinear = terms.linear;
        } else {
            // Isotropic and Eddington are exact (no table); the others read the table of their lobe.
            const std::string tableType = ltsdTableFor(phase.type);
            LtsdTable table;
            if (!tableType.empty()) {
                p.tablePath = ltsdTablePath(tableType).string();
                table = loadLtsdTable(p.tablePath, tableType);
            }
            const LtsdPhaseTerms terms = ltsdPhaseTerms(phase, tableType.empty() ? nullptr : &table);
            f.upper = terms.upper;
            f.lower = terms.lower;
            f.phaseIsotropic = terms.isotropic;
            f.phaseLinear = terms.linear;
        }
    }
    f.planeCount = int(p.planes.size());
    if (p.planes.empty()) p.planes.emplace_back(0.0f);

    // GGX surfaces read the LTC GGX tables (docs/tables.md, "LTC GGX tables"): the isotropic one for alphaX = alphaY,
    // the anisotropic one otherwise, each loaded only when a material needs it (so that a scene without GGX renders
    // without the files), one after the other in one buffer.
    bool isotropicGgx = false;
    for (const Material& m : scene.materials) {
        if (m.kind != Material::Kind::GGX) continue;
        if (m.alphaX != m.alphaY)
            p.anyAnisotropic = true;
        else
            isotropicGgx = true;
    }
    if (isotropicGgx) {
        p.ltcTablePath = ltcTablePath("ggx").string();
        LtcTable table = loadLtcTable(p.ltcTablePath);
        if (!table.isotropicTable())
            throw InputError(InputLocation{p.ltcTablePath, 0, 0, "header.dimensions"},
                             "the isotropic LTC GGX table must have 2 dimensions");
        f.ltcXCount = table.xCount();
        f.ltcAlphaCount = table.alphaCount();
        f.ltcAlphaMin = table.alphaMin;
        p.ltcEntries = std::move(table.entries);
    }
    if (p.anyAnisotropic) {
        p.ltcAnisotropicTablePath = ltcTablePath("ggx-aniso").string();
        LtcTable table = loadLtcTable(p.ltcAnisotropicTablePath);
        if (table.isotropicTable())
            throw InputError(InputLocation{p.ltcAnisotropicTablePath, 0, 0, "header.dimensions"},
                             "the anisotropic LTC GGX table must have 4 dimensions");
        f.ltcAnisoBase = int(p.ltcEntries.size());
        f.ltcAnisoThetaCount = table.thetaCount();
        f.ltcAnisoPhiCount = table.phiCount();
        f.ltcAnisoAlphaCount = table.alphaCount();
        f.ltcAnisoRatioCount = table.ratioCount();
        f.ltcAnisoAlphaMin = table.alphaMin;
        f.ltcAnisoRatioMin = table.ratioMin;
        p.ltcEntries.insert(p.ltcEntries.end(), table.entries.begin(), table.entries.end());
    }
    if (p.ltcEntries.empty()) p.ltcEntries.push_back(shader::LtcEntry{});

    p.surfaces = prepareGpuSurfaces(scene, projectDir);
    f.rayOffset = p.surfaces.rayOffset;
    return p;
}

}  // namespace tyndall::ltsd

// The accessors of shaders/shared/ltsd_scene.h over the scene bound to this thread.
namespace tyndall::shader {
LtsdLight ltsdLight(int i) {
    return ltsd::bound().lights[std::size_t(i)];
}
vec4 ltsdPlane(int i) {
    return ltsd::bound().planes[std::size_t(i)];
}
SurfaceTriangle ltsdTriangle(int id) {
    return ltsd::bound().surfaces.triangles[std::size_t(id)];
}
MaterialParams ltsdMaterial(int i) {
    return ltsd::bound().surfaces.materials[std::size_t(i)];
}
LtcEntry ltsdLtcEntry(int i) {
    return ltsd::bound().ltcEntries[std::size_t(i)];
}
}  // namespace tyndall::shader
