// Reflected technique parameters (model: Falcor's RenderPass::getProperties / reflect). A technique declares its
// parameters once; the studio builds its panels from them, the project file stores their values as JSON, and the CLI's
// `--set views[i].parameters.NAME=VALUE` overrides them. Values are checked against the declaration in one place.
#pragma once

#include "tyndall/core/scene.h"

#include <cstdint>
#include <map>
#include <string>
#include <variant>
#include <vector>

namespace tyndall {

enum class ParamType { Float, Int, Bool, Enum, Rgb };

using ParamValue = std::variant<double, std::int64_t, bool, std::string, Rgb>;

struct ParamInfo {
    std::string name;                    // identifier used in project files and on the command line
    ParamType type = ParamType::Float;
    std::string doc;                     // one line, shown as the tooltip
    std::string unit;                    // "1/m", "spp", "" for unitless
    double min = 0.0;                    // Float/Int/Rgb: inclusive range
    double max = 1.0;
    ParamValue defaultValue = 0.0;
    std::vector<std::string> enumValues; // Enum: allowed values
    bool logScale = false;               // a hint for sliders
};

const char* toString(ParamType type);
std::string toString(const ParamValue& value);

// A set of parameter values for one technique, always complete and valid against its declarations.
class ParamSet {
public:
    ParamSet() = default;
    explicit ParamSet(std::vector<ParamInfo> infos);  // every value at its default

    const std::vector<ParamInfo>& infos() const { return infos_; }
    const ParamInfo* find(const std::string& name) const;

    // Set a value, converting numbers between int and float where exact; throws InputError naming the parameter and
    // what is allowed when the name is unknown (with the nearest known name), the type is wrong or the value is out of
    // range.
    void set(const std::string& name, const ParamValue& value);

    const ParamValue& get(const std::string& name) const;
    double getFloat(const std::string& name) const;
    std::int64_t getInt(const std::string& name) const;
    bool getBool(const std::string& name) const;
    const std::string& getEnum(const std::string& name) const;
    Rgb getRgb(const std::string& name) const;

    const std::map<std::string, ParamValue>& values() const { return values_; }

private:
    std::vector<ParamInfo> infos_;
    std::map<std::string, ParamValue> values_;
};

}  // namespace tyndall
