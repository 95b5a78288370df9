#!/usr/bin/env bash
# Configures BUILD_DIR (Ninja, RelWithDebInfo, warnings as errors) when it is not yet, and builds everything: what
# packaging/deb.sh and packaging/bundle.sh package.
#   packaging/configure-build.sh BUILD_DIR
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:?usage: packaging/configure-build.sh BUILD_DIR}
if [ ! -f "$build/CMakeCache.txt" ]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTYNDALL_WARNINGS_AS_ERRORS=ON
fi
cmake --build "$build" -j "$(nproc)"
