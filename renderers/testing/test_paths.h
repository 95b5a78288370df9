// Where a GPU test finds the source tree's files it reads (projects, shaders), its compiled test shaders and its
// scratch folder: the folders of the build that made it (compiled in), unless the environment names others, as the
// relocatable bundle's gpu-check.sh does (packaging/bundle.sh): $TYNDALL_TEST_SOURCE_DIR, $TYNDALL_TEST_SPIRV_DIR,
// $TYNDALL_TEST_TMP. And how a test runs its own executable again.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <string>

namespace tyndall::test {

inline std::string fromEnvironment(const char* variable, const char* built) {
    const char* value = std::getenv(variable);
    return value && *value ? std::string(value) : std::string(built);
}

#ifdef TYNDALL_SOURCE_DIR
inline std::string sourceDir() {
    return fromEnvironment("TYNDALL_TEST_SOURCE_DIR", TYNDALL_SOURCE_DIR);
}
#endif

#ifdef TYNDALL_TEST_TMP
inline std::string scratchDir() {
    return fromEnvironment("TYNDALL_TEST_TMP", TYNDALL_TEST_TMP);
}
#endif

#ifdef TYNDALL_GPU_TEST_SPIRV
inline std::string spirvDir() {
    return fromEnvironment("TYNDALL_TEST_SPIRV_DIR", TYNDALL_GPU_TEST_SPIRV);
}
#endif

// A shell command that runs this test executable again: /proc/PID/exe, or $TYNDALL_SELF_COMMAND where the bundle's
// launcher runs it through the bundle's dynamic loader (/proc/PID/exe is that loader there).
inline std::string selfCommand() {
    return fromEnvironment("TYNDALL_SELF_COMMAND", ("/proc/" + std::to_string(::getpid()) + "/exe").c_str());
}

}  // namespace tyndall::test
