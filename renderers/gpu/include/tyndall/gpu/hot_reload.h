// Shader hot reload: a shader file, its current SPIR-V and the files it depends on. The caller polls (once a frame, or
// between renders); when the shader or any header it included has changed, poll() recompiles. Success swaps in the
// new SPIR-V and bumps the generation, so the caller rebuilds its pipeline; failure keeps the last good SPIR-V running
// and exposes the error with its file and line. No threads: poll() runs on the caller's thread and costs one stat()
// per dependency when nothing changed.
#pragma once

#include "tyndall/gpu/shader_compiler.h"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tyndall::gpu {

class HotShader {
public:
    enum class PollResult {
        Unchanged,  // no dependency changed since the last compilation
        Reloaded,   // recompiled: new SPIR-V, generation() bumped, error() cleared
        Failed,     // recompiled and failed: SPIR-V and generation unchanged, error() set
    };

    // Compiles the shader once. A failure does not throw: hasSpirv() is false, error() says why, and poll() retries
    // when a file changes.
    explicit HotShader(std::filesystem::path path,
                       std::vector<std::filesystem::path> includeDirs = defaultShaderIncludeDirs());

    // Recompiles when the shader or one of its headers has a new modification time (or appeared or vanished).
    PollResult poll();

    // Recompiles now, whether or not anything changed.
    PollResult reload();

    const std::filesystem::path& path() const { return path_; }
    bool hasSpirv() const { return !spirv_.empty(); }
    const std::vector<std::uint32_t>& spirv() const { return spirv_; }       // the last good SPIR-V; empty if none yet
    std::uint64_t generation() const { return generation_; }                 // 0 until the first success, +1 per reload
    const std::optional<ShaderDiagnostic>& error() const { return error_; }  // the error of the latest compilation
    const std::string& log() const { return log_; }                          // glslang's log of the latest compilation
    std::vector<std::filesystem::path> dependencies() const;                 // the files poll() watches

private:
    using Stamp = std::optional<std::filesystem::file_time_type>;  // nullopt: the file does not exist

    static Stamp stamp(const std::filesystem::path& file);

    std::filesystem::path path_;
    std::vector<std::filesystem::path> includeDirs_;
    std::vector<std::pair<std::filesystem::path, Stamp>> watched_;
    std::vector<std::filesystem::path> goodDependencies_;  // the dependencies of the last good SPIR-V
    std::vector<std::uint32_t> spirv_;
    std::uint64_t generation_ = 0;
    std::optional<ShaderDiagnostic> error_;
    std::string log_;
};

}  // namespace tyndall::gpu
