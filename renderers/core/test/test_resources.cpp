// resourceRoot(): $TYNDALL_ROOT when set, else (for a build-tree run) the source tree, which holds shaders/, tables/
// and projects/. (The installed layout, <executable>/../share/tyndall, needs an executable outside the build tree: the
// packaging's to test. Cli.DataFilesComeFromTyndallRoot checks that the GPU paths and the tables use the root.)
#include "tyndall/core/resources.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace tyndall {
namespace {

TEST(ResourceRoot, IsTheSourceTreeInABuildAndTyndallRootWhenSet) {
    ::unsetenv("TYNDALL_ROOT");
    EXPECT_EQ(std::filesystem::weakly_canonical(resourceRoot()), std::filesystem::weakly_canonical(TYNDALL_SOURCE_DIR));
    EXPECT_TRUE(std::filesystem::is_directory(shaderDirectory() / "shared"));
    ::setenv("TYNDALL_ROOT", "/opt/somewhere/share/tyndall", 1);
    EXPECT_EQ(resourceRoot(), std::filesystem::path("/opt/somewhere/share/tyndall"));
    EXPECT_EQ(shaderDirectory(), std::filesystem::path("/opt/somewhere/share/tyndall/shaders"));
    ::setenv("TYNDALL_ROOT", "", 1);  // empty: as if unset
    EXPECT_EQ(std::filesystem::weakly_canonical(resourceRoot()), std::filesystem::weakly_canonical(TYNDALL_SOURCE_DIR));
    ::unsetenv("TYNDALL_ROOT");
}

}  // namespace
}  // namespace tyndall
