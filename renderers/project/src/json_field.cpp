#include "json_field.h"

#include "tyndall/core/params.h"

#include <clocale>
#include <locale.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <unordered_set>

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

std::string describeJson(const nlohmann::json& value) {
    if (value.is_null()) return "null";
    // A long string or array is not serialised whole just to be cut.
    if (value.is_string()) {
        const std::string& s = value.get_ref<const std::string&>();
        const std::size_t end = utf8Boundary(s, kMaxDescribedLength);
        std::string text = nlohmann::json(s.substr(0, end)).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
        if (end < s.size()) text += "... (" + std::to_string(s.size()) + " bytes)";
        return "string " + text;
    }
    if (value.is_structured() && value.size() > kMaxDescribedLength) {
        return jsonTypeName(value) + " of " + std::to_string(value.size()) + (value.is_array() ? " elements" : " keys");
    }
    std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    if (text.size() > kMaxDescribedLength) text = clipForMessage(text, kMaxDescribedLength);
    return jsonTypeName(value) + " " + text;
}

namespace {

// Length of the valid UTF-8 sequence at text[i], or 0 when it is not valid (overlong forms, surrogates and code
// points above U+10FFFF are invalid).
std::size_t utf8SequenceLength(const std::string& text, std::size_t i) {
    const auto byte = [&](std::size_t k) { return k < text.size() ? static_cast<unsigned char>(text[k]) : 0u; };
    const unsigned c = byte(i);
    if (c < 0x80) return 1;
    const auto continuation = [&](std::size_t k, unsigned lo, unsigned hi) { return byte(k) >= lo && byte(k) <= hi; };
    if (c >= 0xC2 && c <= 0xDF) return continuation(i + 1, 0x80, 0xBF) ? 2 : 0;
    if (c >= 0xE0 && c <= 0xEF) {
        const unsigned lo = c == 0xE0 ? 0xA0 : 0x80, hi = c == 0xED ? 0x9F : 0xBF;
        return continuation(i + 1, lo, hi) && continuation(i + 2, 0x80, 0xBF) ? 3 : 0;
    }
    if (c >= 0xF0 && c <= 0xF4) {
        const unsigned lo = c == 0xF0 ? 0x90 : 0x80, hi = c == 0xF4 ? 0x8F : 0xBF;
        return continuation(i + 1, lo, hi) && continuation(i + 2, 0x80, 0xBF) && continuation(i + 3, 0x80, 0xBF) ? 4
                                                                                                                  : 0;
    }
    return 0;
}

// One open array or object while scanning.
struct Level {
    bool object = false;
    bool expectKey = true;  // objects: the next string is a key
    std::size_t index = 0;  // arrays: the element being read
    std::string key;        // objects: the key being read
    std::unordered_set<std::string> keys;
};

std::string fieldPath(const std::string& prefix, const std::vector<Level>& stack) {
    std::string path = prefix;
    for (const Level& level : stack) {
        if (level.object) {
            if (level.key.empty() && level.expectKey) break;
            path += (path.empty() ? "" : ".") + clipForMessage(level.key);
        } else {
            path += "[" + std::to_string(level.index) + "]";
        }
    }
    return path;
}

double parseCNumber(const std::string& token) {
    static const locale_t cLocale = ::newlocale(LC_ALL_MASK, "C", locale_t(0));
    return ::strtod_l(token.c_str(), nullptr, cLocale);
}

}  // namespace

bool isValidUtf8(const std::string& text) {
    for (std::size_t i = 0; i < text.size();) {
        const std::size_t length = utf8SequenceLength(text, i);
        if (length == 0) return false;
        i += length;
    }
    return true;
}

void checkJsonText(const std::string& text, const std::string& file, const std::string& fieldPrefix) {
    std::vector<Level> stack;
    int line = 1, column = 1;
    const auto fail = [&](const std::string& message) {
        throw InputError(InputLocation{.file = file, .line = line, .column = column, .field = fieldPath(fieldPrefix, stack)},
                         message);
    };
    const auto advance = [&](std::size_t from, std::size_t to) {
        for (std::size_t k = from; k < to; ++k) {
            if (text[k] == '\n') {
                ++line;
                column = 1;
            } else if ((static_cast<unsigned char>(text[k]) & 0xC0) != 0x80) {
                ++column;
            }
        }
    };
    std::size_t i = 0;
    while (i < text.size()) {
        const char c = text[i];
        std::size_t next = i + 1;
        if (c == '\0') fail("contains a NUL byte; a project file is UTF-8 text");
        if (utf8SequenceLength(text, i) == 0) fail("is not valid UTF-8 (byte 0x" + [&] {
            char hex[3];
            std::snprintf(hex, sizeof hex, "%02X", static_cast<unsigned char>(c));
            return std::string(hex);
        }() + ")");
        if (c == '"') {
            // A string: find its end; keys are remembered (without decoding escapes) to find duplicates.
            next = i + 1;
            while (next < text.size() && text[next] != '"') {
                if (text[next] == '\0') {
                    advance(i, next);
                    i = next;
                    fail("contains a NUL byte; a project file is UTF-8 text");
                }
                const std::size_t length = utf8SequenceLength(text, next);
                if (length == 0) {
                    advance(i, next);
                    i = next;
                    fail("is not valid UTF-8");
                }
                next += text[next] == '\\' ? 2 : length;
            }
            if (next >= text.size()) return;  // unterminated: the parser reports it
            ++next;
            if (!stack.empty() && stack.back().object && stack.back().expectKey) {
                Level& level = stack.back();
                std::string key = text.substr(i + 1, next - i - 2);
                level.expectKey = false;
                if (!level.keys.insert(key).second) {
                    level.key = key;
                    fail("duplicate key '" + clipForMessage(key) + "' (JSON keys must be unique within an object)");
                }
                level.key = std::move(key);
            }
        } else if (c == '[' || c == '{') {
            if (stack.size() >= static_cast<std::size_t>(kMaxJsonDepth)) {
                fail("nested deeper than " + std::to_string(kMaxJsonDepth) + " levels of arrays and objects (the limit)");
            }
            stack.push_back(Level{.object = c == '{'});
        } else if (c == ']' || c == '}') {
            if (stack.empty()) return;  // unbalanced: the parser reports it
            stack.pop_back();
        } else if (c == ',') {
            if (!stack.empty()) {
                Level& level = stack.back();
                if (level.object) {
                    level.expectKey = true;
                    level.key.clear();
                } else {
                    ++level.index;
                }
            }
        } else if (c == '-' || (c >= '0' && c <= '9')) {
            while (next < text.size() && std::strchr("+-.eE0123456789", text[next]) != nullptr && text[next] != '\0')
                ++next;
            const std::string token = text.substr(i, next - i);
            if (!std::isfinite(parseCNumber(token))) fail("the number " + clipForMessage(token) + " is too large for a double");
        }
        advance(i, next);
        i = next;
    }
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
        std::string message = "unknown key '" + clipForMessage(key) + "'; ";
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
    // "-0" parses as a signed integer 0: it is the number 0, so it is taken as such.
    if (present() && value_->is_number_integer() && value_->get<std::int64_t>() == 0) return 0;
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
