// GLSL to SPIR-V at run time with glslang, for hot reload and for shaders assembled in code. Targets Vulkan 1.2 /
// SPIR-V 1.5. `#include "shared/x.h"` (GL_GOOGLE_include_directive) resolves relative to the including file first, then
// against the include directories (by default the source tree's shaders/ folder). Build-time compilation of the
// shipped shaders is shaders/CMakeLists.txt's job; this is the same compiler, in process.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace tyndall::gpu {

enum class ShaderStage { Compute, Vertex, Geometry, Fragment, Mesh, Task };

// "comp", "vert", "geom", "frag", "mesh", "task": the stage's part of a file name.
const char* stageName(ShaderStage stage);

// The stage of a file named <name>.<stage>.glsl (e.g. "blur.comp.glsl"); nullopt for any other name.
std::optional<ShaderStage> stageFromPath(const std::filesystem::path& path);

// The include directories used when the caller gives none: the source tree's shaders/ folder.
std::vector<std::filesystem::path> defaultShaderIncludeDirs();

// The first error of a compilation: the file it is in (the shader itself or the header that holds it) and the line.
struct ShaderDiagnostic {
    std::string file;     // as glslang names it: the shader's path or virtual name, or a header's resolved path
    int line = 0;         // 1-based; 0 when the message has no location (e.g. a link error)
    std::string message;  // glslang's text after the location
    std::string toString() const;  // "file:line: message"
};

struct CompileResult {
    std::vector<std::uint32_t> spirv;                 // empty unless ok
    std::string log;                                  // glslang's full info log (compile, link and SPIR-V generation)
    std::optional<ShaderDiagnostic> error;            // the first error; set exactly when !ok
    std::vector<std::filesystem::path> dependencies;  // the shader file (when compiled from a file) and every header
                                                      // it read, resolved, sorted, without duplicates
    bool ok = false;
};

// Thrown by compileGlslOrThrow: a compile error in a shader, as a typed error that carries the diagnostic.
class ShaderError : public std::runtime_error {
public:
    explicit ShaderError(ShaderDiagnostic diagnostic)
        : std::runtime_error(diagnostic.toString()), diagnostic_(std::move(diagnostic)) {}
    const ShaderDiagnostic& diagnostic() const { return diagnostic_; }
    const std::string& file() const { return diagnostic_.file; }
    int line() const { return diagnostic_.line; }

private:
    ShaderDiagnostic diagnostic_;
};

// Compiles a shader file; the stage comes from its name (see stageFromPath). A file that cannot be read, or whose name
// names no stage, is reported as an error of that file (line 0). Thread-safe.
CompileResult compileGlsl(const std::filesystem::path& path,
                          const std::vector<std::filesystem::path>& includeDirs = defaultShaderIncludeDirs());

// Compiles source text. `virtualName` is the name errors report for it and the base of its relative includes (a path
// in the source tree works best; a bare name resolves relative includes against the current directory).
CompileResult compileGlslSource(const std::string& source, const std::string& virtualName, ShaderStage stage,
                                const std::vector<std::filesystem::path>& includeDirs = defaultShaderIncludeDirs());

// compileGlsl, throwing ShaderError on failure.
std::vector<std::uint32_t> compileGlslOrThrow(
    const std::filesystem::path& path,
    const std::vector<std::filesystem::path>& includeDirs = defaultShaderIncludeDirs());

// The first "ERROR: file:line: message" of a glslang info log; nullopt when the log has no error line.
std::optional<ShaderDiagnostic> parseFirstGlslangError(const std::string& log);

}  // namespace tyndall::gpu
