#!/usr/bin/env bash
# Installs the dependencies, builds Tyndall with warnings as errors, runs the whole test suite with ctest, the Debian
# package's test (packaging/test-deb.sh), the relocatable bundle's test in an empty chroot (packaging/test-bundle.sh),
# and then the sanitizer stage (packaging/test-sanitizers.sh: the library, the
# CLI and their tests under AddressSanitizer and UBSan, in a second build folder beside the first).
# TYNDALL_SKIP_SANITIZERS=1 skips that stage.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${TYNDALL_BUILD_DIR:-$root/build}"

"$root/packaging/install-deps.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTYNDALL_WARNINGS_AS_ERRORS=ON
cmake --build "$build" -j "$(nproc)"
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" --timeout 1200
# The Debian package from this build: lintian, apt-get install, a render and the studio from /usr (then removed).
"$root/packaging/test-deb.sh" "$build"
# The relocatable bundle from this build, unpacked into an empty root: without a driver, then with lavapipe's.
"$root/packaging/test-bundle.sh" "$build"
if [ "${TYNDALL_SKIP_SANITIZERS:-0}" != 1 ]; then
    TYNDALL_SANITIZER_BUILD_DIR="${TYNDALL_SANITIZER_BUILD_DIR:-$build-sanitizers}" "$root/packaging/test-sanitizers.sh"
fi
