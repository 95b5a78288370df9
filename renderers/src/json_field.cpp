#include "json_field.h"

#include "tyndall/params.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

namespace tyndall {

namespace {

constexpr std::size_t kMaxDescribedLength = 60;

std::string jsonTypeName(const nlohmann::json& value) {
    if (value.is_number_float()) return "number";
    if (value.is_number()) return "integer";
    return value.type_name();
}

bool isIntegral(double value) {
    return std::isfinite(value) && value == std::floor(value);
}

}  // namespace

std::string formatNumber(double value) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
}

std::string formatVec3(const Vec3& v) {
    return "[" + formatNumber(v.x) + ", " + formatNumber(v.y) + ", " + formatNumber(v.z) + "]";
}

std::string describeJson(const nlohmann::json& value) {
    if (value.is_null()) return "null";
    std::string text = value.dump();
    if (text.size() > kMaxDescribedLength) text = text.substr(0, kMaxDescribedLength) + "...";
    return jsonTypeName(value) + " " + text;
}

const nlohmann::json& JsonField::json() const {
    TY_CHECK(value_ != nullptr, "reading the absent field " + path_);
    return *value_;
}

void JsonField::fail(const std::string& message) const {
    throw InputError(InputLocation{.file = *file_, .field = path_}, message);
}

void JsonField::failType(const char* expected) const {
    if (!present()) fail(std::string("is missing; expected ") + expected);
    fail(std::string("must be ") + expected + ", got " + describeJson(*value_));
}

JsonField JsonField::operator[](std::string_view key) const {
    const std::string path = path_.empty() ? std::string(key) : path_ + "." + std::string(key);
    const nlohmann::json& object = json();
    const auto it = object.find(key);
    return JsonField(it == object.end() ? nullptr : &*it, path, *file_);
}

JsonField JsonField::operator[](std::size_t index) const {
    return JsonField(&json().at(index), path_ + "[" + std::to_string(index) + "]", *file_);
}

void JsonField::expectObject(const std::vector<std::string>& known) const {
    if (!present() || !value_->is_object()) failType("an object");
    for (const auto& [key, value] : value_->items()) {
        if (std::find(known.begin(), known.end(), key) != known.end()) continue;
        const std::string nearest = nearestName(key, known);
        std::string message = "unknown key '" + key + "'; ";
        if (!nearest.empty()) {
            message += "did you mean '" + nearest + "'?";
        } else {
            message += "allowed keys:";
            for (const std::string& k : known)
                message += " " + k;
        }
        (*this)[key].fail(message);
    }
}

std::size_t JsonField::arraySize() const {
    if (!present() || !value_->is_array()) failType("an array");
    return value_->size();
}

double JsonField::number() const {
    if (!present() || !value_->is_number()) failType("a number");
    const double value = value_->get<double>();
    requireFinite(*this, value);
    return value;
}

std::int64_t JsonField::integer() const {
    if (present() && value_->is_number_unsigned()) {
        const auto u = value_->get<std::uint64_t>();
        if (u > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) failType("a smaller integer");
        return static_cast<std::int64_t>(u);
    }
    if (present() && value_->is_number_integer()) return value_->get<std::int64_t>();
    // 2^63 is exact in double; integral doubles below it convert exactly.
    if (present() && value_->is_number_float() && isIntegral(value_->get<double>()) &&
        std::abs(value_->get<double>()) < 0x1.0p63) {
        return static_cast<std::int64_t>(value_->get<double>());
    }
    failType("an integer");
}

std::uint64_t JsonField::unsignedInteger() const {
    if (present() && value_->is_number_unsigned()) return value_->get<std::uint64_t>();
    if (present() && value_->is_number_float()) {
        const double d = value_->get<double>();
        if (isIntegral(d) && d >= 0.0 && d < 0x1.0p64) return static_cast<std::uint64_t>(d);
    }
    failType("a non-negative integer");
}

bool JsonField::boolean() const {
    if (!present() || !value_->is_boolean()) failType("true or false");
    return value_->get<bool>();
}

const std::string& JsonField::string() const {
    if (!present() || !value_->is_string()) failType("a string");
    return value_->get_ref<const std::string&>();
}

Vec3 JsonField::vec3() const {
    if (!present() || !value_->is_array() || value_->size() != 3) failType("an array of 3 numbers");
    for (const nlohmann::json& c : *value_) {
        if (!c.is_number()) failType("an array of 3 numbers");
    }
    const Vec3 v((*value_)[0].get<double>(), (*value_)[1].get<double>(), (*value_)[2].get<double>());
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) fail("must be finite, got " + formatVec3(v));
    return v;
}

Rgb JsonField::rgb() const {
    if (present() && value_->is_number()) return Rgb(number());
    if (!present() || !value_->is_array() || value_->size() != 3) failType("[r, g, b] or one number (grey)");
    return vec3();
}

std::vector<double> JsonField::numbers() const {
    std::vector<double> values(arraySize());
    for (std::size_t i = 0; i < values.size(); ++i)
        values[i] = (*this)[i].number();
    return values;
}

std::vector<Vec3> JsonField::vec3s() const {
    std::vector<Vec3> values(arraySize());
    for (std::size_t i = 0; i < values.size(); ++i)
        values[i] = (*this)[i].vec3();
    return values;
}

int JsonField::intInRangeOr(int fallback, int lo, int hi) const {
    if (!present()) return fallback;
    const std::int64_t value = integer();
    if (value < lo || value > hi) {
        fail("must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
             std::to_string(value));
    }
    return static_cast<int>(value);
}

void requireFinite(const JsonField& field, double value) {
    if (!std::isfinite(value)) field.fail("must be finite, got " + formatNumber(value));
}

void requireAtLeast(const JsonField& field, double value, double lo) {
    if (!(value >= lo)) field.fail("must be >= " + formatNumber(lo) + ", got " + formatNumber(value));
}

void requireAbove(const JsonField& field, double value, double lo) {
    if (!(value > lo)) field.fail("must be > " + formatNumber(lo) + ", got " + formatNumber(value));
}

void requireInRange(const JsonField& field, double value, double lo, double hi) {
    if (!(value >= lo && value <= hi)) {
        field.fail("must be in [" + formatNumber(lo) + ", " + formatNumber(hi) + "], got " + formatNumber(value));
    }
}

void requireInOpenRange(const JsonField& field, double value, double lo, double hi) {
    if (!(value > lo && value < hi)) {
        field.fail("must be in (" + formatNumber(lo) + ", " + formatNumber(hi) + "), got " + formatNumber(value));
    }
}

void requireEachAtLeast(const JsonField& field, const Vec3& value, double lo) {
    if (!(value.x >= lo && value.y >= lo && value.z >= lo)) {
        field.fail("each component must be >= " + formatNumber(lo) + ", got " + formatVec3(value));
    }
}

void requireEachAbove(const JsonField& field, const Vec3& value, double lo) {
    if (!(value.x > lo && value.y > lo && value.z > lo)) {
        field.fail("each component must be > " + formatNumber(lo) + ", got " + formatVec3(value));
    }
}

void requireEachInRange(const JsonField& field, const Vec3& value, double lo, double hi) {
    const auto in = [&](double c) { return c >= lo && c <= hi; };
    if (!(in(value.x) && in(value.y) && in(value.z))) {
        field.fail("each component must be in [" + formatNumber(lo) + ", " + formatNumber(hi) + "], got " +
                   formatVec3(value));
    }
}

void requireNonZero(const JsonField& field, const Vec3& value) {
    if (value == Vec3(0.0)) field.fail("must not be the zero vector");
}

}  // namespace tyndall
