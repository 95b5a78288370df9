#!/usr/bin/env bash
# The sanitizer stage of CI: the renderer library, the CLI and their tests built with AddressSanitizer and
# UndefinedBehaviorSanitizer (gcc, -fno-sanitize-recover: the first report fails the test), then the tests that
# exercise the library's CPU code and the CLI. Left out, for time (the whole .ci/run must stay under 25 minutes on
# 2 cores): the studio, the benchmarks, the reference's statistical tests (tyndall_reference_tests) and the GPU
# technique tests (lavapipe under ASan is several times slower). docs/testing.md has the numbers.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${TYNDALL_SANITIZER_BUILD_DIR:-$root/build-sanitizers}"

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTYNDALL_WARNINGS_AS_ERRORS=ON \
      -DTYNDALL_SANITIZERS=address,undefined -DTYNDALL_BUILD_STUDIO=OFF -DTYNDALL_BUILD_BENCHMARKS=OFF \
      ${CMAKE_CXX_COMPILER_LAUNCHER:+-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER}
cmake --build "$build" -j "$(nproc)" --target tyndall tyndall_renderers_tests tyndall_cli_tests \
      tyndall_cli_reliability_tests tyndall_fuzz_project_replay tyndall_fuzz_image_replay

# Mesa's lavapipe and LLVM keep allocations for the life of the process (the CLI's `info` enumerates devices).
export LSAN_OPTIONS="suppressions=$root/.ci/lsan.supp:print_suppressions=0"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# The tests labelled "sanitize" (tyndall_renderers_tests, the CLI's, the fuzz replays).
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" --timeout 1200 -L sanitize
