// FNV-1a, 64 bit: the stable hash of project files, render metadata, sweep tasks and their outputs. Not for security:
// it tells versions apart, it does not authenticate them.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace tyndall {

inline constexpr std::uint64_t kFnv1aOffset = 0xCBF29CE484222325ull;

// Continues `hash` over `bytes`, so that several pieces hash as their concatenation.
inline std::uint64_t fnv1a(std::string_view bytes, std::uint64_t hash = kFnv1aOffset) {
    for (unsigned char c : bytes) {
        hash ^= c;
        hash *= 0x100000001B3ull;
    }
    return hash;
}

// 16 lower-case hex digits.
inline std::string hex16(std::uint64_t value) {
    char text[17];
    std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
    return text;
}

}  // namespace tyndall
