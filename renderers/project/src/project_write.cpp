// projectToJson: every field that applies to an element's type is written, defaults included, so that saved files are
// explicit. Fields that do not apply (a phase function's g for "isotropic") are written only when they differ from
// their defaults, so that nothing is lost and projectFromJson(projectToJson(p)) reproduces p.
#include "project_internal.h"

#include <algorithm>
#include <cmath>

namespace tyndall {

namespace {

using nlohmann::json;

json toJson(const Vec3& v) {
    return json::array({v.x, v.y, v.z});
}

json toJson(const std::vector<Vec3>& vs) {
    json array = json::array();
    for (const Vec3& v : vs)
        array.push_back(toJson(v));
    return array;
}

json toJson(const std::vector<double>& values) {
    return json(values);
}

json toJson(const std::vector<std::string>& strings) {
    return json(strings);
}

json toJson(const OrientedBox& box) {
    return {{"centre", toJson(box.centre)}, {"size", toJson(box.size)}, {"rotate", toJson(box.rotate)}};
}

bool operator==(const OrientedBox& a, const OrientedBox& b) {
    return a.centre == b.centre && a.size == b.size && a.rotate == b.rotate;
}

// Writes `value` when the field applies to the element's type or differs from its default.
template <typename T>
void putWhen(json& object, const char* key, bool applies, const T& value, const T& fallback) {
    if (!applies && value == fallback) return;
    if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, std::vector<double>> || std::is_same_v<T, OrientedBox>) {
        object[key] = toJson(value);
    } else {
        object[key] = value;
    }
}

json toJson(const Camera& camera) {
    return {{"position", toJson(camera.position)},
            {"target", toJson(camera.target)},
            {"up", toJson(camera.up)},
            {"fovY", camera.fovY},
            {"width", camera.width},
            {"height", camera.height}};
}

json toJson(const PhaseFunction& phase) {
    const PhaseFunction defaults;
    const PhaseKind k = phase.kind;
    json j = {{"type", toString(k)}};
    putWhen(j, "g", k == PhaseKind::HenyeyGreenstein || k == PhaseKind::IsoHgMix, phase.g, defaults.g);
    putWhen(j, "a", k == PhaseKind::IsoHgMix, phase.a, defaults.a);
    putWhen(j, "b", k == PhaseKind::Eddington, phase.b, defaults.b);
    putWhen(j, "coefficients", k == PhaseKind::Legendre, phase.legendre, defaults.legendre);
    return j;
}

json toJson(const HomogeneousMedium& medium) {
    json j = {{"name", medium.name},
              {"sigma_s", toJson(medium.sigma_s)},
              {"sigma_a", toJson(medium.sigma_a)},
              {"phase", toJson(medium.phase)},
              {"shape", enumName(kMediumShapeNames, medium.shape)}};
    putWhen(j, "box", medium.shape == MediumShape::Box, medium.box, OrientedBox{});
    if (medium.shape == MediumShape::ConvexPolyhedron || !medium.planes.empty()) {
        json planes = json::array();
        for (const HalfSpace& h : medium.planes)
            planes.push_back({{"normal", toJson(h.normal)}, {"offset", h.offset}});
        j["planes"] = planes;
    }
    return j;
}

json toJson(const Particle& p) {
    const glm::dquat& q = p.orientation;
    return {{"centre", toJson(p.centre)},
            {"scale", p.scale},
            {"orientation", {q.w, q.x, q.y, q.z}},
            {"extinctionMultiplier", p.extinctionMultiplier},
            {"falloff", p.falloff}};
}

json toJson(const ParticleGenerator& g) {
    return {{"count", g.count},
            {"seed", g.seed},
            {"region", toJson(g.region)},
            {"scale", g.scale},
            {"falloff", g.falloff},
            {"multiplierMin", g.multiplierMin},
            {"multiplierMax", g.multiplierMax}};
}

json toJson(const ParticleSimulation& sim) {
    json impulses = json::array();
    for (const ParticleImpulse& i : sim.impulses)
        impulses.push_back(
            {{"step", i.step}, {"position", toJson(i.position)}, {"radius", i.radius}, {"speed", i.speed}});
    return {{"steps", sim.steps},         {"timeStep", sim.timeStep}, {"stiffness", sim.stiffness},
            {"viscosity", sim.viscosity}, {"offset", toJson(sim.offset)}, {"impulses", impulses}};
}

json toJson(const ParticleMedium& medium) {
    json particles = json::array();
    for (const Particle& p : medium.particles)
        particles.push_back(toJson(p));
    json j = {{"name", medium.name},
              {"extinction", toJson(medium.extinction)},
              {"albedo", toJson(medium.albedo)},
              {"phase", toJson(medium.phase)},
              {"particles", particles}};
    if (medium.generator) j["generator"] = toJson(*medium.generator);
    if (medium.simulation) j["simulation"] = toJson(*medium.simulation);
    return j;
}

// Spot exponents are integers; write them as such.
json exponentJson(double n) {
    if (n == std::floor(n) && std::abs(n) < 0x1.0p53) return static_cast<std::int64_t>(n);
    return n;
}

// A direction as the project gave it, when it still is the direction the scene holds (code may have set another).
Vec3 asWritten(const Vec3& written, const Vec3& normalised) {
    const double length = glm::length(written);
    if (!(length > 0.0) || glm::length(written / length - normalised) > 1e-12) return normalised;
    return written;
}

json toJson(const AngularDistribution& d) {
    using Kind = AngularDistribution::Kind;
    const AngularDistribution defaults;
    json j = {{"type", enumName(kDistributionNames, d.kind)}};
    putWhen(j, "axis", d.kind != Kind::Isotropic, asWritten(d.axisAsWritten, d.axis), defaults.axis);
    if (d.kind == Kind::Spot || d.spotExponent != defaults.spotExponent) j["exponent"] = exponentJson(d.spotExponent);
    putWhen(j, "coefficients", d.kind == Kind::Polynomial || d.kind == Kind::Legendre, d.coefficients,
            defaults.coefficients);
    return j;
}

json toJson(const PointLight& light) {
    return {{"type", "point"},
            {"name", light.name},
            {"position", toJson(light.position)},
            {"intensity", toJson(light.intensity)},
            {"distribution", toJson(light.distribution)}};
}

json toJson(const DirectionalLight& light) {
    json j = {{"type", "directional"},
              {"name", light.name},
              {"direction", toJson(asWritten(light.directionAsWritten, light.direction))},
              {"irradiance", toJson(light.irradiance)}};
    if (!light.gobo.empty()) j["gobo"] = toJson(light.gobo);
    return j;
}

json toJson(const AreaLight& light) {
    return {{"type", "area"},
            {"name", light.name},
            {"vertices", toJson(light.vertices)},
            {"radiance", toJson(light.radiance)},
            {"twoSided", light.twoSided}};
}

json toJson(const Material& m) {
    const Material defaults;
    const bool ggx = m.kind == Material::Kind::GGX;
    json j = {{"name", m.name}, {"type", enumName(kMaterialKindNames, m.kind)}};
    putWhen(j, "albedo", !ggx, m.albedo, defaults.albedo);
    putWhen(j, "f0", ggx, m.f0, defaults.f0);
    if (ggx || m.alphaX != defaults.alphaX || m.alphaY != defaults.alphaY) {
        if (m.alphaX == m.alphaY) {
            j["alpha"] = m.alphaX;
        } else {
            j["alphaX"] = m.alphaX;
            j["alphaY"] = m.alphaY;
        }
    }
    return j;
}

json toJson(const Transform& t) {
    return {{"translate", toJson(t.translate)}, {"rotate", toJson(t.rotate)}, {"scale", toJson(t.scale)}};
}

json toJson(const Mesh& mesh) {
    const Mesh defaults;
    json j = {{"name", mesh.name},
              {"shape", enumName(kMeshSourceNames, mesh.source)},
              {"transform", toJson(mesh.transform)},
              {"material", mesh.material},
              {"tangent", toJson(mesh.tangent)}};
    putWhen(j, "file", mesh.source == Mesh::Source::Obj, mesh.file, defaults.file);
    putWhen(j, "subdivisions", mesh.source == Mesh::Source::Sphere, mesh.subdivisions, defaults.subdivisions);
    return j;
}

json toJson(const View& view) {
    json j = {{"name", view.name},
              {"technique", view.technique},
              {"parameters", view.parameters},
              {"exposure", view.exposure}};
    if (view.part) {
        j["lights"] = toJson(view.part->lights);
        j["media"] = toJson(view.part->media);
    }
    return j;
}

json toJson(const ReferenceSettings& r) {
    return {
        {"mode", enumName(kReferenceModeNames, r.mode)}, {"maxDepth", r.maxDepth}, {"spp", r.spp}, {"seed", r.seed}};
}

template <typename T>
json arrayOf(const std::vector<T>& items) {
    json array = json::array();
    for (const T& item : items)
        array.push_back(toJson(item));
    return array;
}

// ---------------------------------------------------------------------------------------------------------------------
// Text of saved files: keys in the order of the schema (the order docs/project-format.md uses), arrays of plain values
// such as vectors on one line, the rest one member or element per line (or all on one line). Numbers are printed by
// nlohmann, which round-trips doubles exactly.

void appendLineBreak(std::string& out, const TextLayout& layout, int depth) {
    out += layout.newline + layout.indent;
    for (int i = 0; i < depth; ++i)
        out += layout.unit;
}

bool isFlat(const json& array) {
    return std::none_of(array.begin(), array.end(), [](const json& v) { return v.is_structured(); });
}

void appendValue(std::string& out, const json& value, ObjectKind kind, const TextLayout& layout, int depth);

void appendArray(std::string& out, const json& array, ObjectKind elementKind, const TextLayout& layout, int depth) {
    const bool oneLine = layout.oneLine || isFlat(array);
    out += "[";
    for (std::size_t i = 0; i < array.size(); ++i) {
        if (i) out += oneLine ? ", " : ",";
        if (!oneLine) appendLineBreak(out, layout, depth + 1);
        appendValue(out, array[i], elementKind, layout, depth + 1);
    }
    if (!oneLine && !array.empty()) appendLineBreak(out, layout, depth);
    out += "]";
}

void appendObject(std::string& out, const json& object, ObjectKind kind, const TextLayout& layout, int depth) {
    const auto keys = keysInSchemaOrder(object, kind);
    out += "{";
    for (std::size_t i = 0; i < keys.size(); ++i) {
        if (i) out += layout.oneLine ? ", " : ",";
        if (!layout.oneLine) appendLineBreak(out, layout, depth + 1);
        out += json(keys[i].first).dump() + ": ";
        appendValue(out, object.at(keys[i].first), keys[i].second, layout, depth + 1);
    }
    if (!layout.oneLine && !keys.empty()) appendLineBreak(out, layout, depth);
    out += "}";
}

void appendValue(std::string& out, const json& value, ObjectKind kind, const TextLayout& layout, int depth) {
    if (value.is_object()) {
        appendObject(out, value, kind, layout, depth);
    } else if (value.is_array()) {
        appendArray(out, value, kind, layout, depth);
    } else {
        out += value.dump();
    }
}

}  // namespace

std::vector<std::pair<std::string, ObjectKind>> keysInSchemaOrder(const json& object, ObjectKind kind) {
    std::vector<std::pair<std::string, ObjectKind>> keys;
    const std::span<const KeySpec> specs = keySpecs(kind == ObjectKind::Light ? lightKind(object) : kind);
    for (const KeySpec& spec : specs) {
        if (object.contains(spec.name)) keys.emplace_back(spec.name, spec.child);
    }
    for (const auto& item : object.items()) {
        const std::string& key = item.key();  // a named reference: clang 14 cannot capture structured bindings
        const auto known = [&](const KeySpec& spec) { return key == spec.name; };
        if (std::none_of(specs.begin(), specs.end(), known)) keys.emplace_back(key, ObjectKind::None);
    }
    return keys;
}

std::string projectValueText(const json& value, ObjectKind kind, const TextLayout& layout) {
    std::string text;
    appendValue(text, value, kind, layout, 0);
    return text;
}

std::string projectText(const Project& project) {
    return projectValueText(projectToJson(project), ObjectKind::Project, TextLayout{}) + "\n";
}

json projectToJson(const Project& project) {
    const Scene& scene = project.scene;
    // Lights are written grouped by type: point, directional, area (see docs/project-format.md).
    json lights = arrayOf(scene.pointLights);
    for (const json& light : arrayOf(scene.directionalLights))
        lights.push_back(light);
    for (const json& light : arrayOf(scene.areaLights))
        lights.push_back(light);
    return {{"tyndall", kProjectFormatVersion},
            {"name", project.name},
            {"camera", toJson(scene.camera)},
            {"media", arrayOf(scene.media)},
            {"particleMedia", arrayOf(scene.particleMedia)},
            {"lights", lights},
            {"materials", arrayOf(scene.materials)},
            {"meshes", arrayOf(scene.meshes)},
            {"views", arrayOf(project.views)},
            {"reference", toJson(project.reference)}};
}

}  // namespace tyndall
