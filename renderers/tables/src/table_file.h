// The machinery shared by the fitted tables' files (LTSD tables, ltsd_table.cpp; LTC GGX tables, ltc_table.cpp):
// little-endian fields, atomic writes, reading a whole file, the 64-bit checksum's text form. The checksum itself is
// ltsdTableChecksum (FNV-1a 64 over the whole file with bytes [48, 56) taken as zero), which both formats store at
// offset 48 (docs/tables.md).
#pragma once

#include "tyndall/core/error.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

namespace tyndall::table_file {

inline constexpr std::size_t kChecksumOffset = 48;

// Little-endian fields; this machine and every target Tyndall builds for are little-endian.
template <typename T>
void put(std::vector<std::uint8_t>& bytes, std::size_t offset, T value) {
    std::memcpy(bytes.data() + offset, &value, sizeof(T));
}
template <typename T>
T get(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
    T value;
    std::memcpy(&value, bytes.data() + offset, sizeof(T));
    return value;
}

inline void writeAtomically(const std::filesystem::path& file, const void* data, std::size_t size) {
    const std::filesystem::path tmp = file.string() + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw InputError(InputLocation{file.string(), 0, 0, ""}, "cannot write the file");
        out.write(static_cast<const char*>(data), std::streamsize(size));
        if (!out) throw InputError(InputLocation{file.string(), 0, 0, ""}, "cannot write the file");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, file, ec);
    if (ec) throw InputError(InputLocation{file.string(), 0, 0, ""}, "cannot write the file: " + ec.message());
}

inline std::string hex64(std::uint64_t v) {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
    return text;
}

// The whole file; an InputError naming it ("cannot open the <what>") when it cannot be read.
inline std::vector<std::uint8_t> readAll(const std::filesystem::path& file, const std::string& what) {
    std::ifstream in(file, std::ios::binary);
    if (!in)
        throw InputError(InputLocation{file.string(), 0, 0, ""},
                         "cannot open the " + what + " (set TYNDALL_TABLES_DIR or --tables to the folder holding it)");
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace tyndall::table_file
