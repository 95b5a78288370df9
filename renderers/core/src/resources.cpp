#include "tyndall/core/resources.h"

#include <cstdlib>
#include <system_error>

#ifndef TYNDALL_SOURCE_ROOT
#error "TYNDALL_SOURCE_ROOT must name the source tree"
#endif

namespace tyndall {

std::filesystem::path resourceRoot() {
    if (const char* env = std::getenv("TYNDALL_ROOT"); env && *env) return env;
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const std::filesystem::path installed = exe.parent_path().parent_path() / "share" / "tyndall";
        if (std::filesystem::is_directory(installed / "shaders", ec)) return installed;
    }
    return TYNDALL_SOURCE_ROOT;
}

std::filesystem::path shaderDirectory() {
    return resourceRoot() / "shaders";
}

}  // namespace tyndall
