// libFuzzer target: a project file, with --set overrides, read and validated as `tyndall validate` reads it, then each
// view's job made (technique, part, parameters) and the project saved and read back. It does not prepare scenes for
// rendering (Embree, OBJ files), which would cost milliseconds per input and keep it from millions of runs. Input: any
// number of leading lines "#set PATH=VALUE" (the overrides), then the project's JSON text, so that a bundled project
// file is itself a seed. InputError is the expected answer to bad input; anything else escaping (a ContractError, a
// standard exception) is a finding, and so is every sanitizer report.
#include "tyndall/core/error.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string text(reinterpret_cast<const char*>(data), size);
    std::vector<std::string> overrides;
    static constexpr std::string_view kSet = "#set ";
    while (text.starts_with(kSet)) {
        const std::size_t end = text.find('\n');
        overrides.push_back(text.substr(kSet.size(), end == std::string::npos ? std::string::npos : end - kSet.size()));
        text = end == std::string::npos ? std::string() : text.substr(end + 1);
    }
    try {
        const tyndall::Project project =
            tyndall::parseProject(tyndall::techniqueCatalogue(), text, "fuzz.json", overrides);
        for (const tyndall::View& view : project.views) {
            try {
                (void)tyndall::makeViewJob(project, "fuzz.json", view.name);
            } catch (const tyndall::InputError&) {
            }
        }
        // What is read must save and read back.
        (void)tyndall::parseProject(tyndall::techniqueCatalogue(), tyndall::projectToJson(project).dump(), "saved.json",
                                    {});
    } catch (const tyndall::InputError&) {
    }
    return 0;
}
