#!/usr/bin/env bash
# The sanitizer stage of CI: the renderer library, the CLI and their tests built with AddressSanitizer and
# UndefinedBehaviorSanitizer (clang, -fno-sanitize-recover: the first report fails the test), then the tests that
# exercise the library's CPU code and the CLI, the fuzz targets' replays of their corpora and their deterministic
# libFuzzer short runs (the same build: clang's -fsanitize=fuzzer-no-link adds the coverage libFuzzer needs). Left out, for time (the whole .ci/run must stay under 25 minutes on
# 2 cores): the studio, the benchmarks, the reference's statistical tests (tyndall_reference_tests) and the GPU
# technique tests (lavapipe under ASan is several times slower). docs/testing.md has the numbers.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${TYNDALL_SANITIZER_BUILD_DIR:-$root/build-sanitizers}"

# -O1 -g1 (and NDEBUG, as in the main build): the optimisation the sanitizers' documentation recommends, and line
# tables for the reports' stacks; both compile much faster than -O2 -g, which is what fits the stage into the budget.
cxx=${TYNDALL_SANITIZER_CXX:-clang++-14}
cc=${TYNDALL_SANITIZER_CC:-clang-14}
if ! command -v "$cxx" >/dev/null; then
    echo "sanitizers: $cxx is missing (packaging/debian-packages.txt lists clang-14; run packaging/install-deps.sh)" >&2
    exit 1
fi
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_C_COMPILER="$cc" \
      -DTYNDALL_FUZZ=ON -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g1 -DNDEBUG" \
      -DCMAKE_C_FLAGS_SANITIZE="-O1 -g1 -DNDEBUG" -DTYNDALL_WARNINGS_AS_ERRORS=ON \
      -DTYNDALL_SANITIZERS=address,undefined -DTYNDALL_BUILD_STUDIO=OFF -DTYNDALL_BUILD_BENCHMARKS=OFF \
      ${CMAKE_CXX_COMPILER_LAUNCHER:+-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER}
cmake --build "$build" -j "$(nproc)" --target tyndall tyndall_core_tests tyndall_framework_tests tyndall_image_tests tyndall_tables_tests \
      tyndall_project_tests tyndall_shared_tests tyndall_cli_tests \
      tyndall_cli_reliability_tests tyndall_fuzz_project_replay tyndall_fuzz_image_replay tyndall_fuzz_project \
      tyndall_fuzz_image

# Mesa's lavapipe and LLVM keep allocations for the life of the process (the CLI's `info` enumerates devices). Their
# suppressions match only while the driver is loaded when LeakSanitizer reports at exit: since Debian's Mesa
# 22.3.6-1+deb12u2 (December 2026) even device enumeration leaves such an allocation, reported from an unloaded module,
# so every test process keeps its modules loaded (.ci/keep_modules.c, preloaded; the ASan runtime is linked
# statically by clang, so it need not come first).
export LSAN_OPTIONS="suppressions=$root/.ci/lsan.supp:print_suppressions=0"
"$cc" -shared -fPIC -O2 -o "$build/libtyndall_keep_modules.so" "$root/.ci/keep_modules.c"
export LD_PRELOAD="$build/libtyndall_keep_modules.so"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# The test programs of the library and the CLI, and the fuzz replays. Each program runs as one process, two at a time:
# ctest would start a process per test case, and a sanitized process takes about a second to start (4 minutes of
# tests become 1.5). Left out: the ISV render on lavapipe (Cli.RendersTheIsvSmoke...): lavapipe's geometry-stage code
# leaks 112 bytes from a module it has unloaded by the time LeakSanitizer reports, so the report names no module that
# a suppression could match, and a full unwind on every allocation (fast_unwind_on_malloc=0) makes the render take
# minutes. That test runs in the plain build.
logs="$build/sanitizer-logs"
mkdir -p "$logs"
run_tests() {  # name folder program [arguments]
    local name=$1 dir=$2
    shift 2
    if (cd "$build/$dir" && "$@") >"$logs/$name.log" 2>&1; then
        echo "sanitizers: passed $name ($(grep -a -c '^\[       OK \]' "$logs/$name.log") tests)"
    else
        echo "sanitizers: FAILED $name; the end of $logs/$name.log:"
        tail -n 200 "$logs/$name.log"
        return 1
    fi
}
status=0
(
    s=0
    # The renderer library's unit tests, one program per layer (renderers/<layer>/test, shaders/shared/test).
    for layer in core framework image tables project; do
        run_tests "$layer" "renderers/$layer/test" "./tyndall_${layer}_tests" || s=1
    done
    run_tests shared shaders/shared/test ./tyndall_shared_tests || s=1
    run_tests reliability tests ./tyndall_cli_reliability_tests || s=1
    exit $s
) &
first=$!
run_tests cli tests ./tyndall_cli_tests '--gtest_filter=-Cli.RendersTheIsvSmoke*' || status=1
wait "$first" || status=1
# The fuzz targets: the replays of the seeds and past findings, and libFuzzer's short runs (a fixed seed and run count,
# fuzz/CMakeLists.txt), two at a time. They unwind fully on every allocation: the leak that OpenImageIO's PNG reader
# leaves (.ci/lsan.supp) is allocated inside libstdc++, where the fast unwinder stops, so without a full stack no
# suppression can name it.
LSAN_OPTIONS="$LSAN_OPTIONS:fast_unwind_on_malloc=0" ctest --test-dir "$build" --output-on-failure -j 2 -R '^Fuzz\.' || status=1
exit "$status"
