// Shared by the project reader, writer and --set overrides: the names of enumerations in project files, the keys every
// kind of JSON object may hold (one table, so that unknown-key errors and overrides agree), and small helpers.
#pragma once

#include "json_field.h"

#include "tyndall/core/params.h"
#include "tyndall/project/project.h"

#include <nlohmann/json.hpp>

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tyndall {

// ---------------------------------------------------------------------------------------------------------------------
// Enumerations as they are spelled in project files.

template <typename E>
struct EnumName {
    E value;
    const char* name;
};

inline constexpr EnumName<PhaseKind> kPhaseKindNames[] = {
    {PhaseKind::Isotropic, "isotropic"}, {PhaseKind::HenyeyGreenstein, "hg"}, {PhaseKind::IsoHgMix, "mix"},
    {PhaseKind::Rayleigh, "rayleigh"},   {PhaseKind::Eddington, "eddington"}, {PhaseKind::Legendre, "legendre"},
    {PhaseKind::HazyMie, "hazy-mie"},    {PhaseKind::MurkyMie, "murky-mie"},
};
inline constexpr EnumName<MediumShape> kMediumShapeNames[] = {
    {MediumShape::Infinite, "infinite"}, {MediumShape::Box, "box"}, {MediumShape::ConvexPolyhedron, "polyhedron"}};
inline constexpr EnumName<AngularDistribution::Kind> kDistributionNames[] = {
    {AngularDistribution::Kind::Isotropic, "isotropic"},
    {AngularDistribution::Kind::Spot, "spot"},
    {AngularDistribution::Kind::Polynomial, "polynomial"},
    {AngularDistribution::Kind::Legendre, "legendre"}};
inline constexpr EnumName<Material::Kind> kMaterialKindNames[] = {{Material::Kind::Diffuse, "diffuse"},
                                                                  {Material::Kind::GGX, "ggx"}};
inline constexpr EnumName<Mesh::Source> kMeshSourceNames[] = {{Mesh::Source::Plane, "plane"},
                                                              {Mesh::Source::Box, "box"},
                                                              {Mesh::Source::Sphere, "sphere"},
                                                              {Mesh::Source::Obj, "obj"}};
inline constexpr EnumName<ReferenceSettings::Mode> kReferenceModeNames[] = {
    {ReferenceSettings::Mode::Single, "single"}, {ReferenceSettings::Mode::Multiple, "multiple"}};

template <typename E, std::size_t N>
const char* enumName(const EnumName<E> (&table)[N], E value) {
    for (const EnumName<E>& entry : table) {
        if (entry.value == value) return entry.name;
    }
    TY_CHECK(false, "enumeration value without a name");
    return "";
}

template <typename E, std::size_t N>
std::vector<std::string> enumNames(const EnumName<E> (&table)[N]) {
    std::vector<std::string> names;
    for (const EnumName<E>& entry : table)
        names.emplace_back(entry.name);
    return names;
}

// Fails at `field` with the allowed names (and the nearest one) when the string is none of them.
std::string requireOneOf(const JsonField& field, const std::vector<std::string>& allowed);

template <typename E, std::size_t N>
E readEnum(const JsonField& field, const EnumName<E> (&table)[N]) {
    const std::string name = requireOneOf(field, enumNames(table));
    for (const EnumName<E>& entry : table) {
        if (name == entry.name) return entry.value;
    }
    return table[0].value;
}

inline constexpr const char* kLightTypes[] = {"point", "directional", "area"};

// ---------------------------------------------------------------------------------------------------------------------
// The keys each kind of object may hold, and what the object or array under a key holds.

enum class ObjectKind {
    None,  // a plain value (number, string, vector...)
    Project,
    Camera,
    Medium,
    Phase,
    Box,
    Plane,
    ParticleMedium,
    Particle,
    Generator,
    Simulation,
    Impulse,
    Light,  // point, directional or area, by its "type"
    PointLight,
    DirectionalLight,
    AreaLight,
    Distribution,
    Material,
    Mesh,
    Transform,
    View,
    Parameters,  // a view's technique parameters: the keys are the technique's parameter names
    Reference,
};

struct KeySpec {
    const char* name;
    ObjectKind child = ObjectKind::None;  // the object under this key, or the elements of the array under it
    bool array = false;
};

std::span<const KeySpec> keySpecs(ObjectKind kind);
std::vector<std::string> keyNames(ObjectKind kind);
// PointLight, DirectionalLight or AreaLight from a light's "type"; Light when the type is missing or unknown.
ObjectKind lightKind(const nlohmann::json& light);

// ---------------------------------------------------------------------------------------------------------------------

// A technique parameter as given in JSON: a number, boolean, string or [r, g, b]. Fails at `field` otherwise.
ParamValue paramValueFromJson(const JsonField& field);

// The object's keys with the kind of what each holds: first those of the schema in its order, then any others.
std::vector<std::pair<std::string, ObjectKind>> keysInSchemaOrder(const nlohmann::json& object, ObjectKind kind);

// How the text of saved files is laid out: one member or structured element per line, the first line of a value
// indented by `indent` and each level inside it by `unit` more; or everything on one line ({"a": 1, "b": [1, 2]}).
// Arrays of plain values (vectors) are on one line either way.
struct TextLayout {
    bool oneLine = false;
    std::string indent;         // of the line the value starts on
    std::string unit = "  ";    // one level of indentation
    std::string newline = "\n";
};

// `value`, a part of projectToJson holding objects of `kind`, as saved files write it (keys in the schema's order).
std::string projectValueText(const nlohmann::json& value, ObjectKind kind, const TextLayout& layout);

// The text saveProject writes: projectToJson with 2-space indent, keys in the schema's order and vectors on one line.
std::string projectText(const Project& project);

// Applies "path=value" overrides (the CLI's --set) to a project's JSON; see docs/project-format.md.
void applyOverrides(const TechniqueCatalogue& techniques, nlohmann::json& root,
                    const std::vector<std::string>& overrides);

}  // namespace tyndall
