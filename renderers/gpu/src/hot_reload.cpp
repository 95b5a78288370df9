#include "tyndall/gpu/hot_reload.h"

#include <algorithm>
#include <map>

namespace fs = std::filesystem;

namespace tyndall::gpu {

HotShader::HotShader(fs::path path, std::vector<fs::path> includeDirs)
    : path_(std::move(path)), includeDirs_(std::move(includeDirs)) {
    reload();
}

HotShader::Stamp HotShader::stamp(const fs::path& file) {
    std::error_code ec;
    fs::file_time_type time = fs::last_write_time(file, ec);
    if (ec) return std::nullopt;
    return time;
}

HotShader::PollResult HotShader::poll() {
    for (const auto& [file, recorded] : watched_) {
        if (stamp(file) != recorded) return reload();
    }
    return PollResult::Unchanged;
}

HotShader::PollResult HotShader::reload() {
    // Stamp what we know of before compiling: an edit saved while the compiler runs then shows up on the next poll
    // instead of being recorded as already seen.
    std::map<fs::path, Stamp> before;
    for (const auto& [file, recorded] : watched_)
        before[file] = stamp(file);
    const fs::path self = fs::absolute(path_).lexically_normal();
    before.try_emplace(self, stamp(self));

    CompileResult result = compileGlsl(path_, includeDirs_);
    log_ = std::move(result.log);

    // After a failure keep watching the last good version's files too: the fix may be in a header that the broken
    // version no longer reached (e.g. when the error stopped it before an #include).
    std::vector<fs::path> files = result.dependencies;
    if (!result.ok) files.insert(files.end(), goodDependencies_.begin(), goodDependencies_.end());
    files.push_back(self);
    std::sort(files.begin(), files.end());
    files.erase(std::unique(files.begin(), files.end()), files.end());

    watched_.clear();
    for (const fs::path& file : files) {
        auto known = before.find(file);
        watched_.emplace_back(file, known != before.end() ? known->second : stamp(file));
    }

    if (!result.ok) {
        error_ = std::move(result.error);
        return PollResult::Failed;
    }
    spirv_ = std::move(result.spirv);
    goodDependencies_ = std::move(result.dependencies);
    error_.reset();
    ++generation_;
    return PollResult::Reloaded;
}

std::vector<fs::path> HotShader::dependencies() const {
    std::vector<fs::path> files;
    files.reserve(watched_.size());
    for (const auto& entry : watched_)
        files.push_back(entry.first);
    return files;
}

}  // namespace tyndall::gpu
