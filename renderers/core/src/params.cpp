#include "tyndall/core/params.h"

#include "tyndall/core/error.h"

#include "tyndall/core/text.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numeric>
#include <optional>

namespace tyndall {

namespace {

std::string joined(const std::vector<std::string>& items) {
    std::string out;
    for (const std::string& item : items)
        out += (out.empty() ? "" : ", ") + item;
    return out;
}

std::string rangeText(const ParamInfo& info) {
    std::string text = "[" + formatNumber(info.min) + ", " + formatNumber(info.max) + "]";
    if (!info.unit.empty()) text += " " + info.unit;
    return text;
}

// Integers up to 2^53 convert to double and back without loss.
constexpr double kExactIntegerLimit = 9007199254740992.0;

bool isExactInteger(double value) {
    return std::isfinite(value) && value == std::floor(value) && std::abs(value) <= kExactIntegerLimit;
}

bool matchesType(ParamType type, const ParamValue& value) {
    switch (type) {
        case ParamType::Float:
            return std::holds_alternative<double>(value);
        case ParamType::Int:
            return std::holds_alternative<std::int64_t>(value);
        case ParamType::Bool:
            return std::holds_alternative<bool>(value);
        case ParamType::Enum:
            return std::holds_alternative<std::string>(value);
        case ParamType::Rgb:
            return std::holds_alternative<Rgb>(value);
    }
    return false;
}

const char* valueTypeName(const ParamValue& value) {
    if (std::holds_alternative<double>(value)) return "a number";
    if (std::holds_alternative<std::int64_t>(value)) return "an integer";
    if (std::holds_alternative<bool>(value)) return "a boolean";
    if (std::holds_alternative<std::string>(value)) return "a string";
    return "an RGB triple";
}

// What a parameter accepts, in words, for error messages.
std::string allowedText(const ParamInfo& info) {
    switch (info.type) {
        case ParamType::Float:
            return "a number in " + rangeText(info);
        case ParamType::Int:
            return "an integer in " + rangeText(info);
        case ParamType::Bool:
            return "true or false";
        case ParamType::Enum:
            return "one of " + joined(info.enumValues);
        case ParamType::Rgb:
            return "an RGB triple [r, g, b] with each component in " + rangeText(info);
    }
    return "";
}

std::string describeValue(const ParamValue& value) {
    if (std::holds_alternative<std::string>(value)) return "'" + std::get<std::string>(value) + "'";
    return toString(value);
}

[[noreturn]] void rejectValue(const ParamInfo& info, const ParamValue& value) {
    throw InputError(InputLocation{.field = info.name},
                     "expects " + allowedText(info) + ", got " + describeValue(value));
}

// The value converted to the declared type, or nullopt when no exact conversion exists.
std::optional<ParamValue> convertToType(ParamType type, const ParamValue& value) {
    if (matchesType(type, value)) return value;
    if (type == ParamType::Float && std::holds_alternative<std::int64_t>(value)) {
        const auto i = std::get<std::int64_t>(value);
        if (std::abs(static_cast<double>(i)) <= kExactIntegerLimit) return static_cast<double>(i);
    }
    if (type == ParamType::Int && std::holds_alternative<double>(value)) {
        const double d = std::get<double>(value);
        if (isExactInteger(d)) return static_cast<std::int64_t>(d);
    }
    if (type == ParamType::Rgb && std::holds_alternative<double>(value)) return Rgb(std::get<double>(value));
    if (type == ParamType::Rgb && std::holds_alternative<std::int64_t>(value)) {
        return Rgb(static_cast<double>(std::get<std::int64_t>(value)));
    }
    return std::nullopt;
}

bool inRange(const ParamInfo& info, double x) {
    return std::isfinite(x) && x >= info.min && x <= info.max;
}

bool isAllowed(const ParamInfo& info, const ParamValue& value) {
    switch (info.type) {
        case ParamType::Float:
            return inRange(info, std::get<double>(value));
        case ParamType::Int:
            return inRange(info, static_cast<double>(std::get<std::int64_t>(value)));
        case ParamType::Bool:
            return true;
        case ParamType::Enum: {
            const auto& e = info.enumValues;
            return std::find(e.begin(), e.end(), std::get<std::string>(value)) != e.end();
        }
        case ParamType::Rgb: {
            const Rgb c = std::get<Rgb>(value);
            return inRange(info, c.r) && inRange(info, c.g) && inRange(info, c.b);
        }
    }
    return false;
}

}  // namespace

ParamSet::ParamSet(std::vector<ParamInfo> infos) : infos_(std::move(infos)) {
    for (const ParamInfo& info : infos_) {
        TY_CHECK(!values_.count(info.name), "parameter '" + info.name + "' is declared twice");
        TY_CHECK(matchesType(info.type, info.defaultValue),
                 "default of parameter '" + info.name + "' is not of type " + toString(info.type));
        TY_CHECK(isAllowed(info, info.defaultValue), "default of parameter '" + info.name + "' is not allowed");
        values_[info.name] = info.defaultValue;
    }
}

const ParamInfo* ParamSet::find(const std::string& name) const {
    for (const ParamInfo& info : infos_) {
        if (info.name == name) return &info;
    }
    return nullptr;
}

void ParamSet::set(const std::string& name, const ParamValue& value) {
    const ParamInfo* info = find(name);
    if (!info) {
        std::vector<std::string> known;
        for (const ParamInfo& i : infos_)
            known.push_back(i.name);
        const std::string nearest = nearestName(name, known);
        std::string message = "unknown parameter '" + clipForMessage(name) + "'";
        message += nearest.empty() ? "; known parameters: " + joined(known) : "; did you mean '" + nearest + "'?";
        throw InputError(InputLocation{.field = name}, message);
    }
    const std::optional<ParamValue> converted = convertToType(info->type, value);
    if (!converted) {
        throw InputError(InputLocation{.field = name}, "expects " + allowedText(*info) + ", got " +
                                                           valueTypeName(value) + " " + describeValue(value));
    }
    if (!isAllowed(*info, *converted)) rejectValue(*info, *converted);
    values_[name] = *converted;
}

const ParamValue& ParamSet::get(const std::string& name) const {
    const auto it = values_.find(name);
    TY_CHECK(it != values_.end(), "no parameter named '" + name + "'");
    return it->second;
}

double ParamSet::getFloat(const std::string& name) const {
    const ParamValue& v = get(name);
    TY_CHECK(std::holds_alternative<double>(v), "parameter '" + name + "' is not a float");
    return std::get<double>(v);
}

std::int64_t ParamSet::getInt(const std::string& name) const {
    const ParamValue& v = get(name);
    TY_CHECK(std::holds_alternative<std::int64_t>(v), "parameter '" + name + "' is not an int");
    return std::get<std::int64_t>(v);
}

bool ParamSet::getBool(const std::string& name) const {
    const ParamValue& v = get(name);
    TY_CHECK(std::holds_alternative<bool>(v), "parameter '" + name + "' is not a bool");
    return std::get<bool>(v);
}

const std::string& ParamSet::getEnum(const std::string& name) const {
    const ParamValue& v = get(name);
    TY_CHECK(std::holds_alternative<std::string>(v), "parameter '" + name + "' is not an enum");
    return std::get<std::string>(v);
}

Rgb ParamSet::getRgb(const std::string& name) const {
    const ParamValue& v = get(name);
    TY_CHECK(std::holds_alternative<Rgb>(v), "parameter '" + name + "' is not an RGB triple");
    return std::get<Rgb>(v);
}

const char* toString(ParamType type) {
    switch (type) {
        case ParamType::Float:
            return "float";
        case ParamType::Int:
            return "int";
        case ParamType::Bool:
            return "bool";
        case ParamType::Enum:
            return "enum";
        case ParamType::Rgb:
            return "rgb";
    }
    return "unknown";
}

std::string toString(const ParamValue& value) {
    if (const auto* d = std::get_if<double>(&value)) return formatNumber(*d);
    if (const auto* i = std::get_if<std::int64_t>(&value)) return std::to_string(*i);
    if (const auto* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
    if (const auto* s = std::get_if<std::string>(&value)) return *s;
    const Rgb c = std::get<Rgb>(value);
    return "[" + formatNumber(c.r) + ", " + formatNumber(c.g) + ", " + formatNumber(c.b) + "]";
}

}  // namespace tyndall
