// Reading user JSON with errors that name the field: a JsonField is a value (or its absence) together with its path
// in the document ("lights[2].radiance"), and every read checks the type and reports what was found.
#pragma once

#include "tyndall/core/error.h"
#include "tyndall/core/scene.h"
#include "tyndall/core/text.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tyndall {

// A JSON value for an error message: its type and (truncated) text, e.g. `string "nan"`.
std::string describeJson(const nlohmann::json& value);

// Nesting deeper than this is refused before parsing (project files nest about 6 levels), so that no recursive walk
// over a document (nlohmann's dump, comparison, our readers) can exhaust the stack.
inline constexpr int kMaxJsonDepth = 64;

// Checks JSON text for what nlohmann's parser accepts silently or reports without a position: nesting deeper than
// kMaxJsonDepth, NUL bytes (the parser stops at the first one and ignores the rest), duplicate keys in an object (the
// parser keeps the last), numbers too large for a double and invalid UTF-8. Throws an InputError with the line,
// column and field path of the first problem; `fieldPrefix` is prepended to the path (e.g. "--set camera"). Text that
// is not JSON at all is left to the parser.
bool isValidUtf8(const std::string& text);
void checkJsonText(const std::string& text, const std::string& file, const std::string& fieldPrefix = "");

class JsonField {
public:
    // `value` may be null (an absent key); `file` must outlive the field.
    JsonField(const nlohmann::json* value, std::string path, const std::string& file)
        : value_(value), path_(std::move(path)), file_(&file) {}

    bool present() const { return value_ != nullptr; }
    const nlohmann::json& json() const;
    const std::string& path() const { return path_; }
    const std::string& file() const { return *file_; }

    // Throws InputError at this field.
    [[noreturn]] void fail(const std::string& message) const;

    // A member of this object (absent when missing) and an element of this array.
    JsonField operator[](std::string_view key) const;
    JsonField operator[](std::size_t index) const;

    // Checks that this is an object whose keys are all in `known`; an unknown key fails at that key with the nearest
    // known key as a suggestion.
    void expectObject(const std::vector<std::string>& known) const;
    // Checks that this is an array and returns its size.
    std::size_t arraySize() const;

    double number() const;  // any finite JSON number
    std::int64_t integer() const;
    std::uint64_t unsignedInteger() const;
    bool boolean() const;
    const std::string& string() const;
    Vec3 vec3() const;  // [x, y, z]
    Rgb rgb() const;    // [r, g, b] or one number for grey
    std::vector<double> numbers() const;
    std::vector<Vec3> vec3s() const;

    double numberOr(double fallback) const { return present() ? number() : fallback; }
    bool booleanOr(bool fallback) const { return present() ? boolean() : fallback; }
    std::string stringOr(const std::string& fallback) const { return present() ? string() : fallback; }
    Vec3 vec3Or(const Vec3& fallback) const { return present() ? vec3() : fallback; }
    Rgb rgbOr(const Rgb& fallback) const { return present() ? rgb() : fallback; }
    std::vector<double> numbersOr(const std::vector<double>& fallback) const {
        return present() ? numbers() : fallback;
    }
    std::uint64_t unsignedIntegerOr(std::uint64_t fallback) const { return present() ? unsignedInteger() : fallback; }
    // An integer in [lo, hi], or the fallback when absent.
    int intInRangeOr(int fallback, int lo, int hi) const;

private:
    [[noreturn]] void failType(const char* expected) const;

    const nlohmann::json* value_;
    std::string path_;
    const std::string* file_;
};

// Range rules. Each fails at `field` with the value and what is allowed.
void requireFinite(const JsonField& field, double value);
void requireAtLeast(const JsonField& field, double value, double lo);                 // value >= lo
void requireAbove(const JsonField& field, double value, double lo);                   // value > lo
void requireInRange(const JsonField& field, double value, double lo, double hi);      // lo <= value <= hi
void requireInOpenRange(const JsonField& field, double value, double lo, double hi);  // lo < value < hi
void requireEachAtLeast(const JsonField& field, const Vec3& value, double lo);
void requireEachAbove(const JsonField& field, const Vec3& value, double lo);
void requireEachInRange(const JsonField& field, const Vec3& value, double lo, double hi);
void requireNonZero(const JsonField& field, const Vec3& value);

}  // namespace tyndall
