#include "project_internal.h"

namespace tyndall {

namespace {

using K = ObjectKind;

constexpr KeySpec kProjectKeys[] = {
    {"tyndall"},
    {"name"},
    {"camera", K::Camera},
    {"media", K::Medium, true},
    {"particleMedia", K::ParticleMedium, true},
    {"lights", K::Light, true},
    {"materials", K::Material, true},
    {"meshes", K::Mesh, true},
    {"views", K::View, true},
    {"reference", K::Reference},
};
constexpr KeySpec kCameraKeys[] = {{"position"}, {"target"}, {"up"}, {"fovY"}, {"width"}, {"height"}};
constexpr KeySpec kMediumKeys[] = {
    {"name"},   {"sigma_s"},     {"sigma_a"},
    {"albedo"}, {"extinction"},  {"phase", K::Phase},
    {"shape"},  {"box", K::Box}, {"planes", K::Plane, true},
};
constexpr KeySpec kPhaseKeys[] = {{"type"}, {"g"}, {"a"}, {"b"}, {"coefficients"}};
constexpr KeySpec kBoxKeys[] = {{"centre"}, {"size"}, {"rotate"}};
constexpr KeySpec kPlaneKeys[] = {{"normal"}, {"offset"}};
constexpr KeySpec kParticleMediumKeys[] = {
    {"name"},
    {"extinction"},
    {"albedo"},
    {"phase", K::Phase},
    {"particles", K::Particle, true},
    {"generator", K::Generator},
    {"simulation", K::Simulation},
};
constexpr KeySpec kParticleKeys[] = {{"centre"}, {"scale"}, {"orientation"}, {"extinctionMultiplier"}, {"falloff"}};
constexpr KeySpec kGeneratorKeys[] = {{"count"},   {"seed"},          {"region", K::Box}, {"scale"},
                                      {"falloff"}, {"multiplierMin"}, {"multiplierMax"}};
constexpr KeySpec kSimulationKeys[] = {{"steps"},  {"timeStep"}, {"stiffness"},
                                       {"viscosity"}, {"offset"}, {"impulses", K::Impulse, true}};
constexpr KeySpec kImpulseKeys[] = {{"step"}, {"position"}, {"radius"}, {"speed"}};
constexpr KeySpec kPointLightKeys[] = {
    {"type"}, {"name"}, {"position"}, {"intensity"}, {"distribution", K::Distribution}};
constexpr KeySpec kDirectionalLightKeys[] = {{"type"}, {"name"}, {"direction"}, {"irradiance"}, {"gobo"}};
constexpr KeySpec kAreaLightKeys[] = {{"type"}, {"name"}, {"vertices"}, {"radiance"}, {"twoSided"}};
constexpr KeySpec kAnyLightKeys[] = {
    {"type"},      {"name"},       {"position"}, {"intensity"}, {"distribution", K::Distribution},
    {"direction"}, {"irradiance"}, {"gobo"},     {"vertices"},  {"radiance"},
    {"twoSided"},
};
constexpr KeySpec kDistributionKeys[] = {{"type"}, {"axis"}, {"exponent"}, {"coefficients"}};
constexpr KeySpec kMaterialKeys[] = {{"name"}, {"type"}, {"albedo"}, {"f0"}, {"alpha"}, {"alphaX"}, {"alphaY"}};
constexpr KeySpec kMeshKeys[] = {
    {"name"}, {"shape"}, {"file"}, {"subdivisions"}, {"transform", K::Transform}, {"material"}, {"tangent"},
};
constexpr KeySpec kTransformKeys[] = {{"translate"}, {"rotate"}, {"scale"}};
constexpr KeySpec kViewKeys[] = {
    {"name"}, {"technique"}, {"parameters", K::Parameters}, {"lights"}, {"media"}, {"exposure"},
};
constexpr KeySpec kReferenceKeys[] = {{"mode"}, {"maxDepth"}, {"spp"}, {"seed"}};

}  // namespace

std::span<const KeySpec> keySpecs(ObjectKind kind) {
    switch (kind) {
        case K::None:
            return {};
        case K::Project:
            return kProjectKeys;
        case K::Camera:
            return kCameraKeys;
        case K::Medium:
            return kMediumKeys;
        case K::Phase:
            return kPhaseKeys;
        case K::Box:
            return kBoxKeys;
        case K::Plane:
            return kPlaneKeys;
        case K::ParticleMedium:
            return kParticleMediumKeys;
        case K::Particle:
            return kParticleKeys;
        case K::Generator:
            return kGeneratorKeys;
        case K::Simulation:
            return kSimulationKeys;
        case K::Impulse:
            return kImpulseKeys;
        case K::Light:
            return kAnyLightKeys;
        case K::PointLight:
            return kPointLightKeys;
        case K::DirectionalLight:
            return kDirectionalLightKeys;
        case K::AreaLight:
            return kAreaLightKeys;
        case K::Distribution:
            return kDistributionKeys;
        case K::Material:
            return kMaterialKeys;
        case K::Mesh:
            return kMeshKeys;
        case K::Transform:
            return kTransformKeys;
        case K::View:
            return kViewKeys;
        case K::Parameters:
            return {};
        case K::Reference:
            return kReferenceKeys;
    }
    return {};
}

std::vector<std::string> keyNames(ObjectKind kind) {
    std::vector<std::string> names;
    for (const KeySpec& spec : keySpecs(kind))
        names.emplace_back(spec.name);
    return names;
}

ObjectKind lightKind(const nlohmann::json& light) {
    const auto type = light.find("type");
    if (type == light.end() || !type->is_string()) return K::Light;
    const std::string& name = type->get_ref<const std::string&>();
    if (name == "point") return K::PointLight;
    if (name == "directional") return K::DirectionalLight;
    if (name == "area") return K::AreaLight;
    return K::Light;
}

std::string requireOneOf(const JsonField& field, const std::vector<std::string>& allowed) {
    const std::string& value = field.string();
    if (std::find(allowed.begin(), allowed.end(), value) != allowed.end()) return value;
    std::string list;
    for (const std::string& name : allowed)
        list += (list.empty() ? "" : ", ") + name;
    std::string message = "unknown value '" + clipForMessage(value) + "'; allowed: " + list;
    const std::string nearest = nearestName(value, allowed);
    if (!nearest.empty()) message += "; did you mean '" + nearest + "'?";
    field.fail(message);
}

ParamValue paramValueFromJson(const JsonField& field) {
    const nlohmann::json& value = field.json();
    if (value.is_boolean()) return value.get<bool>();
    if (value.is_string()) return value.get<std::string>();
    if (value.is_number_float()) return field.number();
    if (value.is_number()) return field.integer();
    if (value.is_array()) return field.vec3();
    field.fail("must be a number, true/false, a string or [r, g, b], got " + describeJson(value));
}

}  // namespace tyndall
