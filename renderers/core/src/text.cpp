#include "tyndall/core/text.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace tyndall {

namespace {

std::string lowercase(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

std::size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> previous(b.size() + 1), current(b.size() + 1);
    std::iota(previous.begin(), previous.end(), std::size_t{0});
    for (std::size_t i = 1; i <= a.size(); ++i) {
        current[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t substitution = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitution});
        }
        std::swap(previous, current);
    }
    return previous[b.size()];
}

}  // namespace

std::string formatNumber(double value) {
    if (std::isnan(value)) return "nan";  // whatever its sign bit
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
}

std::string formatVec3(const Vec3& v) {
    return "[" + formatNumber(v.x) + ", " + formatNumber(v.y) + ", " + formatNumber(v.z) + "]";
}

std::string formatShort(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.6g", value);
    return buffer;
}

std::size_t utf8Boundary(const std::string& text, std::size_t limit) {
    if (text.size() <= limit) return text.size();
    std::size_t end = limit;
    while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80)
        --end;
    return end;
}

std::string clipForMessage(const std::string& text, std::size_t limit) {
    if (text.size() <= limit) return text;
    return text.substr(0, utf8Boundary(text, limit)) + "... (" + std::to_string(text.size()) + " bytes)";
}

std::string nearestName(const std::string& name, const std::vector<std::string>& known) {
    const std::string wanted = lowercase(name);
    const std::string* best = nullptr;
    std::size_t bestDistance = 0;
    for (const std::string& candidate : known) {
        const std::size_t d = editDistance(wanted, lowercase(candidate));
        if (!best || d < bestDistance) {
            best = &candidate;
            bestDistance = d;
        }
    }
    const std::size_t limit = std::max<std::size_t>(2, name.size() / 3);
    return best && bestDistance <= limit ? *best : "";
}

}  // namespace tyndall
