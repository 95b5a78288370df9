// Where Tyndall's data files are at run time (shaders/, tables/, projects/), so that an installed copy or an unpacked
// bundle runs away from the source tree it was built from.
#pragma once

#include <filesystem>

namespace tyndall {

// The folder that holds shaders/, tables/ and projects/: $TYNDALL_ROOT when it is set; else
// <executable>/../share/tyndall when that holds shaders/ (an installed layout: /usr/bin/tyndall and
// /usr/share/tyndall; in the bundle the executable is its dynamic loader, lib/ld-linux-x86-64.so.2, beside share/);
// else the source tree the build was configured from.
std::filesystem::path resourceRoot();

// resourceRoot() / "shaders": the GLSL sources the GPU paths compile at run time.
std::filesystem::path shaderDirectory();

}  // namespace tyndall
