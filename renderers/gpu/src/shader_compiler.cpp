#include "tyndall/gpu/shader_compiler.h"

#include "tyndall/core/resources.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>
#include <utility>

namespace fs = std::filesystem;

namespace tyndall::gpu {

namespace {

// glslang's process-wide tables are built once; after that each compilation only touches its own TShader/TProgram.
void initializeGlslang() {
    static std::once_flag once;
    std::call_once(once, [] { glslang::InitializeProcess(); });
}

EShLanguage toGlslang(ShaderStage stage) {
    switch (stage) {
        case ShaderStage::Compute:
            return EShLangCompute;
        case ShaderStage::Vertex:
            return EShLangVertex;
        case ShaderStage::Geometry:
            return EShLangGeometry;
        case ShaderStage::Fragment:
            return EShLangFragment;
        case ShaderStage::Mesh:
            return EShLangMesh;
        case ShaderStage::Task:
            return EShLangTask;
    }
    return EShLangCompute;
}

std::optional<std::string> readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) return std::nullopt;
    return std::move(text).str();
}

fs::path normalized(const fs::path& path) {
    std::error_code ec;
    fs::path absolute = fs::absolute(path, ec);
    return (ec ? path : absolute).lexically_normal();
}

// Resolves `#include "x"` relative to the including file, then against the include directories; `#include <x>` only
// against the include directories. Headers are named by their normalized absolute path, so that errors inside them
// name the file and nested relative includes resolve from the header's own folder. Records every header it reads.
class Includer : public glslang::TShader::Includer {
public:
    explicit Includer(const std::vector<fs::path>& includeDirs) : includeDirs_(includeDirs) {}

    IncludeResult* includeLocal(const char* headerName, const char* includerName, size_t depth) override {
        if (depth > kMaxDepth) return nullptr;
        fs::path includer = includerName ? fs::path(includerName) : fs::path();
        return tryOpen(includer.parent_path() / headerName);
    }

    IncludeResult* includeSystem(const char* headerName, const char* /*includerName*/, size_t depth) override {
        if (depth > kMaxDepth) return nullptr;
        for (const fs::path& dir : includeDirs_) {
            if (IncludeResult* result = tryOpen(dir / headerName)) return result;
        }
        return nullptr;
    }

    void releaseInclude(IncludeResult* result) override {
        if (!result) return;
        delete static_cast<std::string*>(result->userData);
        delete result;
    }

    const std::set<fs::path>& headers() const { return headers_; }

private:
    static constexpr size_t kMaxDepth = 64;  // include guards stop real cycles; this stops unguarded ones

    IncludeResult* tryOpen(const fs::path& candidate) {
        std::error_code ec;
        if (!fs::is_regular_file(candidate, ec)) return nullptr;
        std::optional<std::string> text = readFile(candidate);
        if (!text) return nullptr;
        fs::path resolved = normalized(candidate);
        headers_.insert(resolved);
        auto* content = new std::string(std::move(*text));
        return new IncludeResult(resolved.string(), content->data(), content->size(), content);
    }

    const std::vector<fs::path>& includeDirs_;
    std::set<fs::path> headers_;
};

CompileResult failure(const std::string& file, const std::string& message) {
    CompileResult result;
    result.error = ShaderDiagnostic{file, 0, message};
    result.log = result.error->toString() + "\n";
    return result;
}

}  // namespace

const char* stageName(ShaderStage stage) {
    switch (stage) {
        case ShaderStage::Compute:
            return "comp";
        case ShaderStage::Vertex:
            return "vert";
        case ShaderStage::Geometry:
            return "geom";
        case ShaderStage::Fragment:
            return "frag";
        case ShaderStage::Mesh:
            return "mesh";
        case ShaderStage::Task:
            return "task";
    }
    return "?";
}

std::optional<ShaderStage> stageFromPath(const fs::path& path) {
    if (path.extension() != ".glsl") return std::nullopt;
    const std::string inner = path.stem().extension().string();
    for (ShaderStage stage : {ShaderStage::Compute, ShaderStage::Vertex, ShaderStage::Geometry, ShaderStage::Fragment,
                              ShaderStage::Mesh, ShaderStage::Task}) {
        if (inner == std::string(".") + stageName(stage)) return stage;
    }
    return std::nullopt;
}

std::vector<fs::path> defaultShaderIncludeDirs() {
    return {shaderDirectory()};
}

std::string ShaderDiagnostic::toString() const {
    std::string out = file;
    if (line > 0) out += ":" + std::to_string(line);
    return out + ": " + message;
}

std::optional<ShaderDiagnostic> parseFirstGlslangError(const std::string& log) {
    // glslang writes "ERROR: <file>:<line>: <message>", where <file> is the string's name (or its index when it has
    // none). Errors without a location ("ERROR: Linking compute stage: ...") come after the located ones, if at all.
    static const std::regex located(R"(^ERROR: (.+?):(\d+): (.*)$)");
    std::istringstream lines(log);
    std::string line;
    std::optional<ShaderDiagnostic> unlocated;
    while (std::getline(lines, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.rfind("ERROR: ", 0) != 0) continue;
        std::smatch match;
        if (std::regex_match(line, match, located)) {
            return ShaderDiagnostic{match[1].str(), std::stoi(match[2].str()), match[3].str()};
        }
        if (!unlocated) unlocated = ShaderDiagnostic{"", 0, line.substr(7)};
    }
    return unlocated;
}

CompileResult compileGlslSource(const std::string& source, const std::string& virtualName, ShaderStage stage,
                                const std::vector<fs::path>& includeDirs) {
    initializeGlslang();
    const EShLanguage language = toGlslang(stage);
    const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);

    glslang::TShader shader(language);
    const char* text = source.c_str();
    const int length = static_cast<int>(source.size());
    const char* name = virtualName.c_str();
    shader.setStringsWithLengthsAndNames(&text, &length, &name, 1);
    shader.setEnvInput(glslang::EShSourceGlsl, language, glslang::EShClientVulkan, 100);
    shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
    shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);

    Includer includer(includeDirs);
    CompileResult result;
    bool ok = shader.parse(GetDefaultResources(), 460, ENoProfile, false, false, messages, includer);
    result.log = shader.getInfoLog();

    glslang::TProgram program;
    if (ok) {
        program.addShader(&shader);
        ok = program.link(messages);
        result.log += program.getInfoLog();
    }
    if (ok) {
        spv::SpvBuildLogger logger;
        glslang::SpvOptions options;
        options.validate = false;  // spirv-val runs in the tests; the driver validates what it loads
        glslang::GlslangToSpv(*program.getIntermediate(language), result.spirv, &logger, &options);
        const std::string spvMessages = logger.getAllMessages();
        result.log += spvMessages;
        if (result.spirv.empty()) {
            ok = false;
            if (spvMessages.find("ERROR: ") == std::string::npos) result.log += "ERROR: SPIR-V generation failed\n";
        }
    }

    result.dependencies.assign(includer.headers().begin(), includer.headers().end());
    result.ok = ok;
    if (!ok) {
        result.spirv.clear();
        result.error = parseFirstGlslangError(result.log);
        if (!result.error) result.error = ShaderDiagnostic{virtualName, 0, "compilation failed"};
        // A string without a name is reported by index; ours has one, but keep the mapping in case.
        if (result.error->file.empty() || result.error->file == "0") result.error->file = virtualName;
    }
    return result;
}

CompileResult compileGlsl(const fs::path& path, const std::vector<fs::path>& includeDirs) {
    const std::optional<ShaderStage> stage = stageFromPath(path);
    if (!stage) {
        return failure(path.string(),
                       "cannot tell the shader stage from the file name (expected *.comp.glsl, *.vert.glsl, "
                       "*.geom.glsl, *.frag.glsl, *.mesh.glsl or *.task.glsl)");
    }
    const std::optional<std::string> source = readFile(path);
    if (!source) {
        CompileResult result = failure(path.string(), "cannot read the shader file");
        result.dependencies.push_back(normalized(path));  // so that a watcher notices when it appears
        return result;
    }
    CompileResult result = compileGlslSource(*source, path.string(), *stage, includeDirs);
    const fs::path self = normalized(path);
    if (std::find(result.dependencies.begin(), result.dependencies.end(), self) == result.dependencies.end()) {
        result.dependencies.insert(std::upper_bound(result.dependencies.begin(), result.dependencies.end(), self),
                                   self);
    }
    return result;
}

std::vector<std::uint32_t> compileGlslOrThrow(const fs::path& path, const std::vector<fs::path>& includeDirs) {
    CompileResult result = compileGlsl(path, includeDirs);
    if (!result.ok) throw ShaderError(*result.error);
    return std::move(result.spirv);
}

}  // namespace tyndall::gpu
